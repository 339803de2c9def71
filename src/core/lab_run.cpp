#include "collision_lab/core/lab_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "collision_lab/core/paper.h"
#include "collision_lab/core/precision.h"
#include "float_ops.h"

namespace collision_lab {
namespace core {

namespace {

/// What a run that was not simulated reports for the quantities it did not measure.
constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

/// In double, a zero always +0 (outputs must not show "-0").
template <class Vector>
std::array<double, 3> toArray(const Vector& v) {
  return {detail::toDouble(v(0)), detail::toDouble(v(1)), detail::toDouble(v(2))};
}

template <class T>
std::array<double, 3> toArray(const std::array<T, 3>& v) {
  return toArray(Eigen::Matrix<T, 3, 1>(v[0], v[1], v[2]));
}

/// The closed form in double; at 50 digits, whose exponent range has no end in sight,
/// where a finite-mass ratio beyond 2^1000 would underflow the light body's share of the
/// mass-weighted velocities (S = diag(sqrt(m / m_max))) in double.
class ClosedForm {
 public:
  explicit ClosedForm(const ThreeBodyScene& scene) {
    int smallest = std::numeric_limits<int>::max(), largest = std::numeric_limits<int>::min();
    for (int i = 0; i < 3; ++i) {
      if (scene.isWall(i)) continue;
      smallest = std::min(smallest, std::ilogb(scene.masses[i]));
      largest = std::max(largest, std::ilogb(scene.masses[i]));
    }
    if (largest - smallest <= 1000) {
      fast_.emplace(scene);
    } else {
      wide_.emplace(scene);
    }
  }

  std::array<double, 3> velocitiesAfter(std::uint64_t n) const {
    return fast_ ? toArray(fast_->velocitiesAfter(n)) : toArray(wide_->velocitiesAfter(n));
  }
  std::array<double, 3> energyTransfer(std::uint64_t n) const {
    return fast_ ? toArray(fast_->energyTransfer(n)) : toArray(wide_->energyTransfer(n));
  }
  double psi() const { return fast_ ? fast_->psi() : static_cast<double>(wide_->psi()); }

 private:
  std::optional<AnalyticModel<double>> fast_;
  std::optional<AnalyticModel<HighPrecision>> wide_;
};

/// Relative error in the energy norm: |S (a - b)| / |S v_0| with S = diag(sqrt(m)), in
/// the wall's frame. Scale-free, and the norm in which every impact is an isometry, so a
/// light body's rounding is weighed by the energy it carries.
class EnergyNormError {
 public:
  explicit EnergyNormError(const ThreeBodyScene& scene) : scene_(scene), mass_max_(largestFiniteMass(scene.masses)) {
    const int wall = scene.wallIndex();
    const double frame = wall >= 0 ? scene.velocities[wall] : 0.0;
    double norm_sq = 0.0;
    for (int i = 0; i < 3; ++i) {
      if (i == wall) continue;
      const double dv = scene.velocities[i] - frame;
      norm_sq += scene.masses[i] / mass_max_ * dv * dv;
    }
    initial_norm_ = norm_sq > 0.0 ? std::sqrt(norm_sq) : 1.0;
  }

  double operator()(const std::array<double, 3>& a, const std::array<double, 3>& b) const {
    double norm_sq = 0.0;
    for (int i = 0; i < 3; ++i) {
      if (scene_.isWall(i)) continue;
      const double d = a[i] - b[i];
      norm_sq += scene_.masses[i] / mass_max_ * d * d;
    }
    return std::sqrt(norm_sq) / initial_norm_;
  }

