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

using reference::Q;
using testing_support::kInf;

/// Is `value` the double nearest to `exact` (either one on an exact tie)? Exact: the
/// distances to `value` and to its two neighbours are compared as rationals.
bool correctlyRounded(double value, const Q& exact) {
  if (!std::isfinite(value)) return false;
  const Q distance = abs(Q(value) - exact);
  for (const double neighbour : {std::nextafter(value, kInf), std::nextafter(value, -kInf)}) {
    if (std::isfinite(neighbour) && abs(Q(neighbour) - exact) < distance) return false;
  }
  return true;
}

Scene general(const ThreeBodyScene& scene) {
  return {{scene.masses.begin(), scene.masses.end()},
          {scene.positions.begin(), scene.positions.end()},
          {scene.velocities.begin(), scene.velocities.end()},
          {}};
}

std::string describe(const ThreeBodyScene& s) {
  std::string text;
  for (const auto* values : {&s.masses, &s.positions, &s.velocities}) {
    for (double x : *values) text += std::to_string(x) + " ";
    text += "| ";
  }
  return text;
}

/// The scenes: the hard classes, the example, and seeded random ones.
std::vector<ThreeBodyScene> scenes() {
  std::vector<ThreeBodyScene> all = {
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
  for (const ThreeBodyScene& scene : scenes()) {
    const reference::Run truth = reference::simulateVelocities(scene, 100000);
    ASSERT_FALSE(truth.truncated) << describe(scene);
    SceneRunOptions options;
    options.lab.events = EventPolicy::all();
    const SceneRunResult run = runScene(planScene(general(scene)), options);
    ASSERT_TRUE(run.three_body) << describe(scene);
    const RunResult& result = *run.three_body;
    ASSERT_EQ(result.summary.collision_count, truth.impacts.size()) << describe(scene);
    const EngineResult engine = runEngine(general(scene));
    ASSERT_EQ(engine.impact_count, truth.impacts.size()) << describe(scene);
    for (int i = 0; i < 3; ++i) {
      EXPECT_TRUE(correctlyRounded(result.summary.final_velocities[i], truth.final_velocities[i]))
          << describe(scene) << " body " << i << ": " << result.summary.final_velocities[i];
      EXPECT_EQ(result.summary.final_velocities[i], engine.final_velocities[i]) << describe(scene) << i;
    }
    ASSERT_EQ(result.events.size(), truth.impacts.size());
    for (std::size_t k = 0; k < truth.impacts.size(); ++k) {
      EXPECT_EQ(result.events[k].event.pair, truth.impacts[k].pair) << describe(scene) << k;
      for (int i = 0; i < 3; ++i) {
        EXPECT_TRUE(correctlyRounded(result.events[k].event.velocities_after[i], truth.impacts[k].velocities[i]))
            << describe(scene) << " impact " << k + 1 << " body " << i;
      }
    }
    ++scenes_checked;
  }
  EXPECT_EQ(scenes_checked, 69);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
