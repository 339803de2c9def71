// The magnifier under the scene while three bodies crowd together: the three at their
// true separations, in a window a power of ten wide.
#include <algorithm>
#include <cmath>

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

Marker zoomBody(const Canvas& c, const ZoomWindow& window, std::size_t i, double position) {
  const bool wall = isWall(c.run.input(), i);
  Marker body = c.base(ns::kZoom, kZoomBody + static_cast<int>(i), wall ? Marker::CUBE : Marker::SPHERE);
  body.pose.position = point(window.toX(position), kZoomY, i == 1 ? kZoomLightZ : kDotZ);
  body.scale.x = wall ? kZoomWallWidth : (i == 1 ? kZoomLightSize : kZoomHeavySize);
  body.scale.y = wall ? kZoomWallHeight : body.scale.x;
  body.scale.z = body.scale.x;
  body.color = wall ? color(kGrey) : particleColor(i);
  return body;
}

}  // namespace

void drawMagnifier(const Canvas& c, const SceneState& state) {
  // Three bodies only: the wedge's scenes, where a collapse or a burst crowds them.
  const SceneAxis axis = sceneAxis(c.run);
  const bool three = state.positions.size() == 3;
  const auto [lo, hi] = three ? std::minmax({state.positions[0], state.positions[1], state.positions[2]})
                              : std::pair<double, double>{0.0, 0.0};
  const double full = axis.max - axis.min;
  if (!three || !(hi - lo > 0) || hi - lo > kCrowded * full) {
    for (int id = 0; id < kZoomCount; ++id) c.add(deleteMarker(ns::kZoom, id, c.frame_id));
    return;
  }
  const ZoomWindow window{(lo + hi) / 2, std::pow(10.0, std::ceil(std::log10(kZoomMargin * (hi - lo))))};
  Marker line = c.lines(ns::kZoom, kZoomLine, Marker::LINE_LIST, kCursorWidth, color(kGrey));
  line.points = {point(ZoomWindow::left, kZoomY), point(ZoomWindow::right, kZoomY)};
  c.add(line);
  for (std::size_t i = 0; i < 3; ++i) c.add(zoomBody(c, window, i, state.positions[i]));
  c.add(c.text(ns::kZoom, kZoomMagnification, ZoomWindow::left + kZoomMagnificationDx, kZoomY,
               format("magnified x%.2g", full / window.width), kSmallTextSize, color(kLabelGrey)));
  c.add(c.text(ns::kZoom, kZoomWindow, ZoomWindow::right + kZoomWindowDx, kZoomY,
               format("window %.2g m", window.width) + format(" from %.3g m", window.middle - window.width / 2),
               kSmallTextSize, color(kLabelGrey)));
}

}  // namespace collision_lab_ros::markers
