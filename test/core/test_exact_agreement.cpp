// The three-body run (planScene and runScene: the event engine) against exact rational arithmetic on the same doubles: the
// independent reference of rational_reference.h, which shares no code with core::exact.
// core::exact (the engine's own exact fallback) is tested against that reference too.
#include <gtest/gtest.h>

#include <optional>
#include <random>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <vector>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/scene_run.h"
#include "rational_reference.h"
#include "scenes.h"
#include "simulated_run.h"

namespace collision_lab {
namespace core {
namespace {

using testing_support::energyNormError;
using testing_support::kInf;
using testing_support::randomScene;
using testing_support::simulateThreeBodies;
using testing_support::SimulatedRun;

/// What the tests compare of a run, from the independent rational reference.
struct Truth {
  std::uint64_t collision_count = 0;
  std::vector<Pair> pairs;
  std::optional<Pair> first_pair;
  std::array<reference::Q, 3> final_velocities;
};

/// `with_positions` false: velocities only (reference::simulateVelocities), for long runs.
Truth truth(const Scene& scene, bool with_positions = true) {
  const reference::Run run = with_positions ? reference::simulate(scene, 100000)
                                            : reference::simulateVelocities(scene, 100000);
  EXPECT_FALSE(run.truncated);
  Truth truth;
  truth.collision_count = run.impacts.size();
  for (const reference::Impact& impact : run.impacts) truth.pairs.push_back(impact.pair);
  if (!run.impacts.empty()) truth.first_pair = run.impacts.front().pair;
  truth.final_velocities = run.final_velocities;
  return truth;
}

struct Observed {
  testing_support::SimulatedRun result;
  std::vector<Pair> pairs;
};

/// The run with every impact visited (the engine's decisions).
Observed run(const Scene& scene, std::uint64_t max_collisions = 10'000'000) {
  Observed observed;
  observed.result = simulateThreeBodies(scene, EventPolicy::none(), max_collisions, [&](const testing_support::ThreeBodyImpact& e) {
                      observed.pairs.push_back(e.pair);
                    });
  return observed;
}

/// The count-only run: no event published.
testing_support::SimulatedRun countOnly(const Scene& scene) { return simulateThreeBodies(scene); }

void expectMatchesExact(const Scene& scene, double tolerance = 1e-13, bool with_positions = true) {
  const Truth reference = truth(scene, with_positions);
  const Observed observed = run(scene);
  EXPECT_EQ(observed.result.summary.impact_count, reference.collision_count);
  EXPECT_EQ(observed.pairs, reference.pairs);
  EXPECT_EQ(observed.pairs.empty() ? std::nullopt : std::optional<Pair>(observed.pairs.front()), reference.first_pair);
  EXPECT_LE(energyNormError(scene, observed.result.final_velocities, reference.final_velocities), tolerance);
  // Count-only mode must agree too.
  EXPECT_EQ(countOnly(scene).summary.impact_count, reference.collision_count);
  EXPECT_EQ(predictedImpactCount(scene), reference.collision_count);
}

TEST(ExactAgreement, ThousandSeededRandomScenes) {
  std::mt19937_64 rng(20261122);
  int with_collisions = 0, bc_first = 0, walls = 0;
  for (int i = 0; i < 1000; ++i) {
    const Scene scene = randomScene(rng);
    SCOPED_TRACE(::testing::Message() << "scene " << i);
    expectMatchesExact(scene, 1e-12);
    const auto first = firstPair(scene);
    with_collisions += first.has_value();
    bc_first += first == Pair::BC;
    walls += wallIndex(scene) >= 0;
  }
  // The sample really covers the branches.
  EXPECT_GT(with_collisions, 500);
  EXPECT_GT(bc_first, 100);
  EXPECT_GT(walls, 100);
}

// core::exact, which the engine trusts for its hard decisions, against the reference:
// the same pairs and exactly the same final velocities.
TEST(ExactAgreement, CoreExactEqualsTheIndependentReference) {
  std::mt19937_64 rng(20261126);
  for (int i = 0; i < 300; ++i) {
    const Scene scene = randomScene(rng, i < 250 ? 1.0 : 2.5);
    SCOPED_TRACE(::testing::Message() << "scene " << i);
    const exact::MapWalk run = exact::walkVelocityMaps(scene, 100000);
    const Truth reference = truth(scene);
    ASSERT_FALSE(run.truncated);
    EXPECT_EQ(run.impact_count, reference.collision_count);
    EXPECT_EQ(run.pairs, reference.pairs);
    EXPECT_EQ(run.first_pair, reference.first_pair);
    EXPECT_EQ(run.final_velocities, reference.final_velocities);
    const auto& v = scene.velocities;
    const bool both_approach = v[kA] < v[kB] && v[kB] < v[kC];
    if (both_approach) {
      EXPECT_EQ(exact::compareFirstContactTimes(scene) < 0 ? Pair::AB : Pair::BC, *reference.first_pair);
    }
  }
}

TEST(ExactAgreement, WideMassRatiosWithLongerRuns) {
  std::mt19937_64 rng(31);
  for (int i = 0; i < 25; ++i) {
    const Scene scene = randomScene(rng, 2.5);
    SCOPED_TRACE(::testing::Message() << "scene " << i);
    // Exact positions over these runs would take seconds; the velocities decide the pairs.
    expectMatchesExact(scene, 1e-12, false);
  }
}

TEST(ExactAgreement, KaleidoscopicMassesGrazeAtTheEnd) {
  // pi / alpha is an integer (3, 4, 6); from v = (-1, 0, 0) the last contact grazes.
  const std::vector<std::pair<std::array<double, 3>, std::uint64_t>> cases = {
      {{1, 1, 1}, 2}, {{2, 1, 3}, 3}, {{5, 1, 9}, 5}};
  for (const auto& [masses, expected] : cases) {
    const Scene scene = threeBodies(masses, {2, 1, 0}, {-1, 0, 0});
    EXPECT_EQ(run(scene).result.summary.impact_count, expected);
    EXPECT_EQ(predictedImpactCount(scene), expected);
    expectMatchesExact(scene);
  }
}

TEST(ExactAgreement, GrazingEndsWithEqualVelocities) {
  const Scene scene{{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}};
  const Observed observed = run(scene);
  EXPECT_EQ(observed.result.summary.impact_count, 2u);
  const auto& v = observed.result.final_velocities;
  EXPECT_EQ(v[kA], v[kB]);  // exactly
  // The summary comes from the known count, which needs no decision; the engine, which
  // publishes the events, decides the grazing contact in exact rationals.
  EXPECT_EQ(observed.result.summary.escalations.exact_rational, 0u);
  const SceneSimulation engine = runEngine(scene);
  EXPECT_GE(engine.escalations.exact_rational, 1u);
  EXPECT_EQ(engine.final_velocities[kA], engine.final_velocities[kB]);  // it adopted the exact state
  expectMatchesExact(scene);
}

TEST(ExactAgreement, NearTripleCollisionsPickTheExactFirstPair) {
  // t_AB and t_BC differ in the last bits of the positions or velocities.
  for (int ulps = -3; ulps <= 3; ++ulps) {
    if (ulps == 0) continue;
    double x_a = 1.0;
    for (int i = 0; i < std::abs(ulps); ++i) x_a = std::nextafter(x_a, ulps > 0 ? 2.0 : 0.0);
    for (const auto& masses : {std::array<double, 3>{1, 1, 1}, std::array<double, 3>{3, 1, 7}}) {
      const Scene scene = threeBodies(masses, {x_a, 0.0, -1.0}, {-1.0, 0.0, 1.0});
      ASSERT_FALSE(validate(scene));
      const Pair expected = ulps > 0 ? Pair::BC : Pair::AB;
      EXPECT_EQ(firstPair(scene), expected) << ulps;
      expectMatchesExact(scene);
    }
  }
  // Products that round to equal in double but differ exactly.
  const Scene rounded{{1, 2, 3}, {0.3, 0.2, 0.1}, {-0.1, 0.0, 0.1}};
  ASSERT_FALSE(validate(rounded));
  const reference::Run first = reference::simulate(rounded, 1);
  ASSERT_EQ(first.impacts.size(), 1u);
  EXPECT_EQ(firstPair(rounded), first.impacts.front().pair);
  expectMatchesExact(rounded);
}

TEST(ExactAgreement, ExtremeScalesDoNotOverflow) {
  for (double scale : {1e-150, 1e150}) {
    const Scene masses_scaled{{2 * scale, scale, 3 * scale}, {2, 1, 0}, {-1, 0.25, 1}};
    expectMatchesExact(masses_scaled);
    const Scene speeds_scaled{{2, 1, 3}, {2 * scale, scale, 0}, {-scale, 0.25 * scale, scale}};
    expectMatchesExact(speeds_scaled);
  }
}

TEST(ExactAgreement, SubnormalVelocityDifferences) {
  // Found by the fuzzer: rounding is not relative down here.
  const Scene scene{{1, 2, 0.26542376078465163}, {3e-16, 2e-16, 1.5e-16}, {-5e-324, 0, 5e-324}};
  ASSERT_FALSE(validate(scene));
  expectMatchesExact(scene);
}

TEST(ExactAgreement, AFeatherweightCarriesAllTheRelativeMotion) {
  // Found by the fuzzer: A and B share a velocity and C, far lighter, carries all the
  // relative motion, below the rounding of the centre-of-mass velocity in double (and,
  // at 1e-99, in 50 digits too).
  for (double light : {1e-30, 1e-90, 1e-99}) {
    const Scene scene{{5, 1, light}, {2, 1, 0}, {-0.1, -0.1, 0}};
    ASSERT_FALSE(validate(scene));
    expectMatchesExact(scene);
  }
}

TEST(ExactAgreement, WallsMovingAndResting) {
  expectMatchesExact(Scene{{kInf, 1, 3}, {2, 1, 0}, {0.25, 0, 1}});
  expectMatchesExact(Scene{{3, 1, kInf}, {2, 1, 0}, {-1, 0.5, -0.125}});
}

TEST(Conservation, EnergyAndMomentumOverLongRuns) {
  for (const Scene& scene : {Scene{{1e6, 1, 1e6}, {2, 1, 0}, {-1, 0, 0}}, Scene{{1e8, 3, 1e9}, {2, 1, 0}, {-1, 0.5, 0.25}}}) {
    const testing_support::SimulatedRun result = countOnly(scene);
    EXPECT_GT(result.summary.impact_count, 1000u);
    EXPECT_LE(result.summary.energy_relative_drift, 1e-12);
    EXPECT_LE(result.summary.momentum_relative_drift, 1e-12);
  }
  // Every event's running totals stay on the initial values.
  const Scene scene{{1, 2, 3}, {2, 1, 0}, {-1, 0.3, 0.7}};
  const double energy = 0.5 * (1 * 1 + 2 * 0.09 + 3 * 0.49);
  const double momentum = -1 + 2 * 0.3 + 3 * 0.7;
  const SimulatedRun result = simulateThreeBodies(scene, EventPolicy::all());
  ASSERT_FALSE(result.events.empty());
  for (const testing_support::ThreeBodyImpact& e : result.events) {
    EXPECT_NEAR(e.total_energy, energy, 1e-14);
    EXPECT_NEAR(e.total_momentum, momentum, 1e-14);
    EXPECT_NEAR(e.energy_transfer[0] + e.energy_transfer[1] + e.energy_transfer[2], 0.0, 1e-14);
  }
}

TEST(Events, PoliciesCapsAndTimes) {
  const Scene scene{{100, 1, kInf}, {3, 2, 0}, {-1, 0, 0}};
  std::uint64_t visited = 0;
  const SimulatedRun first5 =
      simulateThreeBodies(scene, EventPolicy::firstN(5), 10'000'000, [&](const testing_support::ThreeBodyImpact&) { ++visited; });
  EXPECT_EQ(first5.summary.impact_count, 31u);
  EXPECT_EQ(visited, 31u);
  ASSERT_EQ(first5.events.size(), 5u);
  // First impact: A (x = 3, v = -1) reaches B (x = 2, at rest) at t = 1, x = 2.
  EXPECT_EQ(first5.events[0].pair, Pair::AB);
  EXPECT_DOUBLE_EQ(first5.events[0].time, 1.0);
  EXPECT_DOUBLE_EQ(first5.events[0].position, 2.0);
  // Times increase; contacts with the wall happen at the wall.
  for (std::size_t i = 1; i < first5.events.size(); ++i) EXPECT_GT(first5.events[i].time, first5.events[i - 1].time);
  EXPECT_DOUBLE_EQ(first5.events[1].position, 0.0);

  const SimulatedRun capped = simulateThreeBodies(scene, EventPolicy::none(), 10);
  EXPECT_TRUE(capped.summary.truncated);
  EXPECT_EQ(capped.summary.impact_count, 10u);
  EXPECT_TRUE(capped.events.empty());
  // Exactly the count is not truncation.
  EXPECT_FALSE(simulateThreeBodies(scene, EventPolicy::none(), 31).summary.truncated);
}

TEST(PiDigits, BySimulation) {
  const std::vector<std::pair<double, std::uint64_t>> digits = {{1e2, 31}, {1e4, 314}, {1e6, 3141}, {1e8, 31415}};
  for (const auto& [ratio, expected] : digits) {
    const Scene scene{{ratio, 1, kInf}, {2, 1, 0}, {-1, 0, 0}};
    EXPECT_EQ(countOnly(scene).summary.impact_count, expected);
    EXPECT_EQ(predictedImpactCount(scene), expected);
  }
  const Scene small{{1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}};
  expectMatchesExact(small);
  // 3141 impacts with a light body 1000 times faster at its peak than at the end.
  const Scene pi_1e6{{1e6, 1, kInf}, {2, 1, 0}, {-1, 0, 0}};
  const AnalyticModel<HighPrecision> closed_form(pi_1e6);  // 50 digits
  const auto exact = closed_form.velocitiesAfter(3141);
  const testing_support::SimulatedRun fast = countOnly(pi_1e6);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(fast.final_velocities[i], static_cast<double>(exact(i)), 1e-12) << i;
}

/// Reference for long runs that shares no code with the engine or AnalyticModel: the
/// textbook impact rule v_l' = ((m_l - m_r) v_l + 2 m_r v_r) / (m_l + m_r) applied at 50
/// digits, pair after pair, while the next pair approaches (the pairs alternate after the
/// first impact, physics.md). Finite masses, AB first. Rounding grows like sqrt(count) ulps
/// of 1e-50: far below the 1e-12 asserted.
struct FiftyDigitRun {
  std::uint64_t count = 0;
  std::array<double, 3> final_velocities{};
};

FiftyDigitRun fiftyDigitLoop(const Scene& scene) {
  using Fifty = boost::multiprecision::cpp_bin_float_50;
  std::array<Fifty, 3> m, v;
  for (int i = 0; i < 3; ++i) {
    m[i] = scene.masses[i];
    v[i] = scene.velocities[i];
  }
  // Coefficients of the impact rule for pair (l, r) = (A, B) and (B, C).
  const auto coefficients = [&](int l, int r) {
    const Fifty total = m[l] + m[r];
    return std::array<Fifty, 4>{(m[l] - m[r]) / total, 2 * m[r] / total, 2 * m[l] / total, (m[r] - m[l]) / total};
  };
  const std::array<std::array<Fifty, 4>, 2> c{coefficients(0, 1), coefficients(1, 2)};
  FiftyDigitRun run;
  for (int pair = 0; v[pair] < v[pair + 1]; pair = 1 - pair) {
    const Fifty left = v[pair], right = v[pair + 1];
    v[pair] = c[pair][0] * left + c[pair][1] * right;
    v[pair + 1] = c[pair][2] * left + c[pair][3] * right;
    ++run.count;
  }
  for (int i = 0; i < 3; ++i) run.final_velocities[i] = static_cast<double>(v[i]);
  return run;
}

TEST(HeavyLightHeavy, MillionsOfCollisionsStayAccurate) {
  const Scene scene{{1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0}};
  const testing_support::SimulatedRun fast = countOnly(scene);
  const FiftyDigitRun reference = fiftyDigitLoop(scene);
  EXPECT_EQ(reference.count, 2221441u);  // physics.md, hard cases
  EXPECT_EQ(fast.summary.impact_count, reference.count);
  std::array<reference::Q, 3> reference_state;
  for (int i = 0; i < 3; ++i) reference_state[i] = reference::Q(reference.final_velocities[i]);
  EXPECT_LE(energyNormError(scene, fast.final_velocities, reference_state), 1e-12);
  // Each component too, the light body's included, although it peaks at ~1e6 m/s.
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(fast.final_velocities[i], reference.final_velocities[i], 1e-12) << i;
  EXPECT_LE(fast.summary.energy_relative_drift, 1e-12);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
