// Small floating-point helpers shared by the engine, the closed form and the lab run, for
// double, long double and the multiprecision types alike. Private to the core.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace collision_lab {
namespace core {
namespace detail {

/// a + b = sum + error exactly (Knuth's TwoSum), in any type T that rounds to nearest.
template <class T>
struct TwoSum {
  T sum;
  T error;
};

template <class T>
TwoSum<T> twoSum(const T& a, const T& b) {
  const T sum = a + b;
  const T b_part = sum - a;
  return {sum, (a - (sum - b_part)) + (b - b_part)};
}

/// |x| in any T (std::abs has no overload for every multiprecision expression).
template <class T>
T absOf(const T& x) {
  return x < 0 ? T(-x) : x;
}

/// Rounds to double; a zero is always +0, so that no output shows "-0".
template <class T>
double toDouble(const T& value) {
  const double rounded = static_cast<double>(value);
  return rounded == 0 ? 0.0 : rounded;
}

/// Is each of `a` within 4 ulps of its entry of `b` (a zero against a value below 2^-1000)?
/// The test of a substitution: a certified value for one a few roundings away.
template <class A, class B>
bool withinUlps(const A& a, const B& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double size = std::max(std::fabs(a[i]), std::fabs(b[i]));
    const double ulp = std::nextafter(size, HUGE_VAL) - size;
    if (!(std::fabs(a[i] - b[i]) <= 4 * std::max(ulp, 0x1p-1000))) return false;
  }
  return true;
}

/// Does every value survive scaling by 2^shift and back unchanged?
template <class Values>
bool scalesExactly(const Values& values, int shift) {
  for (double x : values) {
    if (std::ldexp(std::ldexp(x, shift), -shift) != x) return false;
  }
  return true;
}

/// The shift that brings the largest finite |value| to [1/2, 1), or as close as it goes
/// without rounding any value (scaling down can push low bits below the smallest
/// subnormal). Infinities (walls) are left out; they stay infinite. Values: any range of
/// doubles (three bodies' array, a scene's vector).
template <class Values>
int shiftTowardsOne(const Values& values) {
  double largest = 0.0;
  for (double x : values) {
    if (std::isfinite(x)) largest = std::fabs(x) > largest ? std::fabs(x) : largest;
  }
  if (largest == 0.0) return 0;
  int exponent = 0;
  std::frexp(largest, &exponent);  // largest = f 2^exponent, f in [1/2, 1)
  int shift = -exponent;
  while (shift < 0 && !scalesExactly(values, shift)) ++shift;
  return shift;
}

}  // namespace detail
}  // namespace core
}  // namespace collision_lab
