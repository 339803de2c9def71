// The overlays over whatever run is on screen: the banner of a rejected input and the
// hint before the first run, each a framed text.
#include <algorithm>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros {

namespace {

using namespace markers;
using namespace markers::layout;

/// A text with a frame around it. The frame also makes rviz 1.14 draw a text that comes
/// alone: an array of only TEXT_VIEW_FACING markers is received but not drawn.
std::vector<Marker> framedText(const std::string& frame_id, const std::string& ns, double y, const std::string& s,
                               const std_msgs::ColorRGBA& c, double size) {
  const auto [longest, lines_count] = textExtent(s);
  const double half_width = std::min(kHalfCharWidth * size * static_cast<double>(longest) + kFrameMarginX,
                                     kMaxHalfFrameWidth);
  const double half_height = kHalfLineHeight * size * static_cast<double>(lines_count) + kFrameMarginY;
  Marker box = lineMarker(frame_id, ns, kFramedBox, Marker::LINE_LIST, kFramedBoxWidth, c);
  const double l = kCentreX - half_width, r = kCentreX + half_width;
  const double b = y - half_height, t = y + half_height;
  box.points = {point(l, b), point(r, b), point(r, b), point(r, t), point(r, t), point(l, t), point(l, t), point(l, b)};
  return {textMarker(frame_id, ns, kFramedText, kCentreX, y, s, size, c), box};
}

}  // namespace

std::vector<Marker> rejectedBanner(const collision_lab::Rejected& rejected, const std::string& frame_id) {
  const std::string run = rejected.run_id.empty() ? "an input" : "run '" + rejected.run_id + "'";
  return framedText(frame_id, ns::kRejected, kZoomY,
                    "REJECTED " + run + ": " + rejected.reason_name + " in " + rejected.field + "\n" +
                        rejected.message,
                    color(kBannerRed), kTextSize);
}

std::vector<Marker> hintMarkers(const std::string& command, const std::string& frame_id) {
  return framedText(frame_id, ns::kHint, kHintY, command, color(kWhite), kHintTextSize);
}

}  // namespace collision_lab_ros
