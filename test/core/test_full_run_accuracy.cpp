// Issue 13: a full lab run predicts the state after every impact by a rotation recurrence
// (ClosedFormSequence), recomputed exactly every RotationRecurrence::kResynchronizeEvery
// cycles. Its predictions must stay within 1e-13 of the closed form in the energy norm
// |S (v_pred - v_ref)| / |S v_0|, S = diag(sqrt m). Checked on the 22,214,414 impacts of
// masses (1e14, 1, 1e14) against the closed form at 50 decimal digits, written out below
// from the masses, the start and n alone (and itself checked against an exact replay).
#include <gtest/gtest.h>

#include <boost/multiprecision/cpp_dec_float.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/scene_run.h"
#include "rational_reference.h"
#include "simulated_run.h"

namespace collision_lab {
namespace core {
namespace {

using Dec = boost::multiprecision::cpp_dec_float_50;

/// The correct closed form (physics.md, Errata 2) for finite masses, AB first, at 50
/// digits: v_2k = V 1 + S^-1 (cos(k theta) w - sin(k theta) (s_hat x w)),
/// v_2k+1 = D_AB v_2k, with theta = 2 atan(sqrt(m_B M / (m_A m_C))), w = S (v_0 - V 1).
class FiftyDigitClosedForm {
 public:
  explicit FiftyDigitClosedForm(const Scene& scene) {
    Dec mass_sum = 0, momentum = 0, s_norm_sq = 0;
    for (int i = 0; i < 3; ++i) {
      m_[i] = Dec(scene.masses[i]);
      root_[i] = sqrt(m_[i]);
      mass_sum += m_[i];
      momentum += m_[i] * Dec(scene.velocities[i]);
      s_norm_sq += m_[i];
    }
    centre_ = momentum / mass_sum;
    std::array<Dec, 3> s_hat;
    for (int i = 0; i < 3; ++i) {
      s_hat[i] = root_[i] / sqrt(s_norm_sq);
      w_[i] = root_[i] * (Dec(scene.velocities[i]) - centre_);
    }
    x_ = {s_hat[1] * w_[2] - s_hat[2] * w_[1], s_hat[2] * w_[0] - s_hat[0] * w_[2],
          s_hat[0] * w_[1] - s_hat[1] * w_[0]};
    theta_ = 2 * atan(sqrt(m_[kB] * mass_sum / (m_[kA] * m_[kC])));
    start_norm_sq_ = 0;
    for (int i = 0; i < 3; ++i) start_norm_sq_ += m_[i] * Dec(scene.velocities[i]) * Dec(scene.velocities[i]);
  }

  std::array<Dec, 3> after(std::uint64_t n) const {
    const Dec angle = Dec(n / 2) * theta_;
    const Dec c = cos(angle), s = sin(angle);
    std::array<Dec, 3> v;
    for (int i = 0; i < 3; ++i) v[i] = centre_ + (c * w_[i] - s * x_[i]) / root_[i];
    if (n % 2 == 0) return v;
    const Dec m_ab = m_[kA] + m_[kB];
    return {((m_[kA] - m_[kB]) * v[kA] + 2 * m_[kB] * v[kB]) / m_ab,
            (2 * m_[kA] * v[kA] + (m_[kB] - m_[kA]) * v[kB]) / m_ab, v[kC]};
  }

  /// |S (v - reference)| / |S reference_0|, the lab's relative error in the energy norm.
  double relativeError(const std::array<double, 3>& v, const std::array<Dec, 3>& reference) const {
    Dec error_sq = 0;
    for (int i = 0; i < 3; ++i) {
      const Dec d = Dec(v[i]) - reference[i];
      error_sq += m_[i] * d * d;
    }
    return static_cast<double>(sqrt(error_sq / start_norm_sq_));
  }

