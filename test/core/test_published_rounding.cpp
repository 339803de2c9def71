// Issue 44: the rotation model's published values are the correctly rounded exact values of
// what they name, as the simulation's are. References share no code with the core: exact
// rationals (rational_reference.h, a textbook event loop), and other formulas at 500 bits
// (acos for alpha, tan for r_c; the closed form at 500 bits for long runs). Two bodies and
// the spiral: nbody/test_published_rounding_nbody.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <boost/math/constants/constants.hpp>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/precision.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/core/wedge.h"
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
      EXPECT_TRUE(result.prediction->uncertified.empty())
          << describe(scene) << ": " << result.prediction->uncertified.front();
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

/// The paper's eqs. (2.15)/(2.16) after impact n, transcribed again at 500 bits with cos and
/// sin of (n/2) theta from the library's trigonometry (the core walks lambda_+^k in integers).
std::array<DeepPrecision, 3> printedVelocitiesAt500Bits(const Scene& scene, std::uint64_t n) {
  using D = DeepPrecision;
  const D m_a(scene.masses[0]), m_b(scene.masses[1]), m_c(scene.masses[2]);
  const D m_ab = m_a + m_b, m_bc = m_b + m_c, total = m_a + m_b + m_c;
  const D root = sqrt(m_a * m_b * m_c * total);
  const D c = 2 * m_a * m_c / (m_a * m_ab), d = root / (m_a * m_ab), nu_sq = c * c + d * d;
  const D theta = atan2(2 * root / (m_ab * m_bc), (m_a * m_c - m_b * total) / (m_ab * m_bc));
  const D angle = theta * D(n / 2);
  const D vbar = (D(scene.velocities[0]) + D(scene.velocities[1])) / 2;
  const D half_ba = (D(scene.velocities[1]) - D(scene.velocities[0])) / 2, v_c(scene.velocities[2]);
  const D x = ((vbar - v_c) * nu_sq + c * half_ba) * sin(angle) - d * half_ba * cos(angle);
  const D y = (-half_ba - c * (vbar - v_c)) * sin(angle) - d * (vbar - v_c) * cos(angle);
  if (n % 2 == 0) return {x / d + vbar, -x / d + vbar, y / d + vbar};
  return {(m_a - 3 * m_b) * x / (d * m_ab) + vbar, (m_b - 3 * m_a) * x / (d * m_ab) + vbar, y / d + vbar};
}

TEST(PublishedRounding, PsiIsCorrectlyRounded) {
  // psi against the rotation model at 500 bits (its wedge vectors, atan2), with and without
  // a wall, the three-body presets among them.
  std::vector<Scene> scenes = {{{1, 1, 1}, {2, 1, -1}, {-1, 0, 1}}, {{100, 1, kInf}, {2, 1, 0}, {-1, 0, 0}},
                               {{kInf, 10, 1}, {3, 2, 0}, {-0.5, -1, 0}}, {{2, 1, 3}, {2, 1, 0}, {-1, 0, 0}}};
  std::mt19937_64 rng(4406);
  std::uniform_real_distribution<double> decade(-8.0, 8.0), unit(0.0, 1.0);
  for (int k = 0; k < 60; ++k) {
    Scene scene{{std::pow(10.0, decade(rng)), std::pow(10.0, decade(rng)), std::pow(10.0, decade(rng))},
                {2, 1, 0},
                {-unit(rng), 2 * unit(rng) - 1, unit(rng)}};
    if (k % 4 == 1) scene.masses[0] = kInf, scene.velocities[0] = unit(rng) - 0.5;
    if (k % 4 == 3) scene.masses[2] = kInf, scene.velocities[2] = unit(rng) - 0.5;
    scenes.push_back(scene);
  }
  for (const Scene& scene : scenes) {
    const Prediction p = predictionOf(scene);
    ASSERT_TRUE(p.psi) << describe(scene);
    const DeepPrecision psi = AnalyticModel<DeepPrecision>(scene).psi();
    EXPECT_TRUE(nearestTo(*p.psi, psi)) << describe(scene) << ": psi " << *p.psi << " against " << psi.str(20);
    EXPECT_TRUE(std::find(p.uncertified.begin(), p.uncertified.end(), "psi") == p.uncertified.end());
  }
}

struct PrintedAngles {
  DeepPrecision phi_bc;          ///< eq. (3.21)
  DeepPrecision count_argument;  ///< (Omega - phi_BC) / theta of eq. (3.22)
};

