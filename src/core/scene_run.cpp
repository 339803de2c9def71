#include "collision_lab/core/scene_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "collision_lab/core/count_text.h"
#include "float_ops.h"
#include "rotation_run.h"

namespace collision_lab {
namespace core {

namespace {

/// What the closed form alone says, for a finite prediction that no event needs checking
/// (or that is over the cap).
SceneSimulation fromPrediction(const Prediction& prediction) {
  SceneSimulation simulation;
  simulation.impact_count = prediction.impact_count.value_or(0);
  simulation.final_velocities = prediction.final_velocities;
  simulation.energy_lost = prediction.energy_lost;
  simulation.collapsed = prediction.collapsed;
  simulation.collapse_time = prediction.collapse_time;
  simulation.collapse_position = prediction.collapse_position;
  simulation.energy_relative_drift = std::numeric_limits<double>::quiet_NaN();
  simulation.momentum_relative_drift = std::numeric_limits<double>::quiet_NaN();
  simulation.stop_message = std::string("answered by the closed form of ") + modelKindName(prediction.kind) +
                            ": nothing simulated";
  return simulation;
}

/// Predict-only mode with no finite closed form: nothing is known beyond the model.
SceneSimulation notSimulated(const std::optional<Prediction>& prediction) {
  SceneSimulation simulation;
  simulation.energy_lost = std::numeric_limits<double>::quiet_NaN();  // not known
  simulation.energy_relative_drift = std::numeric_limits<double>::quiet_NaN();
  simulation.momentum_relative_drift = std::numeric_limits<double>::quiet_NaN();
  simulation.truncated = prediction && prediction->infinite;
  simulation.stop_message = simulation.truncated
                                ? "predict-only: infinitely many impacts, nothing simulated"
                                : "predict-only: no closed form gives this scene's count, nothing simulated";
  return simulation;
}

/// max_prediction_error's one meaning at one state: |S (v_sim - v_pred)| / |S v_0| with
/// S = diag(sqrt(m)) over the finite bodies and v_0 in the frame of the first wall (if any),
/// the relative error in the energy norm (1 when |S v_0| is 0 and any differs). Masses are
/// taken relative to the largest and velocities to the largest difference, so that nothing
/// overflows or underflows.
double energyNormError(const Scene& scene, const std::vector<double>& simulated, const std::vector<double>& predicted) {
  std::optional<double> frame;
  double mass_max = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (scene.isWall(i)) {
      if (!frame) frame = scene.velocities[i];
      continue;
    }
    mass_max = std::max(mass_max, scene.masses[i]);
  }
  const double frame_velocity = frame.value_or(0.0);
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (scene.isWall(i)) continue;
    scale = std::max({scale, std::fabs(simulated[i] - predicted[i]), std::fabs(scene.velocities[i] - frame_velocity)});
  }
  if (scale == 0.0 || !std::isfinite(scale)) return scale == 0.0 ? 0.0 : std::numeric_limits<double>::quiet_NaN();
  double error_sq = 0.0, initial_sq = 0.0;
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (scene.isWall(i)) continue;
    const double weight = scene.masses[i] / mass_max;
    const double d = (simulated[i] - predicted[i]) / scale, v = (scene.velocities[i] - frame_velocity) / scale;
    error_sq += weight * d * d;
    initial_sq += weight * v * v;
  }
  if (initial_sq == 0.0) return error_sq > 0.0 ? 1.0 : 0.0;
  return std::sqrt(error_sq / initial_sq);
}

bool isUncertified(const Prediction& prediction, const std::string& key) {
  return std::find(prediction.uncertified.begin(), prediction.uncertified.end(), key) != prediction.uncertified.end();
}

/// A collapse of every body, with the model's certified time, point and common velocity.
Collapse certified(Collapse collapse, const Prediction& prediction) {
  collapse.time = *prediction.collapse_time;
  collapse.position = *prediction.collapse_position;
  if (!prediction.final_velocities.empty()) collapse.velocity = prediction.final_velocities[1];  // not a wall's
  if (!isUncertified(prediction, "collapse_time")) collapse.uncertified &= ~kImpactTime;
  if (!isUncertified(prediction, "collapse_position")) collapse.uncertified &= ~kImpactPosition;
  if (!prediction.final_velocities.empty() && !isUncertified(prediction, "predicted_final_velocities")) {
    collapse.uncertified &= ~kPairVelocitiesAfter;
  }
  return collapse;
}

/// The over-cap rule: the model's count exceeds the cap, so the model answers alone.
SceneSimulation overCap(const Prediction& prediction, std::uint64_t cap) {
  SceneSimulation simulation = fromPrediction(prediction);
  simulation.stop_message = std::string("answered by the closed form of ") + modelKindName(prediction.kind) + ": " +
                            countText(*prediction.impact_count) + " impacts predicted, more than the cap of " +
                            countText(cap) + "; nothing simulated (simulating up to the cap must be asked for)";
  return simulation;
}

