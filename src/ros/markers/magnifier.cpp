// The magnifier under the scene while the bodies crowd together (three bodies, or up to
// kMaxPlottedBodies): all of them at their true separations, in a window a round number
// of metres wide.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

/// The magnifier's window: positions [m] around `middle`, `width` wide, drawn in [left, right].
struct ZoomWindow {
  double middle, width;
  static constexpr double left = kSceneLeft + kZoomInset, right = kSceneRight - kZoomInset;
  double toX(double x) const { return left + ((x - middle) / width + 0.5) * (right - left); }
};

/// Light bodies smaller and on top: at a collision a light one touches a heavy one. Three
/// bodies: B is the light one; more: every body lighter than the heaviest.
bool light(const collision_lab::InitialConditions& input, std::size_t i) {
  if (input.masses.size() == 3) return i == 1;
  double heaviest = 0.0;
  for (std::size_t j = 0; j < input.masses.size(); ++j) {
    if (!isWall(input, j)) heaviest = std::max(heaviest, input.masses[j]);
  }
  return input.masses[i] < heaviest;
}

Marker zoomBody(const Canvas& c, const ZoomWindow& window, std::size_t i, double position) {
  const bool wall = isWall(c.run.input(), i), small = !wall && light(c.run.input(), i);
  Marker body = c.base(ns::kZoom, kZoomBody + static_cast<int>(i), wall ? Marker::CUBE : Marker::SPHERE);
  body.pose.position = point(window.toX(position), kZoomY, small ? kZoomLightZ : kDotZ);
  body.scale.x = wall ? kZoomWallWidth : (small ? kZoomLightSize : kZoomHeavySize);
  body.scale.y = wall ? kZoomWallHeight : body.scale.x;
  body.scale.z = body.scale.x;
  body.color = bodyColor(c.view, i);
  return body;
}

/// The smallest of 1, 2 and 5 times a power of ten that is >= w.
double roundUp(double w) {
  const double decade = std::pow(10.0, std::floor(std::log10(w)));
  for (double f : {1.0, 2.0, 5.0}) {
    if (f * decade >= w) return f * decade;
  }
  return 10 * decade;
}

/// The window while the bodies crowd together, else none. Three bodies (the wedge's scenes,
/// where a collapse or a burst crowds them): closer than kCrowded of the axis. More: two
/// neighbours closer than kZoomCrowdedGap on screen, and a window that magnifies.
std::optional<ZoomWindow> crowdedWindow(const SceneState& state, const SceneAxis& axis) {
  const std::size_t n = state.positions.size();
  if (n < 3 || n > kMaxPlottedBodies) return std::nullopt;
  const auto [lo, hi] = std::minmax_element(state.positions.begin(), state.positions.end());
  const double spread = *hi - *lo, full = axis.max - axis.min;
  if (!(spread > 0)) return std::nullopt;
  if (n == 3) {
    if (spread > kCrowded * full) return std::nullopt;
    return ZoomWindow{(*lo + *hi) / 2, std::pow(10.0, std::ceil(std::log10(kZoomMargin * spread)))};
  }
  // The bodies keep their order on the axis (they never pass each other).
  double closest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    closest = std::min(closest, std::abs(axis.toX(state.positions[i]) - axis.toX(state.positions[i + 1])));
  }
  const double width = roundUp(kZoomMargin * spread);
  if (!(closest < kZoomCrowdedGap) || full / width < kZoomLeast) return std::nullopt;
  return ZoomWindow{(*lo + *hi) / 2, width};
}

}  // namespace

void drawMagnifier(const Canvas& c, const SceneState& state) {
  const SceneAxis axis = sceneAxis(c.run);
  const std::optional<ZoomWindow> window = largeScene(c.run) ? std::nullopt : crowdedWindow(state, axis);
  if (!window) {
    for (int id = 0; id < kZoomCount; ++id) c.add(deleteMarker(ns::kZoom, id, c.frame_id));
    return;
  }
  const double full = axis.max - axis.min;
  Marker line = c.lines(ns::kZoom, kZoomLine, Marker::LINE_LIST, kCursorWidth, color(kGrey));
  line.points = {point(ZoomWindow::left, kZoomY), point(ZoomWindow::right, kZoomY)};
  c.add(line);
  for (std::size_t i = 0; i < state.positions.size(); ++i) c.add(zoomBody(c, *window, i, state.positions[i]));
  c.add(c.text(ns::kZoom, kZoomMagnification, ZoomWindow::left + kZoomMagnificationDx, kZoomY,
               format("magnified x%.2g", full / window->width), kSmallTextSize, color(kLabelGrey)));
  c.add(c.text(ns::kZoom, kZoomWindow, ZoomWindow::right + kZoomWindowDx, kZoomY,
               format("window %.2g m", window->width) + format(" from %.3g m", window->middle - window->width / 2),
               kSmallTextSize, color(kLabelGrey)));
}

}  // namespace collision_lab_ros::markers
