// Issue 21, "No run hangs": a one-dimensional granular gas whose impacts crowd together
// needs exact decisions whose rationals grow with every impact. The exactness budget
// (tier.h, kExactBudgetBits) makes such a run stop at its last certified impact with a
// reason, and the cancel flag reaches the exact tier's long replays. These runs never
// ended before the budget (100 bodies at e = 0.5: none in 15 minutes).
#include <gtest/gtest.h>

#include <atomic>
#include <string>

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
    const EngineResult run = runEngine(s);
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
  const EngineResult run = runEngine(s, options, {}, [&](const EngineProgress&) { cancel = true; });
  EXPECT_EQ(run.stop, StopReason::kCancelled) << run.stop_message;
  EXPECT_TRUE(run.truncated);
  EXPECT_GT(run.impact_count, 4000u);
  EXPECT_LT(run.impact_count, 5120u);
  EXPECT_GT(run.escalations.exact_rational, 0u);
  EXPECT_NE(run.stop_message.find("cancelled after " + countText(run.impact_count) + " impacts"),
            std::string::npos);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
