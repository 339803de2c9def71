// Issue 21: the inelastic collapse of a group of four or more bodies whose impacts repeat a
// pattern, proved and resolved by the engine (group_collapse.h), against the exact rational
// N-body reference of the test support (reference.h), which steps through the impacts
// without resolving anything: the engine's impacts are the reference's, one by one; the
// reference's impact times converge, and their limit by Aitken's extrapolation of every
// P-th exact time (P the pattern's period) is the engine's collapse time (the engine's comes
// from iterating the period map in 100 digits, no code shared). The rest by hand: the group
// ends on its centre-of-mass line, x_cm(T) = sum m (x0 + v0 T) / M, at V = sum m v0 / M, and
// loses its kinetic energy about V, sum m v0^2 / 2 - M V^2 / 2. The scenes were found by
// exact simulation (Python fractions) of seeded starts: their last impacts repeat a pattern
// that covers every pair.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "collision_lab/core/nbody/engine.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

using reference::makeScene;
using reference::Rational;

/// The whole scene (no wall) collapses with impact pattern period `period`.
void expectWholeGroupCollapses(const Scene& s, std::size_t period, std::uint64_t reference_impacts) {
  EngineOptions options;
  options.keep_events = 100000;
  const SceneSimulation run = runEngine(s, options);
  ASSERT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  ASSERT_TRUE(run.collapsed) << run.stop_message;
  ASSERT_EQ(run.collapses.size(), 1u);
  EXPECT_EQ(run.collapses[0].first_body, 0u);
  EXPECT_EQ(run.collapses[0].last_body, s.size() - 1);
  EXPECT_EQ(run.collapses[0].impacts_before, run.impact_count);
  const reference::Run exact = reference::simulate(s, std::max<std::uint64_t>(reference_impacts, run.impact_count));
  ASSERT_TRUE(exact.truncated);  // the impacts do not stop
  for (std::size_t k = 0; k < run.impact_count; ++k) {
    ASSERT_EQ(run.impacts[k].pair_index, exact.events[k].pair) << "impact " << k + 1;
  }
  // The pattern repeats at the reference's end too.
  const auto& ev = exact.events;
  for (std::size_t k = ev.size() - 2 * period; k < ev.size(); ++k) ASSERT_EQ(ev[k].pair, ev[k - period].pair) << k;
  const double limit = reference::limitOfImpactTimes(exact, period);
  EXPECT_NEAR(*run.collapse_time, limit, 1e-9 * limit);
  EXPECT_LE(static_cast<double>(exact.events.back().time), *run.collapse_time * (1 + 1e-15));
  Rational mass = 0, momentum = 0, moment = 0, energy = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const Rational m(s.masses[k]), v(s.velocities[k]);
    mass += m, momentum += m * v, moment += m * Rational(s.positions[k]), energy += m * v * v / 2;
  }
  const Rational centre = momentum / mass;
  const double position = static_cast<double>((moment + momentum * Rational(limit)) / mass);
  EXPECT_NEAR(*run.collapse_position, position, 1e-9 * (1 + std::fabs(position)));
  for (double v : run.final_velocities) EXPECT_NEAR(v, static_cast<double>(centre), 1e-14);
  const double heat = static_cast<double>(energy - mass * centre * centre / 2);
  EXPECT_NEAR(run.energy_lost, heat, 1e-12 * heat);
  EXPECT_LE(static_cast<double>(exact.energy_lost), run.energy_lost * (1 + 1e-14));
}

TEST(GroupCollapse, FourEqualMassesPeriodEight) {
  expectWholeGroupCollapses(makeScene({1, 1, 1, 1}, {3.3, 2.0, 1.3, 0.0}, {-0.9, -0.2, 0.6, 0.5}, 0.15), 8, 400);
}

TEST(GroupCollapse, FourEqualMassesPeriodTwelve) {
  expectWholeGroupCollapses(makeScene({2, 2, 2, 2}, {3.3, 2.1, 0.9, 0.3}, {0.2, 0.7, 0.4, 0.7}, 0.1), 12, 400);
}

TEST(GroupCollapse, FiveEqualMassesPeriodNineteen) {
  expectWholeGroupCollapses(
      makeScene({1, 1, 1, 1, 1}, {3.8, 2.7, 2.2, 1.0, -0.1}, {-0.3, -0.4, 0.5, 1.0, 0.5}, 0.25), 19, 800);
}

TEST(GroupCollapse, FiveUnequalMassesPeriodEight) {
  expectWholeGroupCollapses(
      makeScene({2, 2, 3, 1, 2}, {4.1, 2.9, 1.7, 0.9, 0.3}, {-0.9, -0.4, 0.3, -0.1, 0.7}, 0.25), 8, 700);
}

TEST(GroupCollapse, FiveUnequalMassesPeriodTwentyTwo) {
  expectWholeGroupCollapses(
      makeScene({1, 2, 2, 1, 2}, {4.0, 3.3, 2.1, 0.8, 0.1}, {0.5, -0.1, 0.8, 0.9, 0.8}, 0.25), 22, 700);
}

// The engine goes on after the collapse: a fifth body (1 kg at x = -10 m, 1 m/s, e = 0.5
// on its pair) reaches the four-body cluster of FourEqualMassesPeriodEight (4 kg at
// V = 0 m/s, from x = 1.65 m after its collapse at 3.53 s) long after, and the cluster is hit
// as one body of 4 kg: by hand (physics.md), with V = (4 * 0 + 1 * 1) / 5 = 0.2 m/s, the
// cluster leaves at V + e m_b (v_b - v_c) / M = 0.2 + 0.5 * 1 * 1 / 5 = 0.3 m/s and the body
// at V - e m_c (v_b - v_c) / M = 0.2 - 0.5 * 4 * 1 / 5 = -0.2 m/s.
TEST(GroupCollapse, TheClusterGoesOnAndIsHitAsOneBody) {
  Scene s = makeScene({1, 1, 1, 1, 1}, {3.3, 2.0, 1.3, 0.0, -10.0}, {-0.9, -0.2, 0.6, 0.5, 1.0}, 0.15);
  s.restitution = {0.15, 0.15, 0.15, 0.5};
  const SceneSimulation run = runEngine(s);
  ASSERT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  ASSERT_EQ(run.collapses.size(), 1u) << run.stop_message;
  EXPECT_EQ(run.collapses[0].first_body, 0u);
  EXPECT_EQ(run.collapses[0].last_body, 3u);
  EXPECT_EQ(run.cluster_impacts, 1u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(run.final_velocities[k], 0.3, 1e-14);
  EXPECT_NEAR(run.final_velocities[4], -0.2, 1e-14);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
