// In the wedge's place, for scenes other than three bodies: the velocities now, body by
// body (a profile, small N), or their mass-weighted histogram against the Maxwell-like
// spread (large N): the Gaussian with the same mass-weighted mean and kinetic-energy
// variance, sigma^2 = sum m (v - V)^2 / sum m. Walls are left out.
#include <algorithm>
#include <cmath>

#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

/// The velocity axis [m/s]: symmetric, the largest |v| of the run so far padded, so that
/// every state shown lies inside it (a live run's axis grows as its collisions come).
std::pair<double, double> velocityAxis(const RunRecord& run) {
  const double v_max = std::max(std::abs(run.minVelocity()), std::abs(run.maxVelocity()));
  return v_max > 0 && std::isfinite(v_max) ? paddedRange(-v_max, v_max) : paddedRange(-1.0, 1.0);
}

/// Mass-weighted mean V [m/s] and spread sigma [m/s] of the finite bodies' velocities.
std::pair<double, double> meanAndSpread(const RunRecord& run, const std::vector<double>& v) {
  double mass = 0.0, p = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!run.isWall(i)) mass += run.input().masses[i], p += run.input().masses[i] * v[i];
  }
  const double mean = mass > 0 ? p / mass : 0.0;
  double spread = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!run.isWall(i)) spread += run.input().masses[i] * (v[i] - mean) * (v[i] - mean);
  }
  return {mean, mass > 0 ? std::sqrt(spread / mass) : 0.0};
}

void drawHistogramNow(const Canvas& c, const SceneState& state) {
  const auto [v0, v1] = velocityAxis(c.run);
  const double width = (v1 - v0) / kHistogramBins;
  std::vector<double> share(kHistogramBins, 0.0);
  double mass = 0.0;
  for (std::size_t i = 0; i < state.velocities.size(); ++i) {
    if (c.run.isWall(i)) continue;
    const double m = c.run.input().masses[i];
    const int bin = std::clamp(static_cast<int>(std::floor((state.velocities[i] - v0) / width)), 0, kHistogramBins - 1);
    share[static_cast<std::size_t>(bin)] += m;
    mass += m;
  }
  const auto [mean, sigma] = meanAndSpread(c.run, state.velocities);
  // Mass share per bin against the Gaussian's share, mass * pdf * width.
  const double peak = sigma > 0 ? width / (sigma * std::sqrt(2 * M_PI)) : 1.0;
  double top = peak;
  for (double& s : share) s = mass > 0 ? s / mass : 0.0, top = std::max(top, s);
  const Axes axes{kHistogramBox, v0, v1, 0.0, top * (1 + kRangePadding)};
  Marker bars = c.base(ns::kVelocitiesNow, kSideBars, Marker::TRIANGLE_LIST);
  bars.color = color(kSimulatedOrange);
  for (int k = 0; k < kHistogramBins; ++k) {
    if (!(share[static_cast<std::size_t>(k)] > 0)) continue;
    const double l = axes.toX(v0 + k * width), r = axes.toX(v0 + (k + 1) * width);
    const double b = axes.toY(0.0), t = axes.toY(share[static_cast<std::size_t>(k)]);
    for (const auto& p : {point(l, b), point(r, b), point(r, t), point(l, b), point(r, t), point(l, t)}) bars.points.push_back(p);
  }
  if (bars.points.empty()) c.add(deleteMarker(ns::kVelocitiesNow, kSideBars, c.frame_id));
  else c.add(bars);
  Marker gauss = c.lines(ns::kVelocitiesNow, kSideGaussian, Marker::LINE_STRIP, kSeriesWidth, color(kWhite));
  for (int k = 0; k <= kGaussianSegments && sigma > 0; ++k) {
    const double v = v0 + (v1 - v0) * k / kGaussianSegments;
    gauss.points.push_back(point(axes.toX(v), axes.toY(peak * std::exp(-0.5 * std::pow((v - mean) / sigma, 2))), kDotZ));
  }
  c.addLines(gauss);
  c.add(c.text(ns::kVelocitiesNow, kSideNowText, kHistogramBox.midX(), kHistogramTextY,
               format("now: V = %.3g m/s", mean) + format(", sigma = %.3g m/s", sigma), kSmallTextSize, color(kLabelGrey)));
}

