// The number types of the engine's three tiers and what the error bounds need to know
// about them: the relative error of one operation (eta), whether they are exact, the
// relative error of a conversion to double, and conversions between tiers.
//   tier 0: double-double (about 106 bits), the working precision (DD, or DDFma on the
//           FMA path: fma_path.h)
//   tier 1: cpp_bin_float_100 (about 333 bits), replays for near-ties
//   tier 2: cpp_rational, exact, replays for exact ties
// Internal to the engine; not installed.
#pragma once

#include <cmath>
#include <type_traits>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_int.hpp>

#include "double_double.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {

using Float100 = boost::multiprecision::cpp_bin_float_100;
using Rational = boost::multiprecision::cpp_rational;

/// DD or DDFma: the working tier's double-double (the same values either way).
template <class S>
inline constexpr bool kIsDoubleDouble = std::is_same_v<S, DD> || std::is_same_v<S, DDFma>;

template <class S>
struct Arithmetic;

template <bool kFma>
struct Arithmetic<BasicDD<kFma>> {
  static constexpr bool kExact = false;
  static constexpr double kOpError = kDoubleDoubleOpError;
  static constexpr double kToDoubleError = 0x1p-53;  // hi is the double nearest to hi + lo
  static double toDouble(const BasicDD<kFma>& x) { return x.hi; }
  static int sign(const BasicDD<kFma>& x) { return x.hi > 0 ? 1 : (x.hi < 0 ? -1 : 0); }
};

template <>
struct Arithmetic<Float100> {
  static constexpr bool kExact = false;
  // 333-bit significand, correctly rounded; the bound leaves a wide margin.
  static constexpr double kOpError = 0x1p-320;
  static constexpr double kToDoubleError = 0x1p-51;
  static double toDouble(const Float100& x) { return static_cast<double>(x); }
  static int sign(const Float100& x) { return x.sign(); }
};

template <>
struct Arithmetic<Rational> {
  static constexpr bool kExact = true;
  static constexpr double kOpError = 0.0;
  static constexpr double kToDoubleError = 0x1p-51;
  static double toDouble(const Rational& x) { return static_cast<double>(x); }
  static int sign(const Rational& x) { return x.sign(); }
};

/// Converts a value of a more precise tier to tier To. The relative error of the result is
/// at most conversionError<To>().
template <class To, class From>
To convertTo(const From& x) {
  if constexpr (std::is_same_v<To, From>) {
    return x;
  } else if constexpr (kIsDoubleDouble<To>) {
    const Float100 wide = convertTo<Float100>(x);
    const double hi = static_cast<double>(wide);
    const double lo = static_cast<double>(Float100(wide - hi));
    const DD sum = fastTwoSum(hi, lo);
    return To(sum.hi, sum.lo, 0);
  } else {
    static_assert(std::is_same_v<To, Float100> && std::is_same_v<From, Rational>, "tiers convert downwards");
    return Float100(numerator(x)) / Float100(denominator(x));
  }
}

template <class To>
constexpr double conversionError() {
  if constexpr (kIsDoubleDouble<To>) return 0x1p-100;
  if constexpr (std::is_same_v<To, Float100>) return 0x1p-320;
  return 0.0;
}

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
