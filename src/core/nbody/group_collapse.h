// Inelastic collapse of a group of any size whose impacts repeat a pattern (docs/physics.md,
// "Collapse of a larger group"). Internal to the engine (tier.h); not installed.
//
// State. For a group of g + 1 units (bodies or clusters, a wall at one end) the approach
// speeds d_p = v_(p+1) - v_p and the intercept differences c_p = b_(p+1) - b_p of its g
// pairs; an impact of pair q maps both by the same linear map, and t_q = -c_q / d_q.
//
// Proof. The pattern repeats for ever iff at each of its steps the next pair approaches
// (a linear functional of d) and every other approaching pair hits later (a coordinate of
// the bivector c ^ d, which evolves by the second compound matrix). For each of the two
// linear systems an invariant cone is checked in exact rationals: K = {|y_2..n|_1 <= eps y_1}
// in the coordinates y = P^-1 s of an approximate eigenbasis P (doubles, exact as rationals);
// the period map to the power k maps K's generators e_1 +- eps e_i into K, and every
// functional of k periods is positive on them; the state is in K. Then, by induction, the
// pattern never breaks. Finite time: the bivector's growth bound is below the square of the
// approach speeds' decay bound. Anything not proved returns nullopt: never a guess.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Eigenvalues>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_int.hpp>

namespace collision_lab {
namespace core {
namespace group_detail {

using Rational = boost::multiprecision::cpp_rational;
using Float100 = boost::multiprecision::cpp_bin_float_100;
using Vec = std::vector<Rational>;
using Mat = std::vector<Vec>;  ///< row-major

constexpr std::size_t kMaxPairs = 7;    ///< groups of up to 8 units
constexpr std::size_t kMaxPeriod = 24;  ///< impacts per pattern

/// The impact maps of a group's g pairs: pair q sends share_down[q] d_q to pair q - 1 and
/// share_up[q] d_q to pair q + 1, and d_q becomes -e[q] d_q. share_down = (1 + e) m_(q+1) /
/// (m_q + m_(q+1)) (0 when body q is a wall), share_up = (1 + e) m_q / (m_q + m_(q+1)).
struct GroupMaps {
  Vec e, share_down, share_up;
  std::size_t pairs() const { return e.size(); }
  void apply(std::size_t q, Vec& d) const {
    if (q > 0) d[q - 1] += share_down[q] * d[q];
    if (q + 1 < d.size()) d[q + 1] += share_up[q] * d[q];
    d[q] *= -e[q];
  }
  /// The matrix of pair q's map applied after `m`.
  void applyRows(std::size_t q, Mat& m) const {
    const std::size_t n = m.size();
    for (std::size_t c = 0; c < n; ++c) {
      if (q > 0) m[q - 1][c] += share_down[q] * m[q][c];
      if (q + 1 < n) m[q + 1][c] += share_up[q] * m[q][c];
      m[q][c] *= -e[q];
    }
  }
};

inline Mat identity(std::size_t n) {
  Mat m(n, Vec(n, Rational(0)));
  for (std::size_t i = 0; i < n; ++i) m[i][i] = 1;
  return m;
}

inline Mat multiply(const Mat& a, const Mat& b) {
  const std::size_t n = a.size(), k = b.size(), p = b[0].size();
  Mat c(n, Vec(p, Rational(0)));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < k; ++j) {
      if (a[i][j] == 0) continue;
      for (std::size_t l = 0; l < p; ++l) c[i][l] += a[i][j] * b[j][l];
    }
  }
  return c;
}

inline Vec multiply(const Mat& a, const Vec& x) {
  Vec y(a.size(), Rational(0));
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < x.size(); ++j) y[i] += a[i][j] * x[j];
  }
  return y;
}

/// Row vector times matrix.
inline Vec multiply(const Vec& r, const Mat& a) {
  Vec y(a[0].size(), Rational(0));
  for (std::size_t j = 0; j < a.size(); ++j) {
    if (r[j] == 0) continue;
    for (std::size_t l = 0; l < y.size(); ++l) y[l] += r[j] * a[j][l];
  }
  return y;
}