/// phi_BC and the argument of eq. (3.22) from the wedge's vectors at 500 bits (no wall).
PrintedAngles printedAnglesAt500Bits(const Scene& scene) {
  using D = DeepPrecision;
  const Wedge<D> wedge = wedgeOf<D>(triple(scene.masses));
  const D m_a(scene.masses[0]), m_b(scene.masses[1]), m_c(scene.masses[2]);
  const D v_a(scene.velocities[0]), v_b(scene.velocities[1]);
  const D v_a1 = ((m_a - m_b) * v_a + 2 * m_b * v_b) / (m_a + m_b);
  const D v_b1 = (2 * m_a * v_a + (m_b - m_a) * v_b) / (m_a + m_b);
  const Eigen::Matrix<D, 3, 1> u1(sqrt(m_a) * v_a1, sqrt(m_b) * v_b1, sqrt(m_c) * scene.velocities[2]);
  Eigen::Matrix<D, 3, 1> l_bc = cross<D>(wedge.s_hat, wedge.n_bc);
  l_bc /= sqrt(l_bc.squaredNorm());
  const D phi = atan2(D(u1.dot(wedge.n_bc)), D(u1.dot(l_bc)));
  const D omega = acos(D(wedge.n_ab.dot(wedge.n_bc)));
  return {phi, (omega - phi) / (2 * wedge.alpha)};  // theta = arg lambda_+ = 2 alpha
}

TEST(PublishedRounding, ThePapersPrintedFormulasArePublishedAsTheirExactValuesRounded) {
  // The difference a class sees between the paper and the simulation is the formula's, not
  // the arithmetic's: eqs. (2.15)/(2.16) against the transcription at 500 bits, eqs.
  // (4.4)-(4.7) in rationals at the textbook loop's exact states, phi_BC (3.21) and the count
  // (3.22) from the wedge's vectors at 500 bits.
  std::vector<Scene> scenes = {{{1, 1, 1}, {3, 2, 0}, {-1, 0.3, 0.7}}, {{1, 2, 3}, {3, 2, 0}, {-1, 0.5, 1}},
                               {{1, 1, 1}, {2, 1, -1}, {-1, 0, 1}}};
  std::mt19937_64 rng(4404);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 20; ++k) {
    scenes.push_back({{1 + 30 * unit(rng), 1 + unit(rng), 1 + 30 * unit(rng)},
                      {1 + unit(rng), 0, -1 - unit(rng)},
                      {-unit(rng), 2 * unit(rng) - 1, unit(rng)}});
  }
  int values = 0;
  for (const Scene& scene : scenes) {
    const reference::Run run = reference::simulate(scene, 100);
    if (run.impacts.size() > 64) continue;
    const SceneRunResult result = runScene(planScene(scene), SceneRunOptions{});
    ASSERT_EQ(result.simulation.impacts.size(), run.impacts.size()) << describe(scene);
    const Q m_a(scene.masses[0]), m_b(scene.masses[1]), m_c(scene.masses[2]);
    const Q vbar = (Q(scene.velocities[0]) + Q(scene.velocities[1])) / 2;
    std::array<Q, 3> before{Q(scene.velocities[0]), Q(scene.velocities[1]), Q(scene.velocities[2])};
    std::array<Q, 3> two_before = before;
    for (std::size_t n = 0; n < run.impacts.size(); ++n) {
      const ImpactModelValues& model = *result.simulation.impacts[n].model;
      const auto printed = printedVelocitiesAt500Bits(scene, n + 1);
      for (int i = 0; i < 3; ++i) {
        EXPECT_TRUE(nearestTo(model.paper_velocities_after[i], printed[i]))
            << describe(scene) << " impact " << n + 1 << " body " << i << ": " << model.paper_velocities_after[i];
        ++values;
      }
      std::array<Q, 3> gained{0, 0, 0};
      if (run.impacts[n].pair == Pair::AB) {  // (4.4), (4.5)
        gained[0] = -4 * m_a * m_b * (before[0] - vbar) * (m_a * before[0] + m_b * before[1]) / ((m_a + m_b) * (m_a + m_b));
        gained[1] = -gained[0];
      } else if (n > 0) {  // (4.6), (4.7)
        gained[2] = -4 * m_b * m_c / ((m_b + m_c) * (m_b + m_c)) * (two_before[0] - vbar + two_before[2] - vbar) / 2 *
                    (m_b * before[1] + m_c * before[2]);
        gained[1] = -gained[2];
      }
      for (int i = 0; i < 3; ++i) {
        if (run.impacts[n].pair == Pair::BC && n == 0 && i > 0) continue;  // undefined as printed (NaN)
        EXPECT_TRUE(correctlyRounded(model.paper_energy_transfer[i], gained[i]))
            << describe(scene) << " impact " << n + 1 << " body " << i << ": " << model.paper_energy_transfer[i];
      }
      two_before = before;
      before = run.impacts[n].velocities;
    }
    const Prediction& p = *result.prediction;
    const PrintedAngles printed = printedAnglesAt500Bits(scene);
    ASSERT_TRUE(p.phi_bc);
    EXPECT_TRUE(nearestTo(*p.phi_bc, printed.phi_bc)) << describe(scene) << ": phi_BC " << *p.phi_bc;
    const DeepPrecision& x = printed.count_argument;
    ASSERT_TRUE(p.paper_impact_count);
    EXPECT_EQ(*p.paper_impact_count, 1 + static_cast<std::int64_t>(floor(x)) + static_cast<std::int64_t>(ceil(x)))
        << describe(scene);
    EXPECT_TRUE(p.uncertified.empty()) << describe(scene);
  }
  EXPECT_GE(values, 150);
  // A grazing start: (Omega - phi_BC) / theta is an integer j (to 500 bits here; the core
  // decides it exactly), and eq. (3.22) gives 1 + 2 j.
  const Scene grazing{{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}};
  const DeepPrecision x = printedAnglesAt500Bits(grazing).count_argument;
  const DeepPrecision j = round(x);
  ASSERT_LT(abs(x - j), 1e-140);
  const Prediction p = predictionOf(grazing);
  EXPECT_EQ(p.paper_impact_count, 1 + 2 * static_cast<std::int64_t>(j));
  EXPECT_TRUE(p.uncertified.empty());
}

