// Issue 11: a body squeezed against a wall collapses (infinitely many impacts in finite
// time), resolved to its limit by the engine; against hand derivations and the exact
// rational reference (reference.h), which steps through the impacts without resolving them.
//
// By hand, the wall as the outer body A of the three-body cycle (spiral.h): m_A = inf gives
// k_A = 1 + e and cos^2(alpha) = m_C/(m_B+m_C). Squeeze scene: wall, ball 1 kg, heavy body
// 10 kg, x = (2, 1, 0) m, v = (0, 0, 1) m/s, e = 0.5: cos^2(alpha) = 10/11, the cycle's
// trace T = (1.5)^2 10/11 - 1 = 23/22, determinant 1/4, eigenvalues (23 +- 3 sqrt 5)/44
// (both real: a collapse). Gaps and approach speeds shrink by lambda1 = 0.675 per cycle,
// and the impact times, their ratios, approach the limit by lambda2/lambda1 = 0.548 per
// cycle (checked in exact fractions: 0.5484). Critical value: T = 2e, i.e.
// sqrt(r_c) = (1 - sin alpha)/cos alpha = (sqrt 11 - 1)/sqrt 10, r_c = (6 - sqrt 11)/5 = 0.5367.
// At the collapse all approach
// speeds vanish: every body moves with the wall (0 m/s), at the wall (x = 2 m), and the
// heavy body's 5 J are all lost.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/models.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

constexpr double kWall = std::numeric_limits<double>::infinity();

/// Two bodies and a wall at the right (body 0) or left end (body 2): masses 10^[-1, 1] kg,
/// gaps 0.2-2 m, velocities in [-1, 1] m/s; no restitution set.
Scene seededOneWallScene(std::mt19937_64& rng, bool wall_right) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), gap(0.2, 2.0), decades(-1.0, 1.0);
  Scene s;
  for (int k = 0; k < 3; ++k) s.masses.push_back(std::pow(10.0, decades(rng)));
  s.masses[wall_right ? 0 : 2] = kWall;
  const double x2 = unit(rng), x1 = x2 + gap(rng), x0 = x1 + gap(rng);
  s.positions = {x0, x1, x2};
  for (int k = 0; k < 3; ++k) s.velocities.push_back(unit(rng));
  return s;
}

/// The engine's first impacts follow the exact reference's pairs.
void expectSamePairs(const SceneSimulation& run, const reference::Run& exact, std::size_t count, const std::string& label) {
  ASSERT_LE(count, run.impacts.size()) << label;
  ASSERT_LE(count, exact.events.size()) << label;
  for (std::size_t k = 0; k < count; ++k) {
    ASSERT_EQ(run.impacts[k].pair_index, exact.events[k].pair) << label << ", impact " << k + 1;
  }
}

/// Checks a squeeze that collapses at `position` with every body ending at the wall's
/// velocity `wall_v` and `heat` [J] lost.
void expectSqueeze(const Scene& s, double position, double wall_v, double heat) {
  EngineOptions options;
  options.keep_events = 100000;
  const SceneSimulation run = runEngine(s, options);
  ASSERT_TRUE(run.collapsed) << run.stop_message;
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  ASSERT_EQ(run.collapses.size(), 1u);
  EXPECT_EQ(run.collapses[0].first_body, 0u);
  EXPECT_EQ(run.collapses[0].last_body, 2u);
  const reference::Run exact = reference::simulate(s, 120);
  ASSERT_TRUE(exact.truncated);  // the impacts do not stop
  expectSamePairs(run, exact, std::min<std::size_t>(run.impact_count, 120), "squeeze");
  const double limit = reference::limitOfImpactTimes(exact);
  EXPECT_NEAR(*run.collapse_time, limit, 1e-12 * limit);
  EXPECT_LE(static_cast<double>(exact.events.back().time), *run.collapse_time);
  EXPECT_NEAR(*run.collapse_position, position, 1e-12);
  for (double v : run.final_velocities) EXPECT_EQ(v, wall_v);
  EXPECT_EQ(run.collapses[0].velocity, wall_v);
  EXPECT_NEAR(run.energy_lost, heat, 1e-12 * heat);
  // The exact losses of the reference's first 120 impacts approach the total from below.
  EXPECT_LE(static_cast<double>(exact.energy_lost), run.energy_lost);
  EXPECT_NEAR(static_cast<double>(exact.energy_lost), heat, 1e-6 * heat);
}