/// The exact inverse (Gauss-Jordan in rationals); nullopt when singular.
inline std::optional<Mat> inverse(Mat a) {
  const std::size_t n = a.size();
  Mat inv = identity(n);
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t pivot = c;
    while (pivot < n && a[pivot][c] == 0) ++pivot;
    if (pivot == n) return std::nullopt;
    std::swap(a[pivot], a[c]), std::swap(inv[pivot], inv[c]);
    const Rational f = 1 / a[c][c];
    for (std::size_t l = 0; l < n; ++l) a[c][l] *= f, inv[c][l] *= f;
    for (std::size_t r = 0; r < n; ++r) {
      if (r == c || a[r][c] == 0) continue;
      const Rational g = a[r][c];
      for (std::size_t l = 0; l < n; ++l) a[r][l] -= g * a[c][l], inv[r][l] -= g * inv[c][l];
    }
  }
  return inv;
}

/// Index of the bivector coordinate (i, j), i < j, of g pairs.
inline std::size_t wedgeIndex(std::size_t i, std::size_t j, std::size_t g) { return i * g - i * (i + 1) / 2 + (j - i - 1); }

/// The second compound matrix: (A c) ^ (A d) = C2(A) (c ^ d).
inline Mat compound(const Mat& a) {
  const std::size_t g = a.size(), n = g * (g - 1) / 2;
  Mat c(n, Vec(n, Rational(0)));
  for (std::size_t a1 = 0; a1 < g; ++a1) {
    for (std::size_t b1 = a1 + 1; b1 < g; ++b1) {
      for (std::size_t i = 0; i < g; ++i) {
        for (std::size_t j = i + 1; j < g; ++j) {
          c[wedgeIndex(a1, b1, g)][wedgeIndex(i, j, g)] = a[a1][i] * a[b1][j] - a[a1][j] * a[b1][i];
        }
      }
    }
  }
  return c;
}

/// A linear system s -> A s whose state must keep every functional positive for ever.
struct System {
  Mat period;            ///< A, one period
  Vec state;             ///< s now
  std::vector<Vec> rows;  ///< functionals of the state at the period's start, all > 0
};

/// The proved bounds of a system's dominant coordinate y_1 over `periods` periods:
/// lower * y_1 <= y_1' <= upper * y_1.
struct ConeBounds {
  Rational lower, upper;
  std::uint64_t periods = 0;
};

inline Rational l1Rest(const Vec& v) {
  Rational s = 0;
  for (std::size_t i = 1; i < v.size(); ++i) s += abs(v[i]);
  return s;
}

/// min over the cone's generators e_1 +- eps e_i of r . g, as r_1 - eps max |r_i|.
inline Rational lowestOnCone(const Vec& r, const Rational& eps) {
  Rational m = 0;
  for (std::size_t i = 1; i < r.size(); ++i) m = std::max(m, Rational(abs(r[i])));
  return r[0] - eps * m;
}

