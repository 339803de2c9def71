// The engine against the exact rational reference on seeded random scenes, N = 2..8,
// with walls and per-pair restitution e in {0, 0.3, 0.5, 0.8, 0.95, 1}.
#include <gtest/gtest.h>

#include <random>

#include "engine_checks.h"
#include "random_scenes.h"

namespace collision_lab {
namespace core {
namespace {

using testing_support::expectMatchesReference;
using testing_support::randomScene;

TEST(NBodyEngineRandom, AgreesWithExactReference) {
  std::mt19937_64 rng(20240610);
  int with_wall = 0, with_two_walls = 0, inelastic = 0, sticking = 0, multiple = 0, truncated = 0, impacts = 0;
  for (int trial = 0; trial < 700; ++trial) {
    const std::size_t n = 2 + trial % 7;
    const Scene scene = randomScene(rng, n);
    const SceneSimulation run = expectMatchesReference(scene, 40, "scene " + std::to_string(trial));
    with_wall += scene.wallCount() == 1;
    with_two_walls += scene.wallCount() == 2;
    inelastic += !scene.isElastic();
    for (std::size_t p = 0; p < scene.pairCount(); ++p) sticking += scene.restitutionOf(p) == 0.0 && p == 0;
    multiple += run.multiple_collision.has_value() || run.cluster_impacts > 0;
    truncated += run.truncated;
    impacts += static_cast<int>(run.impact_count);
  }
  // The sample covers every branch the issue names.
  EXPECT_GT(with_wall, 100);
  EXPECT_GT(with_two_walls, 20);
  EXPECT_GT(inelastic, 300);
  EXPECT_GT(sticking, 50);
  EXPECT_GT(multiple, 5);  // stuck pairs hit again: the cluster rule (a multiple collision before issue 11)
  EXPECT_GT(truncated, 20);
  EXPECT_GT(impacts, 6000);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
