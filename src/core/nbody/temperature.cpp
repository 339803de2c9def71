#include "collision_lab/core/nbody/temperature.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace collision_lab {
namespace core {

double granularTemperature(const std::vector<double>& masses, const std::vector<double>& velocities) {
  double mass = 0.0, momentum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < masses.size(); ++i) {
    if (!std::isfinite(masses[i])) continue;
    mass += masses[i];
    momentum += masses[i] * velocities[i];
    ++n;
  }
  if (n == 0) return 0.0;
  const double centre = momentum / mass;
  // Deviations from V, not sum m v^2 - M V^2: no cancellation when the whole moves fast.
  double sum = 0.0;
  for (std::size_t i = 0; i < masses.size(); ++i) {
    if (!std::isfinite(masses[i])) continue;
    const double d = velocities[i] - centre;
    sum += masses[i] * d * d;
  }
  return sum / static_cast<double>(n);
}

TemperatureSampler::TemperatureSampler(const Scene& scene, std::uint64_t every, Sink sink)
    : state_(scene), every_(std::max<std::uint64_t>(every, 1)), sink_(std::move(sink)) {
  send(0, 0.0);
}

void TemperatureSampler::onImpact(const ImpactRecord& impact) {
  state_.apply(impact);
  impacts_ = impact.index;
  time_ = impact.time;
  newest_sent_ = false;
  if (impact.index % every_ == 0) send(impacts_, time_);
}

void TemperatureSampler::onCollapse(const Collapse& collapse) {
  state_.apply(collapse);
  impacts_ = collapse.impacts_before;
  time_ = collapse.time;
  send(impacts_, time_);
}

void TemperatureSampler::finish() {
  if (!newest_sent_) send(impacts_, time_);
}

void TemperatureSampler::send(std::uint64_t impacts, double time) {
  newest_sent_ = true;
  if (sink_) sink_(TemperatureSample{impacts, time, granularTemperature(state_.masses(), state_.velocities())});
}

std::uint64_t temperatureStride(std::size_t bodies) { return std::max<std::uint64_t>(1, bodies / 8); }

void LogTimeSamples::add(const TemperatureSample& sample) {
  const double bin = sample.time > 0 ? std::floor(std::log10(sample.time) * kPerDecade)
                                     : -std::numeric_limits<double>::infinity();
  if (kept_.empty() || bin > last_bin_) {
    kept_.push_back(sample);
    last_bin_ = bin;
    newest_.reset();
  } else {
    newest_ = sample;
  }
}

std::vector<TemperatureSample> LogTimeSamples::samples() const {
  std::vector<TemperatureSample> all = kept_;
  if (newest_) all.push_back(*newest_);
  return all;
}

namespace {

/// The usable samples as (t, ln T).
struct LogSeries {
  std::vector<double> t, log_t;
};

/// Sum of squared ln residuals at ln tau = u, with ln t0 fixed or the best for this tau
/// (written to log_t0).
double haffCost(const LogSeries& s, double u, std::optional<double> fixed_log_t0, double& log_t0) {
  const double tau = std::exp(u);
  const std::size_t n = s.t.size();
  // r_i = ln T_i + 2 ln(1 + t_i/tau) - ln t0
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean += s.log_t[i] + 2 * std::log1p(s.t[i] / tau);
  mean /= static_cast<double>(n);
  log_t0 = fixed_log_t0.value_or(mean);
  double cost = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = s.log_t[i] + 2 * std::log1p(s.t[i] / tau) - log_t0;
    cost += r * r;
  }
  return cost;
}

}  // namespace

HaffFit fitHaff(const std::vector<TemperatureSample>& samples, std::optional<double> fixed_t0) {
  HaffFit fit;
  fit.t0_fixed = fixed_t0.has_value();
  LogSeries s;
  double t_max = 0.0;
  for (const TemperatureSample& sample : samples) {
    if (!(std::isfinite(sample.time) && sample.time >= 0 && sample.temperature > 0 &&
          std::isfinite(sample.temperature))) {
      continue;
    }
    s.t.push_back(sample.time);
    s.log_t.push_back(std::log(sample.temperature));
    t_max = std::max(t_max, sample.time);
  }
  fit.samples = s.t.size();
  if (fit.samples < 2 || !(t_max > 0) || (fixed_t0 && !(*fixed_t0 > 0 && std::isfinite(*fixed_t0)))) return fit;
  const std::optional<double> fixed_log_t0 = fixed_t0 ? std::optional<double>(std::log(*fixed_t0)) : std::nullopt;

  // Grid over ln tau in [ln(1e-6 t_max), ln(1e6 t_max)], 0.05 decades apart.
  constexpr int kSteps = 12 * 20;
  const double lo = std::log(t_max) - 6 * std::log(10.0);
  const double du = 12 * std::log(10.0) / kSteps;
  int best = 0;
  double best_cost = std::numeric_limits<double>::infinity(), log_t0 = 0.0;
  for (int k = 0; k <= kSteps; ++k) {
    const double cost = haffCost(s, lo + k * du, fixed_log_t0, log_t0);
    if (cost < best_cost) {
      best_cost = cost;
      best = k;
    }
  }
  double u = lo + best * du;
  if (best == kSteps) {
    fit.tau = std::numeric_limits<double>::infinity();
    double mean = 0.0;
    for (double y : s.log_t) mean += y;
    log_t0 = fixed_log_t0.value_or(mean / static_cast<double>(s.t.size()));
    best_cost = 0.0;
    for (double y : s.log_t) best_cost += (y - log_t0) * (y - log_t0);
  } else {
    // Golden sections in the bracket around the grid's best point.
    const double phi = (std::sqrt(5.0) - 1) / 2;
    double a = lo + std::max(best - 1, 0) * du, b = lo + std::min(best + 1, kSteps) * du;
    double c = b - phi * (b - a), d = a + phi * (b - a);
    double fc = haffCost(s, c, fixed_log_t0, log_t0), fd = haffCost(s, d, fixed_log_t0, log_t0);
    while (b - a > 1e-13 * std::max(1.0, std::abs(a))) {
      if (fc < fd) {
        b = d;
        d = c;
        fd = fc;
        c = b - phi * (b - a);
        fc = haffCost(s, c, fixed_log_t0, log_t0);
      } else {
        a = c;
        c = d;
        fc = fd;
        d = a + phi * (b - a);
        fd = haffCost(s, d, fixed_log_t0, log_t0);
      }
    }
    u = (a + b) / 2;
    best_cost = haffCost(s, u, fixed_log_t0, log_t0);
    fit.tau = std::exp(u);
  }
  fit.t0 = std::exp(log_t0);
  fit.rms_log_error = std::sqrt(best_cost / static_cast<double>(s.t.size()));
  fit.ok = true;
  return fit;
}

}  // namespace core
}  // namespace collision_lab
