// The x-t diagram: the worldlines (time up, position across on the scene's axis; a sample
// of kMaxTrackedBodies for large N), the ghosts' straight worldlines for equal elastic
// masses, the clusters' joined worldlines up to now (thick amber, under the bodies'), and
// the line of now with the bodies on it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "collision_lab/ros/markers/draw.h"
#include "collision_lab/ros/run_view.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

/// Time [s] up the box, position [m] across it (on the scene's axis).
struct WorldAxes {
  SceneAxis scene;
  double end = 1.0;
  double toX(double position) const {
    return kWorldBox.left + std::clamp((position - scene.min) / (scene.max - scene.min), 0.0, 1.0) *
                                (kWorldBox.right - kWorldBox.left);
  }
  double toY(double time) const {
    return kWorldBox.bottom + std::clamp(time / end, 0.0, 1.0) * (kWorldBox.top - kWorldBox.bottom);
  }
};

/// The axes' fixed labels: "0", "t [s]" and "x [m]".
void addWorldUnits(const Canvas& c) {
  const Box& b = kWorldBox;
  c.add(c.text(ns::kWorldlines, kWorldTimeZero, b.left + kWorldZeroDx, b.bottom, "0", kSmallTextSize));
  c.add(c.text(ns::kWorldlines, kWorldTimeUnit, b.left + kWorldUnitDx, b.top + kWorldUnitDy, "t [s]", kSmallTextSize));
  c.add(c.text(ns::kWorldlines, kWorldPositionUnit, b.midX(), b.bottom + kWorldPositionDy, "x [m]", kSmallTextSize));
}

/// The axes' ends: the time at the top [s], the positions at the bottom [m] (ids in `ns`).
void addWorldRange(const Canvas& c, const std::string& ns, int end_id, int min_id, int max_id, const WorldAxes& axes) {
  const Box& b = kWorldBox;
  c.add(c.text(ns, end_id, b.left + kWorldEndDx, b.top, numberText(axes.end, 3), kSmallTextSize));
  // The scene's number style; the ends' texts within the box's width (the right one would
  // otherwise run off the screen).
  const std::string min = positionText(axes.scene.min, axes.scene.min < 0);
  const std::string max = positionText(axes.scene.max, axes.scene.min < 0);
  c.add(c.text(ns, min_id, b.left + textWidth(min, kSmallTextSize) / 2, b.bottom + kWorldPositionDy, min,
               kSmallTextSize));
  c.add(c.text(ns, max_id, b.right - textWidth(max, kSmallTextSize) / 2, b.bottom + kWorldPositionDy, max,
               kSmallTextSize));
}

/// Large scenes: the shown bodies' worldlines (RunView::worldline_bodies) from 0 to now, and
/// the axes that hold them (time up to now; positions over the worldlines so far and the
/// bodies now).
WorldAxes axesUpToNow(const Canvas& c, const SceneState& state, std::vector<Polyline>& lines) {
  const RunRecord& run = c.run;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const ViewBody& body : c.view.worldline_bodies) {
    const std::size_t i = body.index;
    Polyline poly;
    for (const auto& v : run.worldline(i).polyline()) {
      if (v.x >= state.time) break;
      poly.push_back(v);
    }
    poly.push_back({state.time, state.positions[i], 0.0});
    for (const auto& v : poly) lo = std::min(lo, v.y), hi = std::max(hi, v.y);
    lines.push_back(std::move(poly));
  }
  for (double x : state.positions) {
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  const auto [min, max] = paddedRange(lo, hi, lo);
  const double ring = run.input().ring;
  return WorldAxes{ring > 0 ? SceneAxis{0.0, ring} : SceneAxis{min, max}, state.time > 0 ? state.time : 1.0};
}

/// At most the first, lowest, highest and last vertex of each of `rows` equal rows of time
/// up to `end`, in time order: all that the rows of pixels can show.
Polyline perRow(const Polyline& poly, double end, int rows) {
  Polyline out;
  std::size_t first = 0;
  while (first < poly.size()) {
    const auto row = [&](const Envelope::Vertex& v) { return std::min(static_cast<int>(v.x / end * rows), rows - 1); };
    std::size_t last = first, lowest = first, highest = first;
    while (last + 1 < poly.size() && row(poly[last + 1]) == row(poly[first])) {
      ++last;
      if (poly[last].y < poly[lowest].y) lowest = last;
      if (poly[last].y > poly[highest].y) highest = last;
    }
    std::vector<std::size_t> kept{first, std::min(lowest, highest), std::max(lowest, highest), last};
    kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
    for (std::size_t k : kept) out.push_back(poly[k]);
    first = last + 1;
  }
  return out;
}

