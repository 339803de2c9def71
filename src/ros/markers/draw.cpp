// Marker primitives and plot parts shared by the views (see markers/draw.h).
#include "collision_lab/ros/markers/draw.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab_ros::markers {

using namespace layout;

std_msgs::ColorRGBA color(const Rgba& c) {
  std_msgs::ColorRGBA out;
  out.r = c.r; out.g = c.g; out.b = c.b; out.a = c.a;
  return out;
}

std_msgs::ColorRGBA bodyColor(const RunView& view, std::size_t i, double lighten) {
  unsigned r = 0, g = 0, b = 0;
  if (i >= view.body_colours.size() || std::sscanf(view.body_colours[i].c_str(), "#%02x%02x%02x", &r, &g, &b) != 3) {
    throw std::logic_error("the view has no colour of body " + bodyName(i));
  }
  const auto channel = [lighten](unsigned byte) {
    const double c = byte / 255.0;
    return lighten == 0.0 ? c : c + (1 - c) * lighten;
  };
  return color({channel(r), channel(g), channel(b)});
}

std_msgs::ColorRGBA velocityColor(double v, double v_max) { return color(velocityRgb(v, v_max)); }

std::string bodyName(std::size_t i) { return collision_lab::core::bodyName(i); }

geometry_msgs::Point point(double x, double y, double z) {
  geometry_msgs::Point p;
  p.x = x; p.y = y; p.z = z;
  return p;
}

std::string withSign(const char* fmt, double value) {
  if (value == 0 || std::isnan(value)) return format(fmt, value);
  return (value > 0 ? "+" : "-") + format(fmt, std::abs(value));
}

std::string positionText(double x, bool signed_) {
  const double size = std::abs(x);
  std::string digits;
  if (size >= 1000 && size < 1e15) {
    // Four significant digits, the rest zeros: 1059.6 -> "1,060".
    const double unit = std::pow(10.0, std::floor(std::log10(size)) - 3);
    digits = withSeparators(static_cast<std::uint64_t>(std::round(size / unit) * unit));
  } else {
    digits = format("%.4g", size);
  }
  if (x == 0 || std::isnan(x) || digits == "0") return digits;
  if (x < 0) return "-" + digits;
  return signed_ ? "+" + digits : digits;
}

std::pair<std::size_t, std::size_t> textExtent(const std::string& s) {
  std::size_t longest = 0, lines_count = 1, start = 0;
  for (std::size_t end = s.find('\n'); ; end = s.find('\n', start)) {
    longest = std::max(longest, (end == std::string::npos ? s.size() : end) - start);
    if (end == std::string::npos) break;
    start = end + 1;
    ++lines_count;
  }
  return {longest, lines_count};
}

double textWidth(const std::string& s, double size) {
  return 2 * kHalfCharWidth * size * static_cast<double>(textExtent(s).first);
}

double textHeight(const std::string& s, double size) {
  return 2 * kHalfLineHeight * size * static_cast<double>(textExtent(s).second);
}

std::string wrapped(const std::string& s, double size, double width) {
  const auto fits = static_cast<std::size_t>(std::max(width / (2 * kHalfCharWidth * size), 1.0));
  std::string out, line, word;
  const auto flushWord = [&] {
    if (word.empty()) return;
    if (!line.empty() && line.size() + 1 + word.size() > fits) out += line + '\n', line.clear();
    line += (line.empty() ? "" : " ") + word;
    word.clear();
  };
  for (char ch : s + '\n') {
    if (ch == ' ' || ch == '\n') flushWord();
    else word += ch;
    if (ch == '\n') out += line + '\n', line.clear();
  }
  out.pop_back();  // the '\n' added after the last line
  return out;
}

std::array<double, 3> toArray3(const std::vector<double>& a) {
  std::array<double, 3> result;
  for (std::size_t i = 0; i < result.size(); ++i) result[i] = i < a.size() ? a[i] : std::nan("");
  return result;
}

bool isWall(const collision_lab::InitialConditions& input, std::size_t i) {
  return i < input.masses.size() && std::isinf(input.masses[i]);
}

bool largeScene(const RunRecord& run) { return run.bodies() > kMaxPlottedBodies; }