/// Who answers a run, and the engine's cap where the engine runs: the one decision of
/// simulateScene and plannedImpacts.
struct Route {
  enum Kind {
    kPredicted,     ///< the model's prediction alone
    kNotSimulated,  ///< predict mode, and no model answers
    kOverCap,       ///< the over-cap rule: the model answers alone
    kRotation,      ///< the rotation model, every impact simulated beside it
    kEngine,        ///< the event engine, to its end or engine_cap
  } kind = kEngine;
  std::uint64_t engine_cap = 0;  ///< kRotation and kEngine: impacts at most [1]
};

Route routeOf(const std::optional<Prediction>& prediction, const SceneRunOptions& options) {
  const RunOptions& lab = options.lab;
  if (lab.mode == RunMode::kPredictOnly) {
    // A collapse is infinitely many impacts with a known end: its time, point and heat.
    const bool answered = prediction && (!prediction->infinite || prediction->collapsed);
    return {answered ? Route::kPredicted : Route::kNotSimulated};
  }
  const bool over_cap = prediction && prediction->impact_count && *prediction->impact_count > lab.max_collisions;
  if (over_cap && !options.simulate_to_cap) return {Route::kOverCap};
  // A model that predicts every impact is simulated beside them, whatever the output.
  if (prediction && hasRotationValues(*prediction)) return {Route::kRotation, lab.max_collisions};
  const bool wants_events = lab.mode == RunMode::kFull && lab.events.kind != EventPolicy::Kind::kNone;
  // Nothing approaching: there is nothing to simulate, events or not.
  const bool nothing_happens = prediction && prediction->kind == ModelKind::kNoCollisions;
  // The sticky count assumes that no three bodies meet at once; only the engine can tell.
  const bool count_certain = prediction && prediction->kind != ModelKind::kSticky;
  if (prediction && !prediction->infinite && !over_cap && ((!wants_events && count_certain) || nothing_happens)) {
    return {Route::kPredicted};
  }
  // Impacts that never end are shown, not counted: a display's worth unless asked for more.
  const bool endless = prediction && (prediction->kind == ModelKind::kTwoWallsInfinite ||
                                      prediction->kind == ModelKind::kBoxInfinite ||
                                      (prediction->kind == ModelKind::kGhosts && prediction->infinite));  // a ring
  if (endless && !options.simulate_to_cap) return {Route::kEngine, std::min(lab.max_collisions, kInfiniteRunDisplayCap)};
  return {Route::kEngine, lab.max_collisions};
}

