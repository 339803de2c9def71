// The engine on the hard cases of the issue, with hand-derived numbers and against the
// exact reference: the cradle with gaps, one-ulp near-ties, simultaneous disjoint impacts,
// two strikers, a later multiple collision, mass ratios of 1e6 inside a chain, walls at
// both ends, sticking (e = 0); and the run's contract (records, cancellation, progress).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>

#include "collision_lab/core/nbody/models.h"
#include "engine_checks.h"
#include "random_scenes.h"

namespace collision_lab {
namespace core {
namespace {

using testing_support::expectMatchesReference;
using testing_support::kInf;

constexpr std::uint64_t kCap = 10'000;

std::vector<std::size_t> pairsOf(const SceneSimulation& run) {
  std::vector<std::size_t> pairs;
  for (const ImpactRecord& r : run.impacts) pairs.push_back(r.pair_index);
  return pairs;
}

TEST(NBodyEngineHard, CradleWithGaps) {
  // Five equal masses 1 m apart, A at -1 m/s: A stops at 3 m at t = 1 s, B at 2 m at 2 s,
  // C at 1 m at 3 s, D at 0 m at 4 s, and E leaves at -1 m/s.
  const Scene s{{1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}, {}};
  ASSERT_FALSE(validate(s));
  const SceneSimulation run = expectMatchesReference(s, kCap, "cradle");
  ASSERT_EQ(run.impact_count, 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(run.impacts[k].pair_index, k);
    EXPECT_EQ(run.impacts[k].time, k + 1.0);
    EXPECT_EQ(run.impacts[k].position, 3.0 - k);
    EXPECT_EQ(run.impacts[k].velocities_before[0], -1.0);
    EXPECT_EQ(run.impacts[k].velocities_after[1], -1.0);
    EXPECT_EQ(run.impacts[k].energy_gained[1], 0.5);
  }
  EXPECT_EQ(run.final_velocities, (std::vector<double>{0, 0, 0, 0, -1}));
  EXPECT_EQ(run.final_positions, (std::vector<double>{3, 2, 1, 0, 0}));  // at t = 4 s
  EXPECT_EQ(run.final_time, 4.0);
  EXPECT_EQ(run.stop, StopReason::kFinished);
  // The bodies left at rest touch with exactly zero approach speed. Equal masses swap
  // their velocities without rounding, so the working precision sees those zeros exactly
  // and needs no replay.
  EXPECT_EQ(run.escalations.high_precision + run.escalations.exact_rational, 0u);
  EXPECT_EQ(*predictGhosts(s).impact_count, 4u);
}

TEST(NBodyEngineHard, NearSimultaneousImpactsOneUlpApart) {
  // A and C reach B at t = 1 s exactly (rejected); one ulp of x_A decides who is first.
  Scene s{{1, 2, 3, 4}, {2, 1, 0, -5}, {-1, 0, 1, -1}, {}};
  s.positions[0] = std::nextafter(2.0, 3.0);  // A one ulp further: BC first
  ASSERT_FALSE(validate(s));
  SceneSimulation run = expectMatchesReference(s, kCap, "BC first by one ulp");
  ASSERT_GE(run.impacts.size(), 2u);
  EXPECT_EQ(run.impacts[0].pair_index, 1u);
  EXPECT_EQ(run.impacts[1].pair_index, 0u);
  s.positions[0] = std::nextafter(2.0, 1.0);  // one ulp nearer: AB first
  ASSERT_FALSE(validate(s));
  run = expectMatchesReference(s, kCap, "AB first by one ulp");
  ASSERT_GE(run.impacts.size(), 1u);
  EXPECT_EQ(run.impacts[0].pair_index, 0u);
}

TEST(NBodyEngineHard, DisjointImpactsAtTheSameInstantBothHappen) {
  // AB and CD at t = 1 s exactly, BC at 1.5 s, AB and CD again at 2 s: A and D leave.
  const Scene s{{1, 1, 1, 1}, {3, 2, 1, 0}, {-1, 0, 0, 1}, {}};
  ASSERT_FALSE(validate(s));
  const SceneSimulation run = expectMatchesReference(s, kCap, "two strikers, symmetric");
  EXPECT_EQ(pairsOf(run), (std::vector<std::size_t>{0, 2, 1, 0, 2}));
  const std::vector<double> times{1, 1, 1.5, 2, 2};
  for (std::size_t k = 0; k < run.impacts.size(); ++k) EXPECT_EQ(run.impacts[k].time, times[k]);
  EXPECT_EQ(run.final_velocities, (std::vector<double>{1, 0, 0, -1}));
  EXPECT_GT(run.escalations.exact_rational, 0u);  // exactly equal times: the exact tier orders them
  // One ulp later for D: CD is strictly after AB, and the order is still exact.
  Scene later = s;
  later.positions[3] = std::nextafter(0.0, -1.0);
  ASSERT_FALSE(validate(later));
  expectMatchesReference(later, kCap, "CD one ulp later");
}

TEST(NBodyEngineHard, GrazingContactsAreNoImpacts) {
  // physics.md: from v = (-1, 0, 0) m/s, masses (3, 1, 0.5) kg give exactly 2 impacts and
  // end with v_A = v_B; the kaleidoscopic masses (1, 1, 1), (2, 1, 3), (5, 1, 9) graze
  // too, with 2, 3 and 5 impacts. The last contact has approach speed exactly 0.
  const std::pair<std::vector<double>, std::uint64_t> cases[] = {
      {{3, 1, 0.5}, 2}, {{1, 1, 1}, 2}, {{2, 1, 3}, 3}, {{5, 1, 9}, 5}};
  for (const auto& [masses, count] : cases) {
    const Scene s{masses, {2, 1, 0}, {-1, 0, 0}, {}};
    const SceneSimulation run = expectMatchesReference(s, kCap, "grazing");
    EXPECT_EQ(run.impact_count, count) << masses[0] << ", " << masses[1] << ", " << masses[2];
  }
  const SceneSimulation run = runEngine(Scene{{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}, {}});
  EXPECT_EQ(run.final_velocities[0], run.final_velocities[1]);
  EXPECT_GT(run.escalations.exact_rational, 0u);  // an exact zero after rounded impacts
}

TEST(NBodyEngineHard, TwoStrikers) {
  // Two balls strike a row of three from the right, with gaps: 6 impacts, and two leave.
  const Scene s{{1, 1, 1, 1, 1}, {5.5, 4, 2, 1, 0}, {-1, -1, 0, 0, 0}, {}};
  ASSERT_FALSE(validate(s));
  const SceneSimulation run = expectMatchesReference(s, kCap, "two strikers");
  EXPECT_EQ(run.impact_count, 6u);
  EXPECT_EQ(run.final_velocities, (std::vector<double>{0, 0, 0, -1, -1}));
  EXPECT_EQ(run.impact_count, *predictGhosts(s).impact_count);
}

TEST(NBodyEngineHard, LaterMultipleCollisionEndsTheRun) {
  // AB and DE at 1 s (disjoint, fine); then B and D reach C at 2 s from both sides.
  const Scene s{{1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 1}, {}};
  ASSERT_FALSE(validate(s));
  const SceneSimulation run = expectMatchesReference(s, kCap, "later multiple collision");
  EXPECT_EQ(run.impact_count, 2u);
  EXPECT_EQ(run.stop, StopReason::kMultipleCollision);
  EXPECT_FALSE(run.truncated);
  ASSERT_TRUE(run.multiple_collision);
  EXPECT_EQ(run.multiple_collision->first_body, 1u);
  EXPECT_EQ(run.multiple_collision->time, 2.0);
  EXPECT_NE(run.stop_message.find("B, C and D"), std::string::npos) << run.stop_message;
  EXPECT_NE(run.stop_message.find("t = 2 s"), std::string::npos) << run.stop_message;
  EXPECT_EQ(run.final_velocities, (std::vector<double>{0, -1, 0, 1, 0}));  // before it
  // The scene of the validation test: DE at 0.5 s, then A, B and C meet at 2 s.
  const Scene later{{1, 1, 1, 1, 1}, {20, 10, 0, -10, -10.5}, {-5, 0, 5, -1, 0}, {}};
  const SceneSimulation second = expectMatchesReference(later, kCap, "A, B and C at 2 s");
  EXPECT_EQ(second.impact_count, 1u);
  ASSERT_TRUE(second.multiple_collision);
  EXPECT_EQ(second.multiple_collision->first_body, 0u);
}

TEST(NBodyEngineHard, MassRatiosOfAMillionInsideAChain) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    Scene s{{1, 1e6, 1, 1e6, 1, 2}, {5, 4, 3, 2, 1, 0}, {}, {}};
    for (int k = 0; k < 6; ++k) s.velocities.push_back(unit(rng));
    if (trial % 2) std::swap(s.masses[1], s.masses[2]);
    if (trial % 3 == 0) s.restitution = {0.95};
    if (validate(s)) continue;
    const SceneSimulation run = expectMatchesReference(s, 120, "1e6 chain " + std::to_string(trial));
    if (s.isElastic() && !run.truncated) {
      EXPECT_LT(run.energy_relative_drift, 1e-14) << trial;
    }
    EXPECT_LT(run.momentum_relative_drift, 1e-14) << trial;
  }
}

TEST(NBodyEngineHard, WallsAtBothEnds) {
  // A ball between two walls at 2 m and 0 m, from 1 m at 1 m/s: AB at 1, 5, 9 ... s and BC
  // at 3, 7, 11 ... s, forever; the run stops at the cap.
  const Scene ball{{kInf, 1, kInf}, {2, 1, 0}, {0, 1, 0}, {}};
  EngineOptions options;
  options.max_impacts = 1001;
  options.keep_events = 1001;
  const SceneSimulation run = runEngine(ball, options);
  EXPECT_EQ(run.impact_count, 1001u);
  EXPECT_TRUE(run.truncated);
  for (std::size_t k = 0; k < run.impacts.size(); ++k) {
    EXPECT_EQ(run.impacts[k].pair_index, k % 2);
    EXPECT_EQ(run.impacts[k].time, 1.0 + 2.0 * k);
    EXPECT_EQ(run.impacts[k].position, k % 2 ? 0.0 : 2.0);
  }
  EXPECT_EQ(run.final_velocities[1], -1.0);
  EXPECT_EQ(run.energy_relative_drift, 0.0);
  // Three bodies between walls, with restitution, against the reference.
  const Scene three{{kInf, 1, 2, 3, kInf}, {4, 3, 2, 1, 0}, {0, 1, -0.5, 0.25, 0}, {1, 0.9, 1, 0.5}};
  ASSERT_FALSE(validate(three));
  EXPECT_TRUE(expectMatchesReference(three, 60, "three between walls").truncated);
}

TEST(NBodyEngineHard, StickingWithZeroRestitution) {
  // A hits B at 1 s and they move on together at -0.5 m/s; their touching is no impact.
  const Scene away{{1, 1, 1}, {2, 1, 0}, {-1, 0, -2}, {0.0}};
  const SceneSimulation run = expectMatchesReference(away, kCap, "stuck pair");
  EXPECT_EQ(run.impact_count, 1u);
  EXPECT_EQ(run.final_velocities, (std::vector<double>{-0.5, -0.5, -2}));
  EXPECT_DOUBLE_EQ(run.energy_lost, 0.25);
  EXPECT_EQ(run.stop, StopReason::kFinished);
  // When the stuck pair reaches C at 3 s, C hits the cluster AB as one body of 2 kg (the
  // cluster rule), and all three stick: -1/3 m/s each, 1/4 + 1/12 J lost.
  const Scene onto{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.0}};
  const SceneSimulation hit = expectMatchesReference(onto, kCap, "stuck pair hits C");
  EXPECT_EQ(hit.impact_count, 2u);
  EXPECT_EQ(hit.cluster_impacts, 1u);
  EXPECT_FALSE(hit.multiple_collision);
  EXPECT_FALSE(hit.collapsed);
  for (double v : hit.final_velocities) EXPECT_DOUBLE_EQ(v, -1.0 / 3);
  EXPECT_DOUBLE_EQ(hit.energy_lost, 1.0 / 3);
  EXPECT_NE(hit.stop_message.find("1 impacts hit a cluster"), std::string::npos) << hit.stop_message;
  // A cluster with e = 0.5 towards C bounces: AB (2 kg, -0.5 m/s) on C (1 kg, 0) at 3 s.
  const Scene bounce{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.0, 0.5}};
  const SceneSimulation bounced = expectMatchesReference(bounce, kCap, "cluster bounces off C");
  EXPECT_EQ(bounced.impact_count, 2u);
  EXPECT_EQ(bounced.cluster_impacts, 1u);
  // By hand: M = 3 kg, V = -1/3 m/s, v_AB - v_C = -0.5 m/s, so
  // v_AB' = V - e m_C (v_AB - v_C)/M = -1/3 + 1/12 = -1/4 and v_C' = V + e m_AB (v_AB - v_C)/M = -1/2.
  EXPECT_EQ(bounced.final_velocities, (std::vector<double>{-0.25, -0.25, -0.5}));
}

