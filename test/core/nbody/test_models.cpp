// The model each scene needs: the choice, and each closed-form model against the exact
// reference, the engine, or an independent count.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <random>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/impact_rule.h"
#include "collision_lab/core/nbody/models.h"
#include "random_scenes.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

using testing_support::kInf;
using testing_support::kRestitutions;
using testing_support::randomScene;

Scene scene(std::vector<double> m, std::vector<double> x, std::vector<double> v, std::vector<double> e = {}) {
  return Scene{std::move(m), std::move(x), std::move(v), std::move(e)};
}

TEST(NBodyModels, ChoosesTheCheapestExactModel) {
  const auto kind = [](const Scene& s) {
    EXPECT_FALSE(validate(s)) << validate(s)->message;
    const ModelChoice choice = chooseModel(s);
    EXPECT_FALSE(choice.reason.empty());
    return choice.kind;
  };
  EXPECT_EQ(kind(scene({1}, {0}, {5})), ModelKind::kNoCollisions);
  EXPECT_EQ(kind(scene({1, 2, 3}, {2, 1, 0}, {3, 2, 1})), ModelKind::kNoCollisions);  // all separate
  EXPECT_EQ(kind(scene({1, 2}, {1, 0}, {-1, 1}, {0.8})), ModelKind::kTwoBody);
  EXPECT_EQ(kind(scene({kInf, 1}, {1, 0}, {0, 1})), ModelKind::kTwoBody);
  EXPECT_EQ(kind(scene({1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5})), ModelKind::kThreeBodyRotation);
  EXPECT_EQ(kind(scene({1, 1, 1}, {2, 1, 0}, {-1, 0, 0.5})), ModelKind::kThreeBodyRotation);  // N = 3 keeps its model
  EXPECT_EQ(kind(scene({100, 1, kInf}, {2, 1, 0}, {-1, 0, 0})), ModelKind::kThreeBodyRotation);
  EXPECT_EQ(kind(scene({1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5}, {0.5})), ModelKind::kThreeBodySpiral);
  EXPECT_EQ(kind(scene({1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5}, {0.5, 0.4})), ModelKind::kThreeBodySpiral);  // two e
  EXPECT_NE(chooseModel(scene({1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5}, {0.5, 0.4})).reason.find("two e > 0"),
            std::string::npos);
  EXPECT_EQ(kind(scene({1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5}, {0.5, 0})), ModelKind::kEventEngine);  // one sticks
  EXPECT_NE(chooseModel(scene({1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5}, {0.5, 0})).reason.find("different e"),
            std::string::npos);
  EXPECT_EQ(kind(scene({kInf, 1, 3}, {2, 1, 0}, {0, 0, 0.5}, {0.5})), ModelKind::kThreeBodySpiral);  // a wall
  EXPECT_EQ(kind(scene({kInf, 1, 3}, {2, 1, 0}, {0, 0, 0.5}, {0.5, 0.4})), ModelKind::kThreeBodySpiral);  // two e
  EXPECT_EQ(kind(scene({kInf, 1, kInf}, {2, 1, 0}, {0, 1, 0})), ModelKind::kTwoWallsInfinite);
  // Two or more bodies between the walls: a box, named as one.
  EXPECT_EQ(kind(scene({kInf, 1, 1, kInf}, {3, 2, 1, 0}, {0, 1, 0, 0.5}, {0.9})), ModelKind::kBoxInfinite);
  EXPECT_STREQ(modelKindName(ModelKind::kBoxInfinite), "box_infinite");
  EXPECT_STREQ(modelKindName(ModelKind::kTwoWallsInfinite), "two_walls_infinite");
  EXPECT_EQ(kind(scene({kInf, 1, kInf}, {2, 1, 0}, {1, 3, -1})), ModelKind::kEventEngine);  // walls move apart
  EXPECT_EQ(kind(scene({kInf, 1, 1, kInf}, {3, 2, 1, 0}, {0, 1, 0, 0}, {1, 0, 1})), ModelKind::kEventEngine);  // e = 0 sticks
  EXPECT_EQ(kind(scene({1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0})), ModelKind::kGhosts);
  EXPECT_EQ(kind(scene({1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}, {0.9})), ModelKind::kEventEngine);
  EXPECT_EQ(kind(scene({1, 1, 1, 1, kInf}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0})), ModelKind::kEventEngine);
  EXPECT_EQ(kind(scene({1, 2, 1, 2, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0})), ModelKind::kEventEngine);
  EXPECT_NE(chooseModel(scene({1, 2, 1, 2, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0})).reason.find("no count formula"),
            std::string::npos);
  ASSERT_TRUE(predict(scene({1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5})));   // the rotation model answers, like any model
  EXPECT_EQ(predict(scene({1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5}))->kind, ModelKind::kThreeBodyRotation);
  EXPECT_FALSE(predict(scene({1, 2, 1, 2}, {3, 2, 1, 0}, {-1, 0, 0, 0})));  // the engine answers
}

