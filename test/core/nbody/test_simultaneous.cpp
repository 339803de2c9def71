// Simultaneous impacts of disjoint pairs (engine.h: all performed, in pair order) and the
// precision tiers: an exact tie goes from double-double straight to the exact tier, and a
// later replay of the 100-digit tier must still agree with it. Checked against hand-derived
// numbers and the exact rational reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <string>

#include "collision_lab/core/nbody/engine.h"
#include "engine_checks.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

using testing_support::expectMatchesReference;

/// Four equal masses closing in symmetrically: AB and CD meet at the same instant, then BC.
Scene fourSymmetric() { return Scene{{1, 1, 1, 1}, {3, 2, 1, 0}, {-1, 0, 0, 1}, {0.05}}; }

TEST(SimultaneousImpacts, FourEqualMassesHandDerived) {
  // By hand, with e = 1/20 (the double 0.05 differs by 3e-18 relative). Equal masses: the
  // centre velocity V = (v_i + v_j) / 2, then v_i' = V - e (v_i - v_j) / 2, v_j' = V + e (v_i - v_j) / 2.
  //  1, 2: AB and CD at t = 1 (gap 1 m, approach 1 m/s): v = (-0.475, -0.525, 0.525, 0.475).
  //  3: BC, gap 1 m closing at 1.05 m/s: t = 1 + d, d = 1/1.05, x = 1.5; v_B = 0.02625 = -v_C.
  //  4, 5: AB (gap 0.05 d, closing at 0.50125 m/s) and, mirrored, CD at t = 1 + d + 0.05 d / 0.50125;
  //     AB: V = -0.224375, v_A' = V + 0.01253125 = -0.21184375, v_B' = -0.23690625.
  //  6: BC again at x = 1.5: B and C drifted apart at 0.02625 m/s each from t3 to t4 and now
  //     close at 0.23690625 m/s each, so t6 = t4 + 0.02625 (t4 - t3) / 0.23690625.
  const double d = 1 / 1.05, t3 = 1 + d, t4 = t3 + 0.05 * d / 0.50125;
  const double t6 = t4 + 0.02625 * (t4 - t3) / 0.23690625;
  EngineOptions options;
  options.max_impacts = 60;
  options.keep_events = 60;
  const SceneSimulation run = runEngine(fourSymmetric(), options);
  ASSERT_NE(run.stop, StopReason::kInternalError) << run.stop_message;
  ASSERT_GE(run.impacts.size(), 6u) << run.stop_message;
  const std::size_t pairs[] = {0, 2, 1, 0, 2, 1};
  const double times[] = {1, 1, t3, t4, t4, t6};
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_EQ(run.impacts[k].pair_index, pairs[k]) << "impact " << k + 1;
    EXPECT_NEAR(run.impacts[k].time, times[k], 1e-14 * times[k]) << "impact " << k + 1;
  }
  EXPECT_NEAR(run.impacts[2].position, 1.5, 1e-15);
  EXPECT_NEAR(run.impacts[5].position, 1.5, 1e-15);
  EXPECT_NEAR(run.impacts[3].velocities_after[0], -0.21184375, 1e-15);
  EXPECT_NEAR(run.impacts[3].velocities_after[1], -0.23690625, 1e-15);
  EXPECT_NEAR(run.impacts[4].velocities_after[0], 0.23690625, 1e-15);
  EXPECT_NEAR(run.impacts[4].velocities_after[1], 0.21184375, 1e-15);
  // The impacts go on towards a collapse of all four (not resolved for four bodies): the cap.
  EXPECT_EQ(run.stop, StopReason::kCap) << run.stop_message;
  EXPECT_EQ(run.impact_count, 60u);
}

TEST(SimultaneousImpacts, FourEqualMassesAgreeWithReference) {
  for (double e : {0.0, 0.05, 0.5, 1.0}) {
    Scene scene = fourSymmetric();
    scene.restitution = {e};
    const std::string label = "e = " + std::to_string(e);
    const reference::Run exact = reference::simulate(scene, 60);
    ASSERT_GE(exact.events.size(), 2u) << label;
    EXPECT_EQ(exact.events[0].time, exact.events[1].time) << label;  // AB and CD at once
    expectMatchesReference(scene, 60, label);
  }
}

TEST(SimultaneousImpacts, CollapseLeavesAnExactlyZeroApproach) {
  // D, E, F (x = 3, 1, 0 m; v = -2, 0, 2 m/s; total momentum 0) collapse at their centre
  // x = 4/3 m and then rest, exactly as C (x = 4 m) does: pair CD's approach speed is exactly
  // 0, which the exact tier must decide (no impact). B (v = 1 m/s) reaches A at t = 3 s, x = 8 m;
  // e = 0.05: v_A' = 0.5 + 0.05 / 2, v_B' = 0.5 - 0.05 / 2. Heat: all 4 J of DEF, and AB's
  // (1 - e^2) (1/2) 1^2 / 2 = 0.249375 J.
  const Scene scene{{1, 1, 1, 1, 1, 1}, {8, 5, 4, 3, 1, 0}, {0, 1, 0, -2, 0, 2}, {0.05}};
  const SceneSimulation run = expectMatchesReference(scene, 60, "DEF collapse");
  ASSERT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  ASSERT_EQ(run.collapses.size(), 1u);
  EXPECT_EQ(run.collapses[0].first_body, 3u);
  EXPECT_EQ(run.collapses[0].last_body, 5u);
  EXPECT_NEAR(run.collapses[0].position, 4.0 / 3, 1e-12);
  EXPECT_EQ(run.collapses[0].velocity, 0.0);
  EXPECT_EQ(run.impact_count, run.collapses[0].impacts_before + 1);
  EXPECT_EQ(run.impacts.back().pair_index, 0u);
  EXPECT_NEAR(run.impacts.back().time, 3.0, 1e-15);
  const double expected[] = {0.525, 0.475, 0, 0, 0, 0};
  for (std::size_t k = 0; k < 6; ++k) EXPECT_NEAR(run.final_velocities[k], expected[k], 1e-15) << "body " << k;
  EXPECT_NEAR(run.energy_lost, 4.249375, 1e-14);
}