void drawProfileNow(const Canvas& c, const SceneState& state) {
  const auto [v0, v1] = velocityAxis(c.run);
  const std::size_t n = state.velocities.size();
  const Axes axes{kSideBox, -0.5, static_cast<double>(n) - 0.5, v0, v1};
  Marker dots = c.dots(ns::kVelocitiesNow, kSideBars, kProfileDotSize, color(kWhite));
  for (std::size_t i = 0; i < n; ++i) {
    // Body 0 (the rightmost) on the right, as in the scene.
    dots.points.push_back(point(axes.toX(static_cast<double>(n - 1 - i)), axes.toY(state.velocities[i]), kDotZ));
    dots.colors.push_back(bodyColor(c.view, i));
  }
  if (!dots.points.empty()) c.add(dots);
}

}  // namespace

void drawSideViewAxes(const Canvas& c) {
  const SideView view = sideView(c.run);
  if (view == SideView::kWedge) return;
  const auto [v0, v1] = velocityAxis(c.run);
  const bool histogram = view == SideView::kHistogram;
  const Box& b = histogram ? kHistogramBox : kSideBox;
  if (histogram) {
    Marker frame = c.lines(ns::kVelocities, kSideFrame, Marker::LINE_LIST, kFrameWidth, color(kGrey));
    frame.points = {point(b.left, b.bottom), point(b.right, b.bottom), point(b.left, b.bottom), point(b.left, b.top)};
    c.add(frame);
    c.add(c.text(ns::kVelocities, kSideAxisMin, b.left, b.bottom + kIndexLabelDy, withSign("%.3g", v0), kSmallTextSize));
    c.add(c.text(ns::kVelocities, kSideAxisMax, b.right, b.bottom + kIndexLabelDy, withSign("%.3g", v1), kSmallTextSize));
    c.add(c.text(ns::kVelocities, kSideAxisLabel, b.midX(), b.bottom + kIndexLabelDy, "v [m/s]", kSmallTextSize));
  } else {
    addFrame(c, ns::kVelocities, kSideFrame, Axes{b, 0.0, 1.0, v0, v1}, "v [m/s]");
    c.add(c.text(ns::kVelocities, kSideAxisLabel, b.midX(), b.bottom + kIndexLabelDy,
                 "bodies, " + bodyName(c.run.bodies() - 1) + " (left) to A (right)", kSmallTextSize));
  }
  c.add(c.text(ns::kVelocities, kSideTitle, b.midX(), kPanelTitleY,
               histogram ? "velocities now: histogram" : "velocities now, body by body", kTextSize));
  const double width = b.right - b.left;
  c.add(c.text(ns::kVelocities, kSideLegend, b.midX(), kLegendY,
               wrapped(histogram ? "orange: mass share per bin" : "dots: v of each body now (walls grey)",
                       kSmallTextSize, width),
               kSmallTextSize, color(kLabelGrey)));
  if (histogram) {
    c.add(c.text(ns::kVelocities, kSideNote, b.midX(), b.bottom + kSideNoteDy,
                 wrapped("white: Gaussian of the same mean V and mass-weighted spread sigma (Maxwell-like)",
                         kSmallTextSize, width),
                 kSmallTextSize, color(kLabelGrey)));
  }
}

void drawSideViewNow(const Canvas& c, const SceneState& state) {
  const SideView view = sideView(c.run);
  if (view == SideView::kHistogram) drawHistogramNow(c, state);
  if (view == SideView::kVelocityProfile) drawProfileNow(c, state);
}

}  // namespace collision_lab_ros::markers
