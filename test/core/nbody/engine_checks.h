// Comparison of an engine run with the exact reference, shared by the engine tests.
// A run the engine ends with a resolved collapse is compared up to the collapse (the
// reference steps through it until its cap).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "collision_lab/core/nbody/engine.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace testing_support {

/// Relative time error allowed by the issue: 1e-9.
constexpr double kTimeTolerance = 1e-9;
/// Final velocities in the energy norm: 1e-12.
constexpr double kVelocityTolerance = 1e-12;

/// A collapse the engine resolved: the reference, which cannot resolve it, steps through
/// the same impacts up to it and then impacts forever (it stops at its cap), all before the
/// collapse time.
inline void expectCollapseMatchesReference(const SceneSimulation& run, const reference::Run& exact,
                                           const std::string& label) {
  const Collapse& first = run.collapses.front();
  EXPECT_TRUE(exact.truncated) << label << ": " << run.stop_message;
  EXPECT_GE(exact.events.size(), first.impacts_before) << label;
  const std::size_t shared = std::min<std::size_t>(first.impacts_before, exact.events.size());
  for (std::size_t k = 0; k < std::min(shared, run.impacts.size()); ++k) {
    EXPECT_EQ(run.impacts[k].pair_index, exact.events[k].pair) << label << ", impact " << k + 1;
  }
  const double t = first.time;
  for (const auto& event : exact.events) {
    EXPECT_LE(static_cast<double>(event.time), t * (1 + kTimeTolerance)) << label;
  }
  EXPECT_NE(run.stop, StopReason::kInternalError) << label << ": " << run.stop_message;
}

/// Runs the engine with every event kept and checks it against the exact reference:
/// count, how it ended, the pair sequence, the times and the final velocities.
inline SceneSimulation expectMatchesReference(const Scene& scene, std::uint64_t cap, const std::string& label) {
  const reference::Run exact = reference::simulate(scene, cap);
  EngineOptions options;
  options.max_impacts = cap;
  options.keep_events = cap;
  const SceneSimulation run = runEngine(scene, options);
  if (run.collapsed) {
    expectCollapseMatchesReference(run, exact, label);
    return run;
  }
  EXPECT_EQ(run.impact_count, exact.events.size()) << label << ": " << run.stop_message;
  EXPECT_EQ(run.truncated, exact.truncated) << label;
  EXPECT_EQ(run.multiple_collision.has_value(), exact.multiple_first.has_value()) << label << ": " << run.stop_message;
  if (run.multiple_collision && exact.multiple_first) {
    EXPECT_EQ(run.multiple_collision->first_body, *exact.multiple_first) << label;
    const double t = static_cast<double>(exact.multiple_time);
    EXPECT_NEAR(run.multiple_collision->time, t, kTimeTolerance * std::fabs(t)) << label;
  }
  const std::size_t shared = std::min<std::size_t>(run.impacts.size(), exact.events.size());
  for (std::size_t k = 0; k < shared; ++k) {
    EXPECT_EQ(run.impacts[k].pair_index, exact.events[k].pair) << label << ", impact " << k + 1;
    const double t = static_cast<double>(exact.events[k].time);
    EXPECT_NEAR(run.impacts[k].time, t, kTimeTolerance * std::fabs(t)) << label << ", impact " << k + 1;
    if (run.impacts[k].pair_index != exact.events[k].pair) break;
  }
  if (run.impact_count == exact.events.size()) {
    EXPECT_LE(reference::energyNormError(scene, run.final_velocities, exact.velocities), kVelocityTolerance) << label;
  }
  EXPECT_NE(run.stop, StopReason::kInternalError) << label << ": " << run.stop_message;
  return run;
}

}  // namespace testing_support
}  // namespace core
}  // namespace collision_lab