TEST(WallCollapse, ABallSqueezedAgainstAWallByAHeavyBody) {
  // x = 2 m, 0 m/s, 5 J: see the header comment.
  expectSqueeze(Scene{{kWall, 1, 10}, {2, 1, 0}, {0, 0, 1}, {0.5}}, 2.0, 0.0, 5.0);
}

TEST(WallCollapse, MirrorSceneWithTheWallOnTheOtherEnd) {
  expectSqueeze(Scene{{10, 1, kWall}, {2, 1, 0}, {-1, 0, 0}, {0.5}}, 0.0, 0.0, 5.0);
}

TEST(WallCollapse, AMovingWallCarriesTheClusterAway) {
  // The squeeze scene seen from a frame moving at -0.25 m/s: the same impacts, the same
  // time; the bodies meet at the wall, 2 + 0.25 T m, and move on at 0.25 m/s; the heat is
  // the same 5 J (frame-independent).
  const Scene moving{{kWall, 1, 10}, {2, 1, 0}, {0.25, 0.25, 1.25}, {0.5}};
  const SceneSimulation rest = runEngine(Scene{{kWall, 1, 10}, {2, 1, 0}, {0, 0, 1}, {0.5}});
  ASSERT_TRUE(rest.collapsed) << rest.stop_message;
  expectSqueeze(moving, 2.0 + 0.25 * *rest.collapse_time, 0.25, 5.0);
}

TEST(WallCollapse, AboveTheWallsCriticalRestitutionTheImpactsStop) {
  // r_c = tan^2(pi/4 - alpha/2), cos^2(alpha) = m_C/(m_B+m_C) = 10/11: by hand (6 - sqrt 11)/5.
  const double alpha = std::acos(std::sqrt(10.0 / 11.0)), root = std::tan(M_PI / 4 - alpha / 2);
  const double rc = (6 - std::sqrt(11.0)) / 5;
  EXPECT_NEAR(root * root, rc, 1e-15);
  for (double e : {0.54, 0.6, 0.8}) {  // above r_c = 0.5367: a finite count
    const Scene s{{kWall, 1, 10}, {2, 1, 0}, {0, 0, 1}, {e}};
    EngineOptions options;
    options.keep_events = 100000;
    const SceneSimulation run = runEngine(s, options);
    const reference::Run exact = reference::simulate(s, 100000);
    const std::string label = "e = " + std::to_string(e);
    ASSERT_FALSE(exact.truncated) << label;
    EXPECT_FALSE(run.collapsed) << label;
    EXPECT_EQ(run.stop, StopReason::kFinished) << label << ": " << run.stop_message;
    ASSERT_EQ(run.impact_count, exact.events.size()) << label;
    expectSamePairs(run, exact, exact.events.size(), label);
    EXPECT_LT(reference::energyNormError(s, run.final_velocities, exact.velocities), 1e-13) << label;
    EXPECT_GT(run.impact_count, 3u) << label;
  }
  // Just below r_c the ball is squeezed (the start, at rest against the wall, lies in the
  // approaching cone).
  const SceneSimulation below = runEngine(Scene{{kWall, 1, 10}, {2, 1, 0}, {0, 0, 1}, {0.53}});
  EXPECT_TRUE(below.collapsed) << below.stop_message;
}