TEST(NBodyEngineHard, ThreeEqualMassesWithRestitution) {
  // physics.md, "Reference points" (exact rational simulation): x = (2, 1, 0) m,
  // v = (-1, 0, 0) m/s. The counts near the critical restitution 0.0718 need the 100-digit
  // and rational tiers: the gaps shrink geometrically.
  const std::pair<double, std::uint64_t> counts[] = {{1.0, 2},   {0.5, 3},   {0.25, 3},   {0.17, 4},
                                                     {0.1, 6},   {0.08, 10}, {0.075, 16}, {0.072, 63}};
  for (const auto& [e, count] : counts) {
    const Scene s{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {e}};
    const SceneSimulation run = runEngine(s);
    EXPECT_EQ(run.impact_count, count) << "e = " << e;
    EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
    if (e == 0.072) {
      EXPECT_GT(run.escalations.high_precision, 0u);
    }
  }
  expectMatchesReference(Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.072}}, 100, "e = 0.072");
  // Below it the bodies collapse: infinitely many impacts before a finite time, resolved
  // to its limit; afterwards the three move together at the centre-of-mass velocity.
  for (const double e : {0.06, 0.07}) {
    // The limit of the exact impact times (physics.md: 3.7313542986536 s, 4.2578666486407 s).
    const double time = reference::collapseTime(Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {e}});
    const SceneSimulation run = runEngine(Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {e}});
    EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
    ASSERT_TRUE(run.collapsed) << run.stop_message;
    EXPECT_NEAR(*run.collapse_time, time, 1e-12) << "e = " << e;
    ASSERT_EQ(run.collapses.size(), 1u);
    EXPECT_EQ(run.collapses[0].first_body, 0u);
    EXPECT_EQ(run.collapses[0].last_body, 2u);
    // The meeting point: the centre of mass (1 m at t = 0) moving at -1/3 m/s.
    EXPECT_NEAR(*run.collapse_position, 1.0 - time / 3, 1e-12) << "e = " << e;
    for (double v : run.final_velocities) EXPECT_NEAR(v, -1.0 / 3, 1e-15);
    EXPECT_NEAR(run.energy_lost, 1.0 / 3, 1e-15);  // all the energy about the centre of mass
  }
}

