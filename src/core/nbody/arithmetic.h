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
#include <cstdint>
#include <cstring>
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

/// static_cast<double>(x), the same double (x's 334-bit significand rounded to 53 bits, ties
/// to even), read from the significand's top words instead of through a 53-bit
/// cpp_bin_float: about a sixth of the 100-digit tier's time went to that conversion. Zero,
/// infinities, NaN and results outside the normal range take static_cast.
inline double toDoubleNearest(const Float100& x) {
  const auto& value = x.backend();
  const auto exponent = value.exponent();  // x's leading bit is 2^exponent (special values: huge)
  if (exponent < -1000 || exponent > 1000) return static_cast<double>(x);
  constexpr unsigned kTop = Float100::backend_type::bit_count - 1;  // the significand's leading bit
  constexpr unsigned kLimb = kTop / 64, kOffset = kTop % 64;
  static_assert(kLimb >= 1 && kOffset < 63, "the leading bit's word is not the only one above the 53 bits");
  const auto& significand = value.bits();
  static_assert(sizeof(*significand.limbs()) == 8, "64-bit words");
  if (significand.size() != kLimb + 1) return static_cast<double>(x);
  const auto* words = significand.limbs();  // 64-bit words, the lowest first
  // The leading 64 bits; below them the rest of word kLimb - 1 and the words under it.
  const std::uint64_t window = (words[kLimb] << (63 - kOffset)) | (words[kLimb - 1] >> (kOffset + 1));
  bool sticky = (window & 0x3ff) != 0 || (words[kLimb - 1] & ((std::uint64_t{1} << (kOffset + 1)) - 1)) != 0;
  for (unsigned k = 0; k + 1 < kLimb && !sticky; ++k) sticky = words[k] != 0;
  std::uint64_t mantissa = window >> 11;  // 53 bits, the leading one set
  std::int64_t biased = static_cast<std::int64_t>(exponent) + 1023;
  if (((window >> 10) & 1) != 0 && (sticky || (mantissa & 1) != 0)) {
    if (++mantissa == std::uint64_t{1} << 53) mantissa >>= 1, ++biased;
  }
  const std::uint64_t word = (static_cast<std::uint64_t>(value.sign()) << 63) |
                             (static_cast<std::uint64_t>(biased) << 52) | (mantissa & ((std::uint64_t{1} << 52) - 1));
  double result;
  std::memcpy(&result, &word, sizeof result);
  return result;
}

template <>
struct Arithmetic<Float100> {
  static constexpr bool kExact = false;
  // 333-bit significand, correctly rounded; the bound leaves a wide margin.
  static constexpr double kOpError = 0x1p-320;
  static constexpr double kToDoubleError = 0x1p-51;
  static double toDouble(const Float100& x) { return toDoubleNearest(x); }
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
