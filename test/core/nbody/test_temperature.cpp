// Issue 21: the granular temperature against hand computations, its replay of a run against
// the engine's final state, and the Haff fit against an exact synthetic Haff series.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/temperature.h"

namespace collision_lab {
namespace core {
namespace {

TEST(Temperature, ByHand) {
  // m = (1, 2, 3) kg, v = (-1, 0, 1) m/s: V = 2/6 = 1/3 m/s; sum m (v - V)^2 =
  // 16/9 + 2/9 + 12/9 = 10/3 J; T = 10/9 J.
  EXPECT_NEAR(granularTemperature({1, 2, 3}, {-1, 0, 1}), 10.0 / 9, 1e-15);
  // Blind to a boost of the whole.
  EXPECT_NEAR(granularTemperature({1, 2, 3}, {99, 100, 101}), 10.0 / 9, 1e-12);
  // A wall is not a body of the gas: m = 2 kg alone has T = 0; two bodies of 1 kg at
  // +-1 m/s beside a wall: V = 0, T = (1 + 1) / 2 = 1 J.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(granularTemperature({inf, 2}, {0, 5}), 0.0);
  EXPECT_NEAR(granularTemperature({inf, 1, 1}, {0, 1, -1}), 1.0, 1e-15);
  EXPECT_EQ(granularTemperature({}, {}), 0.0);
}

TEST(Temperature, SamplesOfASmallRunByHand) {
  // Equal masses of 1 kg at x = (2, 1, 0) m, v = (0, 0, 1) m/s, e = 1/2 (exact in binary).
  // Impact 1, CB at t = 1 s: v_B = (1 + e)/2 = 3/4, v_C = (1 - e)/2 = 1/4.
  // Impact 2, BA at t = 1 + 1/(3/4) = 7/3 s: v_A = 3/4 (1 + e)/2 = 9/16, v_B = 3/4 (1 - e)/2 = 3/16.
  // V = 1/3 m/s throughout (no wall). T_0 = (1/9 + 1/9 + 4/9)/3 = 2/9 J;
  // T_1: deviations (-1/3, 5/12, -1/12): (16 + 25 + 1)/144/3 = 7/72 J;
  // T_2: deviations (11/48, -7/48, -4/48): (121 + 49 + 16)/2304/3 = 31/1152 J.
  const Scene scene{{1, 1, 1}, {2, 1, 0}, {0, 0, 1}, {0.5}};
  std::vector<TemperatureSample> samples;
  TemperatureSampler sampler(scene, 1, [&](const TemperatureSample& s) { samples.push_back(s); });
  const SceneSimulation run = runEngine(
      scene, {}, [&](const ImpactRecord& r) { sampler.onImpact(r); }, {},
      [&](const Collapse& c) { sampler.onCollapse(c); });
  sampler.finish();
  ASSERT_GE(samples.size(), 3u);
  EXPECT_EQ(samples.size(), run.impact_count + 1);  // the start and one per impact; finish adds none
  EXPECT_EQ(samples[0].impacts, 0u);
  EXPECT_EQ(samples[0].time, 0.0);
  EXPECT_NEAR(samples[0].temperature, 2.0 / 9, 1e-15);
  EXPECT_EQ(samples[1].impacts, 1u);
  EXPECT_NEAR(samples[1].time, 1.0, 1e-15);
  EXPECT_NEAR(samples[1].temperature, 7.0 / 72, 1e-15);
  EXPECT_EQ(samples[2].impacts, 2u);
  EXPECT_NEAR(samples[2].time, 7.0 / 3, 1e-15);
  EXPECT_NEAR(samples[2].temperature, 31.0 / 1152, 1e-15);
}

TEST(Temperature, DecimatedReplayThroughACollapseEndsAtTheEnginesState) {
  // Three equal masses at e = 0.07 collapse (physics.md, reference points), then move as one:
  // T = 0 after the collapse. The replay of the records and the notice gives the engine's
  // final velocities; with a stride of 2 the samples are the start, the even impacts, the
  // collapse and (finish) nothing more.
  const Scene scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.07}};
  std::vector<TemperatureSample> samples;
  TemperatureSampler sampler(scene, 2, [&](const TemperatureSample& s) { samples.push_back(s); });
  const SceneSimulation run = runEngine(
      scene, {}, [&](const ImpactRecord& r) { sampler.onImpact(r); }, {},
      [&](const Collapse& c) { sampler.onCollapse(c); });
  sampler.finish();
  ASSERT_TRUE(run.collapsed) << run.stop_message;
  EXPECT_EQ(sampler.velocities(), run.final_velocities);
  ASSERT_GE(samples.size(), 2u);
  for (std::size_t k = 1; k + 1 < samples.size(); ++k) EXPECT_EQ(samples[k].impacts % 2, 0u);
  EXPECT_NEAR(samples.back().time, *run.collapse_time, 1e-12);
  EXPECT_NEAR(samples.back().temperature, 0.0, 1e-15);
  // Before: m = 1 kg, v = (-1, 0, 0): V = -1/3, T = (4/9 + 1/9 + 1/9)/3 = 2/9 J.
  EXPECT_NEAR(samples.front().temperature, 2.0 / 9, 1e-15);
  EXPECT_EQ(temperatureStride(3), 1u);
  EXPECT_EQ(temperatureStride(1000), 125u);
}

/// T0 / (1 + t/tau)^2 at times spread over five decades, and t = 0.
std::vector<TemperatureSample> haffSeries(double t0, double tau) {
  std::vector<TemperatureSample> s{{0, 0.0, t0}};
  for (int k = 0; k <= 100; ++k) {
    const double t = tau * std::pow(10.0, -2 + 5.0 * k / 100);
    s.push_back({static_cast<std::uint64_t>(k + 1), t, t0 / ((1 + t / tau) * (1 + t / tau))});
  }
  return s;
}

TEST(HaffFit, RecoversTauOfAnExactSeries) {
  for (const double tau : {0.37, 12.5, 2.0e3}) {
    const auto series = haffSeries(2.5, tau);
    const HaffFit free = fitHaff(series);
    ASSERT_TRUE(free.ok);
    EXPECT_FALSE(free.t0_fixed);
    EXPECT_EQ(free.samples, series.size());
    EXPECT_NEAR(free.tau, tau, 1e-7 * tau);
    EXPECT_NEAR(free.t0, 2.5, 1e-7);
    EXPECT_LT(free.rms_log_error, 1e-7);
    const HaffFit fixed = fitHaff(series, 2.5);
    ASSERT_TRUE(fixed.ok);
    EXPECT_TRUE(fixed.t0_fixed);
    EXPECT_EQ(fixed.t0, 2.5);
    EXPECT_NEAR(fixed.tau, tau, 1e-7 * tau);
  }
}

TEST(HaffFit, SkipsUnusableSamplesAndSaysWhenItCannotFit) {
  auto series = haffSeries(1.0, 3.0);
  series.push_back({1000, 1e9, 0.0});  // T = 0 (one cluster): no logarithm, skipped
  const HaffFit fit = fitHaff(series);
  ASSERT_TRUE(fit.ok);
  EXPECT_EQ(fit.samples, series.size() - 1);
  EXPECT_NEAR(fit.tau, 3.0, 3e-7);
  EXPECT_FALSE(fitHaff({{0, 0.0, 1.0}}).ok);                 // one sample
  EXPECT_FALSE(fitHaff({{0, 0.0, 1.0}, {1, 0.0, 1.0}}).ok);  // no time after the start
  // No cooling: T constant, tau is +inf.
  const HaffFit flat = fitHaff({{0, 0.0, 2.0}, {1, 1.0, 2.0}, {2, 5.0, 2.0}});
  ASSERT_TRUE(flat.ok);
  EXPECT_TRUE(std::isinf(flat.tau));
  EXPECT_NEAR(flat.t0, 2.0, 1e-15);
}

TEST(LogTimeSamples, KeepsTheStartOnePerBinAndTheNewest) {
  LogTimeSamples thin;
  thin.add({0, 0.0, 5.0});
  // 1 s, then 1.01 s (same 1/50-decade bin as 1 s: log10(1.01) = 0.0043 < 0.02), 1.1 s (a new bin).
  thin.add({1, 1.0, 4.0});
  thin.add({2, 1.01, 3.9});
  thin.add({3, 1.1, 3.5});
  thin.add({4, 1.12, 3.4});  // log10(1.12) * 50 = 2.46: bin 2, as 1.1 s (2.07)
  const auto kept = thin.samples();
  ASSERT_EQ(kept.size(), 4u);
  EXPECT_EQ(kept[0].impacts, 0u);
  EXPECT_EQ(kept[1].impacts, 1u);
  EXPECT_EQ(kept[2].impacts, 3u);
  EXPECT_EQ(kept[3].impacts, 4u);  // the newest
  // A million samples over six decades keep at most 50 per decade, plus the start and newest.
  LogTimeSamples many;
  many.add({0, 0.0, 1.0});
  for (int k = 1; k <= 1000000; ++k) many.add({static_cast<std::uint64_t>(k), 1e-3 * k, 1.0});
  EXPECT_LE(many.samples().size(), 6u * 50 + 2);
  EXPECT_EQ(many.samples().back().impacts, 1000000u);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
