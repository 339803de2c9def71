// Issue 32: the engine covers the double range. Each run takes place in working units, an
// exact power-of-two change of units chosen from the scene (src/core/nbody/units.h), so
// impacts after 2^900 s, or far out in metres, run to the end; only what a double cannot
// hold stops a run, truncated and saying why. Against the exact rational reference.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "collision_lab/core/scene_run.h"
#include "../simulated_run.h"
#include "collision_lab/core/nbody/engine.h"
#include "engine_checks.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

constexpr double k2To900 = 0x1p900;

/// Every event's time and position, and the final velocities, within 2^-42 of the exact
/// values (the engine's published time precision; its velocities are closer still).
void expectCloseToReference(const Scene& scene, const SceneSimulation& run, const reference::Run& exact,
                            const std::string& label) {
  ASSERT_EQ(run.impacts.size(), exact.events.size()) << label << ": " << run.stop_message;
  for (std::size_t k = 0; k < exact.events.size(); ++k) {
    const double t = static_cast<double>(exact.events[k].time);
    const double x = static_cast<double>(exact.events[k].position);
    EXPECT_EQ(run.impacts[k].pair_index, exact.events[k].pair) << label << ", impact " << k + 1;
    EXPECT_NEAR(run.impacts[k].time, t, 0x1p-42 * std::fabs(t)) << label << ", impact " << k + 1;
    EXPECT_NEAR(run.impacts[k].position, x, 0x1p-42 * std::fabs(x) + 1e-300) << label << ", impact " << k + 1;
  }
  ASSERT_EQ(run.final_velocities.size(), exact.velocities.size());
  for (std::size_t i = 0; i < exact.velocities.size(); ++i) {
    const double v = static_cast<double>(exact.velocities[i]);
    EXPECT_NEAR(run.final_velocities[i], v, 0x1p-50 * std::fabs(v)) << label << ", body " << i;
  }
  EXPECT_LE(reference::energyNormError(scene, run.final_velocities, exact.velocities), 1e-15) << label;
}

SceneSimulation runKeepingEvents(const Scene& scene, std::uint64_t cap = 1000) {
  EngineOptions options;
  options.max_impacts = cap;
  options.keep_events = cap;
  return runEngine(scene, options);
}

// The chain (--positions 1,0,-1e210,-2e210): its later impacts come after 2^900 s.
// It used to stop at once, OUT_OF_RANGE and not truncated.
TEST(WideRange, AFourBodyChainWithImpactsAfter2To900SecondsRunsToTheEnd) {
  const Scene scene = reference::makeScene({1, 2, 3, 4}, {1, 0, -1e210, -2e210}, {-1e-61, 0, 1e-61, 2e-61}, 1.0);
  ASSERT_FALSE(validate(scene)) << validate(scene)->message;
  const reference::Run exact = reference::simulate(scene, 1000);
  ASSERT_FALSE(exact.truncated);
  ASSERT_EQ(exact.events.size(), 6u);
  ASSERT_GT(static_cast<double>(exact.events.back().time), k2To900);  // the premise
  const SceneSimulation run = runKeepingEvents(scene);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  EXPECT_FALSE(run.truncated);
  EXPECT_EQ(run.impact_count, 6u);
  expectCloseToReference(scene, run, exact, "chain");
  const double last = static_cast<double>(exact.last_time);
  EXPECT_NEAR(run.final_time, last, 0x1p-42 * last);
  EXPECT_LE(run.energy_relative_drift, 1e-15);
}

// A pair whose approach would end only far beyond 2^900 s (C and D creep at 1e-300 m/s
// across 1e210 m) waits, parked; the impacts before it run, and here it never comes. It
// used to stop the run at once, OUT_OF_RANGE.
TEST(WideRange, APairApproachingBeyondTheRangeDoesNotStopTheImpactsBeforeIt) {
  const Scene scene = reference::makeScene({1, 2, 3, 4}, {1, 0, -1e210, -2e210}, {-1, 0, 1e-300, 2e-300}, 1.0);
  ASSERT_FALSE(validate(scene)) << validate(scene)->message;
  const reference::Run exact = reference::simulate(scene, 1000);
  ASSERT_FALSE(exact.truncated);
  const SceneSimulation run = runKeepingEvents(scene);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  EXPECT_EQ(run.impact_count, exact.events.size());
  expectCloseToReference(scene, run, exact, "creeping pair");
}

