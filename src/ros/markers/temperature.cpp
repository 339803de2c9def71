// Large inelastic scenes (a granular gas), in the kinetic energy bars' place: the view's
// granular temperature T(t) (RunView::temperature, to the run's end) on log-log axes beside
// Haff's law T0 / (1 + t/tau)^2 fitted to it (RunView::haff_t0, haff_tau), with the view's
// legend: what the page draws too. And T now, as a dot on the curve and a line of text with
// the kinetic energy now (animated, from the state shown).
#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_lab/core/nbody/temperature.h"
#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

using Samples = std::vector<std::pair<double, double>>;  ///< (t [s], T [J])

/// log10 t across, log10 T up: the samples at t > 0 with T > 0 (a decade at least each way).
struct LogAxes {
  Axes axes;
  bool ok = false;
  double toX(double t) const { return axes.toX(std::log10(t)); }
  double toY(double temperature) const { return axes.toY(std::log10(temperature)); }
};

LogAxes logAxes(const Samples& samples) {
  double t0 = std::numeric_limits<double>::infinity(), t1 = 0.0, lo = t0, hi = 0.0;
  for (const auto& [time, temperature] : samples) {
    if (!(time > 0 && temperature > 0)) continue;
    t0 = std::min(t0, time), t1 = std::max(t1, time);
    lo = std::min(lo, temperature), hi = std::max(hi, temperature);
  }
  // The start's T is the top of the curve, though it has no place on a log time axis.
  if (!samples.empty() && samples.front().second > 0) hi = std::max(hi, samples.front().second);
  LogAxes out;
  out.ok = t1 > 0 && hi > 0;
  if (!out.ok) return out;
  double x0 = std::floor(std::log10(t0)), x1 = std::ceil(std::log10(t1));
  double y0 = std::floor(std::log10(lo)), y1 = std::ceil(std::log10(hi));
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) y1 = y0 + 1;
  out.axes = Axes{kTemperatureBox, x0, x1, y0, y1};
  return out;
}

/// 10^exponent as "0.01", "1", "10,000", "10^6", "10^-5": no e-notation (rviz's font has no
/// superscript digits but ² and ³).
std::string decade(double exponent) {
  const std::string text = format("%g", std::pow(10.0, exponent));
  if (text.find("×10^") != std::string::npos) return format("10^%.0f", exponent);
  return exponent >= 3 ? withSeparators(static_cast<std::uint64_t>(std::pow(10.0, exponent) + 0.5)) : text;
}

}  // namespace

