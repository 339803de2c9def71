// One lab run: prediction first, then the simulation with every event put beside the
// closed-form prediction and the paper's printed formulas. The simulation is the exact
// event engine's (nbody/engine.h), as for every scene: exact decisions and correctly
// rounded velocities, in the engine's working units, to the ends of the double range. A run
// whose next impact no double can hold (after the largest double, 1.8e308 s) stops honestly
// at its last certified impact, truncated, as every engine run does (OUT_OF_RANGE). Shared
// by the CLI, the ROS node and the benchmarks, so all of them report the same numbers.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/scene.h"
#include "collision_lab/core/events.h"

namespace collision_lab {
namespace core {

/// What a run models. Values match the ROS message constants MODE_*.
enum class RunMode : std::uint8_t {
  kFull = 0,         ///< simulate, report every event
  kPredictOnly = 1,  ///< closed form only, no simulation
  kSummaryOnly = 2,  ///< simulate, report no per-collision output
};

/// Analytic predictions for a scene, computed before (and without) any simulation.
struct AnalyticPrediction {
  std::uint64_t collision_count = 0;           ///< correct count, exact
  std::optional<std::int64_t> paper_collision_count;  ///< eq. (3.22) as printed; empty if undefined
  std::uint64_t max_possible_collision_count = 0;     ///< ceil(pi / alpha), exact
  Angles angles;                               ///< alpha, theta, Omega [rad]
  double phi_bc = 0.0;                         ///< the paper's phi_BC, eq. (3.21) [rad]
  double psi = 0.0;                            ///< angle of u_perp from r_BC [rad]
  std::optional<Pair> first_pair;
  std::array<double, 3> final_velocities{};    ///< closed form after collision_count [m/s]
};

AnalyticPrediction predict(const ThreeBodyScene& scene);

struct RunOptions {
  std::uint64_t max_collisions = 10'000'000;
  EventPolicy events = EventPolicy::all();  ///< which impacts RunResult keeps
  RunMode mode = RunMode::kFull;
  /// When the predicted count exceeds max_collisions, answer at once from the closed form
  /// (simulated false, its count and final velocities) instead of simulating up to the cap.
  bool skip_simulation_over_cap = false;
  /// When set (by a signal handler or another thread), the simulation stops within 1024
  /// collisions, marked truncated and cancelled.
  const std::atomic<bool>* cancel = nullptr;
  /// Called every progress_interval impacts (0: never) with the impacts so far and the
  /// time of the last impact [s], NaN where the run takes no impact times (the known-count
  /// path). It only watches: with it or without, the run takes the same path.
  ProgressCallback progress;
  std::uint64_t progress_interval = 0;
};

/// A run that was not simulated (predict-only, or skipped over the cap) measured nothing:
/// its max_prediction_error, energy_relative_drift and momentum_relative_drift are NaN,
/// "not measured", and its final_velocities are the predicted ones.
struct LabRunSummary {
  std::uint64_t collision_count = 0;        ///< simulated; the predicted count when not simulated
  bool truncated = false;
  std::string truncation_reason;            ///< empty unless truncated
  bool cancelled = false;                   ///< truncated by RunOptions::cancel
  /// Why the simulation ended: the engine's reason (kFinished when not simulated).
  StopReason stop = StopReason::kFinished;
  bool simulated = false;                   ///< false for predict-only and over-cap runs
  std::array<double, 3> final_velocities{}; ///< simulated, else the closed form's after the predicted count [m/s]
  /// max over reported states of |S (v_sim - v_pred)| / |S v_0|, S = diag(sqrt(m)):
  /// relative error in the energy norm, in the wall's frame (dimensionless).
  double max_prediction_error = 0.0;
  double energy_relative_drift = 0.0;       ///< |E_end - E_0| / E_0, in the wall's frame
  double momentum_relative_drift = 0.0;     ///< |p_end - p_0| / sum |m v|; NaN with a wall
  double compute_time_s = 0.0;              ///< wall time of prediction + simulation [s]
  EscalationStats escalation;
};

struct RunResult {
  AnalyticPrediction prediction;
  LabRunSummary summary;
  /// As RunOptions::events says: the engine's records, each with its model block
  /// (ImpactRecord::model: every body's state, the closed form's and the paper's values).
  std::vector<ImpactRecord> events;
};

/// Runs a validated scene. The visitor sees every impact in order, with its model block
/// (none in predict-only or summary-only mode). Precondition: validate(scene) passed.
RunResult runLab(const ThreeBodyScene& scene, const RunOptions& options, const ImpactVisitor& visitor = {});

/// The same with the prediction already made (for callers that publish it first);
/// `prediction` must be predict(scene).
RunResult runLab(const ThreeBodyScene& scene, const RunOptions& options, const AnalyticPrediction& prediction,
                 const ImpactVisitor& visitor = {});

}  // namespace core
}  // namespace collision_lab
