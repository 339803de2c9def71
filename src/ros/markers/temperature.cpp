// Large inelastic scenes (a granular gas), in the kinetic energy bars' place: the granular
// temperature T(t) on log-log axes (static: from the kept exact states, core::
// granularTemperature) beside Haff's law T0 / (1 + t/tau)^2 fitted to it (core::fitHaff:
// T0 and tau, least squares on ln T), labelled with tau, both to the run's end; and T now, as a dot on the curve
// and a line of text with the kinetic energy now (animated). What the core computes; this
// file only draws it.
#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_lab/core/nbody/temperature.h"
#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

namespace {

std::vector<double> massesOf(const RunRecord& run) {
  return std::vector<double>(run.input().masses.begin(), run.input().masses.end());
}

/// T just after each kept state, and at the start, thinned to 50 per decade of time.
std::vector<collision_lab::core::TemperatureSample> temperatureSamples(const RunRecord& run) {
  const std::vector<double> masses = massesOf(run);
  collision_lab::core::LogTimeSamples thin;
  const auto& in = run.input();
  thin.add({0, 0.0, collision_lab::core::granularTemperature(masses, {in.velocities.begin(), in.velocities.end()})});
  for (const Keyframe& f : run.keyframes()) {
    thin.add({f.index, f.time, collision_lab::core::granularTemperature(masses, f.velocities)});
  }
  return thin.samples();
}

/// The samples, and T held from the last one to the run's end (endTime): no collision
/// changes it in the free flight after the last one. What the curve draws and its axes hold.
std::vector<collision_lab::core::TemperatureSample> toRunEnd(const RunRecord& run,
                                                             std::vector<collision_lab::core::TemperatureSample> samples) {
  const double end = endTime(run);
  if (!samples.empty() && end > samples.back().time) {
    collision_lab::core::TemperatureSample held = samples.back();
    held.time = end;
    samples.push_back(held);
  }
  return samples;
}

/// log10 t across, log10 T up: the samples at t > 0 with T > 0 (a decade at least each way).
struct LogAxes {
  Axes axes;
  bool ok = false;
  double toX(double t) const { return axes.toX(std::log10(t)); }
  double toY(double temperature) const { return axes.toY(std::log10(temperature)); }
};

LogAxes logAxes(const std::vector<collision_lab::core::TemperatureSample>& samples) {
  double t0 = std::numeric_limits<double>::infinity(), t1 = 0.0, lo = t0, hi = 0.0;
  for (const auto& s : samples) {
    if (!(s.time > 0 && s.temperature > 0)) continue;
    t0 = std::min(t0, s.time), t1 = std::max(t1, s.time);
    lo = std::min(lo, s.temperature), hi = std::max(hi, s.temperature);
  }
  // The start's T is the top of the curve, though it has no place on a log time axis.
  if (!samples.empty() && samples.front().temperature > 0) hi = std::max(hi, samples.front().temperature);
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

/// 10^exponent as "0.01", "1", "1e+05".
std::string decade(double exponent) { return format("%g", std::pow(10.0, exponent)); }

}  // namespace

bool temperatureView(const RunRecord& run) {
  const auto& e = run.input().restitution;
  return largeScene(run) && std::any_of(e.begin(), e.end(), [](double value) { return value < 1.0; });
}

void drawTemperature(const Canvas& c) {
  if (!temperatureView(c.run)) return;
  const Box& b = kTemperatureBox;
  c.add(c.text(ns::kTemperature, kTemperatureTitle, kBarsBox.midX(), kBarsBox.top + kBarsTitleDy,
               "granular temperature T(t) [J], log-log", kTextSize));
  const auto samples = temperatureSamples(c.run);
  const auto drawn = toRunEnd(c.run, samples);
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
  for (const auto& s : drawn) {
    if (s.time > 0 && s.temperature > 0) series.points.push_back(point(log.toX(s.time), log.toY(s.temperature), kDotZ));
  }
  c.addLines(series);

  const collision_lab::core::HaffFit fit = collision_lab::core::fitHaff(samples);
  std::string legend = "white: T = sum m (v - V)^2 / N\ncyan: Haff's law T0/(1 + t/tau)^2 fitted on ln T:\n";
  if (fit.ok && std::isfinite(fit.tau)) {
    // From the axis' start to the run's end, not beyond: the law is fitted to this run.
    Marker haff = c.lines(ns::kTemperature, kTemperatureHaff, Marker::LINE_STRIP, kCursorWidth, color(kHaffCyan));
    const double last = std::log10(drawn.back().time);
    for (int k = 0; k <= kHaffSegments; ++k) {
      const double t = std::pow(10.0, a.x0 + (last - a.x0) * k / kHaffSegments);
      const double value = fit.t0 / ((1 + t / fit.tau) * (1 + t / fit.tau));
      if (value > 0) haff.points.push_back(point(log.toX(t), log.toY(value)));
    }
    c.addLines(haff);
    legend += format("tau = %.3g s", fit.tau) + format(", T0 = %.3g J", fit.t0);
  } else {
    legend += fit.ok ? "T does not fall" : "too few states";
  }
  c.add(c.text(ns::kTemperature, kTemperatureLegend, kBarsBox.midX(), kTemperatureLegendY,
               wrapped(legend, kSmallTextSize, kLeftTextWidth), kSmallTextSize, color(kLabelGrey)));
}

void drawTemperatureNow(const Canvas& c, const SceneState& state) {
  if (!temperatureView(c.run)) return;
  const std::vector<double> masses = massesOf(c.run);
  const double now = collision_lab::core::granularTemperature(masses, state.velocities);
  double energy = 0.0;  // [J] of the finite masses shown
  for (std::size_t i = 0; i < masses.size() && i < state.velocities.size(); ++i) {
    energy += collision_lab::core::kineticEnergy(masses[i], state.velocities[i]);
  }
  c.add(c.text(ns::kTemperatureNow, kTemperatureNowText, kTemperatureBox.midX(), kTemperatureNowY,
               format("now: T = %.3g J,  E = ", now) + format("%.3g J", energy) +
                   format(" of %.3g J", c.run.startEnergy()),
               kSmallTextSize));
  const LogAxes log = logAxes(toRunEnd(c.run, temperatureSamples(c.run)));
  if (!(log.ok && state.time > 0 && now > 0)) {
    c.add(deleteMarker(ns::kTemperatureNow, kTemperatureNowDot, c.frame_id));
    return;
  }
  Marker dot = c.dots(ns::kTemperatureNow, kTemperatureNowDot, kSimulatedDotSize, color(kAmber));
  dot.points.push_back(point(log.toX(state.time), log.toY(now), kCursorZ));
  c.add(dot);
}

}  // namespace collision_lab_ros::markers
