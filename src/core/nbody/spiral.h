// Three bodies with one restitution e for both pairs: the AB/BC cycle as a 2x2 map
// (shared/physics.md, "Restitution"). Internal to the core (models.cpp, engine.cpp).
//
// State. The approach speeds d = (a, c) = (v_B - v_A, v_C - v_B) [m/s]. Impact AB maps
// (a, c) -> (-e a, c + k_A a), impact BC maps (a, c) -> (a + k_C c, -e c), with
// k_A = (1+e) m_A/(m_A+m_B), k_C = (1+e) m_C/(m_B+m_C). Pair AB approaches iff a > 0, BC iff
// c > 0, and after the first impact the pairs alternate, so the count depends only on d
// and on the first pair. The same maps act on the differences of the intercepts
// b = x - v t, which gives the collapse time in closed form (collapseTime()).
//
// Decisions. Whether the impacts go on for ever is decided exactly (ConeTest); the count
// comes from the checks' closed forms (closedFormWalk(), doubleEigenvalueWalk()). Where
// those leave it open (a value next to an integer), the walk runs in double, then
// double-double, then 100-digit floats, then in exact rationals.
// A sign is taken when it exceeds a forward error estimate, 64 (k+1) u kappa^2 |d|_1 after
// k impacts, with u the unit roundoff and kappa the conditioning of the cycle's eigenbasis
// (about 2e / sqrt|T^2 - 4e^2| times the mass spread, which grows near r_c): an error made
// at one impact is carried by the same maps as the state, and relative to the state it can
// grow by kappa^2 at most. Otherwise the next tier walks again from the start. The rationals are exact and decide every borderline case (a graze, e
// within rounding of r_c); they are used only while the count stays below kRationalLimit.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include <boost/math/constants/constants.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_int.hpp>

#include "double_double.h"

