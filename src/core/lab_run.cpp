#include "collision_lab/core/lab_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "collision_lab/core/paper.h"

namespace collision_lab {

namespace {

std::array<double, 3> toArray(const Eigen::Vector3d& v) { return {v(0), v(1), v(2)}; }

/// Relative error in the energy norm: |S (a - b)| / |S v_0| with S = diag(sqrt(m)), in
/// the wall's frame. Scale-free, and the norm in which every impact is an isometry, so a
/// light body's rounding is weighed by the energy it carries.
class EnergyNormError {
 public:
  explicit EnergyNormError(const Scene& scene) : scene_(scene) {
    for (int i = 0; i < 3; ++i) {
      if (!scene.isWall(i)) mass_max_ = std::max(mass_max_, scene.masses[i]);
    }
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
  const Scene& scene_;
  double mass_max_ = 0.0;
  double initial_norm_ = 1.0;
};

bool keeps(const EventPolicy& policy, std::uint64_t index) {
  return policy.kind == EventPolicy::Kind::kAll ||
         (policy.kind == EventPolicy::Kind::kFirstN && index <= policy.first_n);
}

}  // namespace

AnalyticPrediction predict(const Scene& scene) {
  const AnalyticModel<double> model(scene);
  AnalyticPrediction prediction;
  prediction.collision_count = predictedCollisionCount(scene);
  prediction.paper_collision_count = paper::collisionCount(scene);
  prediction.max_possible_collision_count = maxPossibleCollisionCount(scene.masses);
  prediction.angles = anglesFor(scene.masses);
  prediction.phi_bc = paper::phiBC(scene);
  prediction.psi = model.psi();
  prediction.first_pair = model.firstPair();
  prediction.final_velocities = toArray(model.velocitiesAfter(prediction.collision_count));
  return prediction;
}

RunResult runLab(const Scene& scene, const RunOptions& options, const LabEventVisitor& visitor) {
  const auto started = std::chrono::steady_clock::now();
  RunResult result = runLab(scene, options, predict(scene), visitor);
  result.summary.compute_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

RunResult runLab(const Scene& scene, const RunOptions& options, const AnalyticPrediction& prediction,
                 const LabEventVisitor& visitor) {
  const auto started = std::chrono::steady_clock::now();
  RunResult result;
  result.prediction = prediction;
  LabRunSummary& summary = result.summary;
  const EnergyNormError relative_error(scene);

  const bool over_cap = result.prediction.collision_count > options.max_collisions;
  if (options.mode == RunMode::kPredictOnly) {
    summary.collision_count = result.prediction.collision_count;
    summary.final_velocities = result.prediction.final_velocities;
  } else if (over_cap && options.skip_simulation_over_cap) {
    summary.truncated = true;
    summary.truncation_reason = "predicted " + std::to_string(result.prediction.collision_count) +
                                " collisions exceed max_collisions = " + std::to_string(options.max_collisions) +
                                "; not simulated";
    summary.final_velocities = scene.velocities;
  } else {
    const AnalyticModel<double> model(scene);
    SimulationOptions simulation_options;
    simulation_options.max_collisions = options.max_collisions;
    EventVisitor enrich;
    std::array<double, 3> previous_before = scene.velocities;
    if (options.mode == RunMode::kFull) {
      enrich = [&](const ImpactEvent& event) {
        LabEvent lab;
        lab.event = event;
        lab.predicted_velocities_after = toArray(model.velocitiesAfter(event.index));
        lab.paper_velocities_after = paper::velocitiesAfter(scene, event.index);
        const auto predicted_gain = model.energyTransfer(event.index);
        std::copy(predicted_gain.begin(), predicted_gain.end(), lab.predicted_energy_transfer.begin());
        lab.paper_energy_transfer =
            paper::energyTransfer(scene, event.index, event.pair, event.velocities_before, previous_before);
        for (int i = 0; i < 3; ++i) {
          const double v = event.velocities_after[i];
          lab.kinetic_energy_after[i] = scene.isWall(i) ? 0.0 : scene.masses[i] * v * v / 2;
        }
        previous_before = event.velocities_before;
        summary.max_prediction_error = std::max(summary.max_prediction_error, relative_error(event.velocities_after, lab.predicted_velocities_after));
        if (visitor) visitor(lab);
        if (keeps(options.events, event.index)) result.events.push_back(std::move(lab));
      };
    }
    const SimulationResult simulation = simulate(scene, simulation_options, options.precision, enrich);
    summary.simulated = true;
    summary.collision_count = simulation.collision_count;
    summary.truncated = simulation.truncated;
    if (simulation.truncated) {
      summary.truncation_reason = "stopped at max_collisions = " + std::to_string(options.max_collisions) +
                                  " of " + std::to_string(result.prediction.collision_count) + " predicted";
    }
    summary.final_velocities = simulation.final_velocities;
    summary.energy_relative_drift = simulation.energy_relative_drift;
    summary.momentum_relative_drift = simulation.momentum_relative_drift;
    summary.escalation = simulation.escalation;
    const auto predicted_final = toArray(model.velocitiesAfter(simulation.collision_count));
    summary.max_prediction_error =
        std::max(summary.max_prediction_error, relative_error(simulation.final_velocities, predicted_final));
  }
  summary.compute_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace collision_lab
