// One run of a scene of any size: the model that the scene needs (chooseModel), its
// closed-form prediction where one exists, and the simulation summary. The front ends'
// single entry point (the CLI today; the ROS node with issue 12). ROS-free.
//
// Three elastic bodies that the three-body path accepts (validate(ThreeBodyScene)) are
// handed to runLab unchanged, so their output stays that of the paper's rotation model.
// Every other scene is answered by its model (models.h): a closed form alone when no event
// is asked for and the prediction is finite; otherwise the exact event engine, whose
// summary is put beside the prediction.
//
// The over-cap rule, the same for every front end: when a model predicts more impacts than
// the cap (max_collisions), the model answers at once (simulated false, its count and final
// state) and nothing is simulated unless SceneRunOptions::simulate_to_cap asks for it. Two
// walls, whose impacts never end, are simulated up to kInfiniteRunDisplayCap impacts (or
// the cap, if lower) unless simulate_to_cap asks for the cap.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "collision_lab/core/lab_run.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/models.h"
#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {

/// Impacts simulated of a run that never ends (two walls) unless simulate_to_cap: enough to
/// show its pattern, few enough to show at once.
constexpr std::uint64_t kInfiniteRunDisplayCap = 1000;

struct SceneRunOptions {
  /// Cap, event policy, mode and precision. The precision applies to the three-body path
  /// only (the event engine decides everything exactly); max_collisions caps the engine.
  /// When lab.events asks for any event (in full mode), a closed-form scene is simulated
  /// too, and the simulation is checked against the prediction.
  RunOptions lab;
  /// Keep the events that lab.events selects (RunResult::events of the three-body path,
  /// SceneSimulation::impacts and collapses of the engine). False, for front ends that
  /// stream: the visitors still see them all.
  bool keep_events = true;
  /// Simulate up to the cap even when the model predicts more impacts than it (or, for two
  /// walls, infinitely many). False: the over-cap rule (above) answers from the model.
  bool simulate_to_cap = false;
  /// When set (by a signal handler or another thread), the run stops within 1024 impacts,
  /// marked truncated (the event engine's stop reason CANCELLED, the three-body summary's
  /// cancelled flag).
  const std::atomic<bool>* cancel = nullptr;
  std::uint64_t progress_interval = std::uint64_t{1} << 20;  ///< impacts between progress calls
};

/// The simulation of an N-body scene (not filled for the three-body path).
struct SceneSimulation {
  bool simulated = false;          ///< false: answered by the closed form alone (or predict-only)
  /// The run's answer: simulated, or the model's count when not simulated (0 when the model
  /// gives none: predict-only without a count formula).
  std::uint64_t impact_count = 0;
  bool truncated = false;          ///< the cap or a cancellation stopped it: more impacts were due
  StopReason stop = StopReason::kFinished;
  std::string stop_message;  ///< one sentence: why the run ended
  std::optional<MultipleCollision> multiple_collision;
  double final_time = 0.0;               ///< time of the last impact [s]
  std::vector<double> final_velocities;  ///< [m/s]; the predicted ones when not simulated
  double energy_lost = 0.0;              ///< total kinetic energy turned into heat [J]; NaN: not known
  /// An inelastic collapse was resolved (simulated) or is predicted (closed form alone):
  /// infinitely many impacts before collapse_time, then the bodies move as one cluster.
  bool collapsed = false;
  std::optional<double> collapse_time;      ///< of the first collapse [s]
  std::optional<double> collapse_position;  ///< where its bodies meet [m]
  std::vector<Collapse> collapses;          ///< every collapse the engine resolved, in order
  /// Impacts in which a cluster (stuck by e = 0 or left by a collapse) was hit as one body
  /// of its total mass (the cluster rule, nbody/engine.h).
  std::uint64_t cluster_impacts = 0;
  /// Impacts the scene's restitution model made elastic (EngineResult::rule_elastic_impacts).
  std::uint64_t rule_elastic_impacts = 0;
  double energy_relative_drift = 0.0;    ///< as EngineResult; NaN when not simulated
  double momentum_relative_drift = 0.0;  ///< as EngineResult; NaN when not simulated or with a wall
  /// Simulated and predicted with a finite count: the engine's count equals it and
  /// max |v_sim - v_pred| / max |v_0| is max_prediction_error. Empty otherwise.
  std::optional<bool> matches_prediction;
  double max_prediction_error = std::numeric_limits<double>::quiet_NaN();  ///< [1], NaN: not compared
  Escalations escalations;
  /// The impacts that options.lab.events selects, in order, when options.keep_events (the
  /// collapses between them are in `collapses`, each after impacts_before impacts).
  std::vector<ImpactRecord> impacts;
};

struct SceneRunResult {
  ModelChoice model;                       ///< which model answered, and why (one line)
  std::optional<Prediction> prediction;    ///< closed-form models (not three_body_rotation, event_engine)
  std::optional<RunResult> three_body;     ///< set when the three-body path answered
  SceneSimulation simulation;              ///< the N-body summary (unset for the three-body path)
  double compute_time_s = 0.0;             ///< wall time of choice, prediction and simulation [s]
};

/// True when runScene hands this scene to runLab: three elastic bodies that
/// validate(ThreeBodyScene) accepts. Precondition: validate(scene) passed.
bool usesThreeBodyPath(const Scene& scene);
/// The three-body scene of a three-body scene. Precondition: scene.size() == 3.
ThreeBodyScene toThreeBodyScene(const Scene& scene);

/// What runScene calls back. Each may be empty.
struct SceneVisitors {
  LabEventVisitor three_body_event;  ///< every event of the three-body path (full mode)
  ImpactVisitor impact;              ///< every impact of the event engine (full mode)
  /// Every collapse the event engine resolves (full mode), in order with the impacts
  /// (CollapseVisitor: right after the record of impact impacts_before).
  CollapseVisitor collapse;
  ProgressCallback progress;         ///< the event engine's progress
};

/// Checks a scene for runScene: validate(scene), one validation with one set of reasons for
/// every N and every restitution. The message never repeats the field. Returns nothing when
/// the scene is valid.
/// Never throws for any input (short of memory).
std::optional<ValidationError> validateForRun(const Scene& scene);

/// Runs a scene. Precondition: validateForRun(scene) returned nothing. Never throws (short
/// of memory); the visitors may throw, which ends the run.
SceneRunResult runScene(const Scene& scene, const SceneRunOptions& options, const SceneVisitors& visitors = {});

}  // namespace core
}  // namespace collision_lab
