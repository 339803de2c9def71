#include "collision_lab/core/nbody/impact_rule.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "../correct_rounding.h"
#include "double_double.h"
#include "viscoelastic.h"

namespace collision_lab {
namespace core {

double impactEnergyLost(double m_i, double m_j, double approach, double e) {
  if (e == 1.0) return 0.0;
  // mu = m_i m_j / (m_i + m_j), without overflow or inf / inf; a wall leaves the other mass,
  // and so does a mass heavier past the double range's ratio (m_i / m_j = inf: mu = m_j).
  const double ratio = m_i / m_j;
  const double mu = std::isinf(m_i) ? m_j : std::isinf(m_j) ? m_i : std::isinf(ratio) ? m_j : m_i / (1.0 + ratio);
  return 0.5 * (1.0 - e) * (1.0 + e) * mu * approach * approach;
}

namespace nbody_detail {

namespace {

/// The law's constants C1 = 1.15344 and C2 = 0.79826, as the decimals n / 100000 they are.
constexpr int kC1 = 115344, kC2 = 79826, kDecimals = 100000;

/// The double of a value known to lie in [low, high] (low <= 1 + a little): e = min(1, f);
/// anything from 1 - 2^-54 up rounds to 1.
template <class F>
std::optional<double> roundedIn(const F& low, const F& high) {
  if (low >= F(1) - F(0x1p-54)) return 1.0;
  const double a = static_cast<double>(low), b = static_cast<double>(high < F(1) ? high : F(1));
  if (a != b) return std::nullopt;
  return a;
}

/// e near v (known within `error`) in the multiprecision type F, relative precision `unit`
/// of its arithmetic (several roundings and pow included).
template <class F>
std::optional<double> viscoelasticIn(const F& v, const F& error, double v_star, const F& unit) {
  const F c1 = F(kC1) / kDecimals, c2 = F(kC2) / kDecimals;
  const F x = v / F(v_star);
  const F s = pow(x, F(1) / 5);
  const F f = 1 - c1 * s + c2 * s * s;
  // |f'(v)| = |2 c2 s - c1| s / (5 v), bounded over [v - error, v + error] by s's bound
  // there (s grows like v^(1/5): at most s (1 + error / v)) and v - error.
  const F s_high = s * (1 + error / v);
  const F slope = (c1 + 2 * c2 * s_high) * s_high / (5 * (v - error));
  const F bound = slope * error + unit * (1 + c1 * s_high + c2 * s_high * s_high) * 16;
  return roundedIn(F(f - bound), F(f + bound));
}

/// The integer r >= 0 with r^5 = n (n >= 0), if there is one.
std::optional<boost::multiprecision::cpp_int> fifthRoot(const boost::multiprecision::cpp_int& n) {
  using boost::multiprecision::cpp_int;
  if (n < 2) return n;
  // Newton's iteration from above: r <- (4 r + n / r^4) / 5 decreases to floor(n^(1/5)).
  cpp_int r = cpp_int(1) << (msb(n) / 5 + 1);
  for (;;) {
    const cpp_int next = (4 * r + n / (r * r * r * r)) / 5;
    if (next >= r) break;
    r = next;
  }
  if (r * r * r * r * r != n) return std::nullopt;
  return r;
}

}  // namespace

std::optional<double> viscoelasticOver(long double v, long double error, double v_star) {
  if constexpr (std::numeric_limits<long double>::digits < 64) return std::nullopt;
  constexpr long double c1 = static_cast<long double>(kC1) / kDecimals, c2 = static_cast<long double>(kC2) / kDecimals;  // within 2^-64
  const long double x = v / v_star;
  if (!(x > 0x1p-1000L && x < 0x1p1000L)) return std::nullopt;
  // s = x^(1/5): pow in double (within an ulp, 2^-52), then one Newton step for s^5 = x in
  // long double, which leaves 2 (2^-52)^2 relatively and the step's roundings: within
  // 2^-62. f's own few operations stay within 2^-61 of its terms. Over [v - error,
  // v + error], |f'(v)| = |2 c2 s - c1| s / (5 v) is at most (c1 + 2 c2 s') s' / (5 (v - error)),
  // s' = s (1 + error / v).
  const long double guess = std::pow(static_cast<double>(x), 0.2);
  const long double guess_4 = (guess * guess) * (guess * guess);
  const long double s = guess - (guess_4 * guess - x) / (5 * guess_4);
  const long double relative = 0x1p-62L;
  const long double s_high = s * (1 + relative) * (1 + error / v);
  const long double slope = (c1 + 2 * c2 * s_high) * s_high / (5 * (v - error));
  const long double bound = slope * error + 0x1p-61L * (1 + c1 * s_high + c2 * s_high * s_high) +
                            (c1 * s_high + 2 * c2 * s_high * s_high) * relative;
  const long double f = 1 - c1 * s + c2 * s * s;
  return roundedIn(f - bound, f + bound);
}

std::optional<double> viscoelasticDD(const DD& v, double error, double v_star) {
  const DD x = v / DD(v_star);
  if (!(x.hi > 0x1p-900 && x.hi < 0x1p900) || !(error < 0x1p-20 * v.hi)) return std::nullopt;
  // s from pow in double (within 2^-52 relatively), then one Newton step for s^5 = x in
  // double-double: 2 (2^-52)^2 relatively, plus a dozen double-double operations (2^-104
  // each): within 2^-98.
  DD s(std::pow(x.hi, 0.2));
  const DD s_sq = s * s, s_4 = s_sq * s_sq;
  s = s - (s_4 * s - x) / (s_4 * 5.0);
  const DD c1 = DD(kC1) / DD(kDecimals), c2 = DD(kC2) / DD(kDecimals);  // within 2^-104
  const DD f = DD(1.0) - c1 * s + c2 * (s * s);
  const double size = s.hi * (1 + 0x1p-40);
  // f's bound: s's error through f' = 2 c2 s - c1, f's own operations (2^-100 of its
  // terms), and the speed's bound through f'(v) = f'(s) s / (5 v).
  const double slope = (1.15345 + 2 * 0.79827 * size) * size;
  const double bound =
      (slope * 0x1p-98 + 0x1p-99 * (1 + 1.15345 * size + 0.79827 * size * size)) + slope * error / (5 * (v.hi - error));
  const DD low = f - DD(bound * (1 + 0x1p-40)), high = f + DD(bound * (1 + 0x1p-40));
  // From 1 - 2^-54 (the midpoint below 1, a tie that goes to 1) up, e rounds to 1; a
  // normalized double-double there has hi = 1, or hi = 1 - 2^-53 with lo = 2^-54.
  const auto reaches_one = [](const DD& x) {
    return x.hi > 1 || (x.hi == 1 && x.lo >= -0x1p-54) || (x.hi == 1 - 0x1p-53 && x.lo >= 0x1p-54);
  };
  if (reaches_one(low)) return 1.0;
  if (reaches_one(high)) return std::nullopt;
  // A normalized double-double rounds to its hi unless its lo reaches half an ulp.
  const double half_ulp = (std::nextafter(low.hi, 2.0) - low.hi) / 2;
  if (low.hi != high.hi || !(low.lo > -half_ulp) || !(high.lo < half_ulp)) return std::nullopt;
  return low.hi;
}

std::optional<double> viscoelasticNear(const Float100& v, const Float100& error, double v_star) {
  // 128 bits first (a double-double tier's speed is known to about 2^-100): a few times
  // cheaper than 100 digits.
  using Narrow = boost::multiprecision::number<boost::multiprecision::cpp_bin_float<128, boost::multiprecision::digit_base_2>>;
  const Narrow narrow_error = Narrow(error) * (1 + ldexp(Narrow(1), -120)) + Narrow(v) * ldexp(Narrow(1), -126);
  if (const auto e = viscoelasticIn(Narrow(v), narrow_error, v_star, Narrow(ldexp(Narrow(1), -122)))) return e;
  if (error > v * ldexp(Float100(1), -120)) return std::nullopt;  // more digits cannot narrow the speed's bound
  return viscoelasticIn(v, error, v_star, Float100(ldexp(Float100(1), -325)));
}

double viscoelasticAt(const Rational& v, double v_star) {
  // v / v* the fifth power of a rational: s is rational, and so is e, which may then be a
  // double or a tie; decided exactly.
  const Rational x = v / Rational(v_star);
  const auto root = fifthRoot(numerator(x)), root_of_denominator = fifthRoot(denominator(x));
  if (root && root_of_denominator) {
    const Rational s(*root, *root_of_denominator);
    const Rational f = 1 - Rational(kC1, kDecimals) * s + Rational(kC2, kDecimals) * s * s;
    return f >= 1 ? 1.0 : core::detail::nearestDouble(f);
  }
  const Float100 wide = Float100(numerator(v)) / Float100(denominator(v));  // within 2^-330
  if (const auto e = viscoelasticNear(wide, wide * ldexp(Float100(1), -329), v_star)) return *e;
  // Within the bound of a rounding boundary: 500 digits. e is irrational wherever v / v* is
  // not a fifth power of a rational (above), so no tie is left, only a bound this close to one.
  using Deep = boost::multiprecision::number<boost::multiprecision::cpp_bin_float<500>>;
  const Deep deep = Deep(numerator(v)) / Deep(denominator(v));
  const Deep unit = ldexp(Deep(1), -1640);
  if (const auto e = viscoelasticIn(deep, Deep(deep * unit * 2), v_star, unit)) return *e;
  return *viscoelasticIn(deep, Deep(0), v_star, Deep(0));  // the 500-digit value, rounded
}

}  // namespace nbody_detail

double viscoelasticRestitution(double speed, double v_star) {
  if (!(speed > 0)) return 1.0;  // s = 0
  if (const auto e = nbody_detail::viscoelasticOver(speed, 0.0L, v_star)) return *e;
  if (const auto e = nbody_detail::viscoelasticDD(nbody_detail::DD(speed), 0.0, v_star)) return *e;
  return nbody_detail::viscoelasticAt(nbody_detail::Rational(speed), v_star);
}

ImpactOutcome impact(double m_i, double m_j, double v_i, double v_j, double e) {
  using nbody_detail::DD;
  const ImpactMap<DD> map = makeImpactMap<DD>(m_i, m_j, e);
  DD q_i(v_i), q_j(v_j);
  applyImpactMap(map, q_i, q_j);
  return ImpactOutcome{q_i.hi, q_j.hi, impactEnergyLost(m_i, m_j, v_j - v_i, e)};
}

}  // namespace core
}  // namespace collision_lab