/// A scene built to have impacts of disjoint pairs at the same instant: small integer gaps
/// [m] and velocities [m/s]; when `mirrored`, symmetric about its centre (x_k = -x_{n-1-k}
/// after a shift, v_k = -v_{n-1-k}, m_k = m_{n-1-k}), with walls at both ends one time in
/// four. Masses [kg] all 1 one time in two, else integers 1..3. One restitution e for every
/// pair. Invalid draws (a first contact of three) are drawn again.
Scene tieScene(std::mt19937_64& rng, std::size_t n, bool mirrored, double e) {
  std::uniform_int_distribution<int> gap(1, 3), speed(-2, 2), mass(1, 3), walls(0, 3), coin(0, 1);
  while (true) {
    const bool equal = coin(rng) == 0;
    Scene scene;
    scene.masses.assign(n, 1.0);
    scene.positions.assign(n, 0.0);
    scene.velocities.assign(n, 0.0);
    scene.restitution = {e};
    std::vector<int> gaps(n - 1);
    for (std::size_t k = 0; k + 1 < n; ++k) gaps[k] = mirrored && 2 * k + 2 > n ? gaps[n - 2 - k] : gap(rng);
    for (std::size_t k = n - 1; k-- > 0;) scene.positions[k] = scene.positions[k + 1] + gaps[k];
    for (std::size_t k = 0; k < n; ++k) {
      const bool image = mirrored && 2 * k + 1 > n;  // the mirror image of body n-1-k
      scene.velocities[k] = image ? -scene.velocities[n - 1 - k] : (mirrored && 2 * k + 1 == n ? 0 : speed(rng));
      scene.masses[k] = image ? scene.masses[n - 1 - k] : (equal ? 1.0 : mass(rng));
    }
    if (mirrored && walls(rng) == 0) {
      for (std::size_t k : {std::size_t{0}, n - 1}) {
        scene.masses[k] = std::numeric_limits<double>::infinity();
        scene.velocities[k] = 0.0;
      }
    }
    if (!validate(scene)) return scene;
  }
}

/// Two impacts in a row at exactly the same time (disjoint pairs, necessarily).
bool hasSimultaneous(const reference::Run& exact) {
  for (std::size_t k = 0; k + 1 < exact.events.size(); ++k) {
    if (exact.events[k].time == exact.events[k + 1].time) return true;
  }
  return false;
}

TEST(SimultaneousImpacts, SeededSweepAgreesWithReference) {
  std::mt19937_64 rng(20240917);
  const double restitutions[] = {0.0, 0.05, 0.5, 1.0};
  constexpr std::uint64_t kCap = 40;
  int simultaneous = 0, both_tiers = 0, multiple = 0, collapsed = 0, walls = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t n = 3 + trial % 6;             // 3..8 bodies
    const double e = restitutions[(trial / 6) % 4];  // each n with each e
    const bool mirrored = (trial / 24) % 2 == 0;     // each (n, e) both ways
    const Scene scene = tieScene(rng, n, mirrored, e);
    const std::string label = "scene " + std::to_string(trial) + ", n = " + std::to_string(n) + ", e = " + std::to_string(e);
    const SceneSimulation run = expectMatchesReference(scene, kCap, label);
    const reference::Run exact = reference::simulate(scene, kCap);
    // Disjoint pairs at one instant go in pair order (engine.h).
    const std::size_t shared = std::min(run.impacts.size(), exact.events.size());
    for (std::size_t k = 0; k + 1 < shared; ++k) {
      if (exact.events[k].time != exact.events[k + 1].time) continue;
      EXPECT_LT(run.impacts[k].pair_index, run.impacts[k + 1].pair_index) << label << ", impact " << k + 1;
    }
    simultaneous += hasSimultaneous(exact);
    both_tiers += run.escalations.high_precision > 0 && run.escalations.exact_rational > 0;
    multiple += run.multiple_collision.has_value();
    collapsed += run.collapsed;
    walls += scene.wallCount() > 0;
  }
  // The sample has what it is built for: simultaneous disjoint impacts, runs that use both
  // the 100-digit and the exact tier (the disagreement this guards against), and the other
  // endings near them.
  EXPECT_GT(simultaneous, 120);
  EXPECT_GT(both_tiers, 10);
  EXPECT_GT(multiple, 40);
  EXPECT_GT(collapsed, 20);
  EXPECT_GT(walls, 40);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
