// The three-body run as the core tests observe it: runLab (lab_run.h), which the event
// engine simulates, with its impacts as ImpactEvents.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "collision_lab/core/lab_run.h"

namespace collision_lab {
namespace core {
namespace testing_support {

struct SimulatedRun {
  LabRunSummary summary;
  std::vector<ImpactEvent> events;  ///< those `events` keeps
};

/// Runs `scene` in full mode up to `max_collisions`, keeping the impacts `events` selects;
/// `visitor`, when given, sees every impact.
inline SimulatedRun simulateThreeBodies(const ThreeBodyScene& scene, EventPolicy events = EventPolicy::none(),
                                        std::uint64_t max_collisions = 10'000'000,
                                        const std::function<void(const ImpactEvent&)>& visitor = {}) {
  RunOptions options;
  options.events = events;
  options.max_collisions = max_collisions;
  LabEventVisitor lab_visitor;
  if (visitor) lab_visitor = [&visitor](const LabEvent& lab) { visitor(lab.event); };
  const RunResult result = runLab(scene, options, lab_visitor);
  SimulatedRun run{result.summary, {}};
  for (const LabEvent& lab : result.events) run.events.push_back(lab.event);
  return run;
}

}  // namespace testing_support
}  // namespace core
}  // namespace collision_lab