SideView sideView(const RunRecord& run) {
  std::size_t walls = 0;
  for (std::size_t i = 0; i < run.bodies(); ++i) walls += run.isWall(i) ? 1 : 0;
  if (run.bodies() == 3 && walls <= 1) return SideView::kWedge;
  return largeScene(run) ? SideView::kHistogram : SideView::kVelocityProfile;
}

namespace {

Marker baseMarker(const std::string& frame_id, const std::string& ns, int id, int type) {
  Marker m;
  m.header.frame_id = frame_id;  // stamp 0: rviz uses the latest transform
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = 1.0;
  m.color = color(kWhite);
  return m;
}

}  // namespace

Marker textMarker(const std::string& frame_id, const std::string& ns, int id, double x, double y,
                  const std::string& s, double size, const std_msgs::ColorRGBA& c) {
  Marker m = baseMarker(frame_id, ns, id, Marker::TEXT_VIEW_FACING);
  // Moved sideways into the screen when it would run off an edge (rviz cuts it there).
  const double half = textWidth(s, size) / 2;
  if (2 * half < kScreen.right - kScreen.left) x = std::clamp(x, kScreen.left + half, kScreen.right - half);
  m.pose.position = point(x, y, kTextZ);
  m.scale.z = size;
  m.color = c;
  m.text = s;
  return m;
}

Marker lineMarker(const std::string& frame_id, const std::string& ns, int id, int type, double width,
                  const std_msgs::ColorRGBA& c) {
  Marker m = baseMarker(frame_id, ns, id, type);
  m.scale.x = width;
  m.color = c;
  return m;
}

Marker Canvas::base(const std::string& ns, int id, int type) const { return baseMarker(frame_id, ns, id, type); }

Marker Canvas::text(const std::string& ns, int id, double x, double y, const std::string& s, double size,
                    const std_msgs::ColorRGBA& c) const {
  return textMarker(frame_id, ns, id, x, y, s, size, c);
}

Marker Canvas::lines(const std::string& ns, int id, int type, double width, const std_msgs::ColorRGBA& c) const {
  return lineMarker(frame_id, ns, id, type, width, c);
}

Marker Canvas::dots(const std::string& ns, int id, double size, const std_msgs::ColorRGBA& c) const {
  Marker m = base(ns, id, Marker::SPHERE_LIST);
  m.scale.x = m.scale.y = m.scale.z = size;
  m.color = c;
  return m;
}

void Canvas::addLines(Marker m) const {
  if (m.points.size() >= 2) out.push_back(std::move(m));
}

// ---- plots ----

double Axes::toX(double x) const {
  return box.left + std::clamp((x - x0) / (x1 - x0), 0.0, 1.0) * (box.right - box.left);
}

double Axes::toY(double y) const {
  return box.bottom + std::clamp((y - y0) / (y1 - y0), 0.0, 1.0) * (box.top - box.bottom);
}

std::pair<double, double> paddedRange(double lo, double hi, double always) {
  lo = std::min(lo, always);
  hi = std::max(hi, always);
  if (!(hi > lo) || !std::isfinite(hi - lo)) {
    const double centre = std::isfinite(lo) ? lo : 0.0;
    return {centre - 1.0, centre + 1.0};
  }
  const double pad = kRangePadding * (hi - lo);
  return {lo - pad, hi + pad};
}

void addFrame(const Canvas& c, const std::string& ns, int base, const Axes& axes, const std::string& label) {
  const Box& b = axes.box;
  const bool zero_inside = axes.y0 < 0 && axes.y1 > 0;
  const double zero = axes.toY(0.0);
  Marker frame = c.lines(ns, base + kFrameLines, Marker::LINE_LIST, kFrameWidth, color(kGrey));
  frame.points = {point(b.left, b.bottom), point(b.right, b.bottom), point(b.left, b.bottom), point(b.left, b.top)};
  if (zero_inside) {
    frame.points.push_back(point(b.left, zero));
    frame.points.push_back(point(b.right, zero));
  }
  c.add(frame);
  // Zero is labelled whenever it is inside; an end label too close to it gives way. When a
  // negative end value is shown, every sign is written.
  const bool top_shown = !zero_inside || b.top - zero > kLabelClearance;
  const bool bottom_shown = !zero_inside || zero - b.bottom > kLabelClearance;
  const auto value = [&](double y) { return bottom_shown && axes.y0 < 0 ? withSign("%.3g", y) : format("%.3g", y); };
  if (top_shown) {
    c.add(c.text(ns, base + kFrameTopValue, b.left + kValueLabelDx, b.top + kTopValueDy, value(axes.y1), kSmallTextSize));
  }
  if (bottom_shown) {
    c.add(c.text(ns, base + kFrameBottomValue, b.left + kValueLabelDx, b.bottom, value(axes.y0), kSmallTextSize));
  }
  if (zero_inside) c.add(c.text(ns, base + kFrameZeroLabel, b.left + kZeroLabelDx, zero, "0", kSmallTextSize));
  // Bold (drawn twice, a pixel apart): rviz draws '-' a pixel thin and faint, and the
  // labels carry signed drifts in e-notation ("drift -3.9e-19").
  Marker title = c.text(ns, base + kFrameLabel, b.midX(), b.top + kFrameLabelDy, label, kSmallTextSize);
  Marker again = title;
  again.id = base + kFrameLabelBold;
  again.pose.position.y -= kBoldDy;
  c.add(std::move(title));
  c.add(std::move(again));
}

