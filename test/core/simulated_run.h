// The three-body run as the core tests observe it: planScene and runScene, as every front
// end takes them, with each impact seen as the state of all three bodies (the engine's
// record and its model block, ImpactRecord::model).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <vector>

#include "collision_lab/core/scene_run.h"

namespace collision_lab {
namespace core {
namespace testing_support {

/// One impact of a three-body run: the record's pair, time and point, its model block's
/// state of every body.
struct ThreeBodyImpact {
  std::uint64_t index = 0;
  Pair pair = Pair::AB;
  double time = 0.0;                          ///< [s]
  double position = 0.0;                      ///< [m]
  std::array<double, 3> positions{};          ///< [m]
  std::array<double, 3> velocities_before{};  ///< [m/s]
  std::array<double, 3> velocities_after{};   ///< [m/s]
  std::array<double, 3> energy_transfer{};    ///< [J]
  double total_energy = 0.0;                  ///< [J]
  double total_momentum = 0.0;                ///< [kg m/s]
};

/// The view of a record of a rotation-model run, which has its model block.
inline ThreeBodyImpact threeBodyImpact(const ImpactRecord& record) {
  const ImpactModelValues& m = record.model.value();
  return {record.index,        record.pair_index == 0 ? Pair::AB : Pair::BC,
          record.time,         record.position,
          m.positions,         m.velocities_before,
          m.velocities_after,  m.energy_transfer,
          m.total_energy,      m.total_momentum};
}

/// Plans and runs a valid scene as the front ends do; `visitor`, when given, sees every
/// impact. Precondition: the scene is valid.
inline SceneRunResult runPlanned(const Scene& scene, const SceneRunOptions& options, const ImpactVisitor& visitor = {}) {
  const ScenePlan plan = planScene(scene);
  if (plan.error) throw std::invalid_argument("runPlanned: " + plan.error->message);
  SceneVisitors visitors;
  visitors.impact = visitor;
  return runScene(plan, options, visitors);
}

/// The same with the cap, events and mode of `lab`, simulated up to the cap (as asked) when
/// the model predicts more.
inline SceneRunResult runPlanned(const Scene& scene, const RunOptions& lab, const ImpactVisitor& visitor = {}) {
  SceneRunOptions options;
  options.lab = lab;
  options.simulate_to_cap = true;
  return runPlanned(scene, options, visitor);
}

struct SimulatedRun {
  SceneSimulation summary;
  std::array<double, 3> final_velocities{};  ///< summary.final_velocities [m/s]
  std::vector<ThreeBodyImpact> events;       ///< those `events` keeps
};

/// Runs `scene` in full mode up to `max_collisions`, keeping the impacts `events` selects;
/// `visitor`, when given, sees every impact. A scene that the rotation model answers has
/// every body's state in each record's model block; any other three-body scene (the
/// engine's alone) has the pair's, and the view carries the others' velocities from the
/// impacts before (positions NaN).
inline SimulatedRun simulateThreeBodies(const Scene& scene, EventPolicy events = EventPolicy::none(),
                                        std::uint64_t max_collisions = 10'000'000,
                                        const std::function<void(const ThreeBodyImpact&)>& visitor = {}) {
  RunOptions options;
  options.events = EventPolicy::none();
  options.max_collisions = max_collisions;
  SimulatedRun run;
  std::array<double, 3> velocities = triple(scene.velocities);
  ImpactVisitor record_visitor;
  if (visitor || events.kind != EventPolicy::Kind::kNone) {
    record_visitor = [&](const ImpactRecord& record) {
      ThreeBodyImpact impact;
      if (record.model) {
        impact = threeBodyImpact(record);
      } else {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        impact = {record.index, record.pair_index == 0 ? Pair::AB : Pair::BC, record.time, record.position,
                  {nan, nan, nan}, velocities, velocities, {nan, nan, nan}, nan, nan};
        impact.velocities_after[record.pair_index] = record.velocities_after[0];
        impact.velocities_after[record.pair_index + 1] = record.velocities_after[1];
      }
      velocities = impact.velocities_after;
      if (events.keeps(record.index)) run.events.push_back(impact);
      if (visitor) visitor(impact);
    };
  }
  run.summary = runPlanned(scene, options, record_visitor).simulation;
  run.final_velocities = triple(run.summary.final_velocities);
  return run;
}

}  // namespace testing_support
}  // namespace core
}  // namespace collision_lab
