// The x-t diagram: the worldlines (time up, position across on the scene's axis) and the
// line of now with the bodies on it.
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

}  // namespace

void drawWorldlines(const Canvas& c) {
  const WorldAxes axes{sceneAxis(c.run), endTime(c.run)};
  const SceneState last = stateAt(c.run, axes.end);
  const Box& b = kWorldBox;
  Marker frame = c.lines(ns::kWorldlines, kWorldFrame, Marker::LINE_LIST, kFrameWidth, color(kGrey));
  frame.points = {point(b.left, b.bottom), point(b.right, b.bottom), point(b.left, b.bottom), point(b.left, b.top)};
  c.add(frame);
  for (int i = 0; i < 3; ++i) {
    Polyline poly = c.run.worldline(i).polyline();
    poly.push_back({last.time, last.positions[i], 0.0});
    const bool wall = isWall(c.run.input(), i);
    Marker line = c.lines(ns::kWorldlines, kWorldLines + i, Marker::LINE_STRIP, wall ? kWallLineWidth : kBodyLineWidth,
                          wall ? color(kGrey) : particleColor(i));
    for (const auto& v : poly) line.points.push_back(point(axes.toX(v.y), axes.toY(v.x)));
    c.addLines(line);
  }
  addWorldLabels(c, axes);
  c.add(c.text(ns::kWorldlines, kWorldTitle, b.midX(), kPanelTitleY, "x-t diagram (worldlines)", kTextSize));
  c.add(c.text(ns::kWorldlines, kWorldLegend, b.midX(), kLegendY,
               c.run.worldline(1).exact() ? "exact" : "min/max of x per time column", kSmallTextSize,
               color(kLabelGrey)));
}

void drawWorldlinesCursor(const Canvas& c, const SceneState& state) {
  const WorldAxes world{sceneAxis(c.run), endTime(c.run)};
  Marker now = c.lines(ns::kWorldlinesNow, kWorldNowLine, Marker::LINE_LIST, kCursorWidth, color(kCursorWhite));
  now.points = {point(kWorldBox.left, world.toY(state.time)), point(kWorldBox.right, world.toY(state.time))};
  c.add(now);
  Marker bodies = c.dots(ns::kWorldlinesNow, kWorldNowBodies, kWorldNowDotSize, color(kWhite));
  for (double x : state.positions) bodies.points.push_back(point(world.toX(x), world.toY(state.time), kDotZ));
  c.add(bodies);
}

}  // namespace collision_lab_ros::markers
