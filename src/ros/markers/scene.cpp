// The scene: the title, the position axis with its range and note, the bodies (sized by
// mass, walls as walls) with their tags and velocities, and the status line.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The finite masses' range [kg], for sizes on a log scale.
std::pair<double, double> massRange(const collision_lab::InitialConditions& input) {
  double lo = kInf, hi = 0.0;
  for (std::size_t j = 0; j < input.masses.size(); ++j) {
    if (!isWall(input, j)) lo = std::min(lo, input.masses[j]), hi = std::max(hi, input.masses[j]);
  }
  return {lo, hi};
}

/// Where mass m sits between the lightest (0) and the heaviest (1) on a log scale, over
/// at least one decade.
double massShare(double m, const std::pair<double, double>& range) {
  const double decades = std::max(std::log10(range.second / range.first), 1.0);
  return std::clamp(std::log10(m / range.first) / decades, 0.0, 1.0);
}

/// Wall i as a slab on its outer side of x (body 0 on the right).
Marker wallMarker(const Canvas& c, int id, std::size_t i, double x) {
  const bool right = i == 0;
  Marker m = c.base(ns::kBodies, id, Marker::CUBE);
  m.pose.position = point(x + (right ? kWallWidth / 2 : -kWallWidth / 2), kSceneY);
  m.scale.x = kWallWidth, m.scale.y = kWallHeight, m.scale.z = kWallDepth;
  m.color = bodyColor(c.view, i);
  return m;
}

/// A body as a sphere sized by its mass.
Marker bodyMarker(const Canvas& c, std::size_t i, double x, const std::pair<double, double>& range) {
  if (isWall(c.run.input(), i)) return wallMarker(c, kBody + static_cast<int>(i), i, x);
  Marker m = c.base(ns::kBodies, kBody + static_cast<int>(i), Marker::SPHERE);
  m.pose.position = point(x, kSceneY);
  m.scale.x = m.scale.y = m.scale.z = kSmallestBody + kBodyGrowth * massShare(c.run.input().masses[i], range);
  m.color = bodyColor(c.view, i);
  return m;
}

/// A text of the scene row and its centre [rviz units].
struct PlacedText {
  std::string text;
  double x, y;
};

/// The labels of the axis' ends (min, max): under the axis, or under the wall at an end
/// where a wall stands (a wall is taller than a body).
std::array<PlacedText, 2> endLabels(const RunRecord& run, const SceneAxis& axis) {
  const auto y = [](bool wall) {
    return wall ? kSceneY - kWallHeight / 2 - kWallLabelDy : kSceneY + kSceneLabelDy;
  };
  const auto value = [&axis](double x) { return "x = " + positionText(x, axis.min < 0) + " m"; };
  return {PlacedText{value(axis.min), kSceneLeft + kSceneLabelDx, y(run.isWall(run.bodies() - 1))},
          PlacedText{value(axis.max), kSceneRight - kSceneLabelDx, y(run.isWall(0))}};
}

std::string tagOf(const RunRecord& run, std::size_t i) {
  return isWall(run.input(), i) ? bodyName(i) + " (wall)" : bodyName(i);
}

/// Where each body's tag goes: a wall's on its outer side, over the axis; a body's over or
/// under it (alternately), else in the other row, else moved sideways, so that bodies
/// close together keep tags apart.
std::vector<std::pair<double, double>> tagPlaces(const RunRecord& run, const std::vector<double>& x,
                                                 const SceneAxis& axis) {
  const std::size_t n = x.size();
  std::vector<std::pair<double, double>> place(n);
  std::vector<Box> taken;
  const auto boxAt = [](double cx, double cy, double width, double size = kTextSize) {
    return Box{cx - width / 2 - kTagGap, cx + width / 2 + kTagGap, cy - size / 2, cy + size / 2};
  };
  for (const PlacedText& end : endLabels(run, axis)) {
    taken.push_back(boxAt(end.x, end.y, textWidth(end.text, kSmallTextSize), kSmallTextSize));
  }
  const auto free = [&taken](const Box& b) {
    return std::none_of(taken.begin(), taken.end(), [&b](const Box& t) {
      return b.left < t.right && t.left < b.right && b.bottom < t.top && t.bottom < b.top;
    });
  };
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < n; ++i) {
    if (isWall(run.input(), i)) {
      place[i] = {x[i] + (i == 0 ? kWallTagDx : -kWallTagDx), kSceneY + kTagDy};
      taken.push_back(boxAt(place[i].first, place[i].second, textWidth(tagOf(run, i), kTextSize)));
    } else {
      order.push_back(i);
    }
  }
  // Left to right (the last body is the leftmost).
  std::reverse(order.begin(), order.end());
  for (std::size_t i : order) {
    const double width = textWidth(tagOf(run, i), kTextSize);
    const double first_row = kSceneY + (i % 2 == 1 ? -kTagDy : kTagDy), other_row = 2 * kSceneY - first_row;
    place[i] = {x[i], first_row};
    bool placed = false;
    for (int step = 0; step <= kTagMaxSteps && !placed; ++step) {
      for (double dx : {step * width, -step * width}) {
        for (double row : {first_row, other_row}) {
          if (!placed && free(boxAt(x[i] + dx, row, width))) place[i] = {x[i] + dx, row}, placed = true;
        }
        if (step == 0) break;
      }
    }
    taken.push_back(boxAt(place[i].first, place[i].second, width));
  }
  return place;
}