/// The invariant-cone proof for one system (see the header); nullopt when not proved.
inline std::optional<ConeBounds> proveCone(const System& sys) {
  const std::size_t n = sys.period.size();
  Eigen::MatrixXd a(n, n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) a(i, j) = static_cast<double>(sys.period[i][j]);
  }
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(a);
  if (solver.info() != Eigen::Success) return std::nullopt;
  const auto values = solver.eigenvalues();
  const auto vectors = solver.eigenvectors();
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return std::abs(values[x]) > std::abs(values[y]); });
  const auto top = values[order[0]];
  if (!(top.real() > 0) || top.imag() != 0.0) return std::nullopt;
  if (n > 1 && !(std::abs(values[order[1]]) < top.real() * (1 - 1e-6))) return std::nullopt;
  // P: the eigenvectors in that order, a complex pair as its real and imaginary parts.
  Mat p(n, Vec(n, Rational(0)));
  for (std::size_t c = 0; c < n;) {
    const std::size_t k = order[c];
    const bool complex = values[k].imag() != 0.0 && c + 1 < n;
    for (std::size_t i = 0; i < n; ++i) {
      p[i][c] = Rational(vectors(i, k).real());
      if (complex) p[i][c + 1] = Rational(vectors(i, k).imag());
    }
    c += complex ? 2 : 1;
  }
  const std::optional<Mat> pinv = inverse(p);
  if (!pinv) return std::nullopt;
  Mat q = *pinv;
  Vec y = multiply(q, sys.state);
  if (y[0] == 0) return std::nullopt;
  if (y[0] < 0) {  // orient the dominant coordinate positive
    for (std::size_t i = 0; i < n; ++i) p[i][0] = -p[i][0];
    for (Rational& x : q[0]) x = -x;
    y[0] = -y[0];
  }
  const Rational floor = Rational(1) / (std::uint64_t{1} << 40);
  const Rational eps = std::max(Rational(2 * l1Rest(y) / y[0]), floor);
  if (eps > Rational(1, 8)) return std::nullopt;  // not yet near the dominant direction
  Mat power = identity(n);  // A^m, m < k
  std::vector<Vec> rows_p;  // each functional of each period so far, in cone coordinates
  for (std::uint64_t k = 1; k <= 64; k *= 2) {
    // Functionals of periods power .. power * A^(k/2 .. k-1), then A^k.
    while (rows_p.size() < k * sys.rows.size()) {
      const Mat ap = multiply(power, p);
      for (const Vec& r : sys.rows) rows_p.push_back(multiply(r, ap));
      power = multiply(sys.period, power);
    }
    bool positive = true;
    for (const Vec& r : rows_p) positive = positive && lowestOnCone(r, eps) > 0;
    if (!positive) return std::nullopt;  // a functional fails on the cone: more periods cannot help
    const Mat b = multiply(q, multiply(power, p));  // P^-1 A^k P
    bool invariant = true;
    Rational lower = -1, upper = 0;
    for (std::size_t i = 1; i < n || (n == 1 && i == 1); ++i) {
      for (int sign : {1, -1}) {
        Vec g(n, Rational(0));
        g[0] = 1;
        if (i < n) g[i] = sign * eps;
        const Vec bg = multiply(b, g);
        invariant = invariant && l1Rest(bg) <= eps * bg[0];
        lower = lower < 0 ? bg[0] : std::min(lower, bg[0]);
        upper = std::max(upper, bg[0]);
      }
    }
    if (invariant && lower > 0) return ConeBounds{lower, upper, k};
  }
  return std::nullopt;
}

