// The steps plots against collision index: v_A, v_B, v_C (simulated steps, closed-form
// dots, the paper's printed eqs. (2.15)/(2.16) where they differ, B on its own scale when
// it dwarfs A and C), the total energy and momentum of the finite masses, and the cursor
// on the current step.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct VelocityPanel {
  Axes axes;
  std::vector<std::size_t> bodies;
};

/// Body i's velocity steps: the plotted bodies', or (large scenes) the tracked bodies'.
const Envelope& stepsOf(const RunRecord& run, std::size_t i) {
  return largeScene(run) ? run.trackedVelocity(i) : run.velocity(i);
}

/// A series as drawn: held at its last value up to one past the last collision; a periodic
/// motion's first period only (a thousand periods would fill the panel with steps thinner
/// than a pixel).
Polyline shownSteps(const RunRecord& run, const Envelope& e) {
  const std::optional<Period> period = periodOf(run);
  if (!period) return withTail(e, static_cast<double>(run.collisions()) + 1);
  const double end = static_cast<double>(period->impacts) + 1.0;
  Polyline poly;
  for (const auto& v : e.polyline()) {
    if (v.x < end) poly.push_back(v);
  }
  if (!poly.empty()) poly.push_back({end, poly.back().y, poly.back().mark});
  return poly;
}

double largestSpeed(const Envelope& e) { return std::max(std::abs(e.minY()), std::abs(e.maxY())); }

/// The scale of a panel of these bodies: their steps and final velocities, and the
/// paper's values unless they would squash the simulated ones.
std::pair<double, double> velocityRange(const RunRecord& run, const std::vector<std::size_t>& bodies) {
  const auto final_v = finalVelocitiesNotDrawn(run);
  double lo = kInf, hi = -kInf;
  for (std::size_t i : bodies) {
    lo = std::min(lo, stepsOf(run, i).minY());
    hi = std::max(hi, stepsOf(run, i).maxY());
    if (final_v && std::isfinite(final_v->second[i])) {
      lo = std::min(lo, final_v->second[i]), hi = std::max(hi, final_v->second[i]);
    }
  }
  double paper_lo = lo, paper_hi = hi;
  for (std::size_t i : bodies) {
    paper_lo = std::min(paper_lo, run.paperVelocity(i).minY());
    paper_hi = std::max(paper_hi, run.paperVelocity(i).maxY());
  }
  if (paper_hi - paper_lo <= kPaperScaleFactor * (hi - lo)) lo = paper_lo, hi = paper_hi;
  return paddedRange(lo, hi);
}

/// One panel for the bodies the view shows (RunView::velocity_bodies), or (three bodies) B
/// on its own (top) when it dwarfs A and C.
std::vector<VelocityPanel> velocityPanels(const Canvas& c) {
  const RunRecord& run = c.run;
  const double x1 = indexAxisEnd(run, c.view);
  const auto panel = [&](const Box& box, const std::vector<std::size_t>& bodies) {
    const auto [y0, y1] = velocityRange(run, bodies);
    return VelocityPanel{Axes{box, 0.0, x1, y0, y1}, bodies};
  };
  std::vector<std::size_t> shown;
  for (const ViewBody& body : c.view.velocity_bodies) shown.push_back(body.index);
  if (run.bodies() != 3) return {panel(kVelocityBox, shown)};
  const double others = std::max(largestSpeed(run.velocity(0)), largestSpeed(run.velocity(2)));
  if (largestSpeed(run.velocity(1)) > kOwnScaleFactor * others) {
    const double middle = kVelocityBox.midY();
    return {panel({kVelocityBox.left, kVelocityBox.right, middle + kOwnPanelGap / 2, kVelocityBox.top}, {1}),
            panel({kVelocityBox.left, kVelocityBox.right, kVelocityBox.bottom, middle - kOwnPanelGap / 2}, {0, 2})};
  }
  return {panel(kVelocityBox, shown)};
}

/// The paper's series of body i where it differs from the simulated one; true when some
/// of it lies off the panel's scale.
bool addPaperSeries(const Canvas& c, const Axes& axes, std::size_t i, int id) {
  const Envelope& paper = c.run.paperVelocity(i);
  if (paper.empty()) return false;
  const double tolerance = kPaperTolerance * (axes.y1 - axes.y0);
  c.addLines(markedSegments(c, ns::kPlot, id, shownSteps(c.run, paper), axes, tolerance, color(kPaper)));
  return !(axes.contains(paper.minY()) && axes.contains(paper.maxY()));
}