 private:
  std::array<Dec, 3> m_, root_, w_, x_;
  Dec centre_, theta_, start_norm_sq_;  // |S v_0|^2, in the lab frame as the lab's own measure
};

const Scene kHeavyLightHeavy{{1e14, 1, 1e14}, {2, 1, 0}, {-1, 0, 0}};

TEST(FullRunAccuracy, TheFiftyDigitReferenceIsTheExactRun) {
  // The reference must be right before it judges anything: exact rationals, impact by impact.
  for (const Scene& scene : {kHeavyLightHeavy, Scene{{3, 1, 2}, {2, 1, 0}, {-1, 0.25, 0.5}}}) {
    const FiftyDigitClosedForm reference(scene);
    const reference::Run exact = reference::simulate(scene, 40);
    ASSERT_GE(exact.impacts.size(), 2u);
    ASSERT_EQ(exact.impacts.front().pair, Pair::AB);
    for (std::size_t n = 1; n <= exact.impacts.size(); ++n) {
      const auto predicted = reference.after(n);
      for (int i = 0; i < 3; ++i) {
        const Dec truth = Dec(reference::toWide(exact.impacts[n - 1].velocities[i]));
        EXPECT_LT(static_cast<double>(abs(predicted[i] - truth)), 1e-30 * (1 + static_cast<double>(abs(truth))))
            << "n " << n << " body " << i;
      }
    }
  }
}

TEST(FullRunAccuracy, RecurrenceStaysWithin1e13OfTheClosedFormOver2e7Impacts) {
  constexpr std::uint64_t kCycle = RotationRecurrence::kResynchronizeEvery;
  // The sampled collisions: the first 300, both impacts of the last cycle before every
  // 50th resynchronisation (where the recurrence has run longest), 2,000 seeded random
  // ones, and the last. Filled with the run's predictions by the visitor.
  const std::uint64_t expected_count = 22'214'414;
  std::map<std::uint64_t, std::array<double, 3>> samples;
  for (std::uint64_t n = 1; n <= 300; ++n) samples[n];
  std::uint64_t before_resync = 0;
  for (std::uint64_t k = kCycle - 1; 2 * k + 1 <= expected_count; k += 50 * kCycle) {
    samples[2 * k];
    samples[2 * k + 1];
    ++before_resync;
  }
  std::mt19937_64 random(13);
  std::uniform_int_distribution<std::uint64_t> any(1, expected_count);
  for (int i = 0; i < 2000; ++i) samples[any(random)];
  samples[expected_count];
  ASSERT_GT(before_resync, 3000u);

  RunOptions options;
  options.max_collisions = 30'000'000;
  options.events = EventPolicy::none();
  const SceneSimulation result = testing_support::runPlanned(kHeavyLightHeavy, options, [&](const ImpactRecord& lab) {
    const auto sample = samples.find(lab.index);
    if (sample != samples.end()) sample->second = lab.model->predicted_velocities_after;
  }).simulation;
  ASSERT_FALSE(result.truncated);
  ASSERT_EQ(result.impact_count, expected_count);
  ASSERT_EQ(predictedImpactCount(kHeavyLightHeavy), expected_count);

  const FiftyDigitClosedForm reference(kHeavyLightHeavy);
  double worst = 0.0;
  std::uint64_t worst_n = 0;
  for (const auto& [n, predicted] : samples) {
    const double error = reference.relativeError(predicted, reference.after(n));
    if (error > worst) {
      worst = error;
      worst_n = n;
    }
  }
  char worst_text[32];
  std::snprintf(worst_text, sizeof worst_text, "%.3g", worst);
  RecordProperty("worst_relative_error", worst_text);
  RecordProperty("worst_at_collision", std::to_string(worst_n));
  EXPECT_LE(worst, 1e-13) << "at collision " << worst_n;
  // The run itself, every impact against the predictions: the lab's own measure.
  EXPECT_LE(result.max_prediction_error, 1e-13);
}

TEST(FullRunAccuracy, BatchComparisonIsTheLargestOfTheImpactByImpactOnes) {
  // A long run's impacts are compared with the closed form in batches
  // (largestSquaredError): the largest weighted squared distance must be the one that
  // velocitiesAfter(n), impact by impact, gives, for batches starting at odd and even n and
  // spanning a resynchronisation of the recurrence. The run's velocities here are the
  // model's, perturbed by a seeded amount at every impact.
  const Scene bc_first{{2, 1, 3}, {2, 1, 0}, {0, 0, 1}};
  for (const Scene& scene : {kHeavyLightHeavy, bc_first}) {
    const AnalyticModel<double> model(scene);
    ClosedFormSequence by_impact(model), by_batch(model);
    const std::array<double, 3> weight{scene.masses[0] / 1e14, scene.masses[1] / 1e14, scene.masses[2] / 1e14};
    std::mt19937_64 random(48);
    std::uniform_real_distribution<double> perturbation(-1e-9, 1e-9);
    std::uint64_t first = 1;
    for (const std::size_t count : {std::size_t{1}, std::size_t{2}, std::size_t{127}, std::size_t{256},
                                    std::size_t{0}, std::size_t{255}, std::size_t{3}}) {
      std::vector<std::array<double, 3>> run(count);
      double expected = 0.0;
      for (std::size_t i = 0; i < count; ++i) {
        const Eigen::Vector3d predicted = by_impact.velocitiesAfter(first + i);
        double norm_sq = 0.0;
        for (int j = 0; j < 3; ++j) {
          run[i][j] = predicted(j) + perturbation(random);
          const double d = run[i][j] - predicted(j);
          norm_sq += weight[j] * d * d;
        }
        expected = std::max(expected, norm_sq);
      }
      EXPECT_EQ(by_batch.largestSquaredError(first, run.data(), count, weight), expected)
          << "batch of " << count << " from impact " << first;
      first += count;
    }
    EXPECT_GT(first, 2 * RotationRecurrence::kResynchronizeEvery);  // a resynchronisation inside
  }
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