/// The group's collapse, proved: the impacts repeat `pattern` for ever, in a finite time.
/// maps: the group's impact maps; pattern: pair indices (local), the first one next;
/// c, d: intercept differences [m] and approach speeds [m/s] now. Returns the collapse time
/// [s] (the limit of the impact times, iterated in 100 digits), or nullopt.
inline std::optional<double> proveCollapse(const GroupMaps& maps, const std::vector<std::size_t>& pattern, const Vec& c,
                                           const Vec& d) {
  const std::size_t g = maps.pairs();
  if (g < 2 || g > kMaxPairs || pattern.empty() || pattern.size() > kMaxPeriod) return std::nullopt;
  for (const Rational& e : maps.e) {
    if (e <= 0) return std::nullopt;  // e = 0 sticks: the cluster rule, not a collapse
  }
  // The partial products A_j and the period M.
  std::vector<Mat> partial{identity(g)};
  for (std::size_t q : pattern) {
    Mat next = partial.back();
    maps.applyRows(q, next);
    partial.push_back(next);
  }
  const Mat& m = partial.back();
  // The asymptotic direction of d decides which other pairs must be separating and which
  // must hit later (a double estimate only chooses the conditions; the proof checks them).
  Eigen::MatrixXd md(g, g);
  for (std::size_t i = 0; i < g; ++i) {
    for (std::size_t j = 0; j < g; ++j) md(i, j) = static_cast<double>(m[i][j]);
  }
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(md);
  if (solver.info() != Eigen::Success) return std::nullopt;
  std::size_t top = 0;
  for (std::size_t i = 1; i < g; ++i) {
    if (std::abs(solver.eigenvalues()[i]) > std::abs(solver.eigenvalues()[top])) top = i;
  }
  Eigen::VectorXd v1 = solver.eigenvectors().col(top).real();
  System speeds{m, d, {}};
  System wedges{compound(m), Vec(g * (g - 1) / 2, Rational(0)), {}};
  for (std::size_t i = 0; i < g; ++i) {
    for (std::size_t j = i + 1; j < g; ++j) wedges.state[wedgeIndex(i, j, g)] = c[i] * d[j] - c[j] * d[i];
  }
  if (v1[pattern[0]] < 0) v1 = -v1;
  for (std::size_t j = 0; j < pattern.size(); ++j) {
    const std::size_t q = pattern[j];
    const Mat& a = partial[j];
    speeds.rows.push_back(a[q]);  // pair q approaches
    const Eigen::VectorXd w = [&] {
      Eigen::MatrixXd ad(g, g);
      for (std::size_t r = 0; r < g; ++r) {
        for (std::size_t s = 0; s < g; ++s) ad(r, s) = static_cast<double>(a[r][s]);
      }
      return Eigen::VectorXd(ad * v1);
    }();
    const Mat wedge_map = compound(a);
    for (std::size_t o = 0; o < g; ++o) {
      if (o == q) continue;
      if (w[o] < 0) {  // o separates: -d_o > 0
        Vec r = a[o];
        for (Rational& x : r) x = -x;
        speeds.rows.push_back(r);
      } else {  // o hits later: c_q d_o - c_o d_q > 0, the (q, o) coordinate
        Vec r = wedge_map[wedgeIndex(std::min(q, o), std::max(q, o), g)];
        if (o < q) {
          for (Rational& x : r) x = -x;
        }
        wedges.rows.push_back(r);
      }
    }
  }
  const std::optional<ConeBounds> sb = proveCone(speeds);
  if (!sb) return std::nullopt;
  if (!wedges.rows.empty()) {
    const std::optional<ConeBounds> wb = proveCone(wedges);
    if (!wb) return std::nullopt;
    // Finite time: the intervals (a wedge coordinate over two speeds) shrink geometrically.
    Rational lhs = 1, rhs = 1;
    for (std::uint64_t k = 0; k < sb->periods; ++k) lhs *= wb->upper;
    for (std::uint64_t k = 0; k < 2 * wb->periods; ++k) rhs *= sb->lower;
    if (!(lhs < rhs)) return std::nullopt;
  } else if (!(sb->upper < 1)) {
    return std::nullopt;
  }
  // The collapse time: the impact times of pattern[0], period by period, in 100 digits
  // (scaled by powers of two: the ratio is invariant), to their limit.
  using F = Float100;
  std::vector<F> cf, df;
  for (std::size_t i = 0; i < g; ++i) {
    cf.push_back(F(numerator(c[i])) / F(denominator(c[i])));
    df.push_back(F(numerator(d[i])) / F(denominator(d[i])));
  }
  std::vector<F> ef, up, down;
  for (std::size_t i = 0; i < g; ++i) {
    const auto f = [](const Rational& r) { return F(numerator(r)) / F(denominator(r)); };
    ef.push_back(f(maps.e[i])), up.push_back(f(maps.share_up[i])), down.push_back(f(maps.share_down[i]));
  }
  const auto step = [&](std::size_t q, std::vector<F>& x) {
    if (q > 0) x[q - 1] += down[q] * x[q];
    if (q + 1 < g) x[q + 1] += up[q] * x[q];
    x[q] *= -ef[q];
  };
  const std::size_t q0 = pattern[0];
  F t[3] = {-cf[q0] / df[q0], 0, 0};
  for (int k = 1; k <= 100000; ++k) {
    for (std::size_t q : pattern) step(q, cf), step(q, df);
    int shift = 0;
    frexp(F(abs(df[q0])), &shift);
    for (std::size_t i = 0; i < g; ++i) cf[i] = ldexp(cf[i], -shift), df[i] = ldexp(df[i], -shift);
    t[2] = t[1], t[1] = t[0], t[0] = -cf[q0] / df[q0];
    if (k >= 3 && abs(t[0] - t[1]) <= ldexp(abs(t[0]), -90) + F(1e-300)) {
      const F d1 = t[0] - t[1], d2 = t[1] - t[2];
      const F limit = d2 != d1 ? t[0] - d1 * d1 / (d1 - d2) : t[0];
      return static_cast<double>(limit);
    }
  }
  return std::nullopt;
}

}  // namespace group_detail
}  // namespace core
}  // namespace collision_lab