 private:
  const ThreeBodyScene& scene_;
  double mass_max_;
  double initial_norm_ = 1.0;
};

/// The summary of a run that was not simulated: the closed form answers, and nothing was
/// measured. `skipped`: over the cap, rather than predict-only.
void describeNotSimulated(const RunOptions& options, bool skipped, RunResult& result) {
  LabRunSummary& summary = result.summary;
  summary.collision_count = skipped ? 0 : result.prediction.collision_count;
  summary.final_velocities = result.prediction.final_velocities;
  summary.max_prediction_error = kNotMeasured;
  summary.energy_relative_drift = kNotMeasured;
  summary.momentum_relative_drift = kNotMeasured;
  if (skipped) {
    summary.truncated = true;
    summary.truncation_reason = "predicted " + std::to_string(result.prediction.collision_count) +
                                " collisions exceed max_collisions = " + std::to_string(options.max_collisions) +
                                "; not simulated";
  }
}

/// One simulated collision beside the closed form and the paper's printed formulas.
/// `previous_before`: the velocities before the collision before it (the paper's BC
/// energy formulas refer to them).
LabEvent labEvent(const ThreeBodyScene& scene, const ClosedForm& model, const ImpactEvent& event,
                  const std::array<double, 3>& previous_before) {
  LabEvent lab;
  lab.event = event;
  lab.predicted_velocities_after = model.velocitiesAfter(event.index);
  lab.paper_velocities_after = paper::velocitiesAfter(scene, event.index);
  lab.predicted_energy_transfer = model.energyTransfer(event.index);
  lab.paper_energy_transfer =
      paper::energyTransfer(scene, event.index, event.pair, event.velocities_before, previous_before);
  for (int i = 0; i < 3; ++i) {
    const double v = event.velocities_after[i];
    lab.kinetic_energy_after[i] = scene.isWall(i) ? 0.0 : scene.masses[i] * v * v / 2;
  }
  return lab;
}

/// Simulates, in full mode with every event put beside the prediction, and measures how
/// far the simulation is from the closed form.
void simulateBesidePrediction(const ThreeBodyScene& scene, const RunOptions& options, const LabEventVisitor& visitor,
                              RunResult& result) {
  LabRunSummary& summary = result.summary;
  const EnergyNormError relative_error(scene);
  const ClosedForm model(scene);
  SimulationOptions simulation_options;
  simulation_options.max_collisions = options.max_collisions;
  simulation_options.cancel = options.cancel;
  EventVisitor enrich;
  std::array<double, 3> previous_before = scene.velocities;
  if (options.mode == RunMode::kFull) {
    enrich = [&](const ImpactEvent& event) {
      LabEvent lab = labEvent(scene, model, event, previous_before);
      previous_before = event.velocities_before;
      summary.max_prediction_error = std::max(summary.max_prediction_error,
                                              relative_error(event.velocities_after, lab.predicted_velocities_after));
      if (visitor) visitor(lab);
      if (options.events.keeps(event.index)) result.events.push_back(std::move(lab));
    };
  }
  const SimulationResult simulation = simulate(scene, simulation_options, options.precision, enrich);
  summary.simulated = true;
  summary.collision_count = simulation.collision_count;
  summary.truncated = simulation.truncated;
  summary.cancelled = simulation.cancelled;
  if (simulation.cancelled) {
    summary.truncation_reason = "cancelled after " + std::to_string(simulation.collision_count) + " of " +
                                std::to_string(result.prediction.collision_count) + " predicted";
  } else if (simulation.truncated) {
    summary.truncation_reason = "stopped at max_collisions = " + std::to_string(options.max_collisions) + " of " +
                                std::to_string(result.prediction.collision_count) + " predicted";
  }
  summary.final_velocities = simulation.final_velocities;
  summary.energy_relative_drift = simulation.energy_relative_drift;
  summary.momentum_relative_drift = simulation.momentum_relative_drift;
  summary.escalation = simulation.escalation;
  const auto predicted_final = model.velocitiesAfter(simulation.collision_count);
  summary.max_prediction_error =
      std::max(summary.max_prediction_error, relative_error(simulation.final_velocities, predicted_final));
}

}  // namespace

AnalyticPrediction predict(const ThreeBodyScene& scene) {
  const ClosedForm model(scene);
  AnalyticPrediction prediction;
  prediction.collision_count = predictedCollisionCount(scene);
  prediction.paper_collision_count = paper::collisionCount(scene);
  prediction.max_possible_collision_count = maxPossibleCollisionCount(scene.masses);
  prediction.angles = anglesFor(scene.masses);
  prediction.phi_bc = paper::phiBC(scene);
  prediction.psi = model.psi();
  prediction.first_pair = firstPair(scene);
  prediction.final_velocities = toArray(model.velocitiesAfter(prediction.collision_count));
  return prediction;
}

RunResult runLab(const ThreeBodyScene& scene, const RunOptions& options, const LabEventVisitor& visitor) {
  const auto started = std::chrono::steady_clock::now();
  RunResult result = runLab(scene, options, predict(scene), visitor);
  result.summary.compute_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

RunResult runLab(const ThreeBodyScene& scene, const RunOptions& options, const AnalyticPrediction& prediction,
                 const LabEventVisitor& visitor) {
  const auto started = std::chrono::steady_clock::now();
  RunResult result;
  result.prediction = prediction;
  const bool over_cap = result.prediction.collision_count > options.max_collisions;
  const bool skipped = options.mode != RunMode::kPredictOnly && over_cap && options.skip_simulation_over_cap;
  if (options.mode == RunMode::kPredictOnly || skipped) {
    describeNotSimulated(options, skipped, result);
  } else {
    simulateBesidePrediction(scene, options, visitor, result);
  }
  result.summary.compute_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace core
}  // namespace collision_lab