/// The closed form's velocities of body i after each kept collision (and the final ones
/// when the steps do not get there), as dots on the steps; true when there are any.
bool addPredictedDots(const Canvas& c, const Axes& axes, std::size_t i, int id) {
  const auto final_v = finalVelocitiesNotDrawn(c.run);
  Marker predicted = c.dots(ns::kPlot, id, kPredictedDotSize, bodyColor(c.view, i, kDotLighten));
  for (const Keyframe* f : thinned(c.run.keyframes(), kMaxPredictedDots)) {
    if (i < f->predicted.size() && f->index + 0.5 < axes.x1) predicted.points.push_back(point(axes.toX(f->index + 0.5), axes.toY(f->predicted[i]), kDotZ));
  }
  if (final_v && i < final_v->second.size() && std::isfinite(final_v->second[i]) && final_v->first + 0.5 < axes.x1) predicted.points.push_back(point(axes.toX(final_v->first + 0.5), axes.toY(final_v->second[i]), kDotZ));
  if (predicted.points.empty()) return false;
  c.add(predicted);
  return true;
}

/// What the velocity panels drew besides the simulated steps, for the legend.
struct PaperShown {
  bool any = false, off_scale = false;
  bool dots = false;  ///< some closed-form dots
};

void addVelocityPanel(const Canvas& c, const VelocityPanel& panel, int p, std::size_t panels, PaperShown& paper) {
  const int base = kPlotPanelStride * p;
  const std::string label = panels == 1 ? "v [m/s]" : p == 0 ? "v_B [m/s]" : "v_A, v_C [m/s]";
  addFrame(c, ns::kPlot, base + kPlotFrame, panel.axes, label);
  if (largeScene(c.run)) {
    // The tracked bodies' steps, in their colours (the view's, as in the x-t diagram); no
    // closed form or paper's series for many bodies.
    for (std::size_t k = 0; k < panel.bodies.size(); ++k) {
      const std::size_t i = panel.bodies[k];
      addSeries(c, ns::kPlot, kPlotTracked + static_cast<int>(k), shownSteps(c.run, stepsOf(c.run, i)), panel.axes,
                bodyColor(c.view, i), kCursorWidth);
    }
    return;
  }
  for (std::size_t i : panel.bodies) {
    const int b = static_cast<int>(i);
    addSeries(c, ns::kPlot, base + kPlotSeries + b, shownSteps(c.run, c.run.velocity(i)), panel.axes, bodyColor(c.view, i));
    paper.dots = addPredictedDots(c, panel.axes, i, base + kPlotPredicted + b) || paper.dots;
    paper.any = paper.any || !c.run.paperVelocity(i).empty();
    paper.off_scale = addPaperSeries(c, panel.axes, i, base + kPlotPaper + b) || paper.off_scale;
  }
}

/// The plot's title, the legend (what the paper's series shows) and the series' names.
void addVelocityLegend(const Canvas& c, bool own_scale, const PaperShown& paper) {
  c.add(c.text(ns::kPlot, kPlotTitle, kVelocityBox.midX(), kPanelTitleY,
               own_scale ? "velocity vs collision index (B on its own scale)" : "velocity vs collision index",
               kTextSize));
  std::string legend = paper.dots ? "steps: simulated   dots: closed form" : "steps: simulated";
  if (paper.any) legend += "   pink: paper's eqs. (2.15)/(2.16) where they differ";
  if (paper.off_scale) legend += " (clipped)";
  // A prediction with the paper's values (max_possible_collision_count, the rotation
  // model's) beside a wall, where the printed formulas have no value.
  const bool paper_predicted = c.run.prediction && c.run.prediction->max_possible_collision_count > 0;
  if (!paper.any && paper_predicted && (isWall(c.run.input(), 0) || isWall(c.run.input(), 2))) {
    legend += "   paper's (2.15)/(2.16): undefined with a wall";
  }
  if (const auto period = periodOf(c.run)) {
    legend += "   periodic: one period drawn (" + withSeparators(period->impacts) + " impacts)";
  }
  // Many bodies: which ones, as the page says it (their colours: the scene's colour bar).
  if (largeScene(c.run)) legend = c.view.velocity_legend;
  c.add(c.text(ns::kPlot, kPlotLegend, kVelocityBox.midX(), kLegendY, legend, kSmallTextSize, color(kLabelGrey)));
  if (largeScene(c.run)) return;
  const auto& shown = c.view.velocity_bodies;
  for (std::size_t k = 0; k < shown.size(); ++k) {
    const int id = kPlotSeriesNames + static_cast<int>(shown[k].index);
    c.add(c.text(ns::kPlot, id, kVelocityBox.right + kSeriesNameDx, kVelocityBox.top - kSeriesNamePitch * static_cast<double>(k),
                 "v_" + shown[k].name, shown.size() <= 3 ? kTextSize : kSmallTextSize, bodyColor(c.view, shown[k].index)));
  }
}

