// The kinetic energy per body as bars: the axis with the bodies' names (static) and the
// bars with their values now (animated); for a large scene, the totals now. A large
// inelastic scene shows T(t) in their place instead (temperature.cpp).
#include <algorithm>

#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

double pitch(std::size_t n) { return (kBarsBox.right - kBarsBox.left) / static_cast<double>(std::max<std::size_t>(n, 1)); }
double barX(std::size_t i, std::size_t n) { return kBarsBox.left + (static_cast<double>(i) + 0.5) * pitch(n); }

}  // namespace

void drawEnergyBarsAxis(const Canvas& c) {
  if (c.view.gas) return;
  Marker axis = c.lines(ns::kEnergy, kEnergyAxis, Marker::LINE_LIST, kAxisWidth, color(kGrey));
  axis.points = {point(kBarsBox.left, kBarsBox.bottom), point(kBarsBox.right, kBarsBox.bottom)};
  c.add(axis);
  const std::size_t n = c.run.bodies();
  if (!largeScene(c.run)) {
    for (std::size_t i = 0; i < n; ++i) {
      const bool wall = isWall(c.run.input(), i);
      c.add(c.text(ns::kEnergy, kEnergyBodyNames + static_cast<int>(i), barX(i, n), kBarsBox.bottom + kBarNameDy,
                   wall && n <= 3 ? bodyName(i) + " (wall)" : bodyName(i), kSmallTextSize, bodyColor(c.view, i)));
    }
  }
  c.add(c.text(ns::kEnergy, kEnergyTitle, kBarsBox.midX(), kBarsBox.top + kBarsTitleDy,
               largeScene(c.run) ? "kinetic energy now [J]" : "kinetic energy now, per body [J]", kTextSize));
}

void drawEnergyBars(const Canvas& c, const SceneState& state) {
  if (c.view.gas) return;
  const std::size_t n = c.run.bodies();
  std::vector<double> kinetic(n, 0.0);
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    kinetic[i] = collision_lab::core::kineticEnergy(c.run.input().masses[i], state.velocities[i]);
    total += kinetic[i];
  }
  if (largeScene(c.run)) {
    c.add(c.text(ns::kEnergyBars, kEnergyTotals, kBarsBox.midX(), kBarsBox.midY(),
                 "all " + withSeparators(n) + " bodies: " + format("%.5g J", total) +
                     format("\nat the start: %.5g J", c.run.startEnergy()),
                 kTextSize));
    return;
  }
  const double height = kBarsBox.top - kBarsBox.bottom;
  for (std::size_t i = 0; i < n; ++i) {
    const double h = std::max(total > 0 ? height * kinetic[i] / total : 0.0, kBarMinHeight);
    Marker bar = c.base(ns::kEnergyBars, kEnergyBar + static_cast<int>(i), Marker::CUBE);
    bar.pose.position = point(barX(i, n), kBarsBox.bottom + h / 2);
    bar.scale.x = kBarWidth * pitch(n), bar.scale.y = h, bar.scale.z = kBarDepth;
    bar.color = bodyColor(c.view, i);
    c.add(bar);
    // Values wider than the pitch alternate between two heights, so neighbours stay apart.
    const std::string value = format("%.3g", kinetic[i]);
    const double dy = textWidth(value, kSmallTextSize) > pitch(n) && i % 2 == 1 ? kBarValueStagger : 0.0;
    c.add(c.text(ns::kEnergyBars, kEnergyBarValue + static_cast<int>(i), barX(i, n),
                 kBarsBox.bottom + h + kBarValueDy + dy, value, kSmallTextSize));
  }
}

}  // namespace collision_lab_ros::markers
