// The paper's printed formulas disagree with exact physics where physics.md says so.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/paper.h"
#include "collision_lab/core/simulation.h"
#include "scenes.h"

namespace collision_lab {
namespace core {
namespace {

TEST(PaperErrata, ClosedFormVelocities215AreWrong) {
  // physics.md Erratum 2: masses (1,1,1), v0 = (-1, 0.3, 0.7), k = 1.
  const ThreeBodyScene scene{{1, 1, 1}, {3, 2, 0}, {-1, 0.3, 0.7}};
  const auto printed = paper::velocitiesAfter(scene, 2);
  EXPECT_NEAR(printed[0], -1.2125, 1e-12);
  EXPECT_NEAR(printed[1], 0.5125, 1e-12);
  EXPECT_NEAR(printed[2], -0.475, 1e-12);
  // It does not even conserve momentum (initial momentum 0).
  EXPECT_GT(std::fabs(printed[0] + printed[1] + printed[2]), 0.1);
  // The truth: (0.3, 0.7, -1), exactly what the correct closed form gives.
  const auto truth = exact::velocitiesAfter(scene, Pair::AB, 2);
  EXPECT_EQ(truth[0], exact::Rational(0.3));
  EXPECT_EQ(truth[1], exact::Rational(0.7));
  EXPECT_EQ(truth[2], exact::Rational(-1.0));
  const auto correct = AnalyticModel<double>(scene).velocitiesAfter(2);
  EXPECT_NEAR(correct(0), 0.3, 1e-15);
  EXPECT_NEAR(correct(1), 0.7, 1e-15);
  EXPECT_NEAR(correct(2), -1.0, 1e-15);
}

TEST(PaperErrata, CollisionCount322IsEvenForNonIntegerArguments) {
  // Equal masses (-1, 0, 1) with AB first: 3 collisions; (3.22) cannot give an odd number.
  const ThreeBodyScene scene{{1, 1, 1}, {3, 2, 0}, {-1, 0, 1}};
  ASSERT_EQ(simulate<double>(scene, {}).collision_count, 3u);
  const auto printed = paper::collisionCount(scene);
  ASSERT_TRUE(printed.has_value());
  EXPECT_NE(*printed, 3);
  // On seeded random AB-first starts it rarely matches; the correct count always does.
  std::mt19937_64 rng(2025);
  int matches = 0, ab_first = 0;
  for (int i = 0; i < 500; ++i) {
    const ThreeBodyScene s = testing_support::randomScene(rng);
    if (s.wallIndex() >= 0 || firstPair(s) != Pair::AB) continue;
    ++ab_first;
    const std::uint64_t truth = exact::simulate(s, 100000).collision_count;
    EXPECT_EQ(predictedCollisionCount(s), truth);
    const auto p = paper::collisionCount(s);
    matches += p && *p == static_cast<std::int64_t>(truth);
  }
  EXPECT_GT(ab_first, 100);
  EXPECT_LT(matches, ab_first / 2);
}

TEST(PaperErrata, EnergyTransfer44UsesTheWrongAverage) {
  // (4.4) with v_k against the initial vbar_AB differs from the true change once
  // v_A + v_B has changed, i.e. from the second AB impact on (collision 3).
  const ThreeBodyScene scene{{1, 2, 3}, {3, 2, 0}, {-1, 0.3, 0.7}};
  SimulationOptions options;
  options.events = EventPolicy::all();
  const SimulationResult result = simulate<double>(scene, options);
  ASSERT_GE(result.collision_count, 3u);
  const ImpactEvent& first = result.events[0];
  const auto printed_first =
      paper::energyTransfer(scene, 1, first.pair, first.velocities_before, scene.velocities);
  EXPECT_NEAR(printed_first[0], first.energy_transfer[0], 1e-12);  // right at k = 0
  const ImpactEvent& third = result.events[2];
  ASSERT_EQ(third.pair, Pair::AB);
  const auto printed_third =
      paper::energyTransfer(scene, 3, third.pair, third.velocities_before, result.events[1].velocities_before);
  EXPECT_GT(std::fabs(printed_third[0] - third.energy_transfer[0]), 1e-3);
}

TEST(PaperErrata, OmegaAsPrintedIsPiMinusAlpha) {
  const std::array<double, 3> masses{1, 2, 3};
  EXPECT_NEAR(paper::omega(masses), anglesFor(masses).omega, 1e-14);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
