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
// Decisions. The walk runs in double, then double-double, then 100-digit floats, then in
// exact rationals.
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
  /// T^2 - 4 e^2 > 0 exactly (real, distinct eigenvalues), decided in rationals.
  bool realEigenvalues() const {
    const Rational t = exactTrace();
    return t * t > 4 * Rational(e) * Rational(e) && t > 0;
  }
  /// T^2 < 4 e^2 exactly: complex eigenvalues, the spiral (e > r_c).
  bool complexEigenvalues() const {
    const Rational t = exactTrace();
    return t * t < 4 * Rational(e) * Rational(e);
  }
  double trace() const { return (1 + e) * (1 + e) * cos2_alpha() - 2 * e; }
  double kappa() const {
    const double t = trace(), gap = std::sqrt(std::fabs(t * t - 4 * e * e));
    double heaviest = 0.0, lightest = std::numeric_limits<double>::infinity();  // of the finite masses
    for (int k = 0; k < 3; ++k) {
      if ((k == 0 && wall_a) || (k == 2 && wall_c)) continue;
      heaviest = std::max(heaviest, m[k]), lightest = std::min(lightest, m[k]);
    }
    return (1 + 2 * std::max(e, eBC()) / std::max(gap, 1e-300)) * std::sqrt(heaviest / lightest);
  }

 private:
  Rational exactTrace() const {
    return (1 + Rational(e)) * (1 + Rational(e)) * ratioA<Rational>() * ratioC<Rational>() - 2 * Rational(e);
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

enum class WalkEnd { kFinished, kCollapse, kUndecided };

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

/// Walks the impacts from (a, c) with `first` the first pair to check, in arithmetic T.
/// e = 0 is not walked here (the cluster rule applies; see models.cpp).
template <class T>
Walk walk(const Cycle& cy, int first, const T& a0, const T& c0, std::uint64_t limit) {
  const Maps<T> mp(cy);
  const bool may_collapse = cy.realEigenvalues();
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
    if (may_collapse && w.count % 2 == 0 && w.count >= 4 &&
        dominates(cy, pair, static_cast<long double>(toDouble(a)), static_cast<long double>(toDouble(c)))) {
      w.end = WalkEnd::kCollapse;
      break;
    }
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

/// The walk with exact decisions: double, then 100 digits, then rationals (a count below
/// kRationalLimit). kUndecided only beyond kWalkLimit impacts or the rational limit.
inline Walk walkExactly(const Cycle& cy, int first, const Rational& a0, const Rational& c0) {
  Walk w = walk<double>(cy, first, static_cast<double>(a0), static_cast<double>(c0), kWalkLimit);
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

/// Collapse time [s] for the cycle starting with `first`, from the initial approach
/// speeds dv and intercept differences db = (x_B - x_A, x_C - x_B): the impact times
/// -db_p/dv_p tend to -(w1 . db)/(w1 . dv), w1 the left eigenvector of the dominant
/// eigenvalue. Evaluated in 100 digits. Requires real distinct eigenvalues.
inline double collapseTime(const Cycle& cy, int first, const Rational dv[2], const Rational db[2]) {
  using F = Float100;
  const Maps<F> mp(cy);
  F m00 = 1, m10 = 0, m01 = 0, m11 = 1;
  mp.apply(first, m00, m10), mp.apply(1 - first, m00, m10);
  mp.apply(first, m01, m11), mp.apply(1 - first, m01, m11);
  const F t = m00 + m11, det = m00 * m11 - m01 * m10;
  const F l1 = (t + sqrt(t * t - 4 * det)) / 2;
  // Left eigenvector w with w M = l1 w: (m10, l1 - m00), or (l1 - m11, m01).
  F w0, w1;
  if (abs(m10) >= abs(m01)) {
    w0 = m10, w1 = l1 - m00;
  } else {
    w0 = l1 - m11, w1 = m01;
  }
  auto f = [](const Rational& r) { return F(numerator(r)) / F(denominator(r)); };
  return static_cast<double>(F(-(w0 * f(db[0]) + w1 * f(db[1])) / (w0 * f(dv[0]) + w1 * f(dv[1]))));
}

}  // namespace spiral_detail
}  // namespace core
}  // namespace collision_lab