TEST(NBodyModels, NoCollisionsAgreesWithReferenceAndEngine) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 100; ++trial) {
    Scene s = randomScene(rng, 1 + trial % 8);
    std::sort(s.velocities.begin(), s.velocities.end(), std::greater<double>());  // nothing approaches
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (s.isWall(k)) s.velocities[k] = k == 0 ? 2.0 : -2.0;  // walls moving away
    }
    ASSERT_FALSE(validate(s));
    ASSERT_EQ(chooseModel(s).kind, ModelKind::kNoCollisions);
    const Prediction prediction = *predict(s);
    EXPECT_EQ(prediction.impact_count, 0u);
    EXPECT_EQ(prediction.final_velocities, s.velocities);
    EXPECT_TRUE(reference::simulate(s, 10).events.empty());
    EXPECT_EQ(runEngine(s).impact_count, 0u);
  }
}

TEST(NBodyModels, TwoBodyClosedFormAgreesWithReference) {
  std::mt19937_64 rng(11);
  int impacts = 0, walls = 0, inelastic = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Scene s = randomScene(rng, 2);
    if (trial % 4 == 0) s.restitution = {kRestitutions[trial / 4 % 6]};
    ASSERT_FALSE(validate(s));
    const ModelKind kind = chooseModel(s).kind;
    ASSERT_TRUE(kind == ModelKind::kTwoBody || kind == ModelKind::kNoCollisions) << modelKindName(kind);
    const Prediction p = predictTwoBody(s);
    const reference::Run exact = reference::simulate(s, 5);
    ASSERT_EQ(p.impact_count, exact.events.size()) << trial;
    EXPECT_LE(reference::energyNormError(s, p.final_velocities, exact.velocities), 1e-15) << trial;
    if (exact.events.empty()) continue;
    ++impacts;
    walls += s.wallCount() > 0;
    inelastic += !s.isElastic();
    const double t = static_cast<double>(exact.events[0].time);
    EXPECT_NEAR(*p.impact_time, t, 1e-15 * t) << trial;
    const double x = static_cast<double>(exact.events[0].position);
    EXPECT_NEAR(*p.impact_position, x, 1e-15 * (std::fabs(x) + std::fabs(s.velocities[0] * t))) << trial;
    const double lost = static_cast<double>(exact.energy_lost);
    EXPECT_NEAR(p.energy_lost, lost, 1e-14 * (lost + 1e-300)) << trial;
  }
  EXPECT_GT(impacts, 150);
  EXPECT_GT(walls, 40);
  EXPECT_GT(inelastic, 40);
}

TEST(NBodyModels, TwoCartsByHand) {
  // Equal carts at -1 and +1 m/s toward each other, e = 0.8: they leave at +-0.8 m/s and
  // (1 - 0.64) * (1/2 kg) * (2 m/s)^2 / 2 = 0.36 J turns into heat.
  const Prediction p = *predict(scene({1, 1}, {1, 0}, {-1, 1}, {0.8}));
  EXPECT_EQ(p.impact_count, 1u);
  EXPECT_DOUBLE_EQ(p.final_velocities[0], 0.8);
  EXPECT_DOUBLE_EQ(p.final_velocities[1], -0.8);
  EXPECT_DOUBLE_EQ(p.energy_lost, 0.36);
  EXPECT_DOUBLE_EQ(*p.impact_time, 0.5);
  EXPECT_DOUBLE_EQ(*p.impact_position, 0.5);
  // The same rule against a wall: v' = v_wall - e (v - v_wall).
  // A wall on the right at 0.5 m/s, a 1 kg cart at 2 m/s behind it, e = 0.5.
  const ImpactOutcome wall = impact(kInf, 1.0, 0.5, 2.0, 0.5);
  EXPECT_EQ(wall.velocity_i, 0.5);
  EXPECT_DOUBLE_EQ(wall.velocity_j, -0.25);
  EXPECT_DOUBLE_EQ(wall.energy_lost, 0.75 * 1.0 * 1.5 * 1.5 / 2);
}

