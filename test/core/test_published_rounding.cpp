// Issue 44: the rotation model's published values are the correctly rounded exact values of
// what they name, as the simulation's are. References share no code with the core: exact
// rationals (rational_reference.h, a textbook event loop), and other formulas at 500 bits
// (acos for alpha, tan for r_c; the closed form at 500 bits for long runs). Two bodies and
// the spiral: nbody/test_published_rounding_nbody.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/precision.h"
#include "collision_lab/core/scene_run.h"
#include "rational_reference.h"
#include "scenes.h"

namespace collision_lab {
namespace core {
namespace {

using reference::correctlyRounded;
using testing_support::describe;
using testing_support::kInf;
using Q = reference::Q;

Prediction predictionOf(const Scene& scene) {
  const ScenePlan plan = planScene(scene);
  EXPECT_FALSE(plan.error) << describe(scene);
  return *plan.prediction;
}

/// Is `value` the double nearest x (x known to 500 bits, far from a tie)?
bool nearestTo(double value, const DeepPrecision& x) {
  const DeepPrecision distance = abs(DeepPrecision(value) - x);
  for (const double neighbour : {std::nextafter(value, kInf), std::nextafter(value, -kInf)}) {
    if (abs(DeepPrecision(neighbour) - x) < distance) return false;
  }
  return true;
}

/// Seeded three-body masses over 30 decades, a wall in every fourth.
std::vector<std::array<double, 3>> seededMasses(int count) {
  std::mt19937_64 rng(44);
  std::uniform_real_distribution<double> decade(-15.0, 15.0), unit(0.0, 1.0);
  std::vector<std::array<double, 3>> masses;
  for (int k = 0; k < count; ++k) {
    std::array<double, 3> m{std::pow(10.0, decade(rng)) * (1 + unit(rng)), std::pow(10.0, decade(rng)),
                            std::pow(10.0, decade(rng)) * (1 + unit(rng))};
    if (k % 4 == 1) m[0] = kInf;
    if (k % 4 == 3) m[2] = kInf;
    masses.push_back(m);
  }
  return masses;
}

TEST(PublishedRounding, AnglesAndTheCriticalRestitutionAreCorrectlyRounded) {
  // Another formula at 500 bits: cos^2 alpha = m_A m_C / ((m_A + m_B)(m_B + m_C)) (a wall's
  // ratio 1), alpha = acos(cos alpha), r_c = tan^2(pi/4 - alpha/2).
  int checked = 0;
  for (const auto& m : seededMasses(200)) {
    Scene scene{{m[0], m[1], m[2]}, {2, 1, 0}, {-1, 0, 0}};
    const auto ratio = [](double far, double near) {
      return std::isinf(far) ? DeepPrecision(1) : DeepPrecision(far) / (DeepPrecision(far) + DeepPrecision(near));
    };
    const DeepPrecision alpha = acos(sqrt(ratio(m[0], m[1]) * ratio(m[2], m[1])));
    const DeepPrecision pi = boost::math::constants::pi<DeepPrecision>();
    const DeepPrecision root = tan(pi / 4 - alpha / 2);
    for (const double e : {1.0, 0.5}) {
      scene.restitution = {e};
      const Prediction p = predictionOf(scene);
      ASSERT_TRUE(p.alpha && p.critical_restitution) << describe(scene);
      EXPECT_TRUE(nearestTo(*p.alpha, alpha)) << describe(scene) << " alpha " << *p.alpha;
      EXPECT_TRUE(nearestTo(*p.critical_restitution, root * root)) << describe(scene) << " r_c " << *p.critical_restitution;
      if (e == 1.0) {
        EXPECT_TRUE(nearestTo(*p.theta, 2 * alpha)) << describe(scene);
        EXPECT_TRUE(nearestTo(*p.omega, pi - alpha)) << describe(scene);
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, 400);
}

TEST(PublishedRounding, RotationFinalVelocitiesAreTheExactOnesRoundedExactZerosIncluded) {
  // equal_masses: the model's B ends exactly at rest (it showed -3.3e-16 m/s).
  const Scene equal{{1, 1, 1}, {2, 1, -1}, {-1, 0, 1}};
  const Prediction p = predictionOf(equal);
  EXPECT_EQ(p.final_velocities, (std::vector<double>{1.0, 0.0, -1.0}));
  EXPECT_TRUE(p.uncertified.empty());
  // Seeded scenes against the textbook event loop in rationals: short runs (exact states),
  // and runs past the exact limit (the certified product), kaleidoscopic and grazing ones.
  std::vector<Scene> scenes = {{{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}},  // grazing: ends with v_A = v_B
                               {{2, 1, 3}, {2, 1, 0}, {-1, 0, 0}},    // kaleidoscopic
                               {{5, 1, 9}, {2, 1, 0}, {-1, 0, 0}},
                               {{100, 1, kInf}, {2, 1, 0}, {-1, 0, 0}},
                               {{1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}},
                               {{1e4, 1, 1e4}, {2, 1, 0}, {-1, 0, 0.25}},
                               // Masses of 53 significant bits past the exact walk's budget
                               // (16,384 bits, about 300 impacts): the certified product.
                               {{25000.123456, 1, kInf}, {2, 1, 0}, {-1, 0, 0}},
                               {{30000.789, 1.25, kInf}, {2, 1, 0}, {-0.7, 0.3, 0}},
                               {{20000.123, 1, 30000.456}, {2, 1, 0}, {-1, 0, 0}}};
  std::mt19937_64 rng(4401);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 60; ++k) {
    const double heavy = std::pow(10.0, 4 * unit(rng));
    scenes.push_back({{heavy * (1 + unit(rng)), 1 + unit(rng), k % 3 == 0 ? kInf : heavy * unit(rng) + 0.1},
                      {1 + unit(rng), 0, -1 - unit(rng)},
                      {-unit(rng), 2 * unit(rng) - 1, k % 3 == 0 ? 0.0 : unit(rng)}});
  }
  int long_runs = 0;
  for (const Scene& scene : scenes) {
    const reference::Run run = reference::simulate(scene, 5000);
    ASSERT_FALSE(run.truncated) << describe(scene);
    for (const RunMode mode : {RunMode::kPredictOnly, RunMode::kSummaryOnly}) {
      const SceneRunResult result = testing_support::runInMode(scene, mode, 4'000'000'000);
      ASSERT_EQ(*result.prediction->impact_count, run.impacts.size()) << describe(scene);
      EXPECT_TRUE(result.prediction->uncertified.empty()) << describe(scene);
      for (int i = 0; i < 3; ++i) {
        EXPECT_TRUE(correctlyRounded(result.prediction->final_velocities[i], run.final_velocities[i]))
            << describe(scene) << " body " << i << ": " << result.prediction->final_velocities[i];
        // The simulation names the same exact value: the same bits.
        EXPECT_EQ(result.simulation.final_velocities[i], result.prediction->final_velocities[i]) << describe(scene);
      }
    }
    long_runs += run.impacts.size() > 320;  // past the exact walk's budget for 53-bit masses
  }
  EXPECT_GE(long_runs, 3);  // the certified product's branch, not only the exact walk
}

TEST(PublishedRounding, EveryValueOfAShortRotationRunsEventsIsTheExactOneRounded) {
  // equal_masses showed "max prediction error 2.9e-16", the model's own rounding; the
  // simulated energy transfers were up to 132 ulps off. Runs of up to 64 impacts: every
  // event's state, energies and predictions against the textbook loop in rationals.
  std::vector<Scene> scenes = {{{1, 1, 1}, {2, 1, -1}, {-1, 0, 1}}, {{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}},
                               {{100, 1, kInf}, {2, 1, 0}, {-1, 0, 0}}, {{1, 2, 3}, {3, 2, 0}, {-1, 0.5, 1}}};
  std::mt19937_64 rng(4403);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 30; ++k) {
    scenes.push_back({{1 + 30 * unit(rng), 1 + unit(rng), k % 4 == 0 ? kInf : 1 + 30 * unit(rng)},
                      {1 + unit(rng), 0, -1 - unit(rng)},
                      {-unit(rng), 2 * unit(rng) - 1, k % 4 == 0 ? 0.0 : unit(rng)}});
  }
  int events = 0;
  for (const Scene& scene : scenes) {
    const reference::Run run = reference::simulate(scene, 100);
    if (run.impacts.size() > 64) continue;
    SceneRunOptions options;  // full mode, every event
    const SceneRunResult result = runScene(planScene(scene), options);
    ASSERT_EQ(result.simulation.impacts.size(), run.impacts.size()) << describe(scene);
    EXPECT_EQ(result.simulation.max_prediction_error, 0.0) << describe(scene);
    std::array<Q, 3> before{Q(scene.velocities[0]), Q(scene.velocities[1]), Q(scene.velocities[2])};
    for (std::size_t n = 0; n < run.impacts.size(); ++n) {
      const ImpactRecord& event = result.simulation.impacts[n];
      const ImpactModelValues& values = *event.model;
      const std::array<Q, 3>& after = run.impacts[n].velocities;
      for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_TRUE(correctlyRounded(values.velocities_after[i], after[i])) << describe(scene) << " impact " << n + 1;
        EXPECT_EQ(values.predicted_velocities_after[i], values.velocities_after[i]) << describe(scene);
        if (scene.isWall(i)) continue;
        const Q gained = Q(scene.masses[i]) * (after[i] * after[i] - before[i] * before[i]) / 2;
        EXPECT_TRUE(correctlyRounded(values.energy_transfer[i], gained)) << describe(scene) << " impact " << n + 1;
        EXPECT_EQ(values.predicted_energy_transfer[i], values.energy_transfer[i]) << describe(scene);
      }
      for (std::size_t side = 0; side < 2; ++side) {
        EXPECT_EQ(event.velocities_after[side], values.velocities_after[event.pair_index + side]);
        EXPECT_EQ(event.energy_gained[side], values.energy_transfer[event.pair_index + side]);
      }
      before = after;
      ++events;
    }
  }
  EXPECT_GE(events, 150);
}

TEST(PublishedRounding, RotationPredictionsOfLongRunsAgreeWithTheClosedFormAt500Bits) {
  // The cases: (1e16, 1, 1e16) from rest, whose A ends at +8.78e-18 (printed with the
  // wrong sign), and (1e30, 1, inf) from -1e-10, whose B was 25% off.
  for (const Scene& scene : {Scene{{1e16, 1, 1e16}, {2, 1, 0}, {-1, 0, 0}}, Scene{{1e30, 1, kInf}, {2, 1, 0}, {-1e-10, 0, 0}},
                             Scene{{1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0}}}) {
    const Prediction p = predictionOf(scene);
    const AnalyticModel<DeepPrecision> deep(scene);
    const auto exact = deep.velocitiesAfter(*p.impact_count);
    EXPECT_TRUE(p.uncertified.empty()) << describe(scene);
    for (int i = 0; i < 3; ++i) {
      if (scene.isWall(i)) {
        EXPECT_EQ(p.final_velocities[i], scene.velocities[i]);
        continue;
      }
      EXPECT_TRUE(nearestTo(p.final_velocities[i], exact(i))) << describe(scene) << " body " << i << ": "
                                                             << p.final_velocities[i];
    }
  }
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