void drawTemperature(const Canvas& c) {
  if (!c.view.gas) return;
  const Box& b = kTemperatureBox;
  c.add(c.text(ns::kTemperature, kTemperatureTitle, kBarsBox.midX(), kBarsBox.top + kBarsTitleDy,
               "granular temperature T(t) [J], log-log", kTextSize));
  const Samples& drawn = c.view.temperature;
  const LogAxes log = logAxes(drawn);
  if (!log.ok) {
    c.add(c.text(ns::kTemperature, kTemperatureLegend, b.midX(), b.midY(), "no collision yet", kSmallTextSize,
                 color(kLabelGrey)));
    return;
  }
  const Axes& a = log.axes;
  Marker frame = c.lines(ns::kTemperature, kTemperatureFrame, Marker::LINE_LIST, kFrameWidth, color(kGrey));
  frame.points = {point(b.left, b.bottom), point(b.right, b.bottom), point(b.left, b.bottom), point(b.left, b.top)};
  c.add(frame);
  Marker ticks = c.lines(ns::kTemperature, kTemperatureTicks, Marker::LINE_LIST, kFrameWidth, color(kGrey));
  for (double x = a.x0; x <= a.x1; x += 1) {
    ticks.points.push_back(point(a.toX(x), b.bottom));
    ticks.points.push_back(point(a.toX(x), b.bottom - kTickLength));
  }
  for (double y = a.y0; y <= a.y1; y += 1) {
    ticks.points.push_back(point(b.left, a.toY(y)));
    ticks.points.push_back(point(b.left - kTickLength, a.toY(y)));
  }
  c.addLines(ticks);
  c.add(c.text(ns::kTemperature, kTemperatureTimeMin, b.left, b.bottom + kIndexLabelDy, decade(a.x0), kSmallTextSize));
  c.add(c.text(ns::kTemperature, kTemperatureTimeMax, b.right, b.bottom + kIndexLabelDy, decade(a.x1), kSmallTextSize));
  c.add(c.text(ns::kTemperature, kTemperatureUnits, b.midX(), b.bottom + kIndexLabelDy, "t [s]", kSmallTextSize,
               color(kLabelGrey)));
  c.add(c.text(ns::kTemperature, kTemperatureMin, b.left + kValueLabelDx, b.bottom, decade(a.y0), kSmallTextSize));
  c.add(c.text(ns::kTemperature, kTemperatureMax, b.left + kValueLabelDx, b.top, decade(a.y1), kSmallTextSize));

  // T over the fit (and thicker): where the two agree, the white line is the one seen.
  Marker series = c.lines(ns::kTemperature, kTemperatureSeries, Marker::LINE_STRIP, kTemperatureWidth, color(kWhite));
  double last = a.x0;  // log10 of the curve's last time [s]
  for (const auto& [time, temperature] : drawn) {
    if (!(time > 0 && temperature > 0)) continue;
    series.points.push_back(point(log.toX(time), log.toY(temperature), kDotZ));
    last = std::log10(time);
  }
  c.addLines(series);

  if (c.view.haff_ok) {
    // From the axis' start to the run's end, not beyond: the law is fitted to this run.
    Marker haff = c.lines(ns::kTemperature, kTemperatureHaff, Marker::LINE_STRIP, kCursorWidth, color(kHaffCyan));
    for (int k = 0; k <= kHaffSegments; ++k) {
      const double t = std::pow(10.0, a.x0 + (last - a.x0) * k / kHaffSegments);
      const double value = c.view.haff_t0 / ((1 + t / c.view.haff_tau) * (1 + t / c.view.haff_tau));
      if (value > 0) haff.points.push_back(point(log.toX(t), log.toY(value)));
    }
    c.addLines(haff);
  }
  // The colours' key, then the view's legend (the page's words).
  const std::string legend = "white: T,  cyan: Haff's fit.  " + c.view.temperature_legend;
  c.add(c.text(ns::kTemperature, kTemperatureLegend, kBarsBox.midX(), kTemperatureLegendY,
               wrapped(legend, kSmallTextSize, kLeftTextWidth), kSmallTextSize, color(kLabelGrey)));
}

void drawTemperatureNow(const Canvas& c, const SceneState& state) {
  if (!c.view.gas) return;
  const std::vector<double> masses(c.run.input().masses.begin(), c.run.input().masses.end());
  const double now = collision_lab::core::granularTemperature(masses, state.velocities);
  double energy = 0.0;  // [J] of the finite masses shown
  for (std::size_t i = 0; i < masses.size() && i < state.velocities.size(); ++i) {
    energy += collision_lab::core::kineticEnergy(masses[i], state.velocities[i]);
  }
  c.add(c.text(ns::kTemperatureNow, kTemperatureNowText, kTemperatureBox.midX(), kTemperatureNowY,
               format("now: T = %.3g J,  E = ", now) + format("%.3g J", energy) +
                   format(" of %.3g J", c.run.startEnergy()),
               kSmallTextSize));
  const LogAxes log = logAxes(c.view.temperature);
  if (!(log.ok && state.time > 0 && now > 0)) {
    c.add(deleteMarker(ns::kTemperatureNow, kTemperatureNowDot, c.frame_id));
    return;
  }
  Marker dot = c.dots(ns::kTemperatureNow, kTemperatureNowDot, kSimulatedDotSize, color(kAmber));
  dot.points.push_back(point(log.toX(state.time), log.toY(now), kCursorZ));
  c.add(dot);
}

}  // namespace collision_lab_ros::markers
