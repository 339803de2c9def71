// The kinetic energy per body as bars: the axis with the bodies' names (static) and the
// bars with their values now (animated).
#include <algorithm>

#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

constexpr double kPitch = (kBarsBox.right - kBarsBox.left) / 3;  ///< per body
double barX(int i) { return kBarsBox.left + (i + 0.5) * kPitch; }

}  // namespace

void drawEnergyBarsAxis(const Canvas& c) {
  Marker axis = c.lines(ns::kEnergy, kEnergyAxis, Marker::LINE_LIST, kAxisWidth, color(kGrey));
  axis.points = {point(kBarsBox.left, kBarsBox.bottom), point(kBarsBox.right, kBarsBox.bottom)};
  c.add(axis);
  for (int i = 0; i < 3; ++i) {
    c.add(c.text(ns::kEnergy, kEnergyBodyNames + i, barX(i), kBarsBox.bottom + kBarNameDy,
                 isWall(c.run.input(), i) ? std::string(kNames[i]) + " (wall)" : kNames[i], kSmallTextSize,
                 particleColor(i)));
  }
  c.add(c.text(ns::kEnergy, kEnergyTitle, kBarsBox.midX(), kBarsBox.top + kBarsTitleDy, "kinetic energy now [J]",
               kTextSize));
}

void drawEnergyBars(const Canvas& c, const SceneState& state) {
  std::array<double, 3> kinetic{};
  for (int i = 0; i < 3; ++i) {
    if (!isWall(c.run.input(), i)) kinetic[i] = 0.5 * c.run.input().masses[i] * state.velocities[i] * state.velocities[i];
  }
  const double total = kinetic[0] + kinetic[1] + kinetic[2];
  const double height = kBarsBox.top - kBarsBox.bottom;
  for (int i = 0; i < 3; ++i) {
    const double h = std::max(total > 0 ? height * kinetic[i] / total : 0.0, kBarMinHeight);
    Marker bar = c.base(ns::kEnergyBars, kEnergyBar + i, Marker::CUBE);
    bar.pose.position = point(barX(i), kBarsBox.bottom + h / 2);
    bar.scale.x = kBarWidth * kPitch, bar.scale.y = h, bar.scale.z = kBarDepth;
    bar.color = particleColor(i);
    c.add(bar);
    c.add(c.text(ns::kEnergyBars, kEnergyBarValue + i, barX(i), kBarsBox.bottom + h + kBarValueDy,
                 format("%.3g", kinetic[i]), kSmallTextSize));
  }
}

}  // namespace collision_lab_ros::markers
