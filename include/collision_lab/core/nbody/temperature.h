// Granular temperature of an N-body run and Haff's law of cooling (issue 21). ROS-free:
// part of collision_lab_core. The CLI (--temperature-csv) and the rviz T(t) view use it.
//
// Definition. T = (1/N) sum_i m_i (v_i - V)^2 [J] over the N finite bodies (walls excluded),
// with V = sum m_i v_i / sum m_i the centre-of-mass velocity. T is twice the mean kinetic
// energy per body about the centre of mass (1D, k_B = 1: the "temperature in energy units"
// of granular gases); it is blind to the motion of the whole and so unchanged by a Galilean
// boost. With a wall V is the finite bodies' centre-of-mass velocity at that instant.
//
// Haff's law (P. K. Haff, J. Fluid Mech. 134, 1983): a freely cooling homogeneous gas with
// a constant e has T(t) = T0 / (1 + t/tau)^2. fitHaff fits it to samples by least squares
// on ln T.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "collision_lab/core/nbody/body_state_replay.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {

/// T = (1/N) sum m_i (v_i - V)^2 [J] over the finite masses (definition above); 0 without a
/// finite mass. Precondition: masses.size() == velocities.size().
double granularTemperature(const std::vector<double>& masses, const std::vector<double>& velocities);

/// T just after an impact (or a collapse), or at the start.
struct TemperatureSample {
  std::uint64_t impacts = 0;  ///< impacts so far [1] (a collapse keeps its impacts' count)
  double time = 0.0;          ///< [s]
  double temperature = 0.0;   ///< [J]
};

/// Samples T(t) of a run from the engine's ImpactRecords and collapse notices (replayed by
/// BodyStateReplay). Feed it every impact and
/// every collapse in the engine's order. O(N) memory; each sample costs O(N), each impact
/// O(the bodies it moved).
class TemperatureSampler {
 public:
  using Sink = std::function<void(const TemperatureSample&)>;

  /// Sends the start's sample (0 impacts, t = 0) at once. `every` >= 1: a sample after
  /// every `every`-th impact (impact index a multiple of it) and after every collapse.
  /// Precondition: validate(scene) passed.
  TemperatureSampler(const Scene& scene, std::uint64_t every, Sink sink);

  void onImpact(const ImpactRecord& impact);
  void onCollapse(const Collapse& collapse);
  /// Sends the newest state's sample unless it was the last one sent (the run's end).
  void finish();

  /// Every body's velocity after the impacts fed so far [m/s].
  const std::vector<double>& velocities() const { return state_.velocities(); }

 private:
  void send(std::uint64_t impacts, double time);

  BodyStateReplay state_;  ///< the one replay of the records (body_state_replay.h)
  std::uint64_t every_;
  Sink sink_;
  std::uint64_t impacts_ = 0;
  double time_ = 0.0;
  bool newest_sent_ = true;
};

/// A stride that keeps sampling O(1) per impact on average: max(1, N / 8) for N bodies.
std::uint64_t temperatureStride(std::size_t bodies);

/// Samples thinned for a log-log plot and the Haff fit: the start (t = 0), the first sample
/// of every 1/kPerDecade of a decade of time, and the newest. Memory is bounded by the
/// decades the run spans, whatever its impacts.
class LogTimeSamples {
 public:
  static constexpr int kPerDecade = 50;
  /// Samples must come in time order.
  void add(const TemperatureSample& sample);
  /// The kept samples and the newest, in time order.
  std::vector<TemperatureSample> samples() const;

 private:
  std::vector<TemperatureSample> kept_;
  std::optional<TemperatureSample> newest_;  ///< the newest when it is not kept
  double last_bin_ = -std::numeric_limits<double>::infinity();
};

/// Haff's law T(t) = t0 / (1 + t/tau)^2 fitted to samples.
struct HaffFit {
  bool ok = false;           ///< at least two usable samples, one at t > 0, and tau found
  double t0 = 0.0;           ///< [J]
  double tau = 0.0;          ///< [s]; +inf when T does not fall (no cooling seen)
  bool t0_fixed = false;     ///< t0 was given, not fitted
  std::size_t samples = 0;   ///< usable samples: finite t >= 0 and T > 0
  double rms_log_error = 0.0;  ///< sqrt(mean (ln T - ln T_fit)^2) [1]
};

/// Least squares on ln T over the usable samples (finite t >= 0, T > 0; each sample weighs
/// the same): minimises sum (ln T_i - ln t0 + 2 ln(1 + t_i/tau))^2 over tau, and over t0 too
/// unless fixed_t0 (e.g. the start's T) is given. For a given tau the best ln t0 is the
/// mean, so the fit is a one-dimensional search in ln tau: a grid of 0.05 decades over
/// [1e-6, 1e6] x the last sample's time, then golden sections to the precision of doubles.
/// tau at the grid's upper end is reported as +inf (T does not fall).
HaffFit fitHaff(const std::vector<TemperatureSample>& samples, std::optional<double> fixed_t0 = std::nullopt);

}  // namespace core
}  // namespace collision_lab
