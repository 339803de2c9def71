// The closed-form model against the simulation and exact arithmetic.
#include <gtest/gtest.h>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <random>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/simulation.h"
#include "scenes.h"

namespace collision_lab {
namespace core {
namespace {

using testing_support::energyNormError;
using testing_support::kInf;
using testing_support::randomScene;

TEST(Angles, AtanFormIsWellConditioned) {
  // physics.md: for (1e12, 1, 1e12) pi / alpha is 2221441.469 (the acos form is off).
  const Angles angles = anglesFor({1e12, 1, 1e12});
  EXPECT_NEAR(M_PI / angles.alpha, 2221441.469, 1e-3);
  EXPECT_DOUBLE_EQ(angles.theta, 2 * angles.alpha);
  EXPECT_DOUBLE_EQ(angles.omega, M_PI - angles.alpha);
  EXPECT_NEAR(anglesFor({1, 1, 1}).alpha, M_PI / 3, 1e-15);
  EXPECT_NEAR(anglesFor({100, 1, kInf}).alpha, std::atan(0.1), 1e-16);
}

TEST(Matrices, EigenSolverAgreesWithClosedFormEigenvalues) {
  for (const auto& masses : {std::array<double, 3>{1, 2, 3}, std::array<double, 3>{1e3, 1, 1e3},
                             std::array<double, 3>{0.5, 7, 2}, std::array<double, 3>{100, 1, kInf}}) {
    const EigenCheck check = eigenCheck(masses);
    EXPECT_LE(check.max_difference, 1e-12);
    EXPECT_NEAR(check.determinant, 1.0, 1e-12);
    for (const auto& lambda : check.eigen_solver) EXPECT_NEAR(std::abs(lambda), 1.0, 1e-12);
  }
  // D = D_BC D_AB equals the paper's explicit matrix (1.8), which is correct.
  const ThreeBodyScene scene{{1, 2, 3}, {2, 1, 0}, {-1, 0, 1}};
  const AnalyticModel<double> model(scene);
  const double m_a = 1, m_b = 2, m_c = 3, m_ab = 3, m_bc = 5;
  Eigen::Matrix3d paper;
  paper << m_bc * (m_a - m_b), 2 * m_bc * m_b, 0, 2 * m_a * (m_b - m_c), (m_b - m_a) * (m_b - m_c), 2 * m_c * m_ab,
      4 * m_a * m_b, 2 * m_b * (m_b - m_a), m_ab * (m_c - m_b);
  paper /= m_ab * m_bc;
  EXPECT_LE((model.D() - paper).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ClosedForm, MatchesExactStateAfterEveryCollision) {
  std::mt19937_64 rng(99);
  for (int i = 0; i < 200; ++i) {
    const ThreeBodyScene scene = randomScene(rng);
    const exact::Run reference = exact::simulate(scene, 100000);
    const AnalyticModel<double> model(scene);
    if (!reference.first_pair) continue;
    exact::RationalState state = exact::initialVelocities(scene);
    Pair pair = *reference.first_pair;
    for (std::uint64_t n = 1; n <= reference.collision_count; ++n) {
      exact::applyCollision(scene.masses, pair, state);
      pair = otherPair(pair);
      ASSERT_LE(energyNormError(scene, {model.velocitiesAfter(n)(0), model.velocitiesAfter(n)(1),
                                        model.velocitiesAfter(n)(2)},
                                state),
                1e-12)
          << "scene " << i << " n " << n;
    }
  }
}

TEST(ClosedForm, AgreesWithSimulationUpToAMillionCollisions) {
  const ThreeBodyScene scene{{2e11, 1, 3e11}, {2, 1, 0}, {-1, 0.5, 0.2}};
  SimulationOptions options;
  double worst = 0.0;
  const AnalyticModel<long double> model(scene);
  const SimulationResult result = simulate<double>(scene, options, [&](const ImpactEvent& e) {
    if (e.index % 997 != 0) return;
    const auto predicted = model.velocitiesAfter(e.index);
    const exact::RationalState p{exact::Rational(static_cast<double>(predicted(0))),
                                 exact::Rational(static_cast<double>(predicted(1))),
                                 exact::Rational(static_cast<double>(predicted(2)))};
    worst = std::max(worst, energyNormError(scene, e.velocities_after, p));
  });
  EXPECT_GT(result.collision_count, 500000u);
  EXPECT_LT(result.collision_count, 1500000u);
  EXPECT_EQ(predictedCollisionCount(scene), result.collision_count);
  EXPECT_LE(worst, 1e-11);
}

TEST(Count, PiBilliardByClosedForm) {
  // m_A / m_B = 100^8 with a wall: the first nine digits of pi.
  const ThreeBodyScene scene{{1e16, 1, kInf}, {2, 1, 0}, {-1, 0, 0}};
  EXPECT_EQ(predictedCollisionCount(scene), 314159265u);
  EXPECT_EQ(maxPossibleCollisionCount({1e2, 1, kInf}), 32u);
}

TEST(Count, MaxPossibleIsExactForKaleidoscopicMasses) {
  EXPECT_EQ(maxPossibleCollisionCount({1, 1, 1}), 3u);
  EXPECT_EQ(maxPossibleCollisionCount({2, 1, 3}), 4u);
  EXPECT_EQ(maxPossibleCollisionCount({5, 1, 9}), 6u);
  EXPECT_EQ(maxPossibleCollisionCount({1e12, 1, 1e12}), 2221442u);
  // A heavy B: alpha -> pi/2, pi/alpha exceeds 2 by ~1e-60; 3 collisions are possible.
  EXPECT_EQ(maxPossibleCollisionCount({1, 1e60, 1}), 3u);
  EXPECT_EQ(predictedCollisionCount(ThreeBodyScene{{1, 1e60, 1}, {1e80, 1, 0}, {-1e61, 0, 1}}), 3u);
  // No start exceeds the bound.
  std::mt19937_64 rng(3);
  for (int i = 0; i < 300; ++i) {
    const ThreeBodyScene scene = randomScene(rng);
    EXPECT_LE(predictedCollisionCount(scene), maxPossibleCollisionCount(scene.masses));
  }
}

TEST(Count, ExactUpToMassRatio1e20) {
  // Reference: floor(psi / alpha) evaluated independently at 100 digits.
  using Precise = boost::multiprecision::cpp_bin_float_100;
  for (double ratio : {1e12, 1e14, 1e16, 1e18, 1e20}) {
    for (const auto& v : {std::array<double, 3>{-1, 0, 0}, std::array<double, 3>{-1, 0.3, 0.2}}) {
      const ThreeBodyScene scene{{ratio, 1, 0.5 * ratio}, {2, 1, 0}, v};
      const AnalyticModel<Precise> model(scene);
      Precise q = model.psi() / model.alpha();
      if (*model.firstPair() == Pair::BC) {
        Precise psi_bc = model.alpha() - model.psi();
        if (psi_bc < 0) psi_bc += 2 * boost::math::constants::pi<Precise>();
        q = psi_bc / model.alpha();
      }
      const auto expected = static_cast<std::uint64_t>(static_cast<double>(floor(q)));
      EXPECT_EQ(predictedCollisionCount(scene), expected) << ratio;
    }
  }
  const ThreeBodyScene simulated{{1e12, 1, 0.5e12}, {2, 1, 0}, {-1, 0, 0}};
  EXPECT_EQ(predictedCollisionCount(simulated), simulate<double>(simulated, {}).collision_count);
}

TEST(Count, FloorExceptWhenPsiOverAlphaIsAnInteger) {
  // (3, 1, 0.5) from (-1, 0, 0): q = 3 exactly, the third contact grazes, N = 2.
  const ThreeBodyScene grazing{{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}};
  const AnalyticModel<double> model(grazing);
  EXPECT_NEAR(model.psi() / model.alpha(), 3.0, 1e-12);
  EXPECT_EQ(predictedCollisionCount(grazing), 2u);
  // Equal masses, (-1, 0, 1), AB first: 3 collisions (the paper's formula says even).
  EXPECT_EQ(predictedCollisionCount(ThreeBodyScene{{1, 1, 1}, {3, 2, 0}, {-1, 0, 1}}), 3u);
}

TEST(Inverse, RoundTripRecoversInitialVelocities) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 300; ++i) {
    const ThreeBodyScene scene = randomScene(rng);
    const AnalyticModel<double> model(scene);
    const std::uint64_t count = predictedCollisionCount(scene);
    for (std::uint64_t n : {std::uint64_t{0}, std::uint64_t{1}, count / 2, count}) {
      const Eigen::Vector3d back = model.initialVelocitiesFrom(model.velocitiesAfter(n), n);
      const exact::RationalState v0 = exact::initialVelocities(scene);
      EXPECT_LE(energyNormError(scene, {back(0), back(1), back(2)}, v0), 1e-12) << i << " n=" << n;
    }
  }
}

TEST(EnergyTransfer, FiniteAtTheEdgesOfTheDoubleRange) {
  // Found by the fuzzer: intermediate products overflowed though the energies do not.
  const ThreeBodyScene tiny_masses{{2.6895203214236869e-306, 1.7765824089018436e-307, 1.7765824089018436e-307},
                          {1.7800590868057611e-307, 1.7765824089018436e-307, 0},
                          {5.1294921942786796e-305, -5.4861240687936887e+303, 1}};
  const ThreeBodyScene huge_mass{{kInf, 1.7e308, 1.7e308}, {5, 1, 0}, {0, 0, 1e-10}};
  for (const ThreeBodyScene& scene : {tiny_masses, huge_mass}) {
    ASSERT_FALSE(validate(scene));
    const AnalyticModel<double> model(scene);
    for (std::uint64_t n = 1; n <= 3; ++n) {
      for (double gained : model.energyTransfer(n)) EXPECT_TRUE(std::isfinite(gained)) << n;
    }
  }
}

TEST(EnergyTransfer, ClosedFormMatchesSimulatedEvents) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 100; ++i) {
    const ThreeBodyScene scene = randomScene(rng);
    const AnalyticModel<double> model(scene);
    double energy = 0.0;
    for (int j = 0; j < 3; ++j) {
      if (!scene.isWall(j)) energy += 0.5 * scene.masses[j] * scene.velocities[j] * scene.velocities[j];
    }
    SimulationOptions options;
    options.events = EventPolicy::all();
    const SimulationResult result = simulate<double>(scene, options);
    for (const ImpactEvent& e : result.events) {
      const auto predicted = model.energyTransfer(e.index);
      for (int j = 0; j < 3; ++j) {
        EXPECT_NEAR(predicted[j], e.energy_transfer[j], 1e-10 * std::max(1.0, energy)) << i << " event " << e.index;
      }
    }
  }
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
