// The three-body run as the core tests observe it: runLab (lab_run.h), which the event
// engine simulates, with each impact seen as the state of all three bodies (the engine's
// record and its model block, ImpactRecord::model).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "collision_lab/core/lab_run.h"

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

/// The view of a record of runLab, which has its model block.
inline ThreeBodyImpact threeBodyImpact(const ImpactRecord& record) {
  const ImpactModelValues& m = record.model.value();
  return {record.index,        record.pair_index == 0 ? Pair::AB : Pair::BC,
          record.time,         record.position,
          m.positions,         m.velocities_before,
          m.velocities_after,  m.energy_transfer,
          m.total_energy,      m.total_momentum};
}

struct SimulatedRun {
  LabRunSummary summary;
  std::vector<ThreeBodyImpact> events;  ///< those `events` keeps
};

/// Runs `scene` in full mode up to `max_collisions`, keeping the impacts `events` selects;
/// `visitor`, when given, sees every impact.
inline SimulatedRun simulateThreeBodies(const ThreeBodyScene& scene, EventPolicy events = EventPolicy::none(),
                                        std::uint64_t max_collisions = 10'000'000,
                                        const std::function<void(const ThreeBodyImpact&)>& visitor = {}) {
  RunOptions options;
  options.events = events;
  options.max_collisions = max_collisions;
  ImpactVisitor record_visitor;
  if (visitor) record_visitor = [&visitor](const ImpactRecord& record) { visitor(threeBodyImpact(record)); };
  const RunResult result = runLab(scene, options, record_visitor);
  SimulatedRun run{result.summary, {}};
  for (const ImpactRecord& record : result.events) run.events.push_back(threeBodyImpact(record));
  return run;
}

}  // namespace testing_support
}  // namespace core
}  // namespace collision_lab
