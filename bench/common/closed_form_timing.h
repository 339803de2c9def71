// Timing of the closed form, shared by bench_core and hard_cases.
#pragma once

#include <cstdint>

#include "collision_lab/core/analytic.h"
#include "timing.h"

namespace collision_lab {
namespace bench {

/// Median ns per AnalyticModel<double>::velocitiesAfter(n) query (model built once).
inline double velocitiesAfterNs(const core::Scene& scene, std::uint64_t n, int repeats) {
  const core::AnalyticModel<double> model(scene);
  constexpr int kBatch = 100'000;
  const auto samples = timeRepeats(repeats, [&] {
    // Alternate n so the query cannot be hoisted out of the loop.
    for (int i = 0; i < kBatch; ++i) doNotOptimize(model.velocitiesAfter(n + static_cast<std::uint64_t>(i & 1)));
  });
  return median(samples) * 1e9 / kBatch;
}

/// Median ns per predictedImpactCount(scene) call (builds its model every call).
inline double predictedCountNs(const core::Scene& scene, int repeats) {
  constexpr int kBatch = 200;
  const auto samples = timeRepeats(repeats, [&] {
    for (int i = 0; i < kBatch; ++i) doNotOptimize(core::predictedImpactCount(scene));
  });
  return median(samples) * 1e9 / kBatch;
}

}  // namespace bench
}  // namespace collision_lab
