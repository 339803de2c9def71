// Small floating-point helpers shared by the engine, the closed form and the lab run, for
// double, long double and the multiprecision types alike. Private to the core.
#pragma once

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

}  // namespace detail
}  // namespace core
}  // namespace collision_lab
