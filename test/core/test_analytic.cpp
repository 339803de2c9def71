// The closed-form model against the simulation and exact arithmetic (the independent
// reference of rational_reference.h, no core::exact).
#include <gtest/gtest.h>
#include <complex>
#include <algorithm>

#include <Eigen/Eigenvalues>

#include <boost/math/constants/constants.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <cmath>
#include <random>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/scene_run.h"
#include "rational_reference.h"
#include "scenes.h"
#include "simulated_run.h"

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
    // Eigen's general solver on D against the closed form 1, exp(+-i theta), both sorted
    // by argument.
    const AnalyticModel<double> model(threeBodies(masses, {2, 1, 0}));
    const Eigen::Matrix3d d = model.D();
    const Eigen::EigenSolver<Eigen::Matrix3d> solver(d, false);
    std::array<std::complex<double>, 3> found, closed_form{std::complex<double>(1, 0), std::polar(1.0, model.theta()),
                                                             std::polar(1.0, -model.theta())};
    for (int i = 0; i < 3; ++i) found[i] = solver.eigenvalues()(i);
    const auto by_argument = [](const std::complex<double>& a, const std::complex<double>& b) {
      return std::arg(a) < std::arg(b);
    };
    std::sort(found.begin(), found.end(), by_argument);
    std::sort(closed_form.begin(), closed_form.end(), by_argument);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(std::abs(found[i] - closed_form[i]), 1e-12);
      EXPECT_NEAR(std::abs(found[i]), 1.0, 1e-12);
    }
    EXPECT_NEAR(d.determinant(), 1.0, 1e-12);
  }
  // D = D_BC D_AB equals the paper's explicit matrix (1.8), which is correct.
  const Scene scene{{1, 2, 3}, {2, 1, 0}, {-1, 0, 1}};
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
    const Scene scene = randomScene(rng);
    const reference::Run reference = reference::simulate(scene, 100000);
    ASSERT_FALSE(reference.truncated);
    const AnalyticModel<double> model(scene);
    for (std::uint64_t n = 1; n <= reference.impacts.size(); ++n) {
      const std::array<reference::Q, 3>& state = reference.impacts[n - 1].velocities;
      ASSERT_LE(energyNormError(scene, {model.velocitiesAfter(n)(0), model.velocitiesAfter(n)(1),
                                        model.velocitiesAfter(n)(2)},
                                state),
                1e-12)
          << "scene " << i << " n " << n;
    }
  }
}

TEST(ClosedForm, AgreesWithSimulationUpToAMillionCollisions) {
  const Scene scene{{2e11, 1, 3e11}, {2, 1, 0}, {-1, 0.5, 0.2}};
  double worst = 0.0;
  const AnalyticModel<long double> model(scene);
  const SceneSimulation result = testing_support::simulateThreeBodies(scene, EventPolicy::none(), 10'000'000, [&](const testing_support::ThreeBodyImpact& e) {
    if (e.index % 997 != 0) return;
    const auto predicted = model.velocitiesAfter(e.index);
    const std::array<reference::Q, 3> p{reference::Q(static_cast<double>(predicted(0))),
                                        reference::Q(static_cast<double>(predicted(1))),
                                        reference::Q(static_cast<double>(predicted(2)))};
    worst = std::max(worst, energyNormError(scene, e.velocities_after, p));
  }).summary;
  EXPECT_GT(result.impact_count, 500000u);
  EXPECT_LT(result.impact_count, 1500000u);
  EXPECT_EQ(predictedImpactCount(scene), result.impact_count);
  EXPECT_LE(worst, 1e-11);
}

TEST(Count, PiBilliardByClosedForm) {
  // m_A / m_B = 100^8 with a wall: the first nine digits of pi.
  const Scene scene{{1e16, 1, kInf}, {2, 1, 0}, {-1, 0, 0}};
  EXPECT_EQ(predictedImpactCount(scene), 314159265u);
  EXPECT_EQ(maxPossibleImpactCount({1e2, 1, kInf}), 32u);
}

