// Issue 12's stream: a front end that receives only each impact's record and each collapse
// notice must rebuild every body's velocity exactly (engine.h, ImpactRecord, CollapseVisitor).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "collision_lab/core/nbody/engine.h"
#include "random_scenes.h"

namespace collision_lab {
namespace core {
namespace {

/// What a viewer holds: the initial velocities, then every record and notice applied in
/// the order they arrive. Also checks that order and the extents.
struct Replay {
  explicit Replay(const Scene& scene) : velocities(scene.velocities) {}
  std::vector<double> velocities;
  std::uint64_t impacts = 0, collapses = 0, cluster_impacts = 0;

  void impact(const ImpactRecord& r) {
    ++impacts;
    EXPECT_EQ(r.index, impacts);
    ASSERT_LE(r.first_moved, r.pair_index);
    ASSERT_GT(r.last_moved, r.pair_index);
    ASSERT_LT(r.last_moved, velocities.size());
    if (r.first_moved != r.pair_index || r.last_moved != r.pair_index + 1) ++cluster_impacts;
    for (std::size_t k = r.first_moved; k <= r.last_moved; ++k) {
      velocities[k] = r.velocities_after[k <= r.pair_index ? 0 : 1];
    }
  }
  void collapse(const Collapse& c) {
    ++collapses;
    EXPECT_EQ(c.impacts_before, impacts);  // in order with the impacts
    ASSERT_LT(c.first_body + 1, c.last_body + 1);
    ASSERT_LT(c.last_body, velocities.size());
    for (std::size_t k = c.first_body; k <= c.last_body; ++k) velocities[k] = c.velocity;
  }
};

SceneSimulation runStreamed(const Scene& scene, Replay& replay) {
  EngineOptions options;
  // Low: beyond it, scenes with an accumulation the engine does not resolve (four or more
  // bodies) spend seconds in exact arithmetic before the exactness cap stops them.
  options.max_impacts = 200;
  return runEngine(scene, options, [&](const ImpactRecord& r) { replay.impact(r); }, {},
                   [&](const Collapse& c) { replay.collapse(c); });
}

TEST(ImpactStream, ClusterImpactMovesBothWholeClustersAndTheCollapseIsNotified) {
  // test_restitution.cpp: A, B, C collapse at 3.73 s (e = 0.06), then D hits the cluster
  // as one body of 3 kg; by hand the cluster moves at 0.02 m/s and D at -0.06 m/s.
  const Scene four{{1, 1, 1, 1}, {2, 1, 0, -30}, {-1, 0, 0, 1}, {0.06}};
  Replay replay(four);
  std::vector<Collapse> notices;
  std::vector<ImpactRecord> records;
  const SceneSimulation run = runEngine(four, {}, [&](const ImpactRecord& r) { records.push_back(r), replay.impact(r); },
                                     {}, [&](const Collapse& c) { notices.push_back(c), replay.collapse(c); });
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_EQ(notices[0].first_body, 0u);
  EXPECT_EQ(notices[0].last_body, 2u);
  EXPECT_NEAR(notices[0].velocity, -1.0 / 3, 1e-15);  // the centre of mass of A, B, C
  EXPECT_EQ(notices[0].time, *run.collapse_time);
  const ImpactRecord& last = records.back();
  EXPECT_EQ(last.pair_index, 2u);
  EXPECT_EQ(last.first_moved, 0u);
  EXPECT_EQ(last.last_moved, 3u);
  EXPECT_NEAR(last.velocities_after[0], 0.02, 1e-15);
  EXPECT_NEAR(last.velocities_after[1], -0.06, 1e-15);
  EXPECT_EQ(replay.velocities, run.final_velocities);
  for (std::size_t k = 0; k + 1 < records.size(); ++k) {  // plain impacts before the collapse
    EXPECT_EQ(records[k].last_moved, records[k].pair_index + 1);
    EXPECT_EQ(records[k].first_moved, records[k].pair_index);
  }
}

TEST(ImpactStream, ReplayOfRecordsAndNoticesGivesTheFinalVelocities) {
  std::mt19937_64 rng(1212);
  std::uniform_int_distribution<std::size_t> size(3, 5);
  std::uniform_int_distribution<int> pick(0, 4);
  const double restitutions[] = {0.0, 0.0, 0.05, 0.06, 0.5};
  std::uint64_t collapses = 0, cluster_impacts = 0, runs = 0, corrected = 0;
  for (int scene_index = 0; scene_index < 300; ++scene_index) {
    testing_support::SceneMix mix;
    mix.mass_decades = scene_index % 2 == 0 ? 0.0 : 0.5;  // half equal masses: collapses are frequent
    Scene scene = testing_support::randomScene(rng, size(rng), mix);
    scene.restitution.clear();
    for (std::size_t p = 0; p + 1 < scene.size(); ++p) scene.restitution.push_back(restitutions[pick(rng)]);
    if (validate(scene)) continue;
    Replay replay(scene);
    const SceneSimulation run = runStreamed(scene, replay);
    ++runs;
    ASSERT_EQ(replay.impacts, run.impact_count) << "scene " << scene_index;
    ASSERT_EQ(replay.collapses, run.collapses.size()) << "scene " << scene_index;
    EXPECT_EQ(replay.cluster_impacts, run.cluster_impacts) << "scene " << scene_index;
    // The stream carries the working tier's values; the summary's are certified (runEngine),
    // the same but where the certificate corrected the working value's last bits.
    ASSERT_EQ(replay.velocities.size(), run.final_velocities.size());
    for (std::size_t k = 0; k < run.final_velocities.size(); ++k) {
      const double published = run.final_velocities[k], streamed = replay.velocities[k];
      if (published == streamed) continue;
      ++corrected;
      const double ulp = std::nextafter(std::fabs(published), INFINITY) - std::fabs(published);
      EXPECT_LE(std::fabs(published - streamed), 4 * ulp) << "scene " << scene_index << " body " << k;
    }
    collapses += replay.collapses;
    cluster_impacts += replay.cluster_impacts;
  }
  // The sample must exercise what it is about.
  EXPECT_GT(runs, 250u);
  EXPECT_GT(collapses, 10u);
  EXPECT_GT(cluster_impacts, 200u);
  EXPECT_LE(corrected, 8u);  // 4 with seed 1212
  std::printf("replayed %lu runs: %lu collapses, %lu cluster impacts, %lu final velocities corrected by the certificate\n",
              static_cast<unsigned long>(runs), static_cast<unsigned long>(collapses),
              static_cast<unsigned long>(cluster_impacts), static_cast<unsigned long>(corrected));
}

TEST(ImpactStream, AnUnresolvedAccumulationEndsAtTheExactnessCapInsteadOfRunningOn) {
  // A ball between two walls closing in at 0.5 m/s each (e = 0.5): the walls meet at t = 2 s
  // and before that the ball bounces infinitely often, an accumulation the engine does not
  // resolve (where the walls meet, two infinite masses, nothing is defined). Before the cap
  // every step needed ever larger rationals. (The squeeze of a ball against one wall by a
  // 10 kg body, the scene of this test before, is now resolved: test_wall_collapse.cpp.)
  const Scene closing{{testing_support::kInf, 1, testing_support::kInf}, {2, 1, 0}, {-0.5, 0.25, 0.5}, {0.5}};
  const SceneSimulation run = runEngine(closing);
  EXPECT_EQ(run.stop, StopReason::kCap);
  EXPECT_TRUE(run.truncated);
  EXPECT_FALSE(run.collapsed);
  EXPECT_LT(run.impact_count, 5000u);
  EXPECT_NE(run.stop_message.find("exactness cap"), std::string::npos) << run.stop_message;
  // The impacts performed are real: the ball stays between the walls, which have not met,
  // and its speed (0.25 m/s at first) rises towards the fixed point of |v'| = 0.5 + e (|v| + 0.5), 1.5 m/s.
  EXPECT_LE(run.final_positions[2], run.final_positions[1]);
  EXPECT_LE(run.final_positions[1], run.final_positions[0]);
  EXPECT_LE(run.final_time, 2.0);  // within rounding of 2 s: gaps far below a double's resolution
  EXPECT_GT(std::fabs(run.final_velocities[1]), 1.4);
  EXPECT_LE(std::fabs(run.final_velocities[1]), 1.5);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
