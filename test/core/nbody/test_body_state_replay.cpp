// The one body-state replay (body_state_replay.h) against hand-worked values and against
// the exact rational reference (reference.h, no engine code): velocities, kinetic energies,
// momentum, heat and positions after a run, and energy conservation after every impact.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "collision_lab/core/nbody/body_state_replay.h"
#include "random_scenes.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

using reference::Rational;
using testing_support::kInf;

ImpactRecord impact(std::size_t pair, std::size_t first, std::size_t last, double time, double position,
                    double left_after, double right_after, double lost) {
  ImpactRecord r;
  r.pair_index = pair, r.first_moved = first, r.last_moved = last;
  r.time = time, r.position = position;
  r.velocities_after = {left_after, right_after};
  r.energy_lost = lost;
  return r;
}

TEST(BodyStateReplay, AppliesRecordsByTheirContractWithHandWorkedEnergies) {
  // Bodies 1 and 2 of 1 kg swap their velocities at x = 1 m, t = 1 s; then body 2 bounces
  // off the wall (body 3) at x = 0 m, t = 2 s, and 0.375 J of its 0.5 J turn into heat
  // (e = 0.5: it leaves at 0.5 m/s).
  BodyStateReplay replay({2, 1, 1, kInf}, {3, 2, 1, 0}, {0, -1, 0, 0});
  EXPECT_EQ(replay.totalKineticEnergy(), 0.5);
  EXPECT_EQ(replay.momentum(), -1.0);
  ASSERT_TRUE(replay.apply(impact(1, 1, 2, 1.0, 1.0, 0.0, -1.0, 0.0)));
  EXPECT_EQ(replay.velocities(), (std::vector<double>{0, 0, -1, 0}));
  EXPECT_EQ(replay.kineticEnergies(), (std::vector<double>{0, 0, 0.5, 0}));
  EXPECT_EQ(replay.firstMoved(), 1u);
  EXPECT_EQ(replay.movedCount(), 2u);
  EXPECT_EQ(replay.velocityBefore(1), -1.0);
  EXPECT_EQ(replay.velocityBefore(2), 0.0);
  EXPECT_EQ(replay.velocityBefore(0), 0.0);  // not moved: its velocity now
  EXPECT_EQ(replay.energyGained(1), -0.5);
  EXPECT_EQ(replay.energyGained(2), 0.5);
  EXPECT_EQ(replay.position(2, 1.5), 0.5);
  EXPECT_EQ(replay.position(1, 4.0), 1.0);
  EXPECT_EQ(replay.position(0, 5.0), 3.0);
  ASSERT_TRUE(replay.apply(impact(2, 2, 3, 2.0, 0.0, 0.5, 0.0, 0.375)));
  EXPECT_EQ(replay.impacts(), 2u);
  EXPECT_EQ(replay.time(), 2.0);
  EXPECT_EQ(replay.kinetic(2), 0.125);
  EXPECT_EQ(replay.kinetic(3), 0.0);  // a wall's energy is not counted
  EXPECT_EQ(replay.totalKineticEnergy(), 0.125);
  EXPECT_EQ(replay.heat(), 0.375);
  EXPECT_EQ(replay.lastHeat(), 0.375);
  EXPECT_EQ(replay.momentum(), 0.5);  // the wall took the momentum: it is not counted either
  EXPECT_EQ(replay.position(2, 4.0), 1.0);
}