namespace collision_lab {
namespace core {
namespace spiral_detail {

using DD = nbody_detail::DD;
using Float100 = boost::multiprecision::cpp_bin_float_100;
using Rational = boost::multiprecision::cpp_rational;

constexpr std::uint64_t kWalkLimit = std::uint64_t{1} << 26;  ///< impacts; beyond: undecided
constexpr std::uint64_t kRationalLimit = 3000;              ///< impacts walked in rationals

/// Masses [kg] and restitution [1] of three bodies (or clusters); the cycle's invariants.
/// e_bc < 0 means e_bc = e (the model's case: one e for both pairs). wall_a (wall_c): A (C)
/// is a wall, an infinite mass, and m[0] (m[2]) is unused; then m_A/(m_A+m_B) = 1, so
/// k_A = 1+e and cos^2(alpha) = m_C/(m_B+m_C). Not both: then T^2 - 4 e^2 has the dominant
/// eigenvalue 1 (no collapse) and collapseTime() would divide by a wall's relative speed.
struct Cycle {
  double m[3];
  double e;
  double e_bc = -1.0;
  bool wall_a = false, wall_c = false;
  double eBC() const { return e_bc < 0 ? e : e_bc; }
  /// m_A/(m_A+m_B) and m_C/(m_B+m_C) in arithmetic T (1 for a wall); cos^2(alpha) is their product.
  template <class T>
  T ratioA() const { return wall_a ? T(1) : T(m[0]) / (T(m[0]) + T(m[1])); }
  template <class T>
  T ratioC() const { return wall_c ? T(1) : T(m[2]) / (T(m[1]) + T(m[2])); }
  double cos2_alpha() const {
    if (wall_a || wall_c) return ratioA<double>() * ratioC<double>();
    return m[0] * m[2] / ((m[0] + m[1]) * (m[1] + m[2]));
  }
  /// T^2 < 4 det = 4 e e_bc exactly: complex eigenvalues, the spiral (e > r_c for one e).
  bool complexEigenvalues() const {
    const Rational t = exactTrace();
    return t * t < 4 * Rational(e) * Rational(eBC());
  }
  /// T = (1+e)(1+e_bc) cos^2(alpha) - e - e_bc (for one e rounded as (1+e)^2 cos^2(alpha) - 2e).
  double trace() const {
    return eBC() == e ? (1 + e) * (1 + e) * cos2_alpha() - 2 * e : (1 + e) * (1 + eBC()) * cos2_alpha() - e - eBC();
  }
  double kappa() const {
    const double t = trace(), gap = std::sqrt(std::fabs(t * t - 4 * e * eBC()));
    double heaviest = 0.0, lightest = std::numeric_limits<double>::infinity();  // of the finite masses
    for (int k = 0; k < 3; ++k) {
      if ((k == 0 && wall_a) || (k == 2 && wall_c)) continue;
      heaviest = std::max(heaviest, m[k]), lightest = std::min(lightest, m[k]);
    }
    return (1 + 2 * std::max(e, eBC()) / std::max(gap, 1e-300)) * std::sqrt(heaviest / lightest);
  }
  /// T exactly.
  Rational exactTrace() const {
    return (1 + Rational(e)) * (1 + Rational(eBC())) * ratioA<Rational>() * ratioC<Rational>() - Rational(e) -
           Rational(eBC());
  }
};

/// The two impact maps on (a, c) in arithmetic T.
template <class T>
struct Maps {
  T e_ab, e_bc, k_a, k_c;
  explicit Maps(const Cycle& c)
      : e_ab(T(c.e)), e_bc(T(c.eBC())),
        k_a(c.wall_a ? 1 + T(c.e) : (1 + T(c.e)) * T(c.m[0]) / (T(c.m[0]) + T(c.m[1]))),
        k_c(c.wall_c ? 1 + T(c.eBC()) : (1 + T(c.eBC())) * T(c.m[2]) / (T(c.m[1]) + T(c.m[2]))) {}
  void apply(int pair, T& a, T& c) const {
    if (pair == 0) {
      c = c + k_a * a;
      a = -e_ab * a;
    } else {
      a = a + k_c * c;
      c = -e_bc * c;
    }
  }
};

/// kEndless: infinitely many impacts in an infinite time (ConeTest::slowEigenvector()).
enum class WalkEnd { kFinished, kCollapse, kEndless, kUndecided };

/// The end of a walk: the count, and d at the end as mantissa * 2^exponent.
struct Walk {
  WalkEnd end = WalkEnd::kUndecided;
  std::uint64_t count = 0;
  double a = 0.0, c = 0.0;
  long exponent = 0;
};

template <class T>
double toDouble(const T& x) {
  if constexpr (std::is_same_v<T, DD>) {
    return x.hi;
  } else {
    return static_cast<double>(x);
  }
}

template <class T>
constexpr double roundoff() {
  if constexpr (std::is_same_v<T, double>) return 0x1p-53;
  if constexpr (std::is_same_v<T, DD>) return 0x1p-104;
  if constexpr (std::is_same_v<T, Float100>) return 0x1p-320;
  return 0.0;
}

/// Sufficient test that every later check stays positive: with (a, c) about to be checked
/// for `pair`, split d = x e1 + y e2 along the eigenvectors of the cycle starting with
/// `pair` (real, lambda1 > lambda2 > 0); the checks of the dominant part must beat those
/// of the other by a wide margin (2^-20 relative, far above the walk's error and the
/// rounding of the eigenvectors in long double). Then the impacts never stop.
inline bool dominates(const Cycle& cy, int pair, long double a, long double c) {
  const Maps<long double> mp(cy);
  // Cycle matrix M = (second map)(first map), columns = images of the unit vectors.
  long double m00 = 1, m10 = 0, m01 = 0, m11 = 1;
  mp.apply(pair, m00, m10), mp.apply(1 - pair, m00, m10);
  mp.apply(pair, m01, m11), mp.apply(1 - pair, m01, m11);
  const long double t = m00 + m11, det = m00 * m11 - m01 * m10, disc = t * t - 4 * det;
  if (!(disc > 0) || !(t > 0)) return false;
  const long double l1 = (t + std::sqrt(disc)) / 2, l2 = (t - std::sqrt(disc)) / 2;
  // Eigenvectors (m01, l - m00), or (l - m11, m10) when m01 is 0.
  auto vec = [&](long double l, long double& x, long double& y) {
    if (std::fabs(m01) >= std::fabs(m10)) {
      x = m01, y = l - m00;
    } else {
      x = l - m11, y = m10;
    }
  };
  long double e1a, e1c, e2a, e2c;
  vec(l1, e1a, e1c), vec(l2, e2a, e2c);
  const long double det_e = e1a * e2c - e2a * e1c;
  if (det_e == 0) return false;
  const long double x = (a * e2c - e2a * c) / det_e, y = (e1a * c - a * e1c) / det_e;
  // The check of `pair` now, and of the other pair after this pair's impact.
  long double f1a = e1a, f1c = e1c, f2a = e2a, f2c = e2c;
  mp.apply(pair, f1a, f1c), mp.apply(pair, f2a, f2c);
  const long double p1 = pair == 0 ? x * e1a : x * e1c, p2 = pair == 0 ? y * e2a : y * e2c;
  const long double q1 = pair == 0 ? x * f1c : x * f1a, q2 = pair == 0 ? y * f2c : y * f2a;
  const long double floor = 0x1p-20L * (std::fabs(x) * (std::fabs(e1a) + std::fabs(e1c)) +
                                         std::fabs(y) * (std::fabs(e2a) + std::fabs(e2c)));
  return p1 - std::fabs(p2) > floor && q1 - std::fabs(q2) > floor;
}

/// T^2 - 4 det within 2^-20 T^2 of 0 (in long double): next to the double eigenvalue,
/// where dominates() needs ever more cycles and ConeTest is the test to use.
inline bool nearDoubleEigenvalue(const Cycle& cy) {
  const Maps<long double> mp(cy);
  long double m00 = 1, m10 = 0, m01 = 0, m11 = 1;
  mp.apply(0, m00, m10), mp.apply(1, m00, m10);
  mp.apply(0, m01, m11), mp.apply(1, m01, m11);
  const long double t = m00 + m11, disc = t * t - 4 * (m00 * m11 - m01 * m10);
  return t > 0 && std::fabs(disc) <= 0x1p-20L * t * t;
}

/// The sign of x + y sqrt(delta) (delta >= 0), exactly.
inline int signWithRoot(const Rational& x, const Rational& y, const Rational& delta) {
  const int sx = x > 0 ? 1 : (x < 0 ? -1 : 0), sy = delta == 0 ? 0 : (y > 0 ? 1 : (y < 0 ? -1 : 0));
  if (sy == 0 || sx == sy) return sx != 0 ? sx : sy;
  if (sx == 0) return sy;
  const Rational diff = x * x - y * y * delta;  // |x| against |y| sqrt(delta)
  return diff > 0 ? sx : (diff < 0 ? sy : 0);
}

/// Exact answer to "does every later check stay positive?" (infinitely many impacts: a
/// collapse), with (a, c) about to be checked for `pair`. Each of the two checks, taken once
/// per cycle, is a sequence f(n) with f(n+2) = T f(n+1) - det f(n) (Cayley-Hamilton). With
/// T > 0 and delta = T^2 - 4 det >= 0 the eigenvalues are l1 >= l2 > 0 and
/// f(n) = A l1^n + B l2^n (or (A + n B') l^n for the double eigenvalue, e = r_c), so
/// f(n) / l2^n is monotone: every f(n) > 0 iff f(0) > 0 and A >= 0, where
/// A (l1 - l2) = f(1) - l2 f(0) = f(1) - f(0) T / 2 + f(0) sqrt(delta) / 2. Complex
/// eigenvalues (the spiral) or T <= 0 never collapse. Both sides of r_c and the double
/// eigenvalue alike; decided in rationals, linear in (a, c) for a given cycle.
class ConeTest {
 public:
  explicit ConeTest(const Cycle& cy) : mp_(cy) {
    Rational m00 = 1, m10 = 0, m01 = 0, m11 = 1;
    mp_.apply(0, m00, m10), mp_.apply(1, m00, m10);
    mp_.apply(0, m01, m11), mp_.apply(1, m01, m11);
    trace_ = m00 + m11;
    delta_ = trace_ * trace_ - 4 * (m00 * m11 - m01 * m10);
  }
  bool mayCollapse() const { return trace_ > 0 && delta_ >= 0; }
  const Rational& trace() const { return trace_; }
  const Rational& delta() const { return delta_; }
  /// The check of `pair` now and after one cycle (f0, f1), and of the other pair after this
  /// pair's impact and one cycle later (g0, g1).
  struct Checks {
    Rational f0, f1, g0, g1;
  };
  Checks checks(int pair, const Rational& a, const Rational& c) const {
    Rational a1 = a, c1 = c;
    mp_.apply(pair, a1, c1);
    Checks k{pair == 0 ? a : c, 0, pair == 0 ? c1 : a1, 0};
    mp_.apply(1 - pair, a1, c1);
    k.f1 = pair == 0 ? a1 : c1;
    mp_.apply(pair, a1, c1);
    k.g1 = pair == 0 ? c1 : a1;
    return k;
  }
  bool staysInCone(int pair, const Rational& a, const Rational& c) const {
    if (!mayCollapse()) return false;
    const Checks k = checks(pair, a, c);
    return k.f0 > 0 && k.g0 > 0 && nonDecreasing(k.f0, k.f1) && nonDecreasing(k.g0, k.g1);
  }
  /// (a, c) is an eigenvector of the cycle starting with `pair`, and not of the larger of two
  /// distinct eigenvalues: with no dominant part the impact times -db_p / dv_p grow without
  /// bound (linearly for the double eigenvalue, whose left and right eigenvectors are
  /// orthogonal; geometrically otherwise). If it stays in the cone, infinitely many impacts
  /// take an infinite time: no collapse. Needs a rational eigenvalue, so rare but real: masses
  /// (4, 1, 4), e = 1/4 = r_c, v = (0.5, 0, 1) m/s.
  bool slowEigenvector(int pair, const Rational& a, const Rational& c) const {
    Rational ma = a, mc = c;
    mp_.apply(pair, ma, mc), mp_.apply(1 - pair, ma, mc);
    if (a * mc != c * ma || (a == 0 && c == 0)) return false;
    const Rational l = a != 0 ? ma / a : mc / c;
    return delta_ == 0 || l < trace_ / 2;
  }
  /// Every (a, c) of the box a0 +- ea, c0 +- ec stays in the cone: the conditions are linear
  /// in (a, c), so the four corners decide.
  bool boxStaysInCone(int pair, double a0, double ea, double c0, double ec) const {
    for (int corner = 0; corner < 4; ++corner) {
      const Rational a = Rational(a0) + (corner & 1 ? Rational(ea) : -Rational(ea));
      const Rational c = Rational(c0) + (corner & 2 ? Rational(ec) : -Rational(ec));
      if (!staysInCone(pair, a, c)) return false;
    }
    return true;
  }