TEST(NBodyEngineHard, RecordsConserveEnergyAndMatchTheReference) {
  std::mt19937_64 rng(29);
  for (int trial = 0; trial < 40; ++trial) {
    const Scene s = testing_support::randomScene(rng, 2 + trial % 7);
    const reference::Run exact = reference::simulate(s, 30);
    EngineOptions options;
    options.max_impacts = 30;
    std::vector<ImpactRecord> seen;
    const SceneSimulation run = runEngine(s, options, [&](const ImpactRecord& r) { seen.push_back(r); });
    EXPECT_TRUE(run.impacts.empty());  // nothing kept unless asked
    ASSERT_EQ(seen.size(), exact.events.size()) << trial;
    double scale = 0.0;
    for (std::size_t k = 0; k < s.size(); ++k) {
      if (!s.isWall(k)) scale += s.masses[k] * s.velocities[k] * s.velocities[k];
    }
    for (std::size_t k = 0; k < seen.size(); ++k) {
      const ImpactRecord& r = seen[k];
      EXPECT_EQ(r.index, k + 1);
      const double x = static_cast<double>(exact.events[k].position);
      EXPECT_NEAR(r.position, x, 1e-12 * (1 + std::fabs(x))) << trial;
      const double lost = static_cast<double>(exact.events[k].lost);
      EXPECT_NEAR(r.energy_lost, lost, 1e-12 * scale) << trial;
      EXPECT_NEAR(r.energy_gained[0] + r.energy_gained[1] + r.energy_lost, 0.0, 1e-12 * scale) << trial;
    }
    EXPECT_NEAR(run.energy_lost, static_cast<double>(exact.energy_lost), 1e-12 * scale) << trial;
  }
}