// A ring of L = 10 m: body 2 (2 kg, x = 1 m, -1 m/s) meets body 0 (1 kg, x = 8 m, seen at
// -2 m across the seam, +1 m/s) at t = 1.5 s, x = -0.5 = 9.5 m. Elastic, by hand: the centre
// of mass moves at -1/3 m/s, so body 2 leaves at 1/3 m/s and body 0 at -5/3 m/s.
TEST(BodyStateReplay, ASeamImpactOfARingMovesBodyNMinus1ThenBody0) {
  Scene ring;
  ring.masses = {1, 1, 2}, ring.positions = {8, 5, 1}, ring.velocities = {1, 0, -1}, ring.ring = 10;
  BodyStateReplay replay(ring);
  ASSERT_TRUE(replay.apply(impact(2, 2, 0, 1.5, 9.5, 1.0 / 3, -5.0 / 3, 0.0)));
  EXPECT_EQ(replay.movedCount(), 2u);
  EXPECT_EQ(replay.velocities(), (std::vector<double>{-5.0 / 3, 0, 1.0 / 3}));
  EXPECT_EQ(replay.velocityBefore(0), 1.0);
  EXPECT_EQ(replay.velocityBefore(2), -1.0);
  EXPECT_NEAR(replay.totalKineticEnergy(), 1.5, 1e-15);
  EXPECT_NEAR(replay.energyGained(0), 25.0 / 18 - 0.5, 1e-15);
  EXPECT_NEAR(replay.position(0, 2.5), 9.5 - 5.0 / 3, 1e-14);
  EXPECT_NEAR(replay.position(2, 3.5), 0.5 - 1.0 / 3 + 0.0, 1e-14);  // 9.5 + 2/3 wraps past 10
  EXPECT_FALSE(replay.apply(impact(2, 2, 2, 2.0, 9.0, 0.0, 0.0, 0.0)));  // the seam moves two sides
}

TEST(BodyStateReplay, RejectsRecordsOutsideTheSceneAndLeavesTheStateAlone) {
  BodyStateReplay replay({1, 1}, {1, 0}, {0, 1});
  EXPECT_FALSE(replay.apply(impact(1, 1, 2, 1.0, 1.0, 0.0, 1.0, 0.0)));  // no body 2
  EXPECT_FALSE(replay.apply(impact(0, 1, 1, 1.0, 1.0, 0.0, 1.0, 0.0)));  // first_moved > pair
  Collapse c;
  c.first_body = 0, c.last_body = 0;
  EXPECT_FALSE(replay.apply(c));
  EXPECT_EQ(replay.velocities(), (std::vector<double>{0, 1}));
  EXPECT_EQ(replay.impacts(), 0u);
  EXPECT_EQ(replay.heat(), 0.0);
}

TEST(BodyStateReplay, CollapseAndClusterImpactConserveMomentumAndAccountTheHeat) {
  // test_impact_stream.cpp: A, B, C collapse (e = 0.06) and move on at -1/3 m/s; D hits the
  // cluster as one body of 3 kg. By hand, the cluster ends at 0.02 m/s and D at -0.06 m/s:
  // 1.5e-3 kg m^2/s^2 * 0.4 + 1.8e-3 = 2.4e-3 J left of the 1 J at the start.
  const Scene four{{1, 1, 1, 1}, {2, 1, 0, -30}, {-1, 0, 0, 1}, {0.06}};
  BodyStateReplay replay(four);
  std::size_t collapses = 0;
  const SceneSimulation run = runEngine(
      four, {}, [&](const ImpactRecord& r) { ASSERT_TRUE(replay.apply(r)); },
      {}, [&](const Collapse& c) {
        ASSERT_TRUE(replay.apply(c));
        ++collapses;
        // A, B, C at -1/3 m/s, 1.5/9 J; D untouched at 0.5 J; the rest went to heat.
        EXPECT_NEAR(replay.totalKineticEnergy(), 0.5 + 1.5 / 9, 1e-12);
        EXPECT_NEAR(replay.heat(), 1 - (0.5 + 1.5 / 9), 1e-12);
        EXPECT_GE(replay.lastHeat(), 0.0);
      });
  EXPECT_EQ(collapses, 1u);
  EXPECT_EQ(replay.velocities(), run.final_velocities);
  EXPECT_EQ(replay.impacts(), run.impact_count);
  EXPECT_NEAR(replay.totalKineticEnergy(), 2.4e-3, 1e-14);
  EXPECT_NEAR(replay.heat(), 1 - 2.4e-3, 1e-14);
  EXPECT_NEAR(replay.heat(), run.energy_lost, 1e-14);
  EXPECT_NEAR(replay.momentum(), 0.0, 1e-15);
}

