// The paper's printed formulas disagree with exact physics where physics.md says so.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

#include <Eigen/Dense>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/paper.h"
#include "collision_lab/core/scene_run.h"
#include "scenes.h"
#include "simulated_run.h"

namespace collision_lab {
namespace core {
namespace {

TEST(PaperErrata, Eigenvectors24AreNotEigenvectors) {
  // physics.md Erratum 1: with masses (1, 2, 3), the printed v_+ of eq. (2.4) misses
  // D v_+ = lambda_+ v_+ by 4.9, while the printed lambda_+ (2.2) is an eigenvalue.
  // D is eq. (1.8) as printed (correct), checked here against D_BC D_AB built from the
  // textbook impact rule.
  using Complex = std::complex<double>;
  const double ma = 1, mb = 2, mc = 3, mab = ma + mb, mbc = mb + mc, m = ma + mb + mc;
  Eigen::Matrix3d printed_d;
  printed_d << mbc * (ma - mb), 2 * mbc * mb, 0,  //
      2 * ma * (mb - mc), (mb - ma) * (mb - mc), 2 * mc * mab,  //
      4 * ma * mb, 2 * mb * (mb - ma), mab * (mc - mb);
  printed_d /= mab * mbc;
  Eigen::Matrix3d d_ab = Eigen::Matrix3d::Identity(), d_bc = Eigen::Matrix3d::Identity();
  d_ab.block<2, 2>(0, 0) << (ma - mb) / mab, 2 * mb / mab, 2 * ma / mab, (mb - ma) / mab;
  d_bc.block<2, 2>(1, 1) << (mb - mc) / mbc, 2 * mc / mbc, 2 * mb / mbc, (mc - mb) / mbc;
  EXPECT_LE((printed_d - d_bc * d_ab).norm(), 1e-15);

  const double root = std::sqrt(ma * mb * mc * m);
  const Complex lambda_plus = Complex(ma * mc - mb * m, 2 * root) / (mab * mbc);
  EXPECT_NEAR(std::abs(lambda_plus), 1.0, 1e-15);
  const Eigen::Matrix3cd shifted = printed_d.cast<Complex>() - lambda_plus * Eigen::Matrix3cd::Identity();
  EXPECT_LE(std::abs(shifted.determinant()), 1e-14);  // lambda_+ is right

  Eigen::Vector3cd v_plus;
  v_plus << Complex(-2 * ma * mc, root) / (ma * mab), Complex(2 * ma * mc, -root) / (ma * mab), 1.0;
  const double residual = (shifted * v_plus).norm();
  // 4.88 against |v_+| = 4.12 (physics.md: "about 4"): v_+ is not an eigenvector, nor close.
  EXPECT_GT(residual, 0.5 * v_plus.norm());
}

TEST(PaperErrata, ClosedFormVelocities215AreWrong) {
  // physics.md Erratum 2: masses (1,1,1), v0 = (-1, 0.3, 0.7), k = 1.
  const Scene scene{{1, 1, 1}, {3, 2, 0}, {-1, 0.3, 0.7}};
  const paper::PrintedClosedForm printed_form(scene);
  const auto printed = printed_form.velocitiesAfter(2, std::cos(printed_form.theta()), std::sin(printed_form.theta()));
  EXPECT_NEAR(printed[0], -1.2125, 1e-12);
  EXPECT_NEAR(printed[1], 0.5125, 1e-12);
  EXPECT_NEAR(printed[2], -0.475, 1e-12);
  // It does not even conserve momentum (initial momentum 0).
  EXPECT_GT(std::fabs(printed[0] + printed[1] + printed[2]), 0.1);
  // The truth: (0.3, 0.7, -1), exactly what the correct closed form gives.
  const auto truth = exact::velocitiesAfter(scene, Pair::AB, 2);
  EXPECT_EQ(truth[0], exact::Rational(0.3));
  EXPECT_EQ(truth[1], exact::Rational(0.7));
  EXPECT_EQ(truth[2], exact::Rational(-1.0));
  const auto correct = AnalyticModel<double>(scene).velocitiesAfter(2);
  EXPECT_NEAR(correct(0), 0.3, 1e-15);
  EXPECT_NEAR(correct(1), 0.7, 1e-15);
  EXPECT_NEAR(correct(2), -1.0, 1e-15);
}

TEST(PaperErrata, CollisionCount322IsEvenForNonIntegerArguments) {
  // Equal masses (-1, 0, 1) with AB first: 3 collisions; (3.22) cannot give an odd number.
  const Scene scene{{1, 1, 1}, {3, 2, 0}, {-1, 0, 1}};
  ASSERT_EQ(testing_support::simulateThreeBodies(scene).summary.impact_count, 3u);
  const auto printed = paper::impactCount(scene);
  ASSERT_TRUE(printed.has_value());
  EXPECT_NE(*printed, 3);
  // On seeded random AB-first starts it rarely matches; the correct count always does.
  std::mt19937_64 rng(2025);
  int matches = 0, ab_first = 0;
  for (int i = 0; i < 500; ++i) {
    const Scene s = testing_support::randomScene(rng);
    if (wallIndex(s) >= 0 || firstPair(s) != Pair::AB) continue;
    ++ab_first;
    const std::uint64_t truth = exact::walkVelocityMaps(s, 100000).impact_count;
    EXPECT_EQ(predictedImpactCount(s), truth);
    const auto p = paper::impactCount(s);
    matches += p && *p == static_cast<std::int64_t>(truth);
  }
  EXPECT_GT(ab_first, 100);
  EXPECT_LT(matches, ab_first / 2);
}

TEST(PaperErrata, EnergyTransfer44UsesTheWrongAverage) {
  // (4.4) with v_k against the initial vbar_AB differs from the true change once
  // v_A + v_B has changed, i.e. from the second AB impact on (collision 3).
  const Scene scene{{1, 2, 3}, {3, 2, 0}, {-1, 0.3, 0.7}};
  const auto result = testing_support::simulateThreeBodies(scene, EventPolicy::all());
  ASSERT_GE(result.summary.impact_count, 3u);
  const testing_support::ThreeBodyImpact& first = result.events[0];
  const auto printed_first =
      paper::energyTransfer(scene, 1, first.pair, first.velocities_before, triple(scene.velocities));
  EXPECT_NEAR(printed_first[0], first.energy_transfer[0], 1e-12);  // right at k = 0
  const testing_support::ThreeBodyImpact& third = result.events[2];
  ASSERT_EQ(third.pair, Pair::AB);
  const auto printed_third =
      paper::energyTransfer(scene, 3, third.pair, third.velocities_before, result.events[1].velocities_before);
  EXPECT_GT(std::fabs(printed_third[0] - third.energy_transfer[0]), 1e-3);
}

TEST(PaperErrata, OmegaAsPrintedIsPiMinusAlpha) {
  const std::array<double, 3> masses{1, 2, 3};
  EXPECT_NEAR(paper::omega(masses), anglesFor(masses).omega, 1e-14);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
