// Issue 21, "No run hangs": a one-dimensional granular gas whose impacts crowd together
// needs exact decisions whose rationals grow with every impact. The exactness budget
// (tier.h, kExactBudgetBits) makes such a run stop at its last certified impact with a
// reason, and the cancel flag reaches the exact tier's long replays. These runs never
// ended before the budget (100 bodies at e = 0.5: none in 15 minutes).
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <string>
#include <vector>

#include "collision_lab/core/count_text.h"
#include "collision_lab/core/nbody/engine.h"
#include "granular_gas.h"

namespace collision_lab {
namespace core {
namespace {

using testing_support::granularGas;

constexpr std::uint64_t kSeed = 1;

/// Kinetic energies [J] of the scene's initial velocities and of the run's final ones,
/// summed here (no wall: the lab frame), independently of the engine's drift figure.
long double kinetic(const Scene& s, const std::vector<double>& velocities) {
  long double e = 0;
  for (std::size_t k = 0; k < s.size(); ++k) e += 0.5L * s.masses[k] * velocities[k] * velocities[k];
  return e;
}

TEST(NBodyGasBudget, HundredBodyGasEndsWithAReasonAndBalancesEnergy) {
  for (const double e : {0.1, 0.3, 0.5}) {
    const Scene s = granularGas(100, e, kSeed);
    ASSERT_FALSE(validate(s));
    const SceneSimulation run = runEngine(s);
    const std::string label = "e = " + std::to_string(e) + ": " + run.stop_message;
    // Either honest stop: the work budget of an exact replay, or the exactness cap of an
    // accumulation (the exact tier's own steps outgrew its bits).
    ASSERT_TRUE(run.stop == StopReason::kFinished || run.stop == StopReason::kPrecisionBudget ||
                run.stop == StopReason::kCap)
        << label;
    const long double before = kinetic(s, s.velocities), after = kinetic(s, run.final_velocities);
    EXPECT_LT(std::fabs(static_cast<double>((after + run.energy_lost - before) / before)), 1e-12) << label;
    EXPECT_GT(run.energy_lost, 0.0) << label;
    if (run.stop == StopReason::kFinished) continue;
    // The honest stop: truncated, the count, the crowding bodies and the models to use instead.
    EXPECT_TRUE(run.truncated) << label;
    EXPECT_GT(run.impact_count, 0u);
    ASSERT_FALSE(run.crowding_bodies.empty()) << label;
    EXPECT_LT(run.crowding_bodies.back(), s.size());
    EXPECT_NE(label.find("stopped after " + countText(run.impact_count) +
                         (run.stop == StopReason::kCap ? " impacts at the exactness cap" : " certified impacts")),
              std::string::npos);
    EXPECT_NE(label.find("bodies " + std::to_string(run.crowding_bodies.front())), std::string::npos);
    EXPECT_NE(label.find("--restitution-model tc"), std::string::npos);
    EXPECT_NE(label.find("--restitution-model viscoelastic"), std::string::npos);
  }
}

TEST(NBodyGasBudget, CancelReachesTheExactReplay) {
  // The flag goes up at impact 4,000 (a progress report); the main loop reads it only at
  // multiples of 1,024 impacts, so a stop before 5,120 impacts is the exact tier's own check,
  // during its replay (this gas needs the exact tier after about 4,060 impacts).
  const Scene s = granularGas(100, 0.5, kSeed);
  std::atomic<bool> cancel{false};
  EngineOptions options;
  options.cancel = &cancel;
  options.progress_interval = 4000;
  const SceneSimulation run = runEngine(s, options, {}, [&](const EngineProgress&) { cancel = true; });
  EXPECT_EQ(run.stop, StopReason::kCancelled) << run.stop_message;
  EXPECT_TRUE(run.truncated);
  EXPECT_GT(run.impact_count, 4000u);
  EXPECT_LT(run.impact_count, 5120u);
  EXPECT_GT(run.escalations.exact_rational, 0u);
  EXPECT_NE(run.stop_message.find("cancelled after " + countText(run.impact_count) + " impacts"),
            std::string::npos);
}

/// A run's impacts as published: pair, time and velocities after, bit for bit.
struct Published {
  std::vector<std::size_t> pairs;
  std::vector<double> values;
  bool operator==(const Published& o) const {
    return pairs == o.pairs && values.size() == o.values.size() &&
           std::memcmp(values.data(), o.values.data(), values.size() * sizeof(double)) == 0;
  }
};

SceneSimulation runRecorded(const Scene& s, const EngineOptions& options, Published& out) {
  return runEngine(s, options, [&out](const ImpactRecord& r) {
    out.pairs.push_back(r.pair_index);
    out.values.push_back(r.time);
    out.values.push_back(r.velocities_after[0]);
    out.values.push_back(r.velocities_after[1]);
  });
}

// Issue 34: the budget is foreseen from the work's growth, so a run stops long before it
// would have spent it, with the impacts it would have published.
TEST(NBodyGasBudget, TheForecastStopsWithTheSameImpactsForLessWork) {
  {
    // A replay that cannot be afforded (a budget of 10^9 bit^2, so that spending it is quick
    // too): the same stop, the same impacts, a shorter replay.
    const Scene s = granularGas(100, 0.5, kSeed);
    EngineOptions spend;
    spend.exact_work_budget = 1e9;
    spend.forecast_exact_work = false;
    EngineOptions foresee = spend;
    foresee.forecast_exact_work = true;
    Published spent, foreseen;
    const SceneSimulation a = runRecorded(s, spend, spent);
    const SceneSimulation b = runRecorded(s, foresee, foreseen);
    ASSERT_EQ(a.stop, StopReason::kPrecisionBudget) << a.stop_message;
    ASSERT_EQ(b.stop, StopReason::kPrecisionBudget) << b.stop_message;
    EXPECT_EQ(b.impact_count, a.impact_count);
    EXPECT_TRUE(foreseen == spent);
    EXPECT_EQ(b.final_velocities, a.final_velocities);
    EXPECT_LT(b.escalations.replayed_impacts, a.escalations.replayed_impacts);
    EXPECT_NE(a.stop_message.find("its exact replay reached the work budget after"), std::string::npos) << a.stop_message;
    EXPECT_NE(b.stop_message.find("its exact replay would exceed the work budget: after"), std::string::npos)
        << b.stop_message;
  }
  {
    // Exact impacts in a row, each dearer than the last, towards the exactness cap (256 in a
    // row; at e = 0.1 they cost 38 s of exact arithmetic before the forecast): the run stops
    // at the cap foreseen, and its impacts are those the run without the forecast publishes.
    const Scene s = granularGas(100, 0.1, kSeed);
    Published foreseen, spent;
    const SceneSimulation b = runRecorded(s, EngineOptions{}, foreseen);
    ASSERT_EQ(b.stop, StopReason::kCap) << b.stop_message;
    EXPECT_TRUE(b.truncated);
    EXPECT_NE(b.stop_message.find("impacts at the exactness cap (truncated), foreseen after"), std::string::npos)
        << b.stop_message;
    EngineOptions spend;
    spend.forecast_exact_work = false;
    spend.max_impacts = b.impact_count;
    const SceneSimulation a = runRecorded(s, spend, spent);
    EXPECT_EQ(a.impact_count, b.impact_count);
    EXPECT_TRUE(foreseen == spent);
    EXPECT_EQ(b.final_velocities, a.final_velocities);
  }
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
