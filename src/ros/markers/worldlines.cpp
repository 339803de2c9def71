// The x-t diagram: the worldlines (time up, position across on the scene's axis; a sample
// of kMaxTrackedBodies for large N), the ghosts' straight worldlines for equal elastic
// masses, and the line of now with the bodies on it.
#include <algorithm>

#include "collision_lab/ros/markers/draw.h"

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

void addWorldLabels(const Canvas& c, const WorldAxes& axes) {
  const auto label = [&](int id, double x, double y, const std::string& s) {
    c.add(c.text(ns::kWorldlines, id, x, y, s, kSmallTextSize));
  };
  const Box& b = kWorldBox;
  label(kWorldTimeZero, b.left + kWorldZeroDx, b.bottom, "0");
  label(kWorldTimeEnd, b.left + kWorldEndDx, b.top, format("%.3g", axes.end));
  label(kWorldTimeUnit, b.left + kWorldUnitDx, b.top + kWorldUnitDy, "t [s]");
  label(kWorldPositionMin, b.left, b.bottom + kWorldPositionDy, format("%.3g", axes.scene.min));
  label(kWorldPositionMax, b.right, b.bottom + kWorldPositionDy, format("%.3g", axes.scene.max));
  label(kWorldPositionUnit, b.midX(), b.bottom + kWorldPositionDy, "x [m]");
}

/// Equal elastic masses move as ghosts that pass through each other: the straight lines
/// x_i + v_i t of the tracked bodies' initial states, cut to the box.
void addGhosts(const Canvas& c, const WorldAxes& axes) {
  Marker ghosts = c.lines(ns::kWorldlines, kWorldGhosts, Marker::LINE_LIST, kGhostWidth, color(kGhostGrey));
  for (std::size_t i : c.run.trackedBodies()) {
    const double x = c.run.input().positions[i], v = c.run.input().velocities[i];
    // Inside the box while scene.min <= x + v t <= scene.max.
    double t_end = axes.end;
    if (v > 0) t_end = std::min(t_end, (axes.scene.max - x) / v);
    if (v < 0) t_end = std::min(t_end, (axes.scene.min - x) / v);
    if (!(t_end > 0)) continue;
    ghosts.points.push_back(point(axes.toX(x), axes.toY(0.0)));
    ghosts.points.push_back(point(axes.toX(x + v * t_end), axes.toY(t_end)));
  }
  c.addLines(ghosts);
}

bool ghostScene(const RunRecord& run) {
  return run.prediction && run.prediction->model == collision_lab::Prediction::MODEL_GHOSTS;
}

}  // namespace

void drawWorldlines(const Canvas& c) {
  const WorldAxes axes{sceneAxis(c.run), endTime(c.run)};
  const SceneState last = stateAt(c.run, axes.end);
  const Box& b = kWorldBox;
  Marker frame = c.lines(ns::kWorldlines, kWorldFrame, Marker::LINE_LIST, kFrameWidth, color(kGrey));
  frame.points = {point(b.left, b.bottom), point(b.right, b.bottom), point(b.left, b.bottom), point(b.left, b.top)};
  c.add(frame);
  const auto& tracked = c.run.trackedBodies();
  const double v_max = velocityScale(c.run);
  for (std::size_t k = 0; k < tracked.size(); ++k) {
    const std::size_t i = tracked[k];
    Polyline poly = c.run.worldline(i).polyline();
    poly.push_back({last.time, last.positions[i], 0.0});
    const bool wall = isWall(c.run.input(), i);
    const auto colour = wall ? color(kGrey)
                             : largeScene(c.run) ? velocityColor(c.run.input().velocities[i], v_max) : particleColor(i);
    Marker line = c.lines(ns::kWorldlines, kWorldLines + static_cast<int>(k), Marker::LINE_STRIP,
                          wall ? kWallLineWidth : kBodyLineWidth, colour);
    for (const auto& v : poly) line.points.push_back(point(axes.toX(v.y), axes.toY(v.x)));
    c.addLines(line);
  }
  const bool ghosts = ghostScene(c.run);
  if (ghosts) addGhosts(c, axes);
  addWorldLabels(c, axes);
  c.add(c.text(ns::kWorldlines, kWorldTitle, b.midX(), kPanelTitleY, "x-t diagram (worldlines)", kTextSize));
  bool exact = true;
  for (std::size_t i : tracked) exact = exact && c.run.worldline(i).exact();
  std::string legend = exact ? "exact" : "min/max of x per time column";
  if (tracked.size() < c.run.bodies()) {
    legend += ";  " + withSeparators(tracked.size()) + " of " + withSeparators(c.run.bodies()) +
              " bodies, coloured by v at the start";
  }
  if (ghosts) legend += "\ngrey: the ghosts x_i + v_i t (equal masses pass through each other)";
  c.add(c.text(ns::kWorldlines, kWorldLegend, b.midX(), kLegendY, legend, kSmallTextSize, color(kLabelGrey)));
}

void drawWorldlinesCursor(const Canvas& c, const SceneState& state) {
  const WorldAxes world{sceneAxis(c.run), endTime(c.run)};
  Marker now = c.lines(ns::kWorldlinesNow, kWorldNowLine, Marker::LINE_LIST, kCursorWidth, color(kCursorWhite));
  now.points = {point(kWorldBox.left, world.toY(state.time)), point(kWorldBox.right, world.toY(state.time))};
  c.add(now);
  Marker bodies = c.dots(ns::kWorldlinesNow, kWorldNowBodies, kWorldNowDotSize, color(kWhite));
  for (std::size_t i : c.run.trackedBodies()) {
    bodies.points.push_back(point(world.toX(state.positions[i]), world.toY(state.time), kDotZ));
  }
  c.add(bodies);
}

}  // namespace collision_lab_ros::markers
