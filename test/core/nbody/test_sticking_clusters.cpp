// Perfectly inelastic (e = 0) runs whose clusters grow past 9 bodies: an impact of a cluster
// reschedules pairs far apart (the cluster's two outer neighbours), and the run must go on
// from there exactly. Such runs used to throw a Rational division by zero (std::overflow_error)
// out of runEngine. Checked against hand-derived values and the exact rational reference.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "collision_lab/core/nbody/engine.h"
#include "engine_checks.h"
#include "granular_gas.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

/// Momentum [kg m/s] and kinetic energy [J] of velocities [m/s], summed here in long double.
struct Totals {
  long double momentum = 0, kinetic = 0;
};
Totals totals(const Scene& s, const std::vector<double>& velocities) {
  Totals t;
  for (std::size_t k = 0; k < s.size(); ++k) {
    t.momentum += static_cast<long double>(s.masses[k]) * velocities[k];
    t.kinetic += 0.5L * s.masses[k] * velocities[k] * velocities[k];
  }
  return t;
}

TEST(StickingClusters, SnowballOfEighteenBodiesByHand) {
  // 18 bodies of 1 kg, 1 m apart (body k at 17 - k m), body 0 at -1 m/s, the rest at rest,
  // e = 0: the smallest such snowball that used to throw (17 bodies did not). By hand:
  // impact i (pair i) is the cluster of bodies 0..i (i + 1 kg at -1/(i + 1) m/s, momentum
  // -1 kg m/s) sticking to body i + 1 at x = 16 - i m; the front closes each 1 m gap in
  // i + 1 s, so t_i = (i + 1)(i + 2)/2 s, and the new cluster moves at -1/(i + 2) m/s. Last:
  // pair 16 at 153 s, all at -1/18 m/s at x = 0; heat 1/2 - 1/36 = 17/36 J.
  constexpr std::size_t kBodies = 18;
  Scene s;
  for (std::size_t k = 0; k < kBodies; ++k) {
    s.masses.push_back(1.0);
    s.positions.push_back(static_cast<double>(kBodies - 1 - k));
    s.velocities.push_back(k == 0 ? -1.0 : 0.0);
  }
  s.restitution = {0.0};
  ASSERT_FALSE(validate(s));
  EngineOptions options;
  options.keep_events = kBodies;
  SceneSimulation run;
  ASSERT_NO_THROW(run = runEngine(s, options));
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  EXPECT_FALSE(run.truncated);
  ASSERT_EQ(run.impact_count, kBodies - 1) << run.stop_message;
  EXPECT_EQ(run.cluster_impacts, kBodies - 2);
  for (std::size_t i = 0; i + 1 < kBodies; ++i) {
    const ImpactRecord& r = run.impacts[i];
    const double t = 0.5 * static_cast<double>((i + 1) * (i + 2));
    EXPECT_EQ(r.pair_index, i);
    EXPECT_NEAR(r.time, t, 1e-12 * t) << "impact " << i;
    EXPECT_NEAR(r.position, 16.0 - static_cast<double>(i), 1e-12) << "impact " << i;
    EXPECT_EQ(r.first_moved, 0u);
    EXPECT_EQ(r.last_moved, i + 1);
    for (double v : r.velocities_after) EXPECT_NEAR(v, -1.0 / static_cast<double>(i + 2), 1e-15) << "impact " << i;
  }
  EXPECT_NEAR(run.final_time, 153.0, 153.0 * 1e-12);
  for (std::size_t k = 0; k < kBodies; ++k) {
    EXPECT_NEAR(run.final_velocities[k], -1.0 / 18, 1e-15) << "body " << k;
    EXPECT_NEAR(run.final_positions[k], 0.0, 1e-12) << "body " << k;
  }
  EXPECT_NEAR(run.energy_lost, 17.0 / 36, 1e-14);
}

TEST(StickingClusters, GranularGasesAgainstTheExactReference) {
  // Seeded gases at e = 0 (granular_gas.h) that used to throw, from 18 bodies (the smallest
  // that did) to 200 (the size of the gas that showed it). Every impact sticks two clusters
  // into one, so at most N - 1 impacts happen and the run finishes.
  struct Case {
    std::size_t bodies;
    std::uint64_t seed;
  };
  for (const Case& c : {Case{18, 2}, Case{18, 3}, Case{18, 4}, Case{40, 1}, Case{200, 5}}) {
    const Scene s = testing_support::granularGas(c.bodies, 0.0, c.seed);
    ASSERT_FALSE(validate(s));
    const std::string label = std::to_string(c.bodies) + " bodies, seed " + std::to_string(c.seed);
    SceneSimulation run;
    // The exact reference: the same count, pairs, times and final velocities.
    ASSERT_NO_THROW(run = testing_support::expectMatchesReference(s, c.bodies, label)) << label;
    const reference::Run exact = reference::simulate(s, c.bodies);
    EXPECT_EQ(run.stop, StopReason::kFinished) << label << ": " << run.stop_message;
    EXPECT_FALSE(run.truncated) << label;
    EXPECT_LT(run.impact_count, c.bodies) << label;
    // Momentum is kept; kinetic energy only goes into heat, at every impact.
    const Totals before = totals(s, s.velocities), after = totals(s, run.final_velocities);
    long double scale = 0;
    for (std::size_t k = 0; k < s.size(); ++k) scale += s.masses[k] * std::fabs(s.velocities[k]);
    EXPECT_LT(std::fabs(static_cast<double>((after.momentum - before.momentum) / scale)), 1e-14) << label;
    EXPECT_LT(run.momentum_relative_drift, 1e-14) << label;
    EXPECT_GT(run.energy_lost, 0.0) << label;
    EXPECT_LE(after.kinetic, before.kinetic) << label;
    EXPECT_LT(std::fabs(static_cast<double>((after.kinetic + run.energy_lost - before.kinetic) / before.kinetic)), 1e-12)
        << label;
    const double heat = static_cast<double>(exact.energy_lost);
    EXPECT_NEAR(run.energy_lost, heat, 1e-12 * heat) << label;
    for (const ImpactRecord& r : run.impacts) EXPECT_GT(r.energy_lost, 0.0) << label << ", impact " << r.index;
    // e = 0: the two sides of every pair that met move on as one (same velocity, same
    // place); every other pair has come to rest relative to, or moves away from, its neighbour.
    std::vector<char> met(s.size() - 1, 0);
    for (const ImpactRecord& r : run.impacts) met[r.pair_index] = 1;
    for (std::size_t p = 0; p + 1 < s.size(); ++p) {
      const double v = run.final_velocities[p], w = run.final_velocities[p + 1];
      const double x = run.final_positions[p], y = run.final_positions[p + 1];
      if (met[p]) {
        EXPECT_NEAR(v, w, 1e-15) << label << ", pair " << p;
        EXPECT_NEAR(x, y, 1e-12 * (1 + std::fabs(x))) << label << ", pair " << p;
      } else {
        EXPECT_GE(v, w) << label << ", pair " << p;
        EXPECT_GT(x, y) << label << ", pair " << p;
      }
    }
  }
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