/// Few bodies: each with its tag beside it and its velocity in a row above.
void drawLabelledBodies(const Canvas& c, const SceneState& state, const SceneAxis& axis) {
  const std::size_t n = c.run.bodies();
  const auto range = massRange(c.run.input());
  // Three bodies keep their wide row; more share the scene's width.
  const double pitch = n <= 3 ? kVelocityRowPitch : (kSceneRight - kSceneLeft) / static_cast<double>(n);
  const char* fmt = n <= 3 ? "%.6g" : "%.3g";
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = axis.toX(state.positions[i]);
  const auto tags = tagPlaces(c.run, x, axis);
  for (std::size_t i = 0; i < n; ++i) {
    c.add(bodyMarker(c, i, x[i], range));
    // A short tag beside the body, the value in a fixed row.
    c.add(c.text(ns::kLabels, kBodyTag + static_cast<int>(i), tags[i].first, tags[i].second, tagOf(c.run, i),
                 kTextSize, bodyColor(c.view, i, kTagLighten)));
    const double row_x = kCentreX + pitch * (static_cast<double>(i) - (static_cast<double>(n) - 1) / 2);
    c.add(c.text(ns::kLabels, kVelocityRow + static_cast<int>(i), row_x, kVelocityRowY,
                 "v_" + bodyName(i) + " = " + withSign(fmt, state.velocities[i]) + " m/s",
                 n <= 3 ? kTextSize : kSmallTextSize,
                 bodyColor(c.view, i, kTagLighten)));
  }
}

/// Many bodies: one list per mass class, each body in its colour (its start velocity's);
/// walls as walls.
void drawManyBodies(const Canvas& c, const SceneState& state, const SceneAxis& axis) {
  const auto range = massRange(c.run.input());
  std::vector<Marker> classes;
  for (int k = 0; k < kMassClasses; ++k) {
    Marker m = c.dots(ns::kBodies, kBodyClass + k, kManyBodySize + kManyBodyGrowth * k, color(kWhite));
    classes.push_back(m);
  }
  const std::size_t n = c.run.bodies();
  for (std::size_t i = 0; i < n; ++i) {
    const double x = axis.toX(state.positions[i]);
    if (isWall(c.run.input(), i)) {
      c.add(wallMarker(c, kBodyWall + (i == 0 ? 0 : 1), i, x));
      continue;
    }
    const int k = std::min(kMassClasses - 1, static_cast<int>(massShare(c.run.input().masses[i], range) * kMassClasses));
    classes[static_cast<std::size_t>(k)].points.push_back(point(x, kSceneY));
    classes[static_cast<std::size_t>(k)].colors.push_back(bodyColor(c.view, i));
  }
  for (Marker& m : classes) {
    if (m.points.empty()) c.add(deleteMarker(ns::kBodies, m.id, c.frame_id));
    else c.add(std::move(m));
  }
}

/// The legend of the colour by the start velocity: a bar from -v_max to +v_max, and the
/// view's words for it.
void drawColourLegend(const Canvas& c) {
  const double v_max = c.view.colour_scale;
  const Box& b = kColourBarBox;
  Marker bar = c.base(ns::kScene, kColourBar, Marker::CUBE_LIST);
  const double step = (b.right - b.left) / kColourBarSteps;
  bar.scale.x = step, bar.scale.y = b.top - b.bottom, bar.scale.z = kBarDepth;
  for (int k = 0; k < kColourBarSteps; ++k) {
    bar.points.push_back(point(b.left + (k + 0.5) * step, b.midY()));
    bar.colors.push_back(velocityColor(-v_max + (k + 0.5) * 2 * v_max / kColourBarSteps, v_max));
  }
  c.add(bar);
  // The ends in the legend's numbers.
  c.add(c.text(ns::kScene, kColourMin, b.left - kColourLabelDx, b.midY(), "-" + numberText(v_max) + " m/s", kSmallTextSize,
               color(kLabelGrey)));
  c.add(c.text(ns::kScene, kColourMax, b.right + kColourLabelDx, b.midY(), "+" + numberText(v_max) + " m/s", kSmallTextSize,
               color(kLabelGrey)));
  c.add(c.text(ns::kScene, kColourCaption, b.midX(), b.top + kFrameLabelDy,
               c.view.colour_legend, kSmallTextSize, color(kLabelGrey)));
  // Beside the bar, so that the caption above stays clear of the walls.
  const std::string size = "size: mass (log)";
  c.add(c.text(ns::kScene, kColourSize, b.right + 2 * kColourLabelDx + textWidth(size, kSmallTextSize) / 2, b.midY(),
               size, kSmallTextSize, color(kLabelGrey)));
}

