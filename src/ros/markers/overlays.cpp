// The overlays over whatever run is on screen: the banner of a rejected input and the
// hint before the first run, each a framed text.
#include <algorithm>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros {

namespace {

using namespace markers;
using namespace markers::layout;

/// A text on an opaque panel with a coloured border (one TRIANGLE_LIST, coloured per
/// vertex), over every view: the text is wrapped to fit the screen, and the panel fits the
/// text. The panel also makes rviz 1.14 draw a text that comes alone: an array of only
/// TEXT_VIEW_FACING markers is received but not drawn. `y` is the panel's centre, or with
/// `grow_up` its bottom edge; `bold` draws the text twice, a pixel apart (id kFramedTextBold).
std::vector<Marker> framedText(const std::string& frame_id, const std::string& ns, double y, const std::string& text,
                               const std_msgs::ColorRGBA& c, double size, bool grow_up = false, bool bold = false) {
  const std::string s = wrapped(text, size, 2 * (kMaxHalfFrameWidth - kFrameMarginX) / kFramedWidthFactor);
  const double half_width = kFramedWidthFactor * textWidth(s, size) / 2 + kFrameMarginX;
  const double half_height = textHeight(s, size) / 2 + kFrameMarginY;
  if (grow_up) y += half_height;
  const double l = kCentreX - half_width, r = kCentreX + half_width;
  const double b = y - half_height, t = y + half_height, w = kFramedBoxWidth;
  Marker panel = lineMarker(frame_id, ns, kFramedBox, Marker::TRIANGLE_LIST, 1.0, c);
  panel.pose.position.z = kOverlayZ;
  const auto rectangle = [&panel](double x0, double y0, double x1, double y1, const std_msgs::ColorRGBA& colour) {
    for (const auto& p : {point(x0, y0), point(x1, y0), point(x1, y1), point(x0, y0), point(x1, y1), point(x0, y1)}) {
      panel.points.push_back(p);
      panel.colors.push_back(colour);
    }
  };
  rectangle(l, b, r, t, color(kOverlayBackground));
  rectangle(l, b, r, b + w, c), rectangle(l, t - w, r, t, c);  // the border, over the panel's edges
  rectangle(l, b, l + w, t, c), rectangle(r - w, b, r, t, c);
  Marker label = textMarker(frame_id, ns, kFramedText, kCentreX, y, s, size, c);
  label.pose.position.z = kOverlayZ + kOverlayTextDz;
  if (!bold) return {label, panel};
  Marker again = label;
  again.id = kFramedTextBold;
  again.pose.position.y -= kBoldDy;
  return {label, again, panel};
}

}  // namespace

std::vector<Marker> rejectedBanner(const collision_lab::Rejected& rejected, const std::string& frame_id) {
  // Whose input and which run, as far as the message tells (either may be empty).
  std::string run = rejected.run_id.empty() ? "an input" : "run '" + rejected.run_id + "'";
  if (!rejected.student.empty()) run += " of student '" + rejected.student + "'";
  return framedText(frame_id, ns::kRejected, kBannerBottomY,
                    "REJECTED " + run + ": " + rejected.reason_name + " in " + rejected.field + "\n" +
                        rejected.message,
                    color(kBannerRed), kTextSize, true);
}

std::vector<Marker> hintMarkers(const std::string& command, const std::string& frame_id) {
  return framedText(frame_id, ns::kHint, kHintY, command, color(kWhite), kHintTextSize, false, true);
}

}  // namespace collision_lab_ros