/// Equal elastic masses move as ghosts that pass through each other: the straight lines
/// x_i + v_i t of the tracked bodies' initial states, cut to the box. Each piece of a
/// worldline lies on a ghost's line, so the ghosts are dashed and drawn over the
/// worldlines: the worldline's colour shows between the dashes.
void addGhosts(const Canvas& c, const std::string& ns, int id, const WorldAxes& axes) {
  Marker ghosts = c.lines(ns, id, Marker::LINE_LIST, kGhostWidth, color(kGhostGrey));
  for (const ViewBody& body : c.view.worldline_bodies) {
    const std::size_t i = body.index;
    const double x = c.run.input().positions[i], v = c.run.input().velocities[i];
    // Inside the box while scene.min <= x + v t <= scene.max.
    double t_end = axes.end;
    if (v > 0) t_end = std::min(t_end, (axes.scene.max - x) / v);
    if (v < 0) t_end = std::min(t_end, (axes.scene.min - x) / v);
    if (!(t_end > 0)) continue;
    const geometry_msgs::Point from = point(axes.toX(x), axes.toY(0.0), kGhostZ);
    const geometry_msgs::Point to = point(axes.toX(x + v * t_end), axes.toY(t_end), kGhostZ);
    const double length = std::hypot(to.x - from.x, to.y - from.y);
    const int dashes = std::max(1, static_cast<int>(length / kGhostDashPeriod));
    for (int k = 0; k < dashes; ++k) {
      const double f0 = static_cast<double>(k) / dashes, f1 = (k + kGhostDashShare) / dashes;
      ghosts.points.push_back(point(from.x + f0 * (to.x - from.x), from.y + f0 * (to.y - from.y), kGhostZ));
      ghosts.points.push_back(point(from.x + f1 * (to.x - from.x), from.y + f1 * (to.y - from.y), kGhostZ));
    }
  }
  c.addLines(ghosts);
}

/// Body i's worldline (time up, position across) in its colour (the view's), thick for a wall. On a ring the positions are wrapped into [0, L), so
/// a step across the seam is cut there: drawn to one edge of [0, L) and on from the other,
/// each step taken the shorter way round (a body moves less than L/2 between two vertices).
void addWorldline(const Canvas& c, const std::string& ns, int id, std::size_t i, const Polyline& poly,
                  const WorldAxes& axes) {
  const bool wall = isWall(c.run.input(), i);
  const auto colour = bodyColor(c.view, i);
  const double ring = c.run.input().ring;
  Marker line =
      c.lines(ns, id, ring > 0 ? Marker::LINE_LIST : Marker::LINE_STRIP, wall ? kWallLineWidth : kBodyLineWidth, colour);
  const auto add = [&](double t, double x) { line.points.push_back(point(axes.toX(x), axes.toY(t))); };
  if (!(ring > 0)) {
    for (const auto& v : poly) add(v.x, v.y);
  }
  for (std::size_t k = 1; ring > 0 && k < poly.size(); ++k) {
    const Envelope::Vertex &a = poly[k - 1], &b = poly[k];
    const double step = b.y - a.y;
    if (std::abs(step) <= ring / 2) {
      add(a.x, a.y), add(b.x, b.y);
      continue;
    }
    const double round = step > 0 ? step - ring : step + ring;  // across the seam
    const double edge = round < 0 ? 0.0 : ring;                 // where it leaves [0, L)
    const double seam = a.x + (edge - a.y) / round * (b.x - a.x);
    add(a.x, a.y), add(seam, edge), add(seam, ring - edge), add(b.x, b.y);
  }
  c.addLines(line);
}

/// The clusters' worldlines up to t_now (clustersOf): from each kept state, for as long as
/// its free flight is exact, to the next kept state; at most kMaxClusterSegments segments.
void addClusterWorldlines(const Canvas& c, const WorldAxes& axes, double t_now) {
  Marker lines = c.lines(ns::kClusters, kClusterLines, Marker::LINE_LIST, kClusterLineWidth, color(kClusterAmber));
  if (mayCluster(c.run)) {
    const auto& frames = c.run.keyframes();
    for (std::size_t k = 0; k < frames.size() && frames[k].time < t_now; ++k) {
      const Keyframe& f = frames[k];
      const double next = k + 1 < frames.size() ? frames[k + 1].time : t_now;
      const double until = std::min({f.valid_until, next, t_now});
      for (const auto& [first, last] : clustersOf(c.run, f.positions, f.velocities)) {
        if (lines.points.size() >= 2 * kMaxClusterSegments) break;
        const double x = f.positions[first], v = f.velocities[first];
        lines.points.push_back(point(axes.toX(x), axes.toY(f.time), -kDotZ));
        lines.points.push_back(point(axes.toX(x + v * (until - f.time)), axes.toY(until), -kDotZ));
      }
    }
  }
  if (lines.points.empty()) {
    c.add(deleteMarker(ns::kClusters, kClusterLines, c.frame_id));
  } else {
    c.addLines(lines);
  }
}

bool ghostScene(const RunRecord& run) {
  return run.prediction && run.prediction->model == collision_lab::Prediction::MODEL_GHOSTS;
}

/// The x-t diagram's axes of a small scene: its whole time, or one period of a periodic motion.
WorldAxes wholeRunAxes(const RunRecord& run) {
  const std::optional<Period> period = periodOf(run);
  return WorldAxes{sceneAxis(run), period ? period->time : endTime(run)};
}

}  // namespace