/// The engine's run of an N-body scene, compared with a finite prediction when it finished.
/// With options.keep_events, the shown impacts are kept in simulation.impacts.
SceneSimulation simulateScene(const Scene& scene, const SceneRunOptions& options,
                              const std::optional<Prediction>& prediction, const SceneVisitors& visitors) {
  const RunOptions& lab = options.lab;
  const Route route = routeOf(prediction, options);
  switch (route.kind) {
    case Route::kPredicted: return fromPrediction(*prediction);
    case Route::kNotSimulated: return notSimulated(prediction);
    case Route::kOverCap: return overCap(*prediction, lab.max_collisions);
    case Route::kRotation: return simulateRotationScene(scene, *prediction, options, visitors);
    case Route::kEngine: break;
  }

  EngineOptions engine_options;
  engine_options.max_impacts = route.engine_cap;
  engine_options.progress_interval = options.progress_interval;
  engine_options.cancel = options.cancel;
  const bool full = lab.mode == RunMode::kFull;
  std::vector<ImpactRecord> kept;
  ImpactVisitor on_impact = full ? visitors.impact : ImpactVisitor{};
  if (full && options.keep_events && lab.events.kind != EventPolicy::Kind::kNone) {
    on_impact = [&kept, &visitors, &lab](const ImpactRecord& impact) {
      if (visitors.impact) visitors.impact(impact);
      if (lab.events.keeps(impact.index)) kept.push_back(impact);
    };
  }
  // Two bodies: the engine decides the one impact; its values are the exact ones rounded once
  // (the engine's double-double ones can be an ulp off), in the record and the summary alike.
  std::optional<TwoBodyImpact> two_body;
  if (prediction && prediction->kind == ModelKind::kTwoBody && prediction->impact_count == 1u) {
    two_body = exactTwoBodyImpact(scene);
    if (on_impact) {
      on_impact = [inner = std::move(on_impact), &two_body](const ImpactRecord& impact) {
        ImpactRecord exact = impact;
        exact.time = two_body->time;
        exact.position = two_body->position;
        exact.velocities_after = two_body->velocities_after;
        exact.energy_gained = two_body->energy_gained;
        exact.energy_lost = two_body->energy_lost;
        exact.uncertified = 0;  // the velocities before are the scene's
        inner(exact);
      };
    }
  }
  // Three bodies that collapse: the engine finds the collapse; its time, point and velocity
  // are the model's, certified from the start (the engine's come from its state at the time,
  // and a heavy-light-heavy point cancels), in the record and the summary alike.
  const bool whole_collapse = prediction && prediction->collapsed && prediction->collapse_time;
  CollapseVisitor on_collapse = full ? visitors.collapse : CollapseVisitor{};
  if (whole_collapse && on_collapse) {
    on_collapse = [inner = std::move(on_collapse), &prediction, &scene](const Collapse& collapse) {
      inner(collapse.first_body == 0 && collapse.last_body + 1 == scene.size() ? certified(collapse, *prediction) : collapse);
    };
  }
  SceneSimulation simulation = runEngine(scene, engine_options, on_impact, visitors.progress, on_collapse);
  simulation.impacts = std::move(kept);
  const bool agrees = prediction && prediction->impact_count && simulation.stop == StopReason::kFinished &&
                      simulation.impact_count == *prediction->impact_count;
  if (whole_collapse && simulation.collapsed && simulation.stop == StopReason::kFinished) {
    const bool ends_at_collapse = simulation.final_time == simulation.collapses.back().time;
    for (Collapse& collapse : simulation.collapses) {
      if (collapse.first_body == 0 && collapse.last_body + 1 == scene.size()) collapse = certified(collapse, *prediction);
    }
    simulation.collapse_time = prediction->collapse_time;
    simulation.collapse_position = prediction->collapse_position;
    const Collapse& last = simulation.collapses.back();
    if (ends_at_collapse && last.first_body == 0 && last.last_body + 1 == scene.size()) {
      simulation.final_time = last.time;  // the model's
      if (!(last.uncertified & kImpactTime)) {
        auto& keys = simulation.uncertified;
        keys.erase(std::remove(keys.begin(), keys.end(), "final_time"), keys.end());
      }
    }
  }
  // The engine's own values against the model's, before the run publishes the model's:
  // the comparison checks the engine, not the substitution.
  if (prediction && prediction->impact_count && simulation.stop == StopReason::kFinished) {
    simulation.max_prediction_error = energyNormError(scene, simulation.final_velocities, prediction->final_velocities);
    simulation.matches_prediction = simulation.impact_count == *prediction->impact_count;
  }
  if (agrees || (whole_collapse && simulation.collapsed && simulation.stop == StopReason::kFinished)) {
    // The run reached the state the model gives exactly: its values name the same exact ones,
    // which the model rounded once (the engine's double-double ones can be ulps off). Only
    // values within a few ulps of the engine's are taken: a larger difference is a fault,
    // and the engine's values then stand beside the model's for all to see.
    const auto certify = [&simulation](const std::string& key) {
      auto& keys = simulation.uncertified;
      keys.erase(std::remove(keys.begin(), keys.end(), key), keys.end());
    };
    if (!isUncertified(*prediction, "predicted_final_velocities") &&
        detail::withinUlps(simulation.final_velocities, prediction->final_velocities)) {
      simulation.final_velocities = prediction->final_velocities;
      certify("final_velocities");
    }
    const std::array<double, 1> heat{simulation.energy_lost}, predicted_heat{prediction->energy_lost};
    if (!isUncertified(*prediction, "energy_lost") && detail::withinUlps(heat, predicted_heat)) {
      simulation.energy_lost = prediction->energy_lost;
      certify("energy_lost");
    }
  }
  return simulation;
}

}  // namespace

ScenePlan planScene(Scene scene) {
  const auto start = std::chrono::steady_clock::now();
  ScenePlan plan;
  plan.error = validate(scene);
  if (!plan.error) {
    plan.model = chooseModel(scene);
    plan.prediction = predict(scene);
  }
  plan.scene = std::move(scene);
  plan.plan_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return plan;
}

std::optional<std::uint64_t> plannedImpacts(const ScenePlan& plan, const SceneRunOptions& options) {
  const Route route = routeOf(plan.prediction, options);
  if (route.kind != Route::kRotation && route.kind != Route::kEngine) return 0;
  const std::optional<Prediction>& prediction = plan.prediction;
  if (prediction && prediction->impact_count && !prediction->infinite) {
    return std::min(*prediction->impact_count, route.engine_cap);
  }
  if (prediction && prediction->infinite && !prediction->collapsed) return route.engine_cap;  // endless
  return std::nullopt;
}

std::vector<std::string> uncertifiedValues(const SceneRunResult& result) {
  std::vector<std::string> keys = result.prediction ? result.prediction->uncertified : std::vector<std::string>{};
  for (const std::string& key : result.simulation.uncertified) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
  }
  return keys;
}

SceneRunResult runScene(const ScenePlan& plan, const SceneRunOptions& options, const SceneVisitors& visitors) {
  const auto start = std::chrono::steady_clock::now();
  SceneRunResult result;
  result.model = plan.model;
  result.prediction = plan.prediction;
  result.simulation = simulateScene(plan.scene, options, result.prediction, visitors);
  result.compute_time_s =
      plan.plan_time_s + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace core
}  // namespace collision_lab