// The same chain inelastic (e = 0.5), so the heat is scaled back too.
TEST(WideRange, AnInelasticChainAfter2To900SecondsKeepsItsHeat) {
  const Scene scene = reference::makeScene({1, 2, 3, 4}, {1, 0, -1e210, -2e210}, {-1e-61, 0, 1e-61, 2e-61}, 0.5);
  const reference::Run exact = reference::simulate(scene, 1000);
  ASSERT_FALSE(exact.truncated);
  const SceneSimulation run = runKeepingEvents(scene);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  ASSERT_EQ(run.impacts.size(), exact.events.size()) << run.stop_message;
  expectCloseToReference(scene, run, exact, "inelastic chain");
  const double lost = static_cast<double>(exact.energy_lost);
  EXPECT_NEAR(run.energy_lost, lost, 1e-14 * lost);
  for (std::size_t k = 0; k < exact.events.size(); ++k) {
    const double heat = static_cast<double>(exact.events[k].lost);
    EXPECT_NEAR(run.impacts[k].energy_lost, heat, 1e-14 * heat) << "impact " << k + 1;
  }
}

// Three bodies, the pi billiard (100, 1, wall): 31 impacts whatever the scale; here at
// 1e210 m and 1e-61 m/s, so that they come after 2^900 s. By the engine, and by the lab
// run of three bodies, which now runs it in the engine as well.
TEST(WideRange, AThreeBodyChainAfter2To900SecondsKeepsItsCount) {
  const double kWall = std::numeric_limits<double>::infinity();
  const Scene scene = reference::makeScene({100, 1, kWall}, {2e210, 1e210, 0}, {-1e-61, 0, 0}, 1.0);
  const reference::Run exact = reference::simulate(scene, 1000);
  ASSERT_EQ(exact.events.size(), 31u);
  ASSERT_GT(static_cast<double>(exact.events.back().time), k2To900);
  const SceneSimulation run = runKeepingEvents(scene);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  EXPECT_EQ(run.impact_count, 31u);
  expectCloseToReference(scene, run, exact, "pi billiard");

  const Scene three{{100, 1, kWall}, {2e210, 1e210, 0}, {-1e-61, 0, 0}};
  const SceneSimulation lab = testing_support::runPlanned(three, RunOptions{}).simulation;
  EXPECT_EQ(lab.impact_count, 31u);
  EXPECT_FALSE(lab.truncated) << lab.stop_message;
  ASSERT_EQ(lab.impacts.size(), 31u);
  for (std::size_t k = 0; k < 31; ++k) {
    const double t = static_cast<double>(exact.events[k].time);
    EXPECT_NEAR(lab.impacts[k].time, t, 0x1p-42 * t) << "impact " << k + 1;
  }
  for (int i = 0; i < 2; ++i) {
    const double v = static_cast<double>(exact.velocities[i]);
    EXPECT_NEAR(lab.final_velocities[i], v, 0x1p-50 * std::fabs(v)) << "body " << i;
  }
}

/// `scene` with lengths times 2^length and velocities times 2^velocity (times then scale
/// by 2^(length - velocity)), and its model's parameter with them.
Scene rescaled(Scene scene, int length, int velocity) {
  for (double& x : scene.positions) x = std::ldexp(x, length);
  for (double& v : scene.velocities) v = std::ldexp(v, velocity);
  scene.ring = std::ldexp(scene.ring, length);
  RestitutionModel& model = scene.restitution_model;
  model.tc = std::ldexp(model.tc, length - velocity);
  model.elastic_below = std::ldexp(model.elastic_below, velocity);
  model.viscoelastic_speed = std::ldexp(model.viscoelastic_speed, velocity);
  return scene;
}