TEST(WallCollapse, SeededScenesWithOneWallAgreeWithTheExactReference) {
  std::mt19937_64 rng(2024);
  const double set[] = {0.0, 0.05, 0.3, 0.5, 0.8, 0.95, 1.0};
  constexpr std::uint64_t kCap = 400;
  int collapses = 0, finished = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const bool wall_right = trial % 2 == 0;
    Scene s = seededOneWallScene(rng, wall_right);
    s.restitution = {set[trial / 2 % 7]};
    if (validate(s)) continue;
    const std::string label = "scene " + std::to_string(trial) + ", e = " + std::to_string(s.restitution[0]);
    EngineOptions options;
    options.keep_events = kCap;
    const SceneSimulation run = runEngine(s, options);
    ASSERT_NE(run.stop, StopReason::kInternalError) << label << ": " << run.stop_message;
    ASSERT_EQ(run.stop, StopReason::kFinished) << label << ": " << run.stop_message;
    // Past a collapse the reference's rationals grow by some bits per impact: 60 more suffice.
    const reference::Run exact = reference::simulate(s, run.collapsed ? run.impact_count + 60 : kCap);
    if (run.collapsed) {
      ++collapses;
      ASSERT_TRUE(exact.truncated) << label;
      ASSERT_LE(run.impact_count, kCap) << label;
      expectSamePairs(run, exact, run.impact_count, label);
      EXPECT_LE(static_cast<double>(exact.events.back().time), *run.collapse_time * (1 + 1e-15)) << label;
      const double limit = reference::limitOfImpactTimes(exact);
      EXPECT_NEAR(*run.collapse_time, limit, 1e-9 * std::fabs(limit)) << label;
      for (double v : run.final_velocities) EXPECT_EQ(v, s.velocities[wall_right ? 0 : 2]) << label;
    } else {
      ++finished;
      ASSERT_FALSE(exact.truncated) << label;
      ASSERT_EQ(run.impact_count, exact.events.size()) << label;
      expectSamePairs(run, exact, std::min<std::size_t>(exact.events.size(), kCap), label);
      EXPECT_LT(reference::energyNormError(s, run.final_velocities, exact.velocities), 1e-12) << label;
    }
  }
  EXPECT_GT(collapses, 10);
  EXPECT_GT(finished, 100);
}

// The spiral model with the wall as its outer body, in O(1): the squeeze scenes above by hand,
// the counts above r_c against the exact reference.
TEST(WallCollapse, TheSpiralModelTakesTheWallAsAnInfiniteMass) {
  const Scene squeeze{{kWall, 1, 10}, {2, 1, 0}, {0, 0, 1}, {0.5}};
  ASSERT_EQ(chooseModel(squeeze).kind, ModelKind::kThreeBodySpiral);
  const Prediction p = *predict(squeeze);
  EXPECT_NE(p.reason.find("wall"), std::string::npos);
  EXPECT_NEAR(*p.critical_restitution, (6 - std::sqrt(11.0)) / 5, 1e-15);
  ASSERT_TRUE(p.collapsed) << p.reason;
  const SceneSimulation run = runEngine(squeeze);
  ASSERT_TRUE(run.collapsed) << run.stop_message;
  EXPECT_NEAR(*p.collapse_time, *run.collapse_time, 1e-13 * *run.collapse_time);
  EXPECT_NEAR(*p.collapse_time, 2.276, 5e-4);  // physics.md
  EXPECT_NEAR(*p.collapse_position, 2.0, 1e-15);
  EXPECT_NEAR(p.energy_lost, 5.0, 1e-15);
  for (double v : p.final_velocities) EXPECT_EQ(v, 0.0);
  const Prediction mirror = *predict(Scene{{10, 1, kWall}, {2, 1, 0}, {-1, 0, 0}, {0.5}});
  ASSERT_TRUE(mirror.collapsed);
  EXPECT_NEAR(*mirror.collapse_time, *p.collapse_time, 1e-15 * *p.collapse_time);
  EXPECT_NEAR(*mirror.collapse_position, 0.0, 1e-15);
  const Prediction moving = *predict(Scene{{kWall, 1, 10}, {2, 1, 0}, {0.25, 0.25, 1.25}, {0.5}});
  ASSERT_TRUE(moving.collapsed);
  EXPECT_NEAR(*moving.collapse_position, 2.0 + 0.25 * *moving.collapse_time, 1e-15);
  for (double v : moving.final_velocities) EXPECT_EQ(v, 0.25);
  EXPECT_NEAR(moving.energy_lost, 5.0, 1e-14);
  for (double e : {0.54, 0.6, 0.8}) {  // above r_c = 0.5367
    const Scene s{{kWall, 1, 10}, {2, 1, 0}, {0, 0, 1}, {e}};
    const Prediction q = *predict(s);
    const reference::Run exact = reference::simulate(s, 100000);
    ASSERT_FALSE(exact.truncated);
    ASSERT_TRUE(q.impact_count) << q.reason;
    EXPECT_EQ(*q.impact_count, exact.events.size()) << "e = " << e;
    EXPECT_LT(reference::energyNormError(s, q.final_velocities, exact.velocities), 1e-13) << "e = " << e;
    EXPECT_NEAR(q.energy_lost, static_cast<double>(exact.energy_lost), 1e-13 * 5) << "e = " << e;
  }
}

