#include "correct_rounding.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include <boost/math/constants/constants.hpp>

namespace collision_lab {
namespace core {
namespace detail {

namespace {

bool evenMantissa(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return (bits & 1) == 0;
}

/// x rounded to the nearest double, ties to even, subnormals included: Boost's conversion in
/// the normal range, and below it the nearest multiple of 2^-1074 found in 333 bits (exact:
/// a scaled subnormal has at most 1074 + 1 integer bits, far inside the significand).
double roundToDouble(const Certifying& x) {
  const Certifying magnitude = x < 0 ? Certifying(-x) : x;
  if (x == 0 || !(magnitude < std::numeric_limits<double>::min())) return static_cast<double>(x);
  const Certifying scaled = ldexp(magnitude, 1074);
  Certifying whole = floor(scaled);
  const Certifying fraction = scaled - whole;
  const bool odd = fmod(whole, Certifying(2)) != 0;
  if (fraction > 0.5 || (fraction == 0.5 && odd)) whole += 1;
  const double rounded = std::ldexp(static_cast<double>(whole), -1074);
  return x < 0 ? -rounded : rounded;
}

/// top / bottom (bottom > 0) rounded, when the cheap step decides: each integer within an
/// ulp of long double, the quotient within 3 ulps (2^-61 relative), so decided unless it lies
/// next to a rounding boundary.
std::optional<double> quickQuotient(const boost::multiprecision::cpp_int& top,
                                    const boost::multiprecision::cpp_int& bottom) {
  const long double top_ld = static_cast<long double>(top), bottom_ld = static_cast<long double>(bottom);
  if (!std::isfinite(top_ld) || !std::isfinite(bottom_ld) || bottom_ld == 0) return std::nullopt;
  return quickNearest(top_ld / bottom_ld, 0x1p-59L);
}

}  // namespace

std::optional<double> quickNearest(long double x, long double relative) {
  // The bounds of the callers assume x87's 64-bit significand; where long double is a double,
  // the cheap step decides nothing and the exact or 100-digit step answers.
  if constexpr (std::numeric_limits<long double>::digits < 64) return std::nullopt;
  const long double margin = (x < 0 ? -x : x) * relative;
  const double low = static_cast<double>(x - margin), high = static_cast<double>(x + margin);
  if (low != high || !std::isfinite(low) || !(std::fabs(low) >= std::numeric_limits<double>::min())) {
    return std::nullopt;
  }
  return low;
}

namespace {

constexpr long double kInfinity = std::numeric_limits<long double>::infinity();

/// A bound computed in long double, rounded up: up to 16 roundings of 2^-64 each, and up to
/// four below the normal range, covered. 0 stays 0, so that exact operations stay exact.
long double roundedUp(long double bound) {
  return bound == 0 ? 0 : bound * (1 + 0x1p-60L) + 4 * std::numeric_limits<long double>::denorm_min();
}

/// Error-free transformations (Knuth's TwoSum, Dekker's TwoProduct with Veltkamp's split at
/// 32 of the 64 bits): the exact rounding error of a + b and of a b, so that an operation
/// whose result is exact adds no error, and one that is not adds its true rounding.
long double sumError(long double a, long double b, long double sum) {
  const long double b_virtual = sum - a;
  return (a - (sum - b_virtual)) + (b - b_virtual);
}

std::pair<long double, long double> split(long double a) {
  const long double c = (0x1p32L + 1) * a;
  const long double high = c - (c - a);
  return {high, a - high};
}

long double productError(long double a, long double b, long double product) {
  // Exact away from the ends of the exponent range; near them (never with the doubles'
  // products here) unknown: NaN, which makes the operation's error infinite.
  if (a == 0 || b == 0) return 0;
  constexpr long double kLarge = 0x1p16000L, kSmall = 0x1p-16000L;
  if (!(std::fabs(a) < kLarge && std::fabs(b) < kLarge && std::fabs(product) > kSmall)) {
    return std::numeric_limits<long double>::quiet_NaN();
  }
  const auto [a_high, a_low] = split(a);
  const auto [b_high, b_low] = split(b);
  return ((a_high * b_high - product) + a_high * b_low + a_low * b_high) + a_low * b_low;
}

/// The result of one operation: its operands' errors propagated, and its own rounding (not
/// finite: nothing known).
Filtered rounded(long double value, long double propagated, long double own) {
  if (!std::isfinite(value) || !std::isfinite(own)) return {value, kInfinity};
  return {value, roundedUp(propagated + std::fabs(own))};
}

/// |a - product(b, c)|, exact but for one rounding of the result: the residual of a
/// quotient or a square root.
long double residual(long double a, long double b, long double c) {
  const long double product = b * c;
  return (a - product) - productError(b, c, product);
}

}  // namespace

Filtered operator+(const Filtered& a, const Filtered& b) {
  const long double sum = a.value + b.value;
  return rounded(sum, a.error + b.error, sumError(a.value, b.value, sum));
}

Filtered operator-(const Filtered& a, const Filtered& b) { return a + (-b); }

Filtered operator-(const Filtered& a) { return {-a.value, a.error}; }

Filtered operator*(const Filtered& a, const Filtered& b) {
  const long double product = a.value * b.value;
  return rounded(product, std::fabs(a.value) * b.error + std::fabs(b.value) * a.error + a.error * b.error,
                 productError(a.value, b.value, product));
}

Filtered operator/(const Filtered& a, const Filtered& b) {
  // |A/B - a/b| = |(A - a) b - a (B - b)| / |B b| <= (e_a |b| + |a| e_b) / ((|b| - e_b) |b|);
  // the quotient's own rounding is its residual over b.
  const long double size = std::fabs(b.value);
  const long double quotient = a.value / b.value;
  if (!(b.error < size)) return {quotient, kInfinity};
  const long double room = size - roundedUp(b.error);
  if (!(room > 0)) return {quotient, kInfinity};
  const long double own = residual(a.value, quotient, b.value) / size * (1 + 0x1p-60L);
  return rounded(quotient, (a.error * size + std::fabs(a.value) * b.error) / (room * size), own);
}

Filtered sqrt(const Filtered& a) {
  // |sqrt(A) - sqrt(a)| = |A - a| / (sqrt(A) + sqrt(a)) <= e_a / sqrt(a) for A >= 0; where
  // a <= 0, sqrt(A) <= sqrt(a + e_a). The root's own rounding is its residual over it.
  if (!(a.value > 0)) {
    if (a.value == 0 && a.error == 0) return Filtered(0);
    const long double top = roundedUp(a.value + a.error);
    if (!(top >= 0)) return {0, kInfinity};  // no A >= 0 within the bound: nothing known
    return {0, roundedUp(std::sqrt(top))};
  }
  const long double root = std::sqrt(a.value);
  return rounded(root, a.error / root, residual(a.value, root, root) / root * (1 + 0x1p-60L));
}

Filtered atan2(const Filtered& y, const Filtered& x) {
  const bool y_exact_zero = y.value == 0 && y.error == 0;
  // atan2l: within 2 ulps (glibc); an exact 0 as +0, so that the angle is in (-pi, pi].
  const long double angle = std::atan2(y_exact_zero ? 0.0L : y.value, x.value);
  const long double own = std::fabs(angle) * 0x1p-61L;
  // The exact point lies within `spread` of (x, y), so its direction within
  // asin(spread / radius) <= (pi / 2) spread / radius of (x, y)'s.
  const long double radius = std::hypot(x.value, y.value) * (1 - 0x1p-60L);
  const long double spread = roundedUp(x.error + y.error);
  if (!(spread < radius / 2) || (x.value < 0 && !(y.error < std::fabs(y.value)) && !y_exact_zero)) {
    return {angle, kInfinity};
  }
  long double bound = roundedUp(1.5707963267948966193L * (1 + 0x1p-60L) * spread / radius);
  // Relatively: scaling y by 1 + a and x by 1 + b moves the angle by at most
  // |ln((1 + a) / (1 + b))| times |sin 2 xi| / 2 <= min(1/2, |xi|), xi between the two
  // angles; |ln(1 + a)| <= |a| / (1 - |a|). Tight for small angles, where the first is not.
  if (x.value != 0 && y.value != 0) {
    const long double r_x = x.error / std::fabs(x.value), r_y = y.error / std::fabs(y.value);
    if (r_x < 0.5L && r_y < 0.5L) {
      const long double log_spread = roundedUp((r_x + r_y) / (1 - std::max(r_x, r_y)));
      bound = std::min(bound, roundedUp(log_spread * std::min(0.5L, roundedUp(std::fabs(angle) + bound + own))));
    }
  }
  return {angle, roundedUp(bound + own)};
}

Filtered atan2Sqrt(const Filtered& y, const Filtered& x, const Filtered& scale) {
  // Where X's sign is uncertain (|x| <= its error), size's bound is at least e sqrt(scale),
  // which covers X sqrt(scale) of either sign; atan2 then finds the origin within its reach.
  const Filtered size = sqrt(x * x * scale);
  return atan2(y, x.value < 0 ? -size : size);
}

std::optional<double> filteredNearest(const Filtered& x) {
  if (!kFilterable || !std::isfinite(x.value) || !std::isfinite(x.error)) return std::nullopt;
  if (x.value == 0 && x.error == 0) return 0.0;
  // Widened so that the rounded ends still enclose [value - error, value + error].
  const long double margin = x.error * (1 + 0x1p-62L) + std::fabs(x.value) * 0x1p-62L;
  const double low = static_cast<double>(x.value - margin), high = static_cast<double>(x.value + margin);
  if (low != high || !std::isfinite(low) || !(std::fabs(low) >= std::numeric_limits<double>::min())) {
    return std::nullopt;
  }
  return low;
}

std::optional<double> filteredAtan2Sqrt(const Filtered& y, const Filtered& x, const Filtered& scale,
                                        bool from_zero) {
  const bool y_exact_zero = y.value == 0 && y.error == 0;
  if (y_exact_zero && (x.value >= x.error || (scale.value == 0 && scale.error == 0))) return 0.0;  // exactly
  Filtered angle = atan2Sqrt(y, x, scale);
  if (from_zero && angle.value < 0) {  // in [0, 2 pi): only an angle that is surely negative
    if (!(angle.error < -angle.value)) return std::nullopt;
    angle = angle + Filtered(2 * 3.14159265358979323846264338327950288L, 0x1p-60L);
  }
  return filteredNearest(angle);
}

long double approximate(const ExactRational& q) {
  return static_cast<long double>(numerator(q)) / static_cast<long double>(denominator(q));
}

double nearestDouble(const boost::multiprecision::cpp_int& top, const boost::multiprecision::cpp_int& bottom) {
  if (top == 0) return 0.0;
  if (const auto quick = quickQuotient(top, bottom)) return *quick;
  return nearestDouble(ExactRational(top, bottom));
}

double nearestDouble(const ExactRational& exact) {
  if (exact == 0) return 0.0;
  if (const auto quick = quickQuotient(numerator(exact), denominator(exact))) return *quick;
  double nearest = roundToDouble(Certifying(numerator(exact)) / Certifying(denominator(exact)));
  if (std::isinf(nearest)) return nearest;
  // The estimate is within an ulp: the exact distances to it and its neighbours decide.
  ExactRational best = abs(ExactRational(nearest) - exact);
  const double start = nearest;
  for (const double neighbour : {std::nextafter(start, std::numeric_limits<double>::infinity()),
                                 std::nextafter(start, -std::numeric_limits<double>::infinity())}) {
    if (!std::isfinite(neighbour)) continue;
    const ExactRational distance = abs(ExactRational(neighbour) - exact);
    if (distance < best || (distance == best && evenMantissa(neighbour))) {
      nearest = neighbour;
      best = distance;
    }
  }
  return nearest == 0 ? 0.0 : nearest;
}

std::optional<double> certifiedNearest(const Certifying& value, const Certifying& error) {
  if (isnan(value) || isnan(error)) return std::nullopt;
  const double low = roundToDouble(Certifying(value - error));
  const double high = roundToDouble(Certifying(value + error));
  if (low != high) return std::nullopt;
  return low == 0 ? 0.0 : low;
}

std::optional<ExactRational> rationalSqrt(const ExactRational& q) {
  using boost::multiprecision::cpp_int;
  if (q < 0) return std::nullopt;
  const cpp_int top = numerator(q), bottom = denominator(q);
  const cpp_int top_root = sqrt(top), bottom_root = sqrt(bottom);
  if (top_root * top_root != top || bottom_root * bottom_root != bottom) return std::nullopt;
  return ExactRational(top_root, bottom_root);
}

RoundedAngles roundedAngles(const std::array<double, 3>& m) {
  // Ziv's first step in long double: x = tan^2 alpha within 4 roundings, sqrt correctly
  // rounded, atanl within a few ulps (glibc), all well conditioned: 2^-58 relative is wide.
  // Otherwise (about 1 in 30, or masses beyond long double's exactness) the 100-digit step.
  {
    const long double b_over_a = std::isinf(m[0]) ? 0.0L : static_cast<long double>(m[1]) / m[0];
    const long double b_over_c = std::isinf(m[2]) ? 0.0L : static_cast<long double>(m[1]) / m[2];
    const long double x = b_over_a * (1 + b_over_c) + b_over_c;
    const long double alpha = std::atan(std::sqrt(x));
    const long double sine = std::sqrt(x / (1 + x));
    const long double r_c = 1 / ((1 + x) * (1 + sine) * (1 + sine));
    constexpr long double kRelative = 0x1p-58L;
    const auto quick_alpha = quickNearest(alpha, kRelative);
    const auto quick_omega = quickNearest(3.14159265358979323846264338327950288L - alpha, kRelative);
    const auto quick_r_c = quickNearest(r_c, kRelative);
    if (std::isnormal(x) && quick_alpha && quick_omega && quick_r_c) {
      return {*quick_alpha, 2 * *quick_alpha, *quick_omega, *quick_r_c};
    }
  }
  using F = Certifying;
  // x = tan^2 alpha = m_B M / (m_A m_C) = (m_B/m_A)(1 + m_B/m_C) + m_B/m_C, exactly; a wall's
  // ratio is 0.
  const ExactRational b_over_a = std::isinf(m[0]) ? ExactRational(0) : ExactRational(m[1]) / ExactRational(m[0]);
  const ExactRational b_over_c = std::isinf(m[2]) ? ExactRational(0) : ExactRational(m[1]) / ExactRational(m[2]);
  const ExactRational x = b_over_a * (1 + b_over_c) + b_over_c;
  const F x_f = F(numerator(x)) / F(denominator(x));
  // Each value below is within a few roundings of 333 bits of the exact one, relatively (the
  // square roots, atan and the quotients are well conditioned here): 2^-300 is a wide margin.
  const F relative = ldexp(F(1), -300);
  const F alpha = atan(sqrt(x_f));
  const F omega = boost::math::constants::pi<F>() - alpha;
  const F sine = sqrt(x_f / (1 + x_f));
  const F r_c = 1 / ((1 + x_f) * (1 + sine) * (1 + sine));
  RoundedAngles angles;
  // alpha and omega are transcendental (alpha > 0), never a double nor a tie: the interval
  // always decides, and the estimate's own rounding stands only as a last resort.
  angles.alpha = certifiedNearest(alpha, alpha * relative).value_or(static_cast<double>(alpha));
  angles.theta = 2 * angles.alpha;  // doubling is exact, so 2 round(alpha) = round(2 alpha)
  angles.omega = certifiedNearest(omega, omega * relative).value_or(static_cast<double>(omega));
  if (const auto rounded = certifiedNearest(r_c, r_c * relative)) {
    angles.critical_restitution = *rounded;
  } else if (const auto s = rationalSqrt(x / (1 + x))) {  // r_c rational, perhaps a double
    angles.critical_restitution = nearestDouble(1 / ((1 + x) * (1 + *s) * (1 + *s)));
  } else {
    angles.critical_restitution = static_cast<double>(r_c);
  }
  return angles;
}

long double cheapAtan2Sqrt(const ExactRational& y, const ExactRational& x, const ExactRational& scale) {
  const long double x_size = std::sqrt(approximate(x * x * scale));
  return std::atan2(approximate(y), x < 0 ? -x_size : x_size);
}

Certifying certifyingAtan2Sqrt(const ExactRational& y, const ExactRational& x, const ExactRational& scale) {
  if (y == 0) return x < 0 ? boost::math::constants::pi<Certifying>() : Certifying(0);
  const ExactRational x_sq = x * x * scale;
  const Certifying x_size = sqrt(Certifying(numerator(x_sq)) / Certifying(denominator(x_sq)));
  return atan2(Certifying(numerator(y)) / Certifying(denominator(y)), x < 0 ? Certifying(-x_size) : x_size);
}

std::optional<double> roundedAtan2Sqrt(const ExactRational& y, const ExactRational& x, const ExactRational& scale,
                                       bool from_zero) {
  if (y == 0 && (x >= 0 || scale == 0)) return 0.0;  // exactly (atan2(0, 0) = 0)
  // Shifted by 2 pi (a negative angle only, so in (pi, 2 pi)): the bounds hold relatively.
  long double cheap = cheapAtan2Sqrt(y, x, scale);
  if (from_zero && cheap < 0) cheap += 2 * 3.14159265358979323846264338327950288L;
  if (const auto quick = quickNearest(cheap, 0x1p-57L)) return quick;
  Certifying angle = certifyingAtan2Sqrt(y, x, scale);
  if (from_zero && angle < 0) angle += 2 * boost::math::constants::pi<Certifying>();
  return certifiedNearest(angle, abs(angle) * ldexp(Certifying(1), -298));  // shifted: larger, so wider
}

double roundedSpiralAngle(const ExactRational& trace, const ExactRational& determinant) {
  using F = Certifying;
  // phi = atan2(sqrt(1 - y^2), y), y = T / (2 sqrt(det)), with 1 - y^2 exact: no cancellation
  // near the threshold, where acos would lose half the digits.
  const ExactRational sine_squared = 1 - trace * trace / (4 * determinant);
  const auto f = [](const ExactRational& q) { return F(numerator(q)) / F(denominator(q)); };
  const F phi = atan2(sqrt(f(sine_squared)), f(trace) / (2 * sqrt(f(determinant))));
  return certifiedNearest(phi, phi * ldexp(F(1), -300)).value_or(static_cast<double>(phi));
}

}  // namespace detail
}  // namespace core
}  // namespace collision_lab
