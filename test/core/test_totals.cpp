// totalsOf: the momentum and kinetic energy a lab compares, each the exact value of the
// input doubles correctly rounded (rounding_checks.h's definition, on exact rationals).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <boost/multiprecision/cpp_int.hpp>

#include "collision_lab/core/totals.h"
#include "rounding_checks.h"

namespace collision_lab {
namespace core {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The paper's printed final velocities for equal_masses (1, 1, 1 kg from -1, 0, 1 m/s) carry
// momentum and energy the scene never had (issue 45): 2.5 kg m/s against 0, 1.921875 J
// against 1 J (by hand: 1.375^2 = 1.890625).
TEST(Totals, ThePapersEqualMassesVelocitiesAgainstTheStart) {
  const Totals start = totalsOf({1, 1, 1}, {-1, 0, 1});
  EXPECT_EQ(start.momentum, 0.0);
  EXPECT_EQ(start.kinetic_energy, 1.0);
  const Totals paper = totalsOf({1, 1, 1}, {1.375, 1.375, -0.25});
  EXPECT_EQ(paper.momentum, 2.5);
  EXPECT_EQ(paper.kinetic_energy, 1.921875);
}

// Summed in double, 1e16 + 1 - 1e16 loses the 1; exactly, it is the momentum.
TEST(Totals, NoCancellationLosesAMomentum) {
  EXPECT_EQ(totalsOf({1, 1, 1}, {1e16, 1, -1e16}).momentum, 1.0);
}

// A wall's infinite mass is left out: only the finite masses' momentum and energy.
TEST(Totals, WallsAreLeftOut) {
  const Totals t = totalsOf({kInf, 1, kInf}, {5, 2, -3});
  EXPECT_EQ(t.momentum, 2.0);
  EXPECT_EQ(t.kinetic_energy, 2.0);
}

TEST(Totals, SeededStatesAreCorrectlyRounded) {
  using Q = boost::multiprecision::cpp_rational;
  std::mt19937_64 rng(45);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-40, 40);
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = 2 + trial % 9;
    std::vector<double> m(n), v(n);
    Q momentum = 0, energy = 0;
    for (std::size_t i = 0; i < n; ++i) {
      m[i] = std::ldexp(std::fabs(mantissa(rng)) + 0.5, exponent(rng));
      v[i] = std::ldexp(mantissa(rng), exponent(rng) / 2);
      momentum += Q(m[i]) * Q(v[i]);
      energy += Q(m[i]) * Q(v[i]) * Q(v[i]) / 2;
    }
    const Totals t = totalsOf(m, v);
    EXPECT_TRUE(testing_support::correctlyRounded(t.momentum, momentum)) << trial;
    EXPECT_TRUE(testing_support::correctlyRounded(t.kinetic_energy, energy)) << trial;
  }
}

// The centre of mass: by hand for a wall and two bodies (1 kg at 2 m, 3 kg at 0 m, moving
// -1 and 1 m/s: M = 4 kg, X = 0.5 m, V = 0.5 m/s), then against exact rationals on seeded
// scenes, where P / M is not a dyadic number (1/3, 1/10, ...).
TEST(Totals, CentreOfMassIsTheExactOneCorrectlyRounded) {
  using Q = boost::multiprecision::cpp_rational;
  const CentreOfMass wall = centreOfMass({kInf, 1, 3}, {5, 2, 0}, {0, -1, 1});
  EXPECT_EQ(wall.mass, 4.0);
  EXPECT_EQ(wall.position, 0.5);
  EXPECT_EQ(wall.velocity, 0.5);
  const CentreOfMass third = centreOfMass({1, 1, 1}, {2, 1, 0}, {1, 0, 0});
  EXPECT_EQ(third.velocity, 1.0 / 3.0);  // 1/3 correctly rounded is the double 1.0 / 3.0
  EXPECT_EQ(third.position, 1.0);
  EXPECT_TRUE(std::isnan(centreOfMass({kInf}, {0}, {1}).velocity));
  std::mt19937_64 seeded(45);
  std::uniform_real_distribution<double> value(-1, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = 2 + trial % 7;
    std::vector<double> m(n), x(n), v(n);
    Q mass = 0, moment = 0, momentum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      m[i] = std::ldexp(std::fabs(value(seeded)) + 0.1, trial % 20 - 10);
      x[i] = value(seeded) * 100;
      v[i] = value(seeded);
      mass += Q(m[i]), moment += Q(m[i]) * Q(x[i]), momentum += Q(m[i]) * Q(v[i]);
    }
    const CentreOfMass c = centreOfMass(m, x, v);
    EXPECT_TRUE(testing_support::correctlyRounded(c.mass, mass)) << trial;
    EXPECT_TRUE(testing_support::correctlyRounded(c.position, moment / mass)) << trial;
    EXPECT_TRUE(testing_support::correctlyRounded(c.velocity, momentum / mass)) << trial;
  }
}

// Each body's kinetic energy, a wall's 0: 2 kg at 3 m/s has 9 J; 0.1 kg at 0.1 m/s has
// 0.0005 J, which is not a double: the nearest one.
TEST(Totals, EachBodysKineticEnergyIsCorrectlyRounded) {
  using Q = boost::multiprecision::cpp_rational;
  const std::vector<double> k = kineticEnergies({2, 0.1, kInf}, {3, 0.1, 5});
  ASSERT_EQ(k.size(), 3u);
  EXPECT_EQ(k[0], 9.0);
  EXPECT_TRUE(testing_support::correctlyRounded(k[1], Q(0.1) * Q(0.1) * Q(0.1) / 2));
  EXPECT_EQ(k[2], 0.0);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