TEST(PublishedRounding, TheFiltersAnglesAreTheExactOnesRoundedAcrossTheDoubleRange) {
  // psi, phi_BC and the paper's count come from the filter (long double with a running error
  // bound, no rationals) wherever its bound decides, and from exact rationals elsewhere:
  // either way the exact value rounded. Seeded scenes across the double range, with exact
  // ties (v_B = v_C, v_A = v_B), exact zeros and walls; against 500 bits.
  std::mt19937_64 rng(4810);
  std::uniform_real_distribution<double> unit(0.0, 1.0), mass_decade(-15.0, 15.0), speed_decade(-30.0, 30.0);
  const auto speed = [&] { return (unit(rng) < 0.5 ? -1 : 1) * std::pow(10.0, speed_decade(rng)); };
  int counts_checked = 0;
  for (int k = 0; k < 400; ++k) {
    Scene scene{{std::pow(10.0, mass_decade(rng)), std::pow(10.0, mass_decade(rng)), std::pow(10.0, mass_decade(rng))},
                {2, 1, 0},
                {speed(), speed(), speed()}};
    if (k % 5 == 0) scene.velocities[2] = scene.velocities[1];  // on the BC mirror
    if (k % 5 == 1) scene.velocities[0] = scene.velocities[1];  // on the AB mirror
    if (k % 5 == 2) scene.velocities[k % 3] = 0.0;
    if (k % 7 == 3) scene.masses[0] = kInf;
    if (k % 7 == 4) scene.masses[2] = kInf;
    if (scene.velocities[0] == scene.velocities[1] && scene.velocities[1] == scene.velocities[2]) continue;
    const ScenePlan plan = planScene(scene);
    if (plan.error) continue;  // beyond the lab's envelope (the count's range)
    const Prediction& p = *plan.prediction;
    SCOPED_TRACE(describe(scene));
    ASSERT_TRUE(p.psi);
    const DeepPrecision psi = AnalyticModel<DeepPrecision>(scene).psi();
    if (scene.velocities[1] == scene.velocities[2]) {
      // On the BC mirror psi is exactly 0 or pi; 500 bits put 0 next to 0 or next to 2 pi.
      EXPECT_EQ(*p.psi, abs(psi - boost::math::constants::pi<DeepPrecision>()) < 1 ? M_PI : 0.0) << psi.str(20);
    } else {
      EXPECT_TRUE(nearestTo(*p.psi, psi)) << "psi " << *p.psi;
    }
    EXPECT_TRUE(p.uncertified.empty()) << p.uncertified.front();
    if (scene.isWall(0) || scene.isWall(2)) continue;  // the printed angles are inf / inf
    const PrintedAngles printed = printedAnglesAt500Bits(scene);
    ASSERT_TRUE(p.phi_bc);
    EXPECT_TRUE(nearestTo(*p.phi_bc, printed.phi_bc)) << "phi_BC " << *p.phi_bc;
    const DeepPrecision& x = printed.count_argument;
    if (abs(x - round(x)) < 1e-100) continue;  // a grazing start: decided exactly (the test above)
    ASSERT_TRUE(p.paper_impact_count);
    EXPECT_EQ(*p.paper_impact_count, 1 + static_cast<std::int64_t>(floor(x)) + static_cast<std::int64_t>(ceil(x)));
    ++counts_checked;
  }
  EXPECT_GT(counts_checked, 150);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