/// The run of `scene` far out in the double range is the run near 1, value for value: the
/// change of units is exact and changes no rounding, for the restitution models too.
void expectSameRunAtAnyScale(const Scene& scene, const std::string& label) {
  ASSERT_FALSE(validate(scene)) << label << ": " << validate(scene)->message;
  const SceneSimulation near_one = runKeepingEvents(scene, 400);
  ASSERT_GT(near_one.impact_count, 3u) << label;
  const int length = 600, velocity = -300;  // times 2^900: past 2^900 from 1 s on
  const Scene far = rescaled(scene, length, velocity);
  ASSERT_FALSE(validate(far)) << label << ": " << validate(far)->message;
  const SceneSimulation run = runKeepingEvents(far, 400);
  EXPECT_EQ(run.stop, near_one.stop) << label << ": " << run.stop_message;
  EXPECT_EQ(run.truncated, near_one.truncated) << label;
  ASSERT_EQ(run.impact_count, near_one.impact_count) << label << ": " << run.stop_message;
  EXPECT_EQ(run.rule_elastic_impacts, near_one.rule_elastic_impacts) << label;
  for (std::size_t k = 0; k < run.impacts.size(); ++k) {
    const ImpactRecord& a = run.impacts[k];
    const ImpactRecord& b = near_one.impacts[k];
    ASSERT_EQ(a.pair_index, b.pair_index) << label << ", impact " << k + 1;
    EXPECT_EQ(a.time, std::ldexp(b.time, length - velocity)) << label << ", impact " << k + 1;
    EXPECT_EQ(a.position, std::ldexp(b.position, length)) << label << ", impact " << k + 1;
    for (int side = 0; side < 2; ++side) {
      EXPECT_EQ(a.velocities_after[side], std::ldexp(b.velocities_after[side], velocity)) << label << ", impact " << k + 1;
      EXPECT_EQ(a.energy_gained[side], std::ldexp(b.energy_gained[side], 2 * velocity)) << label << ", impact " << k + 1;
    }
    EXPECT_EQ(a.energy_lost, std::ldexp(b.energy_lost, 2 * velocity)) << label << ", impact " << k + 1;
  }
  for (std::size_t i = 0; i < scene.size(); ++i) {
    EXPECT_EQ(run.final_velocities[i], std::ldexp(near_one.final_velocities[i], velocity)) << label << ", body " << i;
  }
  EXPECT_EQ(run.final_time, std::ldexp(near_one.final_time, length - velocity)) << label;
  EXPECT_EQ(run.energy_lost, std::ldexp(near_one.energy_lost, 2 * velocity)) << label;
}

TEST(WideRange, EveryRestitutionModelRunsTheSameFarOutInTheDoubleRange) {
  const double kWall = std::numeric_limits<double>::infinity();
  Scene box = reference::makeScene({kWall, 1.5, 1, 2.25, kWall}, {4, 3, 2, 1, 0}, {0, -1, 0.5, 0.25, 0}, 0.75);
  expectSameRunAtAnyScale(box, "constant e, a box");
  Scene tc = box;
  tc.restitution_model.kind = RestitutionModelKind::kTc;
  tc.restitution_model.tc = 0.375;
  expectSameRunAtAnyScale(tc, "TC");
  Scene threshold = box;
  threshold.restitution_model.kind = RestitutionModelKind::kThreshold;
  threshold.restitution_model.elastic_below = 0.125;
  expectSameRunAtAnyScale(threshold, "threshold");
  Scene visco = reference::makeScene({kWall, 1.5, 1, 2.25, kWall}, {4, 3, 2, 1, 0}, {0, -1, 0.5, 0.25, 0}, 1.0);
  visco.restitution_model.kind = RestitutionModelKind::kViscoelastic;
  visco.restitution_model.viscoelastic_speed = 8;
  expectSameRunAtAnyScale(visco, "viscoelastic");
  Scene ring = reference::makeScene({1.5, 1, 2.25}, {2.5, 1.25, 0.5}, {-1, 0.5, 0.25}, 0.875);
  ring.ring = 3;
  expectSameRunAtAnyScale(ring, "ring");
}

// An impact at a time no double holds is counted, with exact positions and velocities and
// time +inf (time_beyond_range), and the run goes on. Equal masses swap velocities: A, left
// creeping at 1e-10 m/s, meets B 1e300 m away at about 1e310 s.
TEST(WideRange, AnImpactAfterTheLargestDoubleIsCountedWithTimeInfinity) {
  const Scene scene = reference::makeScene({1, 1, 1, 1}, {3e300, 2e300, 1e300, 0}, {-1, -1e-10, 0, 0}, 1.0);
  ASSERT_FALSE(validate(scene)) << validate(scene)->message;
  const reference::Run exact = reference::simulate(scene, 10);
  ASSERT_GE(exact.events.size(), 4u);
  ASSERT_GT(exact.events[3].time, reference::Rational(std::numeric_limits<double>::max()));  // the premise
  const SceneSimulation run = runKeepingEvents(scene);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  EXPECT_FALSE(run.truncated);
  EXPECT_TRUE(run.time_beyond_range);
  ASSERT_EQ(run.impacts.size(), exact.events.size()) << run.stop_message;
  for (std::size_t k = 0; k < run.impacts.size(); ++k) {
    const reference::Rational& t = exact.events[k].time;
    if (t > reference::Rational(std::numeric_limits<double>::max())) {
      EXPECT_EQ(run.impacts[k].time, std::numeric_limits<double>::infinity()) << "impact " << k + 1;
    } else {
      EXPECT_NEAR(run.impacts[k].time, static_cast<double>(t), 0x1p-42 * static_cast<double>(t)) << "impact " << k + 1;
    }
    const double x = static_cast<double>(exact.events[k].position);
    EXPECT_NEAR(run.impacts[k].position, x, 0x1p-50 * std::fabs(x)) << "impact " << k + 1;
  }
  EXPECT_EQ(run.final_time, std::numeric_limits<double>::infinity());
}