void addSeries(const Canvas& c, const std::string& ns, int id, const Polyline& poly, const Axes& axes,
               const std_msgs::ColorRGBA& colour, double width) {
  // One LINE_STRIP; non-finite vertices are skipped.
  Marker m = c.lines(ns, id, Marker::LINE_STRIP, width, colour);
  for (const auto& v : poly) {
    if (std::isfinite(v.x) && std::isfinite(v.y)) m.points.push_back(point(axes.toX(v.x), axes.toY(v.y)));
  }
  c.addLines(m);
  if (!poly.empty() && axes.toX(poly.back().x) - axes.toX(poly.front().x) < kShortestSeries) {
    Marker dot = c.dots(ns, id + kSeriesStartDot, kStartDotSize, colour);
    dot.points.push_back(point(axes.toX(poly.front().x), axes.toY(poly.front().y), kDotZ));
    c.add(dot);
  }
}

Marker markedSegments(const Canvas& c, const std::string& ns, int id, const Polyline& poly, const Axes& axes,
                      double tolerance, const std_msgs::ColorRGBA& colour) {
  Marker m = c.lines(ns, id, Marker::LINE_LIST, kMarkedWidth, colour);
  for (std::size_t k = 1; k < poly.size(); ++k) {
    const auto& a = poly[k - 1];
    const auto& b = poly[k];
    if (!(std::isfinite(a.y) && std::isfinite(b.y))) continue;
    if (!(std::max(a.mark, b.mark) > tolerance)) continue;
    m.points.push_back(point(axes.toX(a.x), axes.toY(a.y), kMarkedZ));
    m.points.push_back(point(axes.toX(b.x), axes.toY(b.y), kMarkedZ));
  }
  return m;
}

Polyline withTail(const Envelope& e, double x_end) {
  Polyline poly = e.polyline();
  if (!poly.empty() && x_end > poly.back().x) poly.push_back({x_end, e.last().y, e.last().mark});
  return poly;
}

std::vector<const Keyframe*> thinned(const std::vector<Keyframe>& frames, std::size_t n) {
  std::vector<const Keyframe*> out;
  const std::size_t stride = std::max<std::size_t>(1, (frames.size() + n - 1) / n);
  for (std::size_t k = 0; k < frames.size(); k += stride) out.push_back(&frames[k]);
  return out;
}

void addIndexAxisLabels(const Canvas& c, const std::string& ns, int base, const Axes& axes) {
  // Step k (the velocities after k collisions) spans [k, k+1] of the axis; its label sits
  // under its middle: every step while there are few, else the first and the last. (The
  // panels' titles name the axis.)
  const auto last = static_cast<std::uint64_t>(axes.x1) - 1;
  std::vector<std::uint64_t> ticks{0};
  for (std::uint64_t k = last <= kAllIndexLabelsUpTo ? 1 : last; k <= last && k > 0; ++k) ticks.push_back(k);
  for (std::size_t j = 0; j < ticks.size(); ++j) {
    c.add(c.text(ns, base + static_cast<int>(j), axes.toX(ticks[j] + 0.5), axes.box.bottom + kIndexLabelDy,
                 withSeparators(ticks[j]), kSmallTextSize));
  }
}

}  // namespace collision_lab_ros::markers