Rational kineticOf(double mass, const Rational& v) { return std::isinf(mass) ? Rational(0) : Rational(mass) * v * v / 2; }

TEST(BodyStateReplay, AgreesWithTheExactReferenceOnSeededScenes) {
  std::mt19937_64 rng(2020);
  int compared = 0, with_wall = 0, inelastic = 0;
  std::size_t collapses = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Scene scene = testing_support::randomScene(rng, 2 + trial % 6);
    const std::string where = "scene " + std::to_string(trial);
    bool walls_still = true;
    for (std::size_t i = 0; i < scene.size(); ++i) walls_still = walls_still && (!scene.isWall(i) || scene.velocities[i] == 0);
    BodyStateReplay replay(scene);
    const double e0 = replay.totalKineticEnergy();
    EngineOptions options;
    options.max_impacts = 60;
    // With the walls at rest the kinetic energy and the heat add up to the start's.
    const auto conserved = [&] {
      if (walls_still) {
        EXPECT_NEAR(replay.totalKineticEnergy() + replay.heat(), e0, 1e-12 * e0) << where;
      }
    };
    const SceneSimulation run = runEngine(
        scene, options, [&](const ImpactRecord& r) { ASSERT_TRUE(replay.apply(r)) << where, conserved(); }, {},
        [&](const Collapse& c) { ASSERT_TRUE(replay.apply(c)) << where, conserved(); });
    collapses += run.collapses.size();
    if (run.stop != StopReason::kFinished || run.collapsed) continue;
    const reference::Run exact = reference::simulate(scene, 60);
    if (exact.truncated || exact.multiple_first) continue;
    ++compared;
    with_wall += scene.wallCount() > 0;
    inelastic += !scene.isElastic();
    ASSERT_EQ(replay.impacts(), exact.events.size()) << where;
    EXPECT_EQ(replay.velocities(), run.final_velocities) << where;
    Rational energy = 0, momentum = 0, heat = 0, scale = 0;
    for (std::size_t i = 0; i < scene.size(); ++i) {
      energy += kineticOf(scene.masses[i], exact.velocities[i]);
      scale += kineticOf(scene.masses[i], Rational(scene.velocities[i]));
      if (!scene.isWall(i)) momentum += Rational(scene.masses[i]) * exact.velocities[i];
    }
    for (const auto& event : exact.events) heat += event.lost;
    const double tolerance = 1e-12 * static_cast<double>(scale);
    EXPECT_NEAR(replay.totalKineticEnergy(), static_cast<double>(energy), tolerance) << where;
    EXPECT_NEAR(replay.heat(), static_cast<double>(heat), tolerance) << where;
    double momentum_scale = 0;
    for (std::size_t i = 0; i < scene.size(); ++i) {
      if (!scene.isWall(i)) momentum_scale += scene.masses[i] * std::fabs(scene.velocities[i]);
    }
    EXPECT_NEAR(replay.momentum(), static_cast<double>(momentum), 1e-12 * momentum_scale) << where;
    for (std::size_t i = 0; i < scene.size(); ++i) {
      EXPECT_NEAR(replay.kinetic(i), static_cast<double>(kineticOf(scene.masses[i], exact.velocities[i])), tolerance)
          << where << ", body " << i;
      EXPECT_NEAR(replay.position(i, run.final_time), static_cast<double>(exact.positions[i]), 1e-9)
          << where << ", body " << i;
    }
  }
  // The sample covers walls, heat and collapses (checked for conservation).
  EXPECT_GT(compared, 150);
  EXPECT_GT(with_wall, 30);
  EXPECT_GT(inelastic, 60);
  EXPECT_GT(collapses, 5u);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
