// The 100-digit tier's conversion to double (arithmetic.h, toDoubleNearest) gives the double
// Boost.Multiprecision's own conversion gives, the nearest one with ties to even: on random
// quotients, products and sums, exact ties, carries into the next binade, and the edges of
// the normal range, where it hands over to Boost's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "arithmetic.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {
namespace {

TEST(TierArithmetic, TheHundredDigitTiersDoubleIsBoostsNearestDouble) {
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int compared = 0, differ = 0;
  const auto check = [&](const Float100& x) {
    const double fast = toDoubleNearest(x), boost = static_cast<double>(x);
    ++compared;
    if (std::memcmp(&fast, &boost, sizeof(double)) != 0 && ++differ <= 5) {
      ADD_FAILURE() << "toDoubleNearest " << std::hexfloat << fast << ", static_cast " << boost;
    }
  };
  for (int k = 0; k < 50000; ++k) {
    const double a = unit(rng) * std::exp2(900 * unit(rng)), b = unit(rng) * std::exp2(100 * unit(rng));
    const double c = unit(rng);
    check(Float100(a) / Float100(b));
    check(Float100(a) * Float100(b) + Float100(c));
    // Exact ties between two doubles, and a hair either side of them.
    const double d = unit(rng) * std::exp2(500 * unit(rng));
    const Float100 half_ulp = Float100(std::nextafter(d, HUGE_VAL) - d) / 2;
    const Float100 hair = Float100(std::exp2(-300)) * Float100(d);
    check(Float100(d) + half_ulp);
    check(Float100(d) - half_ulp);
    check(Float100(d) + half_ulp + hair);
    check(Float100(d) + half_ulp - hair);
    // 53 ones and a half: the rounding carries into the next power of two.
    const Float100 scale(std::ldexp(1.0, static_cast<int>(300 * unit(rng))));  // a power of two: exact
    check((Float100(std::ldexp(1.0, 53) - 1) + Float100(0.5)) * scale);
  }
  for (int e = -1100; e <= 1100; e += 25) {
    check(Float100(1.5) * boost::multiprecision::pow(Float100(2), e));
    check(-Float100(1.75) * boost::multiprecision::pow(Float100(2), e));
  }
  for (int e : {-1075, -1074, -1022, -1001, -1000, 1000, 1001, 1023, 1024}) {
    check(Float100(1.25) * boost::multiprecision::pow(Float100(2), e));
  }
  check(Float100(0));
  check(-Float100(0));
  check(Float100(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(differ, 0) << "of " << compared;
}

}  // namespace
}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