Scene gas(std::size_t n) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> mass(1.0, 2.0), velocity(-1.0, 1.0);
  Scene s;
  for (std::size_t k = 0; k < n; ++k) {
    s.masses.push_back(mass(rng));
    s.positions.push_back(static_cast<double>(n - k));
    s.velocities.push_back(velocity(rng));
  }
  return s;
}

TEST(NBodyEngineContract, ProgressAndCancellation) {
  const Scene s = gas(1000);
  std::atomic<bool> cancel{false};
  EngineOptions options;
  options.progress_interval = 1000;
  options.cancel = &cancel;
  std::vector<EngineProgress> reports;
  const SceneSimulation run = runEngine(s, options, {}, [&](const EngineProgress& p) {
    reports.push_back(p);
    if (reports.size() == 3) cancel = true;
  });
  EXPECT_EQ(run.stop, StopReason::kCancelled);
  EXPECT_TRUE(run.truncated);
  EXPECT_EQ(run.impact_count, 3072u);  // the flag is read every 1024 impacts
  ASSERT_EQ(reports.size(), 3u);
  EXPECT_EQ(reports[2].impacts, 3000u);
  EXPECT_GT(reports[2].time, reports[0].time);
  // The partial summary is a real state: momentum and energy still balance.
  EXPECT_LT(run.momentum_relative_drift, 1e-14);
  EXPECT_LT(run.energy_relative_drift, 1e-14);
  EXPECT_NE(run.stop_message.find("cancelled after 3,072 impacts"), std::string::npos) << run.stop_message;
}

TEST(NBodyEngineContract, KeepsOnlyTheEventsAskedFor) {
  const Scene s = gas(200);
  EngineOptions options;
  options.keep_events = 10;
  const SceneSimulation run = runEngine(s, options);
  EXPECT_GT(run.impact_count, 1000u);
  ASSERT_EQ(run.impacts.size(), 10u);
  EXPECT_EQ(run.impacts[9].index, 10u);
  EXPECT_EQ(run.stop, StopReason::kFinished);
  EXPECT_LT(run.energy_relative_drift, 1e-14);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