/// Large scenes: the bodies' spread now, so a gas that ends 1e8 m wide still shows its first
/// minutes, when it is a kilometre wide and nearly every collision happens.
SceneAxis bodiesNow(const SceneState& state) {
  double lo = kInf, hi = -kInf;
  for (double x : state.positions) {
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  const auto [min, max] = paddedRange(lo, hi, lo);
  return {min, max};
}

/// The ends of the scene's axis [m], and (large scenes) that they follow the bodies.
void addRangeLabels(const Canvas& c, const std::string& ns, int min_id, int max_id, const SceneAxis& axis) {
  const auto labels = endLabels(c.run, axis);
  c.add(c.text(ns, min_id, labels[0].x, labels[0].y, labels[0].text, kSmallTextSize, color(kLabelGrey)));
  c.add(c.text(ns, max_id, labels[1].x, labels[1].y, labels[1].text, kSmallTextSize, color(kLabelGrey)));
}

}  // namespace

double SceneAxis::toX(double position) const {
  return kSceneLeft + (position - min) / (max - min) * (kSceneRight - kSceneLeft);
}

SceneAxis sceneAxis(const RunRecord& run) {
  if (run.input().ring > 0) return {0.0, run.input().ring};  // the positions lie in [0, L)
  // The outermost bodies bound the others (they never pass each other); both are tracked.
  double lo = kInf, hi = -kInf;
  for (std::size_t i : run.trackedBodies()) {
    lo = std::min(lo, run.worldline(i).minY());
    hi = std::max(hi, run.worldline(i).maxY());
  }
  for (double x : stateAt(run, endTime(run)).positions) {
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  const auto [min, max] = paddedRange(lo, hi, lo);
  return {min, max};
}

SceneAxis bodiesAxis(const RunRecord& run, const SceneState& state) {
  return largeScene(run) && !(run.input().ring > 0) ? bodiesNow(state) : sceneAxis(run);
}

void drawTitle(const Canvas& c) {
  c.add(c.text(ns::kTitle, kTitleText, kCentreX, kTitleY, c.view.title, kTitleSize));
}

void drawSceneAxis(const Canvas& c) {
  Marker axis = c.lines(ns::kScene, kSceneAxis, Marker::LINE_LIST, kAxisWidth, color(kGrey));
  axis.points = {point(kSceneLeft, kSceneY), point(kSceneRight, kSceneY)};
  c.add(axis);
  if (!largeScene(c.run)) addRangeLabels(c, ns::kScene, kSceneMinLabel, kSceneMaxLabel, sceneAxis(c.run));
  const std::string& note = c.view.note;
  if (!note.empty()) c.add(c.text(ns::kScene, kSceneNote, kCentreX, kNoteY, note, kTextSize, color(kAmber)));
  if (c.view.colour_by_start_velocity) drawColourLegend(c);
}

void drawBodies(const Canvas& c, const SceneState& state) {
  if (largeScene(c.run)) {
    const SceneAxis axis = bodiesAxis(c.run, state);
    drawManyBodies(c, state, axis);
    addRangeLabels(c, ns::kLabels, kSceneNowMin, kSceneNowMax, axis);
    // What the axis spans, in the right end label's row, left of it.
    const std::string note = c.view.ring.empty() ? "x range: the bodies now" : "a " + c.view.ring + ": its ends meet";
    const PlacedText right = endLabels(c.run, axis)[1];
    const double note_x = right.x - textWidth(right.text, kSmallTextSize) / 2 - kSceneRangeNoteGap -
                          textWidth(note, kSmallTextSize) / 2;
    c.add(c.text(ns::kLabels, kSceneRangeNote, note_x, right.y, note, kSmallTextSize, color(kLabelGrey)));
  } else {
    drawLabelledBodies(c, state, sceneAxis(c.run));
  }
}

void drawStatus(const Canvas& c, const SceneState& state, const FrameClock& clock) {
  c.add(c.text(ns::kLabels, kStatus, kCentreX, kStatusY, statusLine(c.view, state, clock), kTextSize));
}

}  // namespace collision_lab_ros::markers
