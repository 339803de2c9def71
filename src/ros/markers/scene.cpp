// The scene: the title, the position axis with its range and note, the bodies (sized by
// mass, walls as walls) with their tags and velocities, and the status line.
#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double bodyDiameter(const collision_lab::InitialConditions& input, int i) {
  double lo = kInf, hi = 0.0;
  for (int j = 0; j < 3; ++j) {
    if (!isWall(input, j)) lo = std::min(lo, input.masses[j]), hi = std::max(hi, input.masses[j]);
  }
  const double decades = std::max(std::log10(hi / lo), 1.0);
  return kSmallestBody + kBodyGrowth * std::log10(input.masses[i] / lo) / decades;
}

/// A wall as a slab on its outer side of x, a body as a sphere sized by its mass.
Marker bodyMarker(const Canvas& c, int i, double x) {
  if (isWall(c.run.input(), i)) {
    Marker m = c.base(ns::kBodies, kBody + i, Marker::CUBE);
    m.pose.position = point(x + (i == 0 ? kWallWidth / 2 : -kWallWidth / 2), kSceneY);
    m.scale.x = kWallWidth, m.scale.y = kWallHeight, m.scale.z = kWallDepth;
    m.color = color(kGrey);
    return m;
  }
  Marker m = c.base(ns::kBodies, kBody + i, Marker::SPHERE);
  m.pose.position = point(x, kSceneY);
  m.scale.x = m.scale.y = m.scale.z = bodyDiameter(c.run.input(), i);
  m.color = particleColor(i);
  return m;
}

}  // namespace

double SceneAxis::toX(double position) const {
  return kSceneLeft + (position - min) / (max - min) * (kSceneRight - kSceneLeft);
}

SceneAxis sceneAxis(const RunRecord& run) {
  double lo = kInf, hi = -kInf;
  for (int i = 0; i < 3; ++i) {
    lo = std::min(lo, run.worldline(i).minY());
    hi = std::max(hi, run.worldline(i).maxY());
  }
  for (double x : stateAt(run, endTime(run)).positions) {
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  const auto [min, max] = paddedRange(lo, hi, lo);
  return {min, max};
}

void drawTitle(const Canvas& c) {
  c.add(c.text(ns::kTitle, kTitleText, kCentreX, kTitleY, runTitle(c.run), kTitleSize));
}

void drawSceneAxis(const Canvas& c) {
  Marker axis = c.lines(ns::kScene, kSceneAxis, Marker::LINE_LIST, kAxisWidth, color(kGrey));
  axis.points = {point(kSceneLeft, kSceneY), point(kSceneRight, kSceneY)};
  c.add(axis);
  const SceneAxis scene = sceneAxis(c.run);
  c.add(c.text(ns::kScene, kSceneMinLabel, kSceneLeft + kSceneLabelDx, kSceneY + kSceneLabelDy,
               format("x = %.4g m", scene.min), kSmallTextSize, color(kLabelGrey)));
  c.add(c.text(ns::kScene, kSceneMaxLabel, kSceneRight - kSceneLabelDx, kSceneY + kSceneLabelDy,
               format("x = %.4g m", scene.max), kSmallTextSize, color(kLabelGrey)));
  const std::string note = runNote(c.run);
  if (!note.empty()) c.add(c.text(ns::kScene, kSceneNote, kCentreX, kNoteY, note, kTextSize, color(kAmber)));
}

void drawBodies(const Canvas& c, const SceneState& state) {
  const SceneAxis axis = sceneAxis(c.run);
  for (int i = 0; i < 3; ++i) {
    const bool wall = isWall(c.run.input(), i);
    const double x = axis.toX(state.positions[i]);
    c.add(bodyMarker(c, i, x));
    // A short tag beside the body (walls: on their outer side), the value in a fixed row.
    const double tag_x = wall ? x + (i == 0 ? kWallTagDx : -kWallTagDx) : x;
    const double tag_y = wall ? kSceneY + kTagDy : kSceneY + (i == 1 ? -kTagDy : kTagDy);
    c.add(c.text(ns::kLabels, kBodyTag + i, tag_x, tag_y, wall ? std::string(kNames[i]) + " (wall)" : kNames[i],
                 kTextSize, particleColor(i, kTagLighten)));
    c.add(c.text(ns::kLabels, kVelocityRow + i, kCentreX + kVelocityRowPitch * (i - 1), kVelocityRowY,
                 std::string("v_") + kNames[i] + format(" = %.6g m/s", state.velocities[i]), kTextSize,
                 particleColor(i, kTagLighten)));
  }
}

void drawStatus(const Canvas& c, const SceneState& state, const FrameClock& clock) {
  c.add(c.text(ns::kLabels, kStatus, kCentreX, kStatusY, statusLine(c.run, state, clock), kTextSize));
}

}  // namespace collision_lab_ros::markers