void drawWorldlines(const Canvas& c) {
  const Box& b = kWorldBox;
  Marker frame = c.lines(ns::kWorldlines, kWorldFrame, Marker::LINE_LIST, kFrameWidth, color(kGrey));
  frame.points = {point(b.left, b.bottom), point(b.right, b.bottom), point(b.left, b.bottom), point(b.left, b.top)};
  c.add(frame);
  addWorldUnits(c);
  const auto& shown = c.view.worldline_bodies;
  const bool large = largeScene(c.run);
  // Large scenes draw the worldlines up to now, every frame (drawWorldlinesCursor).
  // A periodic motion: its first period, the rest repeats it (a thousand periods would
  // fill the box with lines thinner than a pixel).
  const std::optional<Period> period = large ? std::nullopt : periodOf(c.run);
  if (!large) {
    const WorldAxes axes = wholeRunAxes(c.run);
    const SceneState last = stateAt(c.run, axes.end);
    for (std::size_t k = 0; k < shown.size(); ++k) {
      const std::size_t i = shown[k].index;
      Polyline poly;
      for (const auto& v : c.run.worldline(i).polyline()) {
        if (v.x < axes.end) poly.push_back(v);
      }
      poly.push_back({last.time, last.positions[i], 0.0});
      addWorldline(c, ns::kWorldlines, kWorldLines + static_cast<int>(k), i, poly, axes);
    }
    if (ghostScene(c.run)) addGhosts(c, ns::kWorldlines, kWorldGhosts, axes);
    addWorldRange(c, ns::kWorldlines, kWorldTimeEnd, kWorldPositionMin, kWorldPositionMax, axes);
  }
  c.add(c.text(ns::kWorldlines, kWorldTitle, b.midX(), kPanelTitleY,
               large ? "x-t diagram (worldlines), up to now" : "x-t diagram (worldlines)", kTextSize));
  bool exact = true;
  for (const ViewBody& body : shown) exact = exact && c.run.worldline(body.index).exact();
  std::string legend = exact ? "exact" : "min/max of x per row";
  // Many bodies: which ones, as the page says it, coloured by v at the start.
  if (large) legend += "; " + c.view.worldline_legend + "; colour: v at the start";
  if (ghostScene(c.run)) legend += ";  grey dashes: ghosts x_i + v_i t, passing through";
  if (mayCluster(c.run)) legend += ";  amber: clusters, moving as one";
  if (period) legend = format("periodic: one period drawn, T = %.4g s; now at t mod T", period->time);
  // Its first line under the title, the others down into the box's top margin, clear of the
  // "t [s]" label at the box's left.
  legend = wrapped(legend, kSmallTextSize, b.right - b.left - 2 * kWorldLegendInset);
  const double below = (static_cast<double>(textExtent(legend).second) - 1) * kHalfLineHeight * kSmallTextSize;
  c.add(c.text(ns::kWorldlines, kWorldLegend, b.midX(), kLegendY - below, legend, kSmallTextSize, color(kLabelGrey)));
}

void drawWorldlinesCursor(const Canvas& c, const SceneState& state) {
  const bool large = largeScene(c.run);
  std::vector<Polyline> lines;
  const WorldAxes world = large ? axesUpToNow(c, state, lines) : wholeRunAxes(c.run);
  const std::optional<Period> period = large ? std::nullopt : periodOf(c.run);
  // A periodic motion: now within its period, and how many periods are behind.
  const double t_now = period ? std::fmod(state.time, period->time) : state.time;
  if (period) {
    c.add(c.text(ns::kWorldlinesNow, kWorldNowPeriods, kWorldBox.midX(), kLegendY + kWorldPeriodsDy,
                 periodsSoFar(*period, state.time), kSmallTextSize, color(kLabelGrey)));
  } else {
    c.add(deleteMarker(ns::kWorldlinesNow, kWorldNowPeriods, c.frame_id));
  }
  if (large) {
    for (std::size_t k = 0; k < lines.size(); ++k) {
      addWorldline(c, ns::kWorldlinesNow, kWorldNowLines + static_cast<int>(k), c.view.worldline_bodies[k].index,
                   perRow(lines[k], world.end, kWorldRows), world);
    }
    if (ghostScene(c.run)) addGhosts(c, ns::kWorldlinesNow, kWorldNowGhosts, world);
    addWorldRange(c, ns::kWorldlinesNow, kWorldNowTimeEnd, kWorldNowPositionMin, kWorldNowPositionMax, world);
  }
  addClusterWorldlines(c, world, period ? 0.0 : state.time);
  Marker now = c.lines(ns::kWorldlinesNow, kWorldNowLine, Marker::LINE_LIST, kCursorWidth, color(kCursorWhite));
  now.points = {point(kWorldBox.left, world.toY(t_now)), point(kWorldBox.right, world.toY(t_now))};
  c.add(now);
  Marker bodies = c.dots(ns::kWorldlinesNow, kWorldNowBodies, kWorldNowDotSize, color(kWhite));
  for (const ViewBody& body : c.view.worldline_bodies) {
    const std::size_t i = body.index;
    bodies.points.push_back(point(world.toX(state.positions[i]), world.toY(t_now), kDotZ));
  }
  c.add(bodies);
}

}  // namespace collision_lab_ros::markers
