// Issue 8, section 4, in the core: what a lab run reports for a run over the cap, the
// energy each body gains per impact, negative zeros, and the wording of rejections.
// References: exact rationals (rational_reference.h), conservation, hand-derived numbers.
#include <gtest/gtest.h>

#include <boost/multiprecision/cpp_bin_float.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "collision_lab/core/count_text.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/core/paper.h"
#include "rational_reference.h"
#include "simulated_run.h"

namespace collision_lab {
namespace core {
namespace {

using reference::Q;

constexpr double kInf = std::numeric_limits<double>::infinity();

bool isNegativeZero(double x) { return x == 0 && std::signbit(x); }

SceneRunResult runAll(const Scene& scene, RunOptions options = {}) {
  options.events = EventPolicy::all();
  return testing_support::runPlanned(scene, options);
}

/// The run over the cap as every front end takes it unless asked to simulate to the cap.
SceneRunResult runAnsweringOverCap(const Scene& scene, const RunOptions& lab) {
  SceneRunOptions options;
  options.lab = lab;
  return testing_support::runPlanned(scene, options);
}

// ---------------------------------------------------------------------------------------
// An over-cap run answered by the closed form.

TEST(LabRunOverCap, ReportsThePredictedFinalVelocitiesAndMeasuresNothing) {
  // Masses (1e30, 1, inf): 3.1e15 collisions, far over a cap of 10.
  const Scene scene{{1e30, 1, kInf}, {2, 1, 0}, {-1, 0, 0}};
  RunOptions options;
  options.max_collisions = 10;
  const SceneRunResult result = runAnsweringOverCap(scene, options);
  ASSERT_FALSE(result.simulation.simulated);
  // The closed form's answer is complete: its count is the run's (issue 20), not truncated.
  EXPECT_FALSE(result.simulation.truncated);
  EXPECT_EQ(result.simulation.impact_count, result.prediction->impact_count);
  EXPECT_EQ(result.simulation.final_velocities, result.prediction->final_velocities);
  // The closed form's end state, checked by physics: energy m_A v_A^2 + m_B v_B^2 = m_A
  // (the wall at rest) and no further impact, v_A >= v_B >= 0 (it was (-1, 0, 0)).
  const auto& v = result.simulation.final_velocities;
  EXPECT_NEAR((1e30 * v[kA] * v[kA] + v[kB] * v[kB]) / 1e30, 1.0, 1e-12);
  EXPECT_GE(v[kA], v[kB]);
  EXPECT_GE(v[kB], 0.0);
  EXPECT_EQ(v[kC], 0.0);
  // Nothing was measured: NaN, as a simulated wall run gives for momentum.
  EXPECT_TRUE(std::isnan(result.simulation.momentum_relative_drift));
  EXPECT_TRUE(std::isnan(result.simulation.energy_relative_drift));
  EXPECT_TRUE(std::isnan(result.simulation.max_prediction_error));
}

TEST(LabRunOverCap, WithoutAWallMomentumIsNotMeasuredEither) {
  const Scene scene{{1e30, 1, 1e30}, {2, 1, 0}, {-1, 0, 0}};
  RunOptions options;
  options.max_collisions = 10;
  const SceneRunResult skipped = runAnsweringOverCap(scene, options);
  EXPECT_TRUE(std::isnan(skipped.simulation.momentum_relative_drift));
  options.mode = RunMode::kPredictOnly;
  const SceneRunResult predicted = runAnsweringOverCap(scene, options);
  EXPECT_TRUE(std::isnan(predicted.simulation.momentum_relative_drift));
  EXPECT_EQ(predicted.simulation.final_velocities, predicted.prediction->final_velocities);
  // A simulated run still measures: 0 drift to rounding, no wall.
  const SceneRunResult simulated = testing_support::runPlanned(Scene{{1, 2, 3}, {2, 1, 0}, {-1, 0, 0.5}}, RunOptions{});
  EXPECT_LE(simulated.simulation.momentum_relative_drift, 1e-15);
}

// ---------------------------------------------------------------------------------------
// Energy transfer per impact.

/// The kinetic energy body i gains in impact k, exactly.
double exactGain(const Scene& scene, const reference::Run& truth, std::size_t k, int i) {
  const Q before = k == 0 ? Q(scene.velocities[i]) : truth.impacts[k - 1].velocities[i];
  const Q after = truth.impacts[k].velocities[i];
  return static_cast<double>(reference::toWide(Q(scene.masses[i]) * (after * after - before * before) / 2));
}

// Ctrl-C: a cancel flag set during the run stops it within 1024 collisions, with the
// summary of what was done: the collisions performed, the state exact arithmetic gives after
// them, and truncated + cancelled. (1e12, 1, 1e12) would give 2,221,441 (physics.md).
TEST(LabRunCancel, AFlagSetDuringTheRunStopsItWithinACheckIntervalWithThePartialSummary) {
  const Scene scene{{1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0}};
  constexpr std::uint64_t kSetAt = 1500;
  for (const bool events : {false, true}) {
    std::atomic<bool> cancel{false};
    SceneRunOptions options;
    options.cancel = &cancel;
    options.lab.events = events ? EventPolicy::all() : EventPolicy::none();
    const SceneRunResult result = testing_support::runPlanned(scene, options, [&](const ImpactRecord& lab) {
      if (lab.index == kSetAt) cancel = true;
    });
    const std::uint64_t count = result.simulation.impact_count;
    EXPECT_GE(count, kSetAt) << events;
    EXPECT_LT(count, kSetAt + 1024) << events;
    EXPECT_TRUE(result.simulation.truncated);
    EXPECT_EQ(result.simulation.stop, StopReason::kCancelled);
    EXPECT_NE(result.simulation.stop_message.find("cancelled after " + countText(count) + " of 2,221,441"),
              std::string::npos)
        << result.simulation.stop_message;
    // Reference: the textbook impact rule applied `count` times at 50 digits.
    using Fifty = boost::multiprecision::cpp_bin_float_50;
    std::array<Fifty, 3> v{Fifty(-1), Fifty(0), Fifty(0)};
    const Fifty ma(1e12), mb(1), mc(1e12);
    for (std::uint64_t k = 0; k < count; ++k) {
      const int l = k % 2;  // AB first, then alternating
      const Fifty m_l = l == 0 ? ma : mb, m_r = l == 0 ? mb : mc;
      const Fifty left = v[l], right = v[l + 1];
      v[l] = ((m_l - m_r) * left + 2 * m_r * right) / (m_l + m_r);
      v[l + 1] = (2 * m_l * left + (m_r - m_l) * right) / (m_l + m_r);
    }
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(result.simulation.final_velocities[i], static_cast<double>(v[i]), 1e-12) << i;
    }
  }
}

TEST(EnergyTransferPerImpact, NonParticipantsAndRestingWallsGainExactlyZero) {
  // A pi billiard against a resting wall C, equal masses, and a general scene.
  for (const Scene& scene : {Scene{{1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}}, Scene{{1, 1, 1}, {2, 1, -1}, {-1, 0, 1}},
                             Scene{{0.3, 0.7, 0.11}, {0.9, 0.2, -0.4}, {-0.3, 0.1, 0.25}}}) {
    const SceneRunResult result = runAll(scene);
    ASSERT_FALSE(result.simulation.impacts.empty());
    for (const ImpactRecord& lab : result.simulation.impacts) {
      const int outsider = (lab.pair_index == 0 ? Pair::AB : Pair::BC) == Pair::AB ? kC : kA;
      for (const auto* gains : {&lab.model->energy_transfer, &lab.model->predicted_energy_transfer, &lab.model->paper_energy_transfer}) {
        EXPECT_EQ((*gains)[outsider], 0.0) << lab.index;
        EXPECT_FALSE(std::signbit((*gains)[outsider])) << lab.index;
      }
      if (scene.isWall(kC) && (lab.pair_index == 0 ? Pair::AB : Pair::BC) == Pair::BC) {
        // The ball bounces off a resting wall with its speed: nobody gains anything.
        for (double gained : lab.model->energy_transfer) EXPECT_EQ(gained, 0.0) << lab.index;
        for (double gained : lab.model->predicted_energy_transfer) EXPECT_EQ(gained, 0.0) << lab.index;
      }
    }
  }
}

TEST(EnergyTransferPerImpact, ThePairsEntriesAreExactOppositesAndExact) {
  for (const Scene& scene : {Scene{{1, 2, 3}, {2, 1, 0}, {-1, 0.3, 0.7}}, Scene{{1e4, 1, 1e4}, {2, 1, 0}, {-1, 0, 0}},
                             Scene{{0.3, 0.7, 0.11}, {0.9, 0.2, -0.4}, {-0.3, 0.1, 0.25}}}) {
    const reference::Run truth = reference::simulate(scene, 5000);
    const SceneRunResult result = runAll(scene);
    ASSERT_EQ(result.simulation.impacts.size(), truth.impacts.size());
    double energy = 0;
    for (int i = 0; i < 3; ++i) energy += scene.masses[i] * scene.velocities[i] * scene.velocities[i] / 2;
    for (std::size_t k = 0; k < truth.impacts.size(); ++k) {
      const ImpactRecord& lab = result.simulation.impacts[k];
      const int left = (lab.pair_index == 0 ? Pair::AB : Pair::BC) == Pair::AB ? kA : kB;
      EXPECT_EQ(lab.model->energy_transfer[left], -lab.model->energy_transfer[left + 1]) << k;
      EXPECT_EQ(lab.model->predicted_energy_transfer[left], -lab.model->predicted_energy_transfer[left + 1]) << k;
      for (int i : {left, left + 1}) {
        EXPECT_NEAR(lab.model->energy_transfer[i], exactGain(scene, truth, k, i), 1e-12 * energy) << k;
        EXPECT_NEAR(lab.model->predicted_energy_transfer[i], exactGain(scene, truth, k, i), 1e-12 * energy) << k;
      }
    }
  }
}

TEST(EnergyTransferPerImpact, AMovingWallsEntryIsMinusWhatTheBallGains) {
  // A wall at A moving at 0.25 m/s: the ball's gain is exact, the wall's is its opposite.
  const Scene scene{{kInf, 1, 3}, {2, 1, 0}, {0.25, 0, 1}};
  const reference::Run truth = reference::simulate(scene, 100);
  const SceneRunResult result = runAll(scene);
  ASSERT_EQ(result.simulation.impacts.size(), truth.impacts.size());
  int wall_impacts = 0;
  for (std::size_t k = 0; k < truth.impacts.size(); ++k) {
    const ImpactRecord& lab = result.simulation.impacts[k];
    if ((lab.pair_index == 0 ? Pair::AB : Pair::BC) != Pair::AB) continue;
    ++wall_impacts;
    const double ball = exactGain(scene, truth, k, kB);
    EXPECT_NE(ball, 0.0);
    EXPECT_NEAR(lab.model->energy_transfer[kB], ball, 1e-15 * std::fabs(ball) + 1e-300) << k;
    EXPECT_EQ(lab.model->energy_transfer[kA], -lab.model->energy_transfer[kB]) << k;
    EXPECT_EQ(lab.model->predicted_energy_transfer[kA], -lab.model->predicted_energy_transfer[kB]) << k;
  }
  EXPECT_GE(wall_impacts, 1);
}

TEST(EnergyTransferPerImpact, ThePapersFormulasLeaveTheThirdBodyAtZero) {
  // BC first: (4.6)/(4.7) refer to the impact before, undefined here; A still gains 0.
  const Scene bc_first{{1, 1, 1}, {3, 1, 0}, {0, 0, -1}};
  const auto gained = paper::energyTransfer(bc_first, 1, Pair::BC, triple(bc_first.velocities), triple(bc_first.velocities));
  EXPECT_EQ(gained[kA], 0.0);
  EXPECT_TRUE(std::isnan(gained[kB]));
  EXPECT_TRUE(std::isnan(gained[kC]));
}

// ---------------------------------------------------------------------------------------
// No negative zeros anywhere in a lab run.

void expectNoNegativeZero(const std::array<double, 3>& values, const char* what, std::uint64_t index) {
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(isNegativeZero(values[i])) << what << "[" << i << "] of event " << index;
}

TEST(NegativeZeros, NoneInEventsPredictionsOrSummaries) {
  // Resting walls, bodies at rest and -0 inputs are where -0 comes from.
  for (const Scene& scene : {Scene{{100, 1, kInf}, {2, 1, 0}, {-1, -0.0, -0.0}}, Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}},
                             Scene{{kInf, 1, 1}, {2, 1, 0}, {-0.0, 0.5, -1}}, Scene{{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}}}) {
    const SceneRunResult result = runAll(scene);
    for (const ImpactRecord& lab : result.simulation.impacts) {
      const std::uint64_t k = lab.index;
      EXPECT_FALSE(isNegativeZero(lab.time)) << k;
      EXPECT_FALSE(isNegativeZero(lab.position)) << k;
      EXPECT_FALSE(isNegativeZero(lab.model->total_energy)) << k;
      EXPECT_FALSE(isNegativeZero(lab.model->total_momentum)) << k;
      expectNoNegativeZero(lab.model->positions, "positions", k);
      expectNoNegativeZero(lab.model->velocities_before, "velocities_before", k);
      expectNoNegativeZero(lab.model->velocities_after, "velocities_after", k);
      expectNoNegativeZero(lab.model->energy_transfer, "energy_transfer", k);
      expectNoNegativeZero(lab.model->predicted_velocities_after, "predicted_velocities_after", k);
      expectNoNegativeZero(lab.model->paper_velocities_after, "paper_velocities_after", k);
      expectNoNegativeZero(lab.model->predicted_energy_transfer, "predicted_energy_transfer", k);
      expectNoNegativeZero(lab.model->paper_energy_transfer, "paper_energy_transfer", k);
      expectNoNegativeZero(lab.model->kinetic_energy_after, "kinetic_energy_after", k);
    }
    expectNoNegativeZero(triple(result.simulation.final_velocities), "summary final_velocities", 0);
    expectNoNegativeZero(triple(result.prediction->final_velocities), "predicted final_velocities", 0);
  }
}