 private:
  bool nonDecreasing(const Rational& f0, const Rational& f1) const {
    return signWithRoot(f1 - f0 * trace_ / 2, f0 / 2, delta_) >= 0;
  }
  Maps<Rational> mp_;
  Rational trace_, delta_;
};

/// Walks the impacts from (a, c) with `first` the first pair to check, in arithmetic T, to
/// the first check that fails: call it only where ConeTest says that one does.
/// e = 0 is not walked here (the cluster rule applies; see models.cpp).
template <class T>
Walk walk(const Cycle& cy, int first, const T& a0, const T& c0, std::uint64_t limit) {
  const Maps<T> mp(cy);
  const double tolerance = 64 * roundoff<T>() * cy.kappa() * cy.kappa();
  T a = a0, c = c0;
  Walk w;
  int pair = first;
  for (;;) {
    const T& check = pair == 0 ? a : c;
    const double size = std::fabs(toDouble(a)) + std::fabs(toDouble(c));
    const double value = toDouble(check);
    if (roundoff<T>() > 0 && !(std::fabs(value) > tolerance * (w.count + 1) * size)) return w;  // undecided
    if (!(check > 0)) {
      w.end = WalkEnd::kFinished;
      break;
    }
    if (w.count == limit) return w;
    mp.apply(pair, a, c);
    ++w.count;
    pair = 1 - pair;
    if constexpr (!std::is_same_v<T, Rational>) {  // keep (a, c) normal: scale by 2^-shift, exactly
      int shift = 0;
      if constexpr (std::is_same_v<T, Float100>) {
        frexp(T(abs(a) + abs(c)), &shift);
      } else {
        std::frexp(std::fabs(toDouble(a)) + std::fabs(toDouble(c)), &shift);
      }
      if (shift < -400) {
        if constexpr (std::is_same_v<T, Float100>) {
          a = ldexp(a, -shift), c = ldexp(c, -shift);
        } else {
          const double factor = std::ldexp(1.0, -shift);
          a = a * factor, c = c * factor;
        }
        w.exponent += shift;
      }
    }
  }
  if constexpr (std::is_same_v<T, Rational>) {  // may lie below the double range
    const T big = T(std::ldexp(1.0, 900));
    T s = abs(a) + abs(c);
    while (s != 0 && s < 1) a *= big, c *= big, s *= big, w.exponent -= 900;
    w.a = static_cast<double>(a), w.c = static_cast<double>(c);
  } else {  // already normal
    w.a = toDouble(a), w.c = toDouble(c);
  }
  return w;
}

/// x^n (x > 0, n <= kWalkLimit) as mantissa * 2^exponent, by squaring with renormalisation.
inline std::pair<long double, long> powerScaled(long double x, std::uint64_t n) {
  int shift = 0;
  long double result = 1, base = std::frexp(x, &shift);
  long exponent = 0, base_exponent = shift;
  for (; n > 0; n >>= 1) {
    if (n & 1) {
      result = std::frexp(result * base, &shift);
      exponent += shift + base_exponent;
    }
    base = std::frexp(base * base, &shift);
    base_exponent = 2 * base_exponent + shift;
  }
  return {result, exponent};
}

/// The first n >= 0 with alpha + n beta <= 0 (none: nullopt).
inline std::optional<std::uint64_t> firstNonPositive(const Rational& alpha, const Rational& beta) {
  if (alpha <= 0) return std::uint64_t{0};
  if (beta >= 0) return std::nullopt;
  const Rational q = alpha / -beta;
  const boost::multiprecision::cpp_int n = (numerator(q) + denominator(q) - 1) / denominator(q);
  if (n > kWalkLimit) return std::uint64_t{kWalkLimit + 1};
  return static_cast<std::uint64_t>(n);
}

/// The double eigenvalue l = T / 2 (delta = 0: e at r_c exactly), in closed form. The cycle
/// map is M = l (I + N) with N nilpotent, so M^n = l^n (I + n N) and each check is
/// l^n (f0 + n beta), beta = f1 / l - f0: the first that fails gives the count, and
/// M^n d0 the state. Precondition: ConeTest says a check fails.
inline Walk doubleEigenvalueWalk(const Cycle& cy, const ConeTest& cone, int first, const Rational& a0, const Rational& c0) {
  const Rational l = cone.trace() / 2;
  const ConeTest::Checks k = cone.checks(first, a0, c0);
  const std::optional<std::uint64_t> nf = firstNonPositive(k.f0, k.f1 / l - k.f0);
  const std::optional<std::uint64_t> ng = firstNonPositive(k.g0, k.g1 / l - k.g0);
  Walk w;
  w.count = std::min(nf ? 2 * *nf : ~std::uint64_t{0}, ng ? 2 * *ng + 1 : ~std::uint64_t{0});
  const std::uint64_t n = w.count / 2;
  if (n > kWalkLimit) return w;  // undecided
  const Maps<Rational> mp(cy);
  Rational a = a0, c = c0;  // M d0, then d0 + n (M d0 / l - d0)
  mp.apply(first, a, c), mp.apply(1 - first, a, c);
  a = a0 + n * (a / l - a0), c = c0 + n * (c / l - c0);
  if (w.count % 2 == 1) mp.apply(first, a, c);
  const auto [mantissa, exponent] = powerScaled(static_cast<long double>(static_cast<double>(l)), n);
  w.end = WalkEnd::kFinished;
  w.a = static_cast<double>(static_cast<long double>(static_cast<double>(a)) * mantissa);
  w.c = static_cast<double>(static_cast<long double>(static_cast<double>(c)) * mantissa);
  w.exponent = exponent;
  return w;
}

/// The count and end state in O(1), from the checks' closed forms (ConeTest): for complex
/// eigenvalues (the spiral, e > r_c) f(n) = rho^n (f0 cos n phi + B sin n phi), first <= 0 at
/// n = ceil((pi/2 + atan2(B, f0)) / phi), with tan phi = sqrt(-delta) / T and
/// B = 2 (f1 - f0 T / 2) / sqrt(-delta); for real positive ones (T > 0, delta > 0) with A < 0
/// (exact sign), f(n) = A l1^n + B l2^n, first <= 0 at n = ceil(log(B / -A) / log(l1 / l2)).
/// Evaluated in 100 digits from exact rationals (relative error near 10^-95); a value within
/// 10^-40 (1 + n) of an integer is left undecided (then the walk decides). The state is
/// M^n d0 in the eigen-decomposition, its scale s^n kept as 2^exponent.
inline Walk closedFormWalk(const Cycle& cy, const ConeTest& cone, int first, const Rational& a0, const Rational& c0) {
  using F = Float100;
  const auto f = [](const Rational& r) { return F(numerator(r)) / F(denominator(r)); };
  const Rational& t = cone.trace();
  const Rational& delta = cone.delta();
  if (delta == 0 || (delta > 0 && t <= 0)) return {};
  const bool spiral = delta < 0;
  const F root = sqrt(f(abs(delta))), tt = f(t), pi = boost::math::constants::pi<F>();
  const F phi = atan2(root, tt), l1 = (tt + root) / 2, l2 = (tt - root) / 2;
  const ConeTest::Checks k = cone.checks(first, a0, c0);
  bool undecided = false;
  const auto first_fail = [&](const Rational& f0, const Rational& f1) -> std::uint64_t {
    if (f0 <= 0) return 0;
    const Rational x = f1 - f0 * t / 2;  // f1 - l2 f0 = x + (f0 / 2) sqrt(delta)
    F cycles;
    if (spiral) {
      cycles = (pi / 2 + atan2(2 * f(x) / root, f(f0))) / phi;
    } else {
      if (signWithRoot(x, f0 / 2, delta) >= 0) return ~std::uint64_t{0};  // A >= 0: never
      const F a = (f(x) + f(f0) / 2 * root) / root;
      cycles = log((f(f0) - a) / -a) / log(l1 / l2);
    }
    const F n = ceil(cycles);
    // Also undecided where the double-valued inputs leave the formula no finite answer (NaN
    // or a negative count, from subnormal scales): the walk does not decide then.
    if (!(n >= 0 && n <= F(std::ldexp(1.0, 60))) || n - cycles < F(1e-40) * (1 + n)) undecided = true;
    return undecided ? 0 : static_cast<std::uint64_t>(n);
  };
  const std::uint64_t nf = first_fail(k.f0, k.f1), ng = first_fail(k.g0, k.g1);
  Walk w;
  if (undecided || (nf == ~std::uint64_t{0} && ng == ~std::uint64_t{0})) return w;
  w.count = std::min(nf == ~std::uint64_t{0} ? nf : 2 * nf, ng == ~std::uint64_t{0} ? ng : 2 * ng + 1);
  // M^n d0 / s^n: spiral (sin n phi M d0 / rho - sin (n-1) phi d0) / sin phi, s = rho;
  // real (M d0 - l2 d0 - r^-n (M d0 - l1 d0)) / (l1 - l2), r = l1 / l2, s = l1.
  const std::uint64_t n = w.count / 2;
  const F nn = F(n), rho = sqrt(f((t * t - delta) / 4));  // sqrt(det)
  Rational ma = a0, mc = c0;
  Maps<Rational>(cy).apply(first, ma, mc), Maps<Rational>(cy).apply(1 - first, ma, mc);
  F a, c;
  if (spiral) {
    const F p = sin(nn * phi) / rho, q = sin((nn - 1) * phi), s = sin(phi);
    a = (p * f(ma) - q * f(a0)) / s, c = (p * f(mc) - q * f(c0)) / s;
  } else {
    const F tail = exp(-nn * log(l1 / l2));
    a = (f(ma) - l2 * f(a0) - tail * (f(ma) - l1 * f(a0))) / root;
    c = (f(mc) - l2 * f(c0) - tail * (f(mc) - l1 * f(c0))) / root;
  }
  if (w.count % 2 == 1) Maps<F>(cy).apply(first, a, c);
  const F scale = nn * log2(spiral ? rho : l1), whole = floor(scale);
  const F mantissa = exp((scale - whole) * log(F(2)));
  w.end = WalkEnd::kFinished;
  w.a = static_cast<double>(a * mantissa), w.c = static_cast<double>(c * mantissa);
  w.exponent = static_cast<long>(whole);
  return w;
}

/// The walk with exact decisions. A collapse is decided first (ConeTest), the double
/// eigenvalue in closed form; otherwise the walk in double, then double-double, then 100
/// digits, then rationals (a count below kRationalLimit). kUndecided only beyond kWalkLimit
/// impacts or the rational limit.
inline Walk walkExactly(const Cycle& cy, int first, const Rational& a0, const Rational& c0) {
  const ConeTest cone(cy);
  if (cone.staysInCone(first, a0, c0)) {
    return {cone.slowEigenvector(first, a0, c0) ? WalkEnd::kEndless : WalkEnd::kCollapse, 0, 0.0, 0.0, 0};
  }
  if (cone.mayCollapse() && cone.delta() == 0) return doubleEigenvalueWalk(cy, cone, first, a0, c0);
  Walk w = closedFormWalk(cy, cone, first, a0, c0);
  if (w.end != WalkEnd::kUndecided) return w;
  w = walk<double>(cy, first, static_cast<double>(a0), static_cast<double>(c0), kWalkLimit);
  if (w.end != WalkEnd::kUndecided) return w;
  const auto dd = [](const Rational& r) {  // to double-double: the double and the rest
    const double hi = static_cast<double>(r);
    return DD(hi) + DD(static_cast<double>(Rational(r - hi)));
  };
  w = walk<DD>(cy, first, dd(a0), dd(c0), kWalkLimit);
  if (w.end != WalkEnd::kUndecided) return w;
  w = walk<Float100>(cy, first, Float100(numerator(a0)) / Float100(denominator(a0)),
                     Float100(numerator(c0)) / Float100(denominator(c0)), kWalkLimit);
  if (w.end != WalkEnd::kUndecided) return w;
  return walk<Rational>(cy, first, a0, c0, kRationalLimit);
}

/// A value in 100 digits and a rigorous bound on its distance from the exact value.
struct Bounded {
  Float100 value;
  Float100 error;
};

/// Collapse time [s] for the cycle starting with `first`, from the initial approach
/// speeds dv and intercept differences db = (x_B - x_A, x_C - x_B): the impact times
/// -db_p/dv_p tend to -(w1 . db)/(w1 . dv), w1 the left eigenvector of the dominant
/// eigenvalue. The cycle's matrix exactly (rationals), the rest in 100 digits with every
/// rounding bounded (first order, with a wide margin). Requires real eigenvalues (for the
/// double one, M^n = l^n (I + n N) gives the same limit, w the left eigenvector). An infinite
/// error where w1 . dv cannot be told from 0.
inline Bounded collapseTimeBounded(const Cycle& cy, int first, const Rational dv[2], const Rational db[2]) {
  using F = Float100;
  const F eps = ldexp(F(1), -320);  // one operation or conversion, relative, with margin
  const Maps<Rational> mp(cy);
  Rational m00 = 1, m10 = 0, m01 = 0, m11 = 1;
  mp.apply(first, m00, m10), mp.apply(1 - first, m00, m10);
  mp.apply(first, m01, m11), mp.apply(1 - first, m01, m11);
  const Rational trace = m00 + m11, disc = trace * trace - 4 * (m00 * m11 - m01 * m10);
  const auto f = [](const Rational& r) { return F(numerator(r)) / F(denominator(r)); };
  // l1 = (T + sqrt(disc)) / 2 with T > 0: no cancellation.
  const F l1 = (f(trace) + sqrt(f(disc > 0 ? disc : Rational(0)))) / 2;
  const F l1_error = 8 * eps * abs(l1);
  // Left eigenvector w with w M = l1 w: (m10, l1 - m00), or (l1 - m11, m01); l1 - m_ii may cancel.
  F w0, w1, e0, e1;
  if (abs(m10) >= abs(m01)) {
    const F d = f(m00);
    w0 = f(m10), e0 = 4 * eps * abs(w0);
    w1 = l1 - d, e1 = l1_error + 4 * eps * (abs(l1) + abs(d));
  } else {
    const F d = f(m11);
    w0 = l1 - d, e0 = l1_error + 4 * eps * (abs(l1) + abs(d));
    w1 = f(m01), e1 = 4 * eps * abs(w1);
  }
  const F b0 = f(db[0]), b1 = f(db[1]), v0 = f(dv[0]), v1 = f(dv[1]);
  const F num = -(w0 * b0 + w1 * b1), den = w0 * v0 + w1 * v1;
  const F num_error = e0 * abs(b0) + e1 * abs(b1) + 8 * eps * (abs(w0 * b0) + abs(w1 * b1));
  const F den_error = e0 * abs(v0) + e1 * abs(v1) + 8 * eps * (abs(w0 * v0) + abs(w1 * v1));
  if (!(abs(den) > 2 * den_error)) return {num / den, std::numeric_limits<F>::infinity()};
  const F time = num / den;
  // |N~/D~ - N/D| <= (e_N + |N~/D~| e_D) / (|D~| - e_D), and the quotient's own rounding.
  return {time, 2 * (num_error + abs(time) * den_error) / (abs(den) - den_error) + 4 * eps * abs(time)};
}

/// collapseTimeBounded's value rounded to double: the correctly rounded collapse time
/// wherever its bound decides (almost always).
inline double collapseTime(const Cycle& cy, int first, const Rational dv[2], const Rational db[2]) {
  return static_cast<double>(collapseTimeBounded(cy, first, dv, db).value);
}

}  // namespace spiral_detail
}  // namespace core
}  // namespace collision_lab
