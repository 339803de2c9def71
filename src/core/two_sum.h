// Error-free addition, shared by the engine's compensated sums. Private to the core.
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

}  // namespace detail
}  // namespace core
}  // namespace collision_lab