// ---------------------------------------------------------------------------------------
// Wording of rejections.

TEST(RejectionWording, NaNIsNaNWithoutASign) {
  Scene scene{{1, 1, 1}, {2, 1, 0}, {-std::numeric_limits<double>::quiet_NaN(), 0, 0}};
  ASSERT_TRUE(std::signbit(scene.velocities[0]));
  EXPECT_EQ(validate(scene)->message, "v_A is NaN; a velocity must be a finite number in m/s");
  scene.velocities[0] = -1;
  scene.positions[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(validate(scene)->message, "x_B is NaN; a position must be a finite number in m");
}

TEST(RejectionWording, NoMessageRepeatsItsField) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Scene> rejected = {
      {{nan, 1, 1}, {2, 1, 0}, {-1, 0, 0}},           {{0, 1, 1}, {2, 1, 0}, {-1, 0, 0}},
      {{1, kInf, 1}, {2, 1, 0}, {-1, 0, 0}},
      {{1, 1, 1}, {0, 1, 2}, {-1, 0, 0}},             {{1, 1, 1}, {1, 1, 0}, {-1, 0, 0}},
      {{1, 1, 1}, {1, 0, -1}, {-1, 0, 1}},            {{1e300, 1, 1}, {2, 1, 0}, {-1e10, 0, 0}},
      {{1, 1, 1}, {1e308, -1e308, -1.5e308}, {-1, 0, 1}}, {{1e40, 1, 1e40}, {2, 1, 0}, {-1, 0, 0}},
      {{1, 1, 1}, {1e300, 0, -1}, {-1e-300, 0, -1}},  {{1, 1, 1}, {kInf, 1, 0}, {-1, 0, 0}}};
  for (const Scene& scene : rejected) {
    const auto error = validate(scene);
    ASSERT_TRUE(error);
    // "positions: positions (0, 1, 2) m ..." said its field twice; front ends show the
    // field beside the message, which therefore names neither the field nor its prefix.
    const std::string base = error->field.substr(0, error->field.find('['));
    EXPECT_EQ(error->message.find(error->field + ":"), std::string::npos) << error->message;
    EXPECT_NE(error->message.rfind(base, 0), 0u) << error->message;
    EXPECT_EQ(error->message.find("nan"), std::string::npos) << error->message;
  }
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