// A velocity of 5e-324 m/s beside 1 m/s on a metre's scale: pair BC's schedule, 2e323 s
// away, is beyond the tiers' range from the start. It waits (parked) while A and B, then B
// and C, meet; the third impact, A creeping to B at rest, comes after the largest double:
// it is counted with time +inf. It used to stop the run at the start, then before it.
TEST(WideRange, ASubnormalApproachSpeedWaitsUntilItsImpactIsNext) {
  const Scene scene = reference::makeScene({1, 1, 1}, {2, 1, 0}, {-1, -5e-324, 0}, 1.0);
  ASSERT_FALSE(validate(scene)) << validate(scene)->message;
  const SceneSimulation run = runKeepingEvents(scene);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  EXPECT_FALSE(run.truncated);
  EXPECT_TRUE(run.time_beyond_range);
  ASSERT_EQ(run.impact_count, 3u);
  // Equal masses exchange velocities: AB at t = 1 (x = 1), BC at t = 2 (x = 0), exactly;
  // then A reaches B at rest at 0 after 1 / 5e-324 s.
  EXPECT_EQ(run.impacts[0].time, 1.0);
  EXPECT_EQ(run.impacts[0].position, 1.0);
  EXPECT_EQ(run.impacts[1].time, 2.0);
  EXPECT_EQ(run.impacts[1].position, 0.0);
  EXPECT_EQ(run.impacts[2].time, std::numeric_limits<double>::infinity());
  EXPECT_EQ(run.impacts[2].position, 0.0);
  EXPECT_EQ(run.final_velocities, (std::vector<double>{0, -5e-324, -1}));
}

// Equal masses 1 m apart, C creeping towards B at 2^-901 m/s: in the units that bring the
// largest position and speed near 1, pair BC's impact would come exactly at 2^900, where
// the tiers end; its bounds straddle that limit. It used to stop the run at once. Now A
// meets B, B meets C, and B, creeping at 2^-901 m/s, reaches A after 2^901 s (6.7e271 s,
// which a double holds): three impacts, against the exact reference.
TEST(WideRange, APairWhoseTimeBoundsStraddle2To900RunsToTheEnd) {
  const Scene scene = reference::makeScene({1, 1, 1}, {2, 1, 0}, {-1, 0, 0x1p-901}, 1.0);
  ASSERT_FALSE(validate(scene)) << validate(scene)->message;
  const reference::Run exact = reference::simulate(scene, 1000);
  ASSERT_FALSE(exact.truncated);
  ASSERT_EQ(exact.events.size(), 3u);
  EXPECT_GT(static_cast<double>(exact.events[2].time), k2To900);
  const SceneSimulation run = runKeepingEvents(scene);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  expectCloseToReference(scene, run, exact, "straddling 2^900");
}

// A pair approaching at 5e-324 m/s whose impact never comes first: the run is not stopped
// for it (it used to stop at the start). B meets C after A meets B.
TEST(WideRange, ASubnormalApproachSpeedThatNeverComesFirstStopsNothing) {
  const Scene scene = reference::makeScene({1, 2, 3}, {2, 1, 0}, {-1, 0, 5e-324}, 1.0);
  ASSERT_FALSE(validate(scene)) << validate(scene)->message;
  const reference::Run exact = reference::simulate(scene, 1000);
  ASSERT_FALSE(exact.truncated);
  ASSERT_EQ(exact.events.size(), 2u);
  const SceneSimulation run = runKeepingEvents(scene);
  EXPECT_EQ(run.stop, StopReason::kFinished) << run.stop_message;
  expectCloseToReference(scene, run, exact, "subnormal approach");
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
