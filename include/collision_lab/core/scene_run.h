// One run of a scene of any size, in two steps that every front end (the CLI, the ROS
// node) takes: planScene validates the scene, chooses its model (chooseModel) and computes
// the model's prediction, once; runScene runs that plan and gives one result whose
// simulation summary is filled for every scene. ROS-free.
//
// Every scene is answered by its model (models.h): a closed form alone when no event is
// asked for and the prediction is finite; otherwise the exact event engine, the one
// simulator, whose summary is put beside the prediction. A model that predicts every
// impact (the rotation model of three elastic bodies) puts its values beside each one, in
// the record's model block; a run of it takes its summary from the known count (no
// decision) wherever it can, with events or without.
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

#include "collision_lab/core/events.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/models.h"
#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {

/// Impacts simulated of a run that never ends (two walls) unless simulate_to_cap: enough to
/// show its pattern, few enough to show at once.
constexpr std::uint64_t kInfiniteRunDisplayCap = 1000;

/// What a run models. Values match the ROS message constants MODE_*.
enum class RunMode : std::uint8_t {
  kFull = 0,         ///< simulate, report every event
  kPredictOnly = 1,  ///< closed form only, no simulation
  kSummaryOnly = 2,  ///< simulate, report no per-impact output
};

/// The cap, the events kept and the mode: what every front end asks of a run.
struct RunOptions {
  std::uint64_t max_collisions = 10'000'000;  ///< the cap on impacts simulated
  EventPolicy events = EventPolicy::all();    ///< which impacts the result keeps
  RunMode mode = RunMode::kFull;
};

struct SceneRunOptions {
  /// Cap, event policy and mode; max_collisions caps the engine.
  /// When lab.events asks for any event (in full mode), a closed-form scene is simulated
  /// too, and the simulation is checked against the prediction.
  RunOptions lab;
  /// Keep the events that lab.events selects (SceneSimulation::impacts and collapses).
  /// False, for front ends that stream: the visitors still see them all.
  bool keep_events = true;
  /// Simulate up to the cap even when the model predicts more impacts than it (or, for two
  /// walls, infinitely many). False: the over-cap rule (above) answers from the model.
  bool simulate_to_cap = false;
  /// When set (by a signal handler or another thread), the run stops within 1024 impacts,
  /// marked truncated with the stop reason CANCELLED.
  const std::atomic<bool>* cancel = nullptr;
  std::uint64_t progress_interval = std::uint64_t{1} << 20;  ///< impacts between progress calls
};

struct SceneRunResult {
  ModelChoice model;                       ///< which model answered, and why (one line): the plan's
  std::optional<Prediction> prediction;    ///< the plan's closed form (empty for event_engine)
  SceneSimulation simulation;              ///< the run's simulation (nbody/engine.h), for every scene
  double compute_time_s = 0.0;             ///< wall time of planning and simulation [s]
};

/// The keys of the result's published values that are not certified correctly rounded: the
/// prediction's and the simulation's, in that order, each once.
std::vector<std::string> uncertifiedValues(const SceneRunResult& result);

/// A scene's plan, computed once by planScene: its one validation, the model that answers
/// it and that model's prediction. runScene and everything after it (the CLI's report, the
/// node's publication, record and markers) take the plan: nothing validates, chooses a
/// model or predicts again.
struct ScenePlan {
  Scene scene;
  /// Set when the scene is rejected (validate(Scene): one set of reasons for every N and
  /// every restitution; the message never repeats the field). Nothing below is set then.
  std::optional<ValidationError> error;
  ModelChoice model;
  /// The chosen model's closed form (models.h); empty for event_engine.
  std::optional<Prediction> prediction;
  double plan_time_s = 0.0;  ///< wall time of validation, choice and prediction [s]
};

/// What runScene calls back. Each may be empty.
struct SceneVisitors {
  /// Every impact (full mode), in order; a model that answers impact by impact (the
  /// rotation model) fills its block (ImpactRecord::model).
  ImpactVisitor impact;
  /// Every collapse the event engine resolves (full mode), in order with the impacts
  /// (CollapseVisitor: right after the record of impact impacts_before).
  CollapseVisitor collapse;
  ProgressCallback progress;         ///< the event engine's progress
};

/// Validates the scene and, when it is valid, chooses its model and computes the model's
/// prediction. Never throws for any input (short of memory).
ScenePlan planScene(Scene scene);

/// The impacts runScene(plan, options) will simulate, as far as the plan knows before the
/// run (the same decision runScene takes): 0 where the model answers alone (predict mode,
/// over the cap, or a count it knows with no event asked for); the count, or the cap, where
/// the engine runs to one of them (a display's worth of endless impacts); empty where the
/// engine runs to an end the plan cannot count (a collapse, or a scene no model counts).
/// Precondition: !plan.error.
std::optional<std::uint64_t> plannedImpacts(const ScenePlan& plan, const SceneRunOptions& options);

/// Runs a planned scene. Precondition: !plan.error. Never throws (short of memory); the
/// visitors may throw, which ends the run.
SceneRunResult runScene(const ScenePlan& plan, const SceneRunOptions& options, const SceneVisitors& visitors = {});

}  // namespace core
}  // namespace collision_lab
