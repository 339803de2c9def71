// Issue 20: three elastic bodies are simulated by the one exact event engine, so a
// three-body run's velocities are the correctly rounded exact ones, bit-identical to the
// engine's, on seeded scenes and on the hard classes of physics.md (kaleidoscopic, grazing,
// near-triple). Reference: exact rationals (rational_reference.h), rounded here by
// comparing with the neighbouring doubles, exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "collision_lab/core/scene_run.h"
#include "rational_reference.h"
#include "scenes.h"

namespace collision_lab {
namespace core {
namespace {

using reference::correctlyRounded;
using testing_support::describe;
using testing_support::kInf;

Scene general(const Scene& scene) {
  return {{scene.masses.begin(), scene.masses.end()},
          {scene.positions.begin(), scene.positions.end()},
          {scene.velocities.begin(), scene.velocities.end()},
          {}};
}

/// The scenes: the hard classes, the example, and seeded random ones.
std::vector<Scene> scenes() {
  std::vector<Scene> all = {
      {{1, 1, 1}, {1, 0, -1}, {-1, 0, 0}},               // kaleidoscopic, 2 impacts
      {{2, 1, 3}, {1, 0, -1}, {-1, 0, 0}},               // kaleidoscopic, 3
      {{5, 1, 9}, {1, 0, -1}, {-1, 0, 0}},               // kaleidoscopic, 5
      {{3, 1, 0.5}, {1, 0, -1}, {-1, 0, 0}},             // grazing
      {{1, 3, 1}, {1, 0, -1}, {-0.7, 0.1, 0.3}},         // near-triple
      {{1, 2, 3}, {1, 0, -1}, {-0.35, 0.05, 0.45}},      // near-triple
      {{kInf, 1, 2}, {2, 1, 0}, {0, 0, 1}},              // issue 20's example
      {{1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}},           // pi billiard, 314 impacts
      {{0.3, 0.7, 0.11}, {0.9, 0.2, -0.4}, {-0.3, 0.1, 0.25}},
  };
  std::mt19937_64 rng(20261126);
  for (int k = 0; k < 60; ++k) all.push_back(testing_support::randomScene(rng, 2.0));
  return all;
}

TEST(ThreeBodyRounding, FinalAndEventVelocitiesAreTheCorrectlyRoundedExactOnesAndTheEngines) {
  int scenes_checked = 0;
  for (const Scene& scene : scenes()) {
    const reference::Run truth = reference::simulateVelocities(scene, 100000);
    ASSERT_FALSE(truth.truncated) << describe(scene);
    SceneRunOptions options;
    options.lab.events = EventPolicy::all();
    const SceneRunResult run = runScene(planScene(general(scene)), options);
    ASSERT_TRUE(run.prediction && hasRotationValues(*run.prediction)) << describe(scene);
    const SceneSimulation& result = run.simulation;
    ASSERT_EQ(result.impact_count, truth.impacts.size()) << describe(scene);
    const SceneSimulation engine = runEngine(general(scene));
    ASSERT_EQ(engine.impact_count, truth.impacts.size()) << describe(scene);
    for (int i = 0; i < 3; ++i) {
      EXPECT_TRUE(correctlyRounded(result.final_velocities[i], truth.final_velocities[i]))
          << describe(scene) << " body " << i << ": " << result.final_velocities[i];
      EXPECT_EQ(result.final_velocities[i], engine.final_velocities[i]) << describe(scene) << i;
    }
    ASSERT_EQ(result.impacts.size(), truth.impacts.size());
    for (std::size_t k = 0; k < truth.impacts.size(); ++k) {
      EXPECT_EQ(result.impacts[k].pair_index, static_cast<std::size_t>(pairIndex(truth.impacts[k].pair))) << describe(scene) << k;
      for (int i = 0; i < 3; ++i) {
        EXPECT_TRUE(correctlyRounded(result.impacts[k].model->velocities_after[i], truth.impacts[k].velocities[i]))
            << describe(scene) << " impact " << k + 1 << " body " << i;
      }
    }
    ++scenes_checked;
  }
  EXPECT_EQ(scenes_checked, 69);
}

// Issue 24: a run that publishes no event (summary mode, or full mode with events none) is
// taken from the closed form's exact count without the engine's queue or decisions
// (nbody/elastic_triple.h). Its count, final velocities and largest prediction error are
// those of the run that publishes every event (the engine's), its velocities the correctly
// rounded exact ones, and, its count being known, it never escalates: at (1e37, 1, inf) the
// engine took 28 of 101 decisions at 100 digits before.
TEST(ThreeBodyRounding, RunsWithoutEventsAreTheEnginesAndNeverEscalateAtExtremeMassRatios) {
  struct Case {
    Scene scene = threeBodies();
    std::uint64_t cap;
  };
  const std::vector<Case> cases = {
      {{{1e37, 1, kInf}, {2, 1, 0}, {-1, 0, 0}}, 100},         // a wall, the example
      {{{kInf, 1, 1e37}, {2, 1, 0}, {0, 0, 1}}, 101},          // the wall on the other side
      {{{1e30, 1, 1e30}, {1, 0, -1}, {-1, 0, 0}}, 100},
      {{{1e14, 1, 1e14}, {1, 0, -1}, {-1, 0, 0}}, 150},
      {{{1e18, 1e-18, 1}, {1, 0, -1}, {-1e-10, 3, 0.5}}, 100},
      {{{2, 1, 3}, {1, 0, -1}, {-1, 0, 0}}, 100},              // kaleidoscopic: ends at zero approach speed
      {{{3, 1, 0.5}, {1, 0, -1}, {-1, 0, 0}}, 100},            // grazing
      {{{1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}}, 400},          // pi billiard (314 impacts), run to its end
  };
  for (const Case& c : cases) {
    const reference::Run truth = reference::simulateVelocities(c.scene, c.cap);
    SceneRunOptions with_events;
    with_events.lab.events = EventPolicy::all();
    with_events.lab.max_collisions = c.cap;
    with_events.simulate_to_cap = true;
    const SceneRunResult published = runScene(planScene(general(c.scene)), with_events);
    ASSERT_TRUE(published.prediction && hasRotationValues(*published.prediction)) << describe(c.scene);
    const SceneSimulation& all = published.simulation;
    for (const RunMode mode : {RunMode::kFull, RunMode::kSummaryOnly}) {
      SceneRunOptions options = with_events;
      options.lab.events = EventPolicy::none();
      options.lab.mode = mode;
      const SceneRunResult run = runScene(planScene(general(c.scene)), options);
      const SceneSimulation& summary = run.simulation;
      ASSERT_EQ(summary.impact_count, truth.impacts.size()) << describe(c.scene);
      EXPECT_EQ(summary.truncated, truth.truncated) << describe(c.scene);
      EXPECT_EQ(summary.escalations.high_precision, 0u) << describe(c.scene);
      EXPECT_EQ(summary.escalations.exact_rational, 0u) << describe(c.scene);
      for (int i = 0; i < 3; ++i) {
        EXPECT_TRUE(correctlyRounded(summary.final_velocities[i], truth.final_velocities[i]))
            << describe(c.scene) << " body " << i << ": " << summary.final_velocities[i];
        EXPECT_EQ(summary.final_velocities[i], all.final_velocities[i]) << describe(c.scene);
      }
      EXPECT_EQ(summary.energy_relative_drift, all.energy_relative_drift) << describe(c.scene);
      if (mode == RunMode::kFull) {
        EXPECT_EQ(summary.max_prediction_error, all.max_prediction_error)
            << describe(c.scene);
      }
    }
  }
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