// Seeded scenes with one wall, e from a set and 1 % either side of the wall's r_c: the
// model against the engine (which the test above checks against the exact reference).
TEST(WallCollapse, SpiralModelWithAWallEqualsTheEngineOnSeededScenes) {
  std::mt19937_64 rng(4242);
  const double set[] = {0.0, 0.3, 0.5, 0.8, 0.95};
  int collapses = 0, finished = 0, near = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const bool wall_right = trial % 2 == 0;
    Scene s = seededOneWallScene(rng, wall_right);
    const double m_c = s.masses[wall_right ? 2 : 0], sine = std::sqrt(1 - m_c / (s.masses[1] + m_c));
    const double rc = (1 - sine) / (1 + sine);  // cos^2(alpha) = m/(m_B + m) by hand
    const int kind = trial / 2 % 3;
    s.restitution = {kind == 0 ? set[trial / 6 % 5] : rc * (kind == 1 ? 1.01 : 0.99)};
    if (validate(s) || chooseModel(s).kind != ModelKind::kThreeBodySpiral) continue;  // e.g. nothing approaches
    const std::string label = "scene " + std::to_string(trial) + ", e = " + std::to_string(s.restitution[0]);
    near += kind != 0;
    const Prediction p = *predict(s);
    EXPECT_NEAR(*p.critical_restitution, rc, 1e-14) << label;
    const SceneSimulation run = runEngine(s);
    ASSERT_EQ(run.stop, StopReason::kFinished) << label << ": " << run.stop_message;
    EXPECT_EQ(p.collapsed, run.collapsed) << label;
    if (run.collapsed && p.collapsed) {
      ++collapses;
      EXPECT_NEAR(*p.collapse_time, *run.collapse_time, 1e-12 * *run.collapse_time) << label;
      EXPECT_NEAR(*p.collapse_position, *run.collapse_position, 1e-12 * (1 + std::fabs(*run.collapse_position))) << label;
    } else if (!run.collapsed) {
      ++finished;
      ASSERT_TRUE(p.impact_count) << label << ": " << p.reason;
      EXPECT_EQ(*p.impact_count, run.impact_count) << label;
    }
    const double scale = std::fabs(s.velocities[0]) + std::fabs(s.velocities[1]) + std::fabs(s.velocities[2]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.final_velocities[k], run.final_velocities[k], 1e-12 * scale) << label;
    EXPECT_NEAR(p.energy_lost, run.energy_lost, 1e-12 * (1 + run.energy_lost)) << label;
  }
  EXPECT_GT(collapses, 8);
  EXPECT_GT(finished, 80);
  EXPECT_GT(near, 60);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
