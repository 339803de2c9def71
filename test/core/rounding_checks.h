// Checks of correct rounding for the tests, on exact rationals: the one home of the test
// suite's definition of a correctly rounded double (rational_reference.h and the N-body
// tests both use it).
#pragma once

#include <cmath>
#include <limits>

#include <boost/multiprecision/cpp_int.hpp>

namespace collision_lab {
namespace core {
namespace testing_support {

/// Is `value` the double nearest to `exact` (either one on an exact tie)? Exact: the
/// distances to `value` and to its two neighbours are compared as rationals.
inline bool correctlyRounded(double value, const boost::multiprecision::cpp_rational& exact) {
  using Q = boost::multiprecision::cpp_rational;
  if (!std::isfinite(value)) return false;
  const Q distance = abs(Q(value) - exact);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const double neighbour : {std::nextafter(value, kInf), std::nextafter(value, -kInf)}) {
    if (std::isfinite(neighbour) && abs(Q(neighbour) - exact) < distance) return false;
  }
  return true;
}

/// Is `value` within `relative` of the exact `truth` (relatively)?
inline bool closeToExact(double value, const boost::multiprecision::cpp_rational& truth, double relative) {
  using Q = boost::multiprecision::cpp_rational;
  if (!std::isfinite(value)) return false;
  return abs(Q(value) - truth) <= Q(relative) * abs(truth);
}

}  // namespace testing_support
}  // namespace core
}  // namespace collision_lab