TEST(Count, MaxPossibleIsExactForKaleidoscopicMasses) {
  EXPECT_EQ(maxPossibleImpactCount({1, 1, 1}), 3u);
  // One unit in the last place off (1, 1, 1): cos^2 alpha just above 1/4, alpha just below
  // pi/3, so pi/alpha just above 3.
  EXPECT_EQ(maxPossibleImpactCount({1, 1, 1 + 0x1p-52}), 4u);
  EXPECT_EQ(maxPossibleImpactCount({kInf, 1, 1}), 4u);           // cos^2 = 1/2: pi/4
  EXPECT_EQ(maxPossibleImpactCount({5 * 0x1p1020, 0x1p1020, 9 * 0x1p1020}), 6u);  // (5, 1, 9) scaled: 3/4
  EXPECT_EQ(maxPossibleImpactCount({2, 1, 3}), 4u);
  EXPECT_EQ(maxPossibleImpactCount({5, 1, 9}), 6u);
  EXPECT_EQ(maxPossibleImpactCount({1e12, 1, 1e12}), 2221442u);
  // A heavy B: alpha -> pi/2, pi/alpha exceeds 2 by ~1e-60; 3 collisions are possible.
  EXPECT_EQ(maxPossibleImpactCount({1, 1e60, 1}), 3u);
  EXPECT_EQ(predictedImpactCount(Scene{{1, 1e60, 1}, {1e80, 1, 0}, {-1e61, 0, 1}}), 3u);
  // No start exceeds the bound.
  std::mt19937_64 rng(3);
  for (int i = 0; i < 300; ++i) {
    const Scene scene = randomScene(rng);
    EXPECT_LE(predictedImpactCount(scene), maxPossibleImpactCount(triple(scene.masses)));
  }
}