TEST(NBodyModels, TwoWallsAreInfinite) {
  const Scene s = scene({kInf, 1, kInf}, {2, 1, 0}, {0, 1, 0});
  const Prediction p = *predict(s);
  EXPECT_TRUE(p.infinite);
  EXPECT_FALSE(p.impact_count);
  EngineOptions options;
  options.max_impacts = 1000;
  const SceneSimulation run = runEngine(s, options);
  EXPECT_EQ(run.impact_count, 1000u);
  EXPECT_TRUE(run.truncated);
  EXPECT_EQ(run.stop, StopReason::kCap);
  EXPECT_NE(run.stop_message.find("two walls"), std::string::npos) << run.stop_message;
}

TEST(NBodyModels, ABallBetweenStillWallsRepeatsEveryPeriodExactlyRounded) {
  // x_A - x_C is not a double here, so 2 (x_A - x_C) / |v_B| in doubles is 1 ulp off
  // (10.824665500268292); the period is the exact value rounded once.
  const double xa = 2.550690257394217, xc = -5.045649129080591, vb = -1.4035240878873405;
  const Scene s = scene({kInf, 1, kInf}, {xa, 0.5, xc}, {0, vb, 0});
  const auto period = wallToWallPeriod(s);
  ASSERT_TRUE(period);
  using Rational = boost::multiprecision::cpp_rational;
  const Rational exact = 2 * (Rational(xa) - Rational(xc)) / -Rational(vb);
  EXPECT_EQ(period->time, exact.convert_to<double>());
  EXPECT_NE(period->time, 2 * (xa - xc) / -vb) << "the doubles' quotient rounds three times";
  EXPECT_EQ(period->impacts, 2u);
  // The engine agrees: impact n + 2 comes one period after impact n, and B moves as at the
  // start after each second impact.
  EngineOptions options;
  options.max_impacts = 9;
  std::vector<ImpactRecord> impacts;
  runEngine(s, options, [&](const ImpactRecord& r) { impacts.push_back(r); });
  ASSERT_EQ(impacts.size(), 9u);
  for (std::size_t n = 0; n + 2 < impacts.size(); ++n) {
    EXPECT_NEAR(impacts[n + 2].time - impacts[n].time, period->time, 1e-12 * impacts[n + 2].time);
  }
  for (std::size_t n = 1; n < impacts.size(); n += 2) {
    const ImpactRecord& r = impacts[n];
    EXPECT_EQ(r.velocities_after[r.pair_index == 0 ? 1 : 0], vb) << "B after impact " << n;  // B is pair AB's left body
  }
}

TEST(NBodyModels, OnlyABallBetweenStillElasticWallsHasAPeriod) {
  EXPECT_TRUE(wallToWallPeriod(scene({kInf, 1, kInf}, {2, 1, 0}, {0, 1, 0})));
  EXPECT_FALSE(wallToWallPeriod(scene({kInf, 1, kInf}, {2, 1, 0}, {0.5, 1, 0})));  // a moving wall
  EXPECT_FALSE(wallToWallPeriod(scene({kInf, 1, kInf}, {2, 1, 0}, {0, 1, 0}, {0.9})));  // inelastic
  EXPECT_FALSE(wallToWallPeriod(scene({kInf, 1, kInf}, {2, 1, 0}, {0, 0, 0})));  // at rest
  EXPECT_FALSE(wallToWallPeriod(scene({kInf, 1, 1, kInf}, {3, 2, 1, 0}, {0, 1, 0, 0})));  // two balls
  EXPECT_FALSE(wallToWallPeriod(scene({1, 1, kInf}, {2, 1, 0}, {0, 1, 0})));  // one wall
}

