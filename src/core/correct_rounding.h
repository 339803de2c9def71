// Correct rounding of published values (physics.md, "How close the published values are"):
// the double nearest the exact value of what a number names, ties to even. Two ways in:
// an exact rational, rounded once; or a multiprecision value with a rigorous error bound,
// rounded when both ends of its interval round to the same double (Ziv's test). A value
// whose interval straddles a rounding boundary is not certified; the caller decides it
// exactly (an exact zero, a wall's velocity, a rational) or says that it is not certified.
// Private to the core.
#pragma once

#include <array>
#include <limits>
#include <optional>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_int.hpp>

namespace collision_lab {
namespace core {
namespace detail {

using ExactRational = boost::multiprecision::cpp_rational;
using Certifying = boost::multiprecision::cpp_bin_float_100;  // about 333 bits

/// The double nearest `exact` (ties to even; +-inf beyond the double range; +0 for 0).
double nearestDouble(const ExactRational& exact);
/// The double nearest top / bottom (bottom > 0), the same, without reducing the fraction
/// unless the cheap step does not decide.
double nearestDouble(const boost::multiprecision::cpp_int& top, const boost::multiprecision::cpp_int& bottom);

/// The double nearest the exact value x when |x - value| <= error and every point of
/// [value - error, value + error] rounds to that double; empty otherwise. A zero is +0.
std::optional<double> certifiedNearest(const Certifying& value, const Certifying& error);

/// The double nearest x when every value within `relative` |x| of x rounds to that double, in
/// the normal range; else empty (Ziv's first, cheap step; empty where long double has fewer
/// than 64 bits).
std::optional<double> quickNearest(long double x, long double relative);

/// q in long double, within 3 ulps of it (2^-61 relative) where long double has 64 bits; not
/// finite where q's numerator or denominator leaves its range.
long double approximate(const ExactRational& q);

/// The angle atan2(y, x sqrt(scale)) [rad] of exact rationals (scale >= 0): in long double
/// within 2^-59 of it relatively (atan2 moves by at most the relative error of its
/// arguments, each within 2^-61 here, times |sin 2 phi| / 2 <= |phi|; atan2l within 2 ulps),
/// where long double has 64 bits; and at 100 digits within 2^-298 of it relatively. y = x =
/// 0 gives 0.
long double cheapAtan2Sqrt(const ExactRational& y, const ExactRational& x, const ExactRational& scale);
Certifying certifyingAtan2Sqrt(const ExactRational& y, const ExactRational& x, const ExactRational& scale);
/// atan2(y, x sqrt(scale)) correctly rounded [rad] (an exact 0 decided exactly), in (-pi, pi],
/// or with `from_zero` in [0, 2 pi) (a negative angle plus 2 pi); empty where neither step
/// certifies it.
std::optional<double> roundedAtan2Sqrt(const ExactRational& y, const ExactRational& x, const ExactRational& scale,
                                       bool from_zero = false);

/// A long double with a rigorous bound on its distance from the exact value it stands for:
/// a floating-point filter's running error bound (as CGAL's filtered predicates). An exact
/// input has error 0; each operation adds its operands' errors, propagated, and its own
/// rounding: the exact one for + and * (error-free transformations, so an exact operation
/// adds nothing), the residual's for / and sqrt; every bound rounded up. A rounding or a decision that the bound settles needs
/// no exact arithmetic; one it does not settle goes to the exact path. The bounds assume
/// long double's 64-bit significand (kFilterable) and values inside its exponent range
/// (products and quotients of a few doubles are: 2^+-16382 against the doubles' 2^+-1074).
struct Filtered {
  Filtered(long double exact = 0) : value(exact) {}  // NOLINT(google-explicit-constructor): exact inputs
  Filtered(long double value_, long double error_) : value(value_), error(error_) {}
  long double value = 0;  ///< the computed value
  long double error = 0;  ///< |exact - value| <= error (infinite: nothing known)
};

/// Long double has exactly the binary 64-bit significand that Filtered's bounds and its
/// error-free transformations (a split at 32 bits) assume: x86's. Elsewhere the exact path
/// answers alone.
constexpr bool kFilterable = std::numeric_limits<long double>::digits == 64 && std::numeric_limits<long double>::radix == 2;

Filtered operator+(const Filtered& a, const Filtered& b);
Filtered operator-(const Filtered& a, const Filtered& b);
Filtered operator-(const Filtered& a);
Filtered operator*(const Filtered& a, const Filtered& b);
/// Infinite error where b's bound does not keep it from 0.
Filtered operator/(const Filtered& a, const Filtered& b);
/// For an exact value known to be >= 0.
Filtered sqrt(const Filtered& a);
/// The angle of (x, y) [rad], in (-pi, pi]; infinite error where the bounds let the exact
/// point reach the origin or cross the branch cut (x < 0, y of either sign).
Filtered atan2(const Filtered& y, const Filtered& x);
/// atan2(y, x sqrt(scale)), for an exact scale >= 0.
Filtered atan2Sqrt(const Filtered& y, const Filtered& x, const Filtered& scale);
/// The double nearest the exact value when every value within the bound rounds to it, in the
/// normal range (an exact 0 as +0); else empty.
std::optional<double> filteredNearest(const Filtered& x);
/// roundedAtan2Sqrt's first step, on filtered arguments: the same correctly rounded angle
/// where the bounds certify it; else empty (the caller takes roundedAtan2Sqrt).
std::optional<double> filteredAtan2Sqrt(const Filtered& y, const Filtered& x, const Filtered& scale,
                                        bool from_zero = false);

/// sqrt(q) when it is rational (numerator and denominator perfect squares); else empty.
std::optional<ExactRational> rationalSqrt(const ExactRational& q);

/// The three-body angles of one set of masses (walls infinite), each the correctly rounded
/// exact value [rad, 1]: alpha = atan(sqrt(m_B M / (m_A m_C))), theta = 2 alpha,
/// omega = pi - alpha and r_c = tan^2(pi/4 - alpha/2) = 1 / ((1 + x)(1 + sin alpha)^2)
/// with x = tan^2 alpha (no cancellation as alpha -> pi/2).
struct RoundedAngles {
  double alpha = 0.0;
  double theta = 0.0;
  double omega = 0.0;
  double critical_restitution = 0.0;
};
RoundedAngles roundedAngles(const std::array<double, 3>& masses);

/// phi in (0, pi) with cos(phi) = T / (2 sqrt(det)), correctly rounded [rad]: the spiral's
/// turn per cycle, for an exact trace T and determinant det > 0 with T^2 < 4 det.
double roundedSpiralAngle(const ExactRational& trace, const ExactRational& determinant);

}  // namespace detail
}  // namespace core
}  // namespace collision_lab