/// The count from physics.md (Erratum 4), computed here from first principles at 100 digits
/// and sharing no code with AnalyticModel: u = S v, the escape cone's boundary rays
/// r_BC = s x n_BC and r_AB = s x n_AB (oriented into the cone), psi the angle of u from r_BC
/// towards r_AB, alpha the cone's opening angle, N = ceil(psi / alpha) - 1 (AB first).
/// Preconditions: finite masses, only AB approaches (so AB is first).
std::uint64_t countFromFirstPrinciples(const Scene& scene) {
  using Precise = boost::multiprecision::cpp_bin_float_100;
  using Vec = std::array<Precise, 3>;
  const auto dot = [](const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const auto cross = [](const Vec& a, const Vec& b) {
    return Vec{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  Vec root_m, u;
  for (int i = 0; i < 3; ++i) {
    root_m[i] = sqrt(Precise(scene.masses[i]));
    u[i] = root_m[i] * Precise(scene.velocities[i]);
  }
  const Vec n_ab{1 / root_m[0], -1 / root_m[1], Precise(0)};
  const Vec n_bc{Precise(0), 1 / root_m[1], -1 / root_m[2]};
  Vec r_bc = cross(root_m, n_bc);
  if (dot(n_ab, r_bc) < 0) r_bc = Vec{-r_bc[0], -r_bc[1], -r_bc[2]};
  Vec r_ab = cross(root_m, n_ab);
  if (dot(n_bc, r_ab) < 0) r_ab = Vec{-r_ab[0], -r_ab[1], -r_ab[2]};
  // Orthonormal basis of the plane s-perp: e1 along r_BC, e2 towards r_AB.
  const Precise r_bc_norm = sqrt(dot(r_bc, r_bc));
  const Vec e1{r_bc[0] / r_bc_norm, r_bc[1] / r_bc_norm, r_bc[2] / r_bc_norm};
  const Precise along = dot(r_ab, e1);
  Vec e2{r_ab[0] - along * e1[0], r_ab[1] - along * e1[1], r_ab[2] - along * e1[2]};
  const Precise e2_norm = sqrt(dot(e2, e2));
  for (Precise& c : e2) c /= e2_norm;
  const Precise two_pi = 2 * boost::math::constants::pi<Precise>();
  const Precise alpha = atan2(dot(r_ab, e2), dot(r_ab, e1));
  Precise psi = atan2(dot(u, e2), dot(u, e1));  // u's component along s drops out
  if (psi < 0) psi += two_pi;
  return static_cast<std::uint64_t>(ceil(psi / alpha)) - 1;
}

TEST(Count, ExactUpToMassRatio1e20) {
  for (double ratio : {1e12, 1e14, 1e16, 1e18, 1e20}) {
    // Both starts have only AB approaching, and q = psi / alpha far from an integer.
    for (const auto& v : {std::array<double, 3>{-1, 0, 0}, std::array<double, 3>{-1, 0.3, 0.2}}) {
      const Scene scene = threeBodies({ratio, 1, 0.5 * ratio}, {2, 1, 0}, v);
      EXPECT_EQ(predictedImpactCount(scene), countFromFirstPrinciples(scene)) << ratio;
    }
  }
  // The reference itself against known counts: equal masses exchange velocities, so
  // (-1, 0.3, 0.2) gives 2 by hand (AB, then BC, then (0.3, 0.2, -1) separates), and
  // (1e12, 1, 1e12) from (-1, 0, 0) gives physics.md's 2,221,441.
  EXPECT_EQ(countFromFirstPrinciples(Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0.3, 0.2}}), 2u);
  EXPECT_EQ(countFromFirstPrinciples(Scene{{1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0}}), 2221441u);
  const Scene simulated{{1e12, 1, 0.5e12}, {2, 1, 0}, {-1, 0, 0}};
  EXPECT_EQ(predictedImpactCount(simulated), testing_support::simulateThreeBodies(simulated).summary.impact_count);
}

TEST(Count, FloorExceptWhenPsiOverAlphaIsAnInteger) {
  // (3, 1, 0.5) from (-1, 0, 0): q = 3 exactly, the third contact grazes, N = 2.
  const Scene grazing{{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}};
  const AnalyticModel<double> model(grazing);
  EXPECT_NEAR(model.psi() / model.alpha(), 3.0, 1e-12);
  EXPECT_EQ(predictedImpactCount(grazing), 2u);
  // Equal masses, (-1, 0, 1), AB first: 3 collisions (the paper's formula says even).
  EXPECT_EQ(predictedImpactCount(Scene{{1, 1, 1}, {3, 2, 0}, {-1, 0, 1}}), 3u);
}

TEST(ClosedForm, KeepsEnergyAndMomentumAtAnyImpactCount) {
  // Every impact is an isometry in the energy norm and keeps the momentum (the wall's frame
  // with a wall): so does the closed form at any n, far past the count as well (its
  // algebraic continuation), whatever rounding the angle n theta carries.
  std::mt19937_64 rng(11);
  for (int i = 0; i < 300; ++i) {
    const Scene scene = randomScene(rng);
    const AnalyticModel<double> model(scene);
    const int wall = wallIndex(scene);
    const double frame = wall >= 0 ? scene.velocities[wall] : 0.0;
    const auto energy = [&](const Eigen::Vector3d& v) {
      double sum = 0.0;
      for (int k = 0; k < 3; ++k) sum += k == wall ? 0.0 : scene.masses[k] * (v(k) - frame) * (v(k) - frame) / 2;
      return sum;
    };
    const auto momentum = [&](const Eigen::Vector3d& v) {
      double sum = 0.0, scale = 0.0;
      for (int k = 0; k < 3; ++k) {
        sum += scene.masses[k] * v(k);
        scale += std::fabs(scene.masses[k] * v(k));
      }
      return std::make_pair(sum, scale);
    };
    const Eigen::Vector3d v0(scene.velocities[0], scene.velocities[1], scene.velocities[2]);
    for (std::uint64_t n : {std::uint64_t{1}, predictedImpactCount(scene), std::uint64_t{1000001}, std::uint64_t{1} << 40}) {
      const Eigen::Vector3d v = model.velocitiesAfter(n);
      EXPECT_NEAR(energy(v), energy(v0), 1e-12 * energy(v0)) << i << " n=" << n;
      if (wall < 0) {
        const auto [p, scale] = momentum(v);
        EXPECT_NEAR(p, momentum(v0).first, 1e-12 * std::max(scale, momentum(v0).second)) << i << " n=" << n;
      }
    }
  }
}

TEST(EnergyTransfer, FiniteAtTheEdgesOfTheDoubleRange) {
  // Found by the fuzzer: intermediate products overflowed though the energies do not.
  const Scene tiny_masses{{2.6895203214236869e-306, 1.7765824089018436e-307, 1.7765824089018436e-307},
                          {1.7800590868057611e-307, 1.7765824089018436e-307, 0},
                          {5.1294921942786796e-305, -5.4861240687936887e+303, 1}};
  const Scene huge_mass{{kInf, 1.7e308, 1.7e308}, {5, 1, 0}, {0, 0, 1e-10}};
  for (const Scene& scene : {tiny_masses, huge_mass}) {
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
    const Scene scene = randomScene(rng);
    const AnalyticModel<double> model(scene);
    double energy = 0.0;
    for (int j = 0; j < 3; ++j) {
      if (!scene.isWall(j)) energy += 0.5 * scene.masses[j] * scene.velocities[j] * scene.velocities[j];
    }
    const auto result = testing_support::simulateThreeBodies(scene, EventPolicy::all());
    for (const testing_support::ThreeBodyImpact& e : result.events) {
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