/// Number of pairs i < j with v_i < v_j, by a Fenwick tree over the ranks of the values:
/// independent of the merge sort in the model.
std::uint64_t fenwickInversions(const std::vector<double>& v) {
  std::vector<double> ranks = v;
  std::sort(ranks.begin(), ranks.end());
  ranks.erase(std::unique(ranks.begin(), ranks.end()), ranks.end());
  std::vector<std::uint64_t> tree(ranks.size() + 1, 0);
  std::uint64_t inversions = 0;
  for (double value : v) {
    const std::size_t rank = std::lower_bound(ranks.begin(), ranks.end(), value) - ranks.begin();  // # smaller values
    for (std::size_t i = rank; i > 0; i -= i & (~i + 1)) inversions += tree[i];  // earlier and smaller
    for (std::size_t i = rank + 1; i < tree.size(); i += i & (~i + 1)) ++tree[i];
  }
  return inversions;
}

Scene equalMasses(std::mt19937_64& rng, std::size_t n, std::size_t distinct_velocities) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), gap(0.5, 1.5);
  std::vector<double> pool(distinct_velocities);
  for (double& v : pool) v = unit(rng);
  std::uniform_int_distribution<std::size_t> pick(0, distinct_velocities - 1);
  Scene s;
  double x = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    s.masses.push_back(2.0);
    s.velocities.push_back(pool[pick(rng)]);
    s.positions.push_back(x);
    x -= gap(rng);
  }
  return s;
}

TEST(NBodyModels, CountInversionsSmallCases) {
  EXPECT_EQ(countInversions({}), 0u);
  EXPECT_EQ(countInversions({1}), 0u);
  EXPECT_EQ(countInversions({-1, 0, 0, 0, 0}), 4u);  // the cradle
  EXPECT_EQ(countInversions({-1, -1, 0, 0, 0}), 6u);  // two strikers
  EXPECT_EQ(countInversions({0, 0, 0}), 0u);         // equal velocities never meet
  EXPECT_EQ(countInversions({1, 2, 3, 4}), 6u);       // every pair
  EXPECT_EQ(countInversions({4, 3, 2, 1}), 0u);
}

TEST(NBodyModels, GhostsAgreeWithReference) {
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 60; ++trial) {
    const Scene s = equalMasses(rng, 3 + trial % 6, trial % 5 == 0 ? 2 : 50);
    if (validate(s)) continue;
    const ModelKind kind = chooseModel(s).kind;
    if (kind != ModelKind::kNoCollisions) {
      EXPECT_EQ(kind, s.size() == 3 ? ModelKind::kThreeBodyRotation : ModelKind::kGhosts);
    }
    const Prediction p = predictGhosts(s);
    const reference::Run exact = reference::simulate(s, 1000);
    if (exact.multiple_first) continue;  // ghosts count the continuous limit there
    EXPECT_EQ(p.impact_count, exact.events.size()) << trial;
    for (std::size_t k = 0; k < s.size(); ++k) EXPECT_EQ(reference::Rational(p.final_velocities[k]), exact.velocities[k]);
  }
}

TEST(NBodyModels, GhostsAgreeWithEngineOnAThousandBodies) {
  std::mt19937_64 rng(17);
  const Scene s = equalMasses(rng, 1000, 1000);
  ASSERT_FALSE(validate(s));
  ASSERT_EQ(chooseModel(s).kind, ModelKind::kGhosts);
  const Prediction p = *predict(s);
  const SceneSimulation run = runEngine(s);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  EXPECT_EQ(run.impact_count, *p.impact_count);
  EXPECT_GT(run.impact_count, 200'000u);
  EXPECT_EQ(run.final_velocities, p.final_velocities);  // equal masses exchange exactly
}

TEST(NBodyModels, GhostsOnAMillionBodies) {
  std::mt19937_64 rng(19);
  const Scene s = equalMasses(rng, 1'000'000, 5000);  // ~200 bodies share each velocity
  ASSERT_FALSE(validate(s));
  ASSERT_EQ(chooseModel(s).kind, ModelKind::kGhosts);
  const Prediction p = *predict(s);
  EXPECT_EQ(*p.impact_count, fenwickInversions(s.velocities));
  EXPECT_GT(*p.impact_count, 200'000'000'000u);  // about N^2 / 4
  std::vector<double> sorted = s.velocities;
  std::sort(sorted.begin(), sorted.end());
  std::reverse(sorted.begin(), sorted.end());
  EXPECT_EQ(p.final_velocities, sorted);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