void addConservedPlot(const Canvas& c, const Envelope& series, const Box& box, int base, const std::string& label) {
  const auto [y0, y1] = paddedRange(series.minY(), series.maxY());
  const Axes axes{box, 0.0, indexAxisEnd(c.run, c.view), y0, y1};
  addFrame(c, ns::kConserved, base, axes, label);
  addSeries(c, ns::kConserved, base + kConservedSeries, shownSteps(c.run, series), axes, color(kWhite), kConservedWidth);
  addIndexAxisLabels(c, ns::kConserved, base + kConservedIndexLabels, axes);
}

/// Kinetic energy against collision index, stepped: the total of the finite masses
/// (white), the heat so far (amber, when any), and each plotted body's (its colour).
void addEnergyPlot(const Canvas& c, const std::string& label) {
  const RunRecord& run = c.run;
  double lo = std::min(run.energy().minY(), run.energyLost().minY());
  double hi = std::max(run.energy().maxY(), run.energyLost().maxY());
  for (std::size_t i : run.plottedBodies()) lo = std::min(lo, run.bodyEnergy(i).minY()), hi = std::max(hi, run.bodyEnergy(i).maxY());
  const auto [y0, y1] = paddedRange(lo, hi);
  const Axes axes{kEnergyBox, 0.0, indexAxisEnd(run, c.view), y0, y1};
  addFrame(c, ns::kConserved, kConservedEnergy, axes, label);
  for (std::size_t i : run.plottedBodies()) {
    addSeries(c, ns::kConserved, kConservedEnergy + kConservedBodies + static_cast<int>(i),
              shownSteps(run, run.bodyEnergy(i)), axes, bodyColor(c.view, i), kCursorWidth);
  }
  addSeries(c, ns::kConserved, kConservedEnergy + kConservedSeries, shownSteps(run, run.energy()), axes, color(kWhite),
            kConservedWidth);
  if (run.energyLost().maxY() > 0) {
    addSeries(c, ns::kConserved, kConservedEnergy + kConservedLost, shownSteps(run, run.energyLost()), axes, color(kAmber),
              kConservedWidth);
  }
  addIndexAxisLabels(c, ns::kConserved, kConservedEnergy + kConservedIndexLabels, axes);
}

}  // namespace

void drawVelocitySteps(const Canvas& c) {
  const auto panels = velocityPanels(c);
  PaperShown paper;
  for (std::size_t p = 0; p < panels.size(); ++p) addVelocityPanel(c, panels[p], static_cast<int>(p), panels.size(), paper);
  addIndexAxisLabels(c, ns::kPlot, kPlotIndexLabels, panels.back().axes);
  addVelocityLegend(c, panels.size() > 1, paper);
}

void drawConservedSteps(const Canvas& c) {
  std::string energy = "E [J] vs collision index: white total";
  if (c.run.energyLost().maxY() > 0) energy += ", amber heat so far";
  if (!c.run.plottedBodies().empty()) energy += ", colours per body";
  std::string p = "p [kg m/s] of the finite masses vs collision index";
  if (c.run.summary && c.run.summary->simulated) {
    // Signed always: rviz draws '-' thin, beside a '+' it still reads as a sign.
    energy += ";  drift " + withSign("%.2g", c.run.summary->energy_relative_drift);
    const double drift = c.run.summary->momentum_relative_drift;
    p += std::isnan(drift) ? "; a wall takes some" : ";  drift " + withSign("%.2g", drift);
  }
  addEnergyPlot(c, energy);
  addConservedPlot(c, c.run.momentum(), kMomentumBox, kConservedMomentum, p);
}

void drawStepsCursor(const Canvas& c, const SceneState& state) {
  // The current step [k, k+1] of the index plots, across the velocity, energy and momentum
  // plots; a periodic motion's step within its period, and the periods so far.
  const Axes index{kVelocityBox, 0.0, indexAxisEnd(c.run, c.view), 0.0, 1.0};
  const std::optional<Period> period = periodOf(c.run);
  const std::uint64_t step = period ? period->inPeriod(state.time, state.collisions) : state.collisions;
  const double cx = index.toX(static_cast<double>(step) + 0.5);
  if (period) {
    c.add(c.text(ns::kPlotCursor, kStepsPeriods, kVelocityBox.right + kStepsPeriodsDx, kLegendY + kWorldPeriodsDy,
                 periodsSoFar(*period, state.time), kSmallTextSize, color(kLabelGrey)));
  } else {
    c.add(deleteMarker(ns::kPlotCursor, kStepsPeriods, c.frame_id));
  }
  Marker cursor = c.lines(ns::kPlotCursor, kCursor, Marker::LINE_LIST, kCursorWidth, color(kCursorWhite));
  cursor.points = {point(cx, kVelocityBox.bottom), point(cx, kVelocityBox.top), point(cx, kMomentumBox.bottom),
                   point(cx, kEnergyBox.top)};
  c.add(cursor);
}

}  // namespace collision_lab_ros::markers
