// Transcriptions of the paper's printed equations. Walls make the printed expressions
// inf/inf; they come out as NaN ("not defined as printed"), never as a guessed limit.
#include "collision_lab/core/paper.h"

#include <cmath>
#include <limits>

#include <boost/math/constants/constants.hpp>

#include "collision_lab/core/wedge.h"
#include "correct_rounding.h"
#include "float_ops.h"

namespace collision_lab {
namespace core {
namespace paper {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A zero is +0, never -0 (outputs must not show "-0").
std::array<double, 3> plusZeros(std::array<double, 3> values) {
  for (double& x : values) x = detail::toDouble(x);
  return values;
}

/// The paper's constants: c + d i of eq. (2.6), nu^2 = c^2 + d^2, theta = arg(lambda_+).
struct Constants {
  double c, d, nu_sq, theta;
};

Constants constantsOf(const std::array<double, 3>& masses) {
  const double m_a = masses[kA], m_b = masses[kB], m_c = masses[kC];
  const double m_ab = m_a + m_b, m_bc = m_b + m_c, m_total = m_a + m_b + m_c;
  const double root = std::sqrt(m_a * m_b * m_c * m_total);
  Constants k;
  k.c = 2 * m_a * m_c / (m_a * m_ab);
  k.d = root / (m_a * m_ab);
  k.nu_sq = k.c * k.c + k.d * k.d;
  // lambda_+ = (m_A m_C - m_B M + 2 i sqrt(m_A m_B m_C M)) / (M_AB M_BC), eq. (2.2).
  k.theta = std::atan2(2 * root / (m_ab * m_bc), (m_a * m_c - m_b * m_total) / (m_ab * m_bc));
  return k;
}

/// phiBC evaluated in double as printed.
double phiBCInDouble(const Scene& scene) {
  // As printed, with s = (sqrt m_i) unscaled: a wall makes it inf / inf.
  if (wallIndex(scene) >= 0) return kNaN;
  const std::array<double, 3> m = triple(scene.masses);
  const auto& v = scene.velocities;
  // u after the first AB impact (eq. 1.1, 1.2), in u = (sqrt(m_i) v_i).
  const double m_ab = m[kA] + m[kB];
  const double va = ((m[kA] - m[kB]) * v[kA] + 2 * m[kB] * v[kB]) / m_ab;
  const double vb = (2 * m[kA] * v[kA] + (m[kB] - m[kA]) * v[kB]) / m_ab;
  const Eigen::Vector3d u1(std::sqrt(m[kA]) * va, std::sqrt(m[kB]) * vb, std::sqrt(m[kC]) * v[kC]);
  const Wedge<double> wedge = wedgeOf<double>(m);
  // l_BC = s_hat x n_BC / |s_hat x n_BC| (eq. 3.20): the line of r_BC, its orientation as printed.
  const Eigen::Vector3d l_bc = cross<double>(wedge.s_hat, wedge.n_bc).normalized();
  return std::atan2(u1.dot(wedge.n_bc), u1.dot(l_bc));  // eq. (3.21)
}

/// impactCount evaluated in double as printed.
std::optional<std::int64_t> impactCountInDouble(const Scene& scene) {
  const double x = (omega(triple(scene.masses)) - phiBCInDouble(scene)) / constantsOf(triple(scene.masses)).theta;
  // Evaluated in double as printed; 1 + floor(x) + ceil(x) must fit the int64 it is reported in.
  if (!std::isfinite(x) || std::fabs(x) > 4e18) return std::nullopt;
  return 1 + static_cast<std::int64_t>(std::floor(x)) + static_cast<std::int64_t>(std::ceil(x));  // eq. (3.22)
}


using detail::Certifying;
using Rational = detail::ExactRational;
using Integer = boost::multiprecision::cpp_int;

Certifying toCertifying(const Rational& q) { return Certifying(numerator(q)) / Certifying(denominator(q)); }

/// The arguments of the printed angles of a scene without a wall, exact (T = Rational) or
/// with a filter's bound (T = detail::Filtered). With u1 after the
/// first AB impact, u1.n_BC and u1.l_BC of eq. (3.21) are, up to one positive factor,
/// Y = v_B1 - v_C1 and X sqrt(m_A / (m_B m_C M)) with X = m_B v_B1 + m_C v_C1 - (m_B + m_C) v_A1;
/// Omega = arccos(n_AB . n_BC) has cos^2 = m_A m_C / q and sin^2 = m_B M / q (cos < 0), and
/// theta = arg lambda_+ = atan2(2 sqrt(D), a) (eq. 2.2), q = m_A m_C + m_B M, a = m_A m_C - m_B M.
template <class T>
struct PrintedAngleArguments {
  explicit PrintedAngleArguments(const Scene& scene)
      : m_a(scene.masses[kA]), m_b(scene.masses[kB]), m_c(scene.masses[kC]), total(m_a + m_b + m_c) {
    const T v_a(scene.velocities[kA]), v_b(scene.velocities[kB]), v_c(scene.velocities[kC]);
    const T m_ab = m_a + m_b;
    const T v_a1 = ((m_a - m_b) * v_a + T(2) * m_b * v_b) / m_ab;
    const T v_b1 = (T(2) * m_a * v_a + (m_b - m_a) * v_b) / m_ab;
    x = m_b * v_b1 + m_c * v_c - (m_b + m_c) * v_a1;
    y = v_b1 - v_c;
    x_scale = m_a / (m_b * m_c * total);
    q = m_a * m_c + m_b * total;
    omega_cos_sq = m_a * m_c / q;
    omega_sin_sq = m_b * total / q;
    theta_d = m_a * m_b * m_c * total;
    theta_a = m_a * m_c - m_b * total;
  }
  T m_a, m_b, m_c, total;       // the masses [kg] and M
  T x, y, x_scale;              // X, Y and m_A / (m_B m_C M): phi_BC = atan2(Y, X sqrt(x_scale))
  T q;
  T omega_cos_sq, omega_sin_sq;
  T theta_d, theta_a;           // D and a
};

/// 1 + floor(x) + ceil(x) of eq. (3.22) when every value within `error` of x gives the same.
std::optional<std::int64_t> decidedCount(const Certifying& x, const Certifying& error) {
  const Certifying low = x - error, high = x + error;
  if (floor(low) != floor(high) || ceil(low) != ceil(high)) return std::nullopt;
  return 1 + static_cast<std::int64_t>(floor(x)) + static_cast<std::int64_t>(ceil(x));
}

/// Is Omega - phi_BC = j theta exactly (a scene without a wall)? With N = m_B M Y - m_A X and
/// S = X + m_C Y (PrintedAngleArguments' X and Y), cos(Omega - phi_BC) = N / sqrt(m_B M q rho^2) and
/// sin(Omega - phi_BC) = S sqrt(m_A / m_C) / sqrt(q rho^2), rho^2 = X^2 m_A / (m_B m_C M) + Y^2,
/// q = m_A m_C + m_B M; lambda_+^j = c_j + i sqrt(D) s_j with rationals c_j, s_j. Equal unit
/// vectors: the signs agree and the cosines' squares are equal. (Equal modulo 2 pi: the caller
/// knows the two angles to be within far less than 2 pi.)
bool isMultipleOfTheta(const PrintedAngleArguments<Rational>& a, std::int64_t j) {
  const Rational &m_a = a.m_a, &m_b = a.m_b, &m_c = a.m_c, &total = a.total, &q = a.q, &x = a.x, &y = a.y;
  // lambda_+^|j| by squaring, (c, s) for c + i sqrt(D) s; a negative j conjugates.
  using Complex = std::pair<Rational, Rational>;
  const auto times = [&a](const Complex& u, const Complex& w) {
    return Complex{u.first * w.first - a.theta_d * u.second * w.second, u.first * w.second + u.second * w.first};
  };
  Complex power{1, 0}, base{a.theta_a / q, Rational(2) / q};
  for (std::uint64_t e = static_cast<std::uint64_t>(j < 0 ? -j : j); e > 0; e >>= 1) {
    if (e & 1) power = times(power, base);
    base = times(base, base);
  }
  if (j < 0) power.second = -power.second;
  const Rational n = m_b * total * y - m_a * x, s = x + m_c * y;
  const Rational rho_sq = x * x * a.x_scale + y * y;
  const auto sign = [](const Rational& value) { return (value > 0) - (value < 0); };
  return sign(n) == sign(power.first) && sign(s) == sign(power.second) &&
         n * n == power.first * power.first * m_b * total * q * rho_sq;
}

}  // namespace

PrintedClosedForm::PrintedClosedForm(const Scene& scene) {
  const std::array<double, 3> m = triple(scene.masses);
  const auto& v0 = scene.velocities;
  const Constants k = constantsOf(m);
  c_ = k.c;
  d_ = k.d;
  nu_sq_ = k.nu_sq;
  theta_ = k.theta;
  vbar_ = (v0[kA] + v0[kB]) / 2;  // the *initial* average (eq. 2.14)
  half_ba_ = (v0[kB] - v0[kA]) / 2;
  v_c_ = v0[kC];
  m_ab_ = m[kA] + m[kB];
  odd_a_ = m[kA] - 3 * m[kB];
  odd_b_ = m[kB] - 3 * m[kA];
}

std::array<double, 3> PrintedClosedForm::velocitiesAfter(std::uint64_t n, double co, double s) const {
  // The two brackets of eq. (2.15).
  const double x = ((vbar_ - v_c_) * nu_sq_ + c_ * half_ba_) * s - d_ * half_ba_ * co;
  const double y = (-half_ba_ - c_ * (vbar_ - v_c_)) * s - d_ * (vbar_ - v_c_) * co;
  if (n % 2 == 0) return plusZeros({x / d_ + vbar_, -x / d_ + vbar_, y / d_ + vbar_});
  // Eq. (2.16).
  return plusZeros({odd_a_ * x / (d_ * m_ab_) + vbar_, odd_b_ * x / (d_ * m_ab_) + vbar_,
                    m_ab_ * y / (d_ * m_ab_) + vbar_});
}

double omega(const std::array<double, 3>& m) {
  const Wedge<double> wedge = wedgeOf<double>(m);
  return std::acos(wedge.n_ab.dot(wedge.n_bc));
}

ExactPrintedClosedForm::ExactPrintedClosedForm(const Scene& scene) {
  // The formulas are of degree 0 in the masses: scaled to integers, they keep their values.
  Integer scale = 1;
  for (const double m : scene.masses) scale = lcm(scale, denominator(Rational(m)));
  std::array<Integer, 3> m;
  for (int k = 0; k < 3; ++k) {
    const Rational exact(scene.masses[k]);
    m[k] = numerator(exact) * (scale / denominator(exact));
  }
  const Integer total = m[kA] + m[kB] + m[kC];
  a_ = m[kA] * m[kC] - m[kB] * total;
  d_ = m[kA] * m[kB] * m[kC] * total;
  q_ = m[kA] * m[kC] + m[kB] * total;
  m_ab_ = m[kA] + m[kB];
  odd_a_ = m[kA] - 3 * m[kB];
  odd_b_ = m[kB] - 3 * m[kA];
  const Rational v_a(scene.velocities[kA]), v_b(scene.velocities[kB]), v_c(scene.velocities[kC]);
  const Rational vbar = (v_a + v_b) / 2, half_ba = (v_b - v_a) / 2, gap = vbar - v_c;
  // x / d = (U Q_k - half_ba P_k) / q^k and y / d = (W Q_k - gap P_k) / q^k, with c = 2 m_C / M_AB,
  // d = sqrt(D) / (m_A M_AB) and nu^2 = c^2 + d^2 (eq. 2.15).
  const Rational c(2 * m[kC], m_ab_);
  const Rational weight(m[kA] * m_ab_);
  const Rational nu_sq = c * c + Rational(d_) / (weight * weight);
  const std::array<Rational, 5> values{(gap * nu_sq + c * half_ba) * weight, half_ba, (-half_ba - c * gap) * weight,
                                       gap, vbar};
  l_ = 1;
  for (const Rational& value : values) l_ = lcm(l_, denominator(value));
  std::array<Integer*, 5> tops{&u_, &h_, &w_, &g_, &b_};
  for (int i = 0; i < 5; ++i) *tops[i] = numerator(values[i]) * (l_ / denominator(values[i]));
}

void ExactPrintedClosedForm::moveTo(std::uint64_t k) {
  if (k < k_) {
    p_ = 1;
    s_ = 0;
    power_ = 1;
    k_ = 0;
  }
  for (; k_ < k; ++k_) {  // lambda^(k+1) = lambda^k (a + 2 i sqrt(D)) / q
    const Integer p = a_ * p_ - 2 * d_ * s_;
    s_ = a_ * s_ + 2 * p_;
    p_ = p;
    power_ *= q_;
  }
}

std::array<double, 3> ExactPrintedClosedForm::velocitiesAfter(std::uint64_t n) {
  moveTo(n / 2);
  const Integer x = u_ * s_ - h_ * p_;  // x / d = x / (l q^k)
  const Integer y = w_ * s_ - g_ * p_;
  const Integer mean = b_ * power_;     // vbar = mean / (l q^k)
  const Integer bottom = l_ * power_;
  const double c = detail::nearestDouble(y + mean, bottom);
  if (n % 2 == 0) return {detail::nearestDouble(x + mean, bottom), detail::nearestDouble(mean - x, bottom), c};
  return {detail::nearestDouble(odd_a_ * x + m_ab_ * mean, m_ab_ * bottom),
          detail::nearestDouble(odd_b_ * x + m_ab_ * mean, m_ab_ * bottom), c};  // eq. (2.16)
}

double phiBC(const Scene& scene, bool* certified) {
  if (wallIndex(scene) >= 0) return kNaN;  // as printed, s = (sqrt m_i) unscaled: inf / inf
  if (detail::kFilterable) {
    const PrintedAngleArguments<detail::Filtered> f(scene);
    if (const auto rounded = detail::filteredAtan2Sqrt(f.y, f.x, f.x_scale)) return *rounded;
  }
  const PrintedAngleArguments<Rational> a(scene);
  if (const auto rounded = detail::roundedAtan2Sqrt(a.y, a.x, a.x_scale)) return *rounded;
  if (certified) *certified = false;
  return phiBCInDouble(scene);
}

std::optional<std::int64_t> impactCount(const Scene& scene, bool* certified) {
  if (wallIndex(scene) >= 0) return std::nullopt;  // phi_BC is inf / inf as printed
  if (detail::kFilterable) {  // the filter first: the arguments with their bounds, no rationals
    using detail::Filtered;
    const PrintedAngleArguments<Filtered> f(scene);
    const Filtered omega = atan2(sqrt(f.omega_sin_sq), -sqrt(f.omega_cos_sq));
    const Filtered theta = atan2(Filtered(2) * sqrt(f.theta_d), f.theta_a);
    const Filtered x = (omega - detail::atan2Sqrt(f.y, f.x, f.x_scale)) / theta;
    if (std::isfinite(x.value) && std::isfinite(x.error) && std::fabs(x.value) + x.error < 4e18L) {
      if (const auto count = decidedCount(Certifying(x.value), Certifying(x.error))) return count;
    }
  }
  const PrintedAngleArguments<Rational> a(scene);
  const Certifying omega = atan2(sqrt(toCertifying(a.omega_sin_sq)), -sqrt(toCertifying(a.omega_cos_sq)));
  const Certifying theta = atan2(2 * sqrt(toCertifying(a.theta_d)), toCertifying(a.theta_a));
  const Certifying x = (omega - detail::certifyingAtan2Sqrt(a.y, a.x, a.x_scale)) / theta;
  // Each angle within 2^-298 of it relatively, so within 2^-296 (below 4): the numerator
  // within 2^-295, x moreover within 2^-296 of it relatively through theta.
  const Certifying unit = ldexp(Certifying(1), -294);
  const Certifying error = unit / theta + abs(x) * unit;
  if (abs(x) + error > 4e18) return std::nullopt;  // as the double evaluation: beyond an int64
  if (const auto count = decidedCount(x, error)) return count;
  // Within the bound of an integer j (a grazing start): x = j exactly when the rotation by
  // Omega - phi_BC is lambda_+^j, decided in rationals (a small j only).
  const Certifying nearest = round(x);
  if (abs(nearest) <= 4096 && isMultipleOfTheta(a, static_cast<std::int64_t>(nearest))) {
    return 1 + 2 * static_cast<std::int64_t>(nearest);
  }
  if (certified) *certified = false;
  return impactCountInDouble(scene);
}

std::array<double, 3> energyTransfer(const Scene& scene, std::uint64_t n, Pair pair,
                                     const std::array<double, 3>& state_before,
                                     const std::array<double, 3>& state_two_before) {
  const std::array<double, 3> m = triple(scene.masses);
  const double vbar = (scene.velocities[kA] + scene.velocities[kB]) / 2;  // initial average
  if (pair == Pair::AB) {
    // Eqs. (4.4), (4.5): v_k from v_A2k = v_k + vbar_AB, P_AB2k the AB momentum before.
    const double v_k = state_before[kA] - vbar;
    const double p_ab = m[kA] * state_before[kA] + m[kB] * state_before[kB];
    const double m_ab = m[kA] + m[kB];
    const double gained_a = -4 * m[kA] * m[kB] * v_k / (m_ab * m_ab) * p_ab;
    return plusZeros({gained_a, -gained_a, 0.0});
  }
  // Eqs. (4.6), (4.7): v_{k-1}, v'_{k-1} from the state two impacts back (2k-2), and
  // P_BC2k-1 from the state just before. The first impact has no such state, so they are
  // undefined as printed; A, which they do not concern, still gains 0.
  if (n < 2) return {0.0, kNaN, kNaN};
  const double v_k1 = state_two_before[kA] - vbar;
  const double v_k1_prime = state_two_before[kC] - vbar;
  const double p_bc = m[kB] * state_before[kB] + m[kC] * state_before[kC];
  const double m_bc = m[kB] + m[kC];
  const double gained_c = -4 * m[kB] * m[kC] / (m_bc * m_bc) * (v_k1 + v_k1_prime) / 2 * p_bc;
  return plusZeros({0.0, -gained_c, gained_c});
}

ExactPrintedEnergy::ExactPrintedEnergy(const Scene& scene) : scene_(scene) {
  for (int k = 0; k < 3; ++k) {
    if (!scene.isWall(k)) mass_scale_ = lcm(mass_scale_, denominator(Rational(scene.masses[k])));
  }
  for (int k = 0; k < 3; ++k) {
    if (scene.isWall(k)) continue;
    const Rational m(scene.masses[k]);
    mass_[k] = numerator(m) * (mass_scale_ / denominator(m));
  }
  const Rational mean = (Rational(scene.velocities[kA]) + Rational(scene.velocities[kB])) / 2;
  mean_top_ = numerator(mean);
  mean_scale_ = denominator(mean);
}

std::array<double, 3> ExactPrintedEnergy::transfer(std::uint64_t n, Pair pair, const ScaledState& before,
                                                   const ScaledState& two_before) const {
  const int i = pairIndex(pair);
  if (scene_.isWall(i) || scene_.isWall(i + 1) || (pair == Pair::BC && n < 2)) {
    const auto rounded = [](const ScaledState& v) {
      return std::array<double, 3>{detail::nearestDouble(v.top[0], v.scale), detail::nearestDouble(v.top[1], v.scale),
                                   detail::nearestDouble(v.top[2], v.scale)};
    };
    return energyTransfer(scene_, n, pair, rounded(before), rounded(two_before));  // its NaNs as printed
  }
  // Masses m_k = mass_k / S, velocities N_k / D, vbar = b / L.
  const Integer& b = mean_top_;
  const Integer& l = mean_scale_;
  if (pair == Pair::AB) {
    // Eqs. (4.4), (4.5): -4 m_A m_B (v_A - vbar)(m_A v_A + m_B v_B) / M_AB^2.
    const Integer sum = mass_[kA] + mass_[kB];
    const Integer top = -4 * mass_[kA] * mass_[kB] * (before.top[kA] * l - b * before.scale) *
                        (mass_[kA] * before.top[kA] + mass_[kB] * before.top[kB]);
    const double gained_a = detail::nearestDouble(top, sum * sum * before.scale * l * mass_scale_ * before.scale);
    return {gained_a, detail::toDouble(-gained_a), 0.0};
  }
  // Eqs. (4.6), (4.7): -4 m_B m_C / M_BC^2 (v_A'' - vbar + v_C'' - vbar) / 2 (m_B v_B + m_C v_C),
  // '' two impacts back.
  const Integer sum = mass_[kB] + mass_[kC];
  const Integer top = -2 * mass_[kB] * mass_[kC] *
                      ((two_before.top[kA] + two_before.top[kC]) * l - 2 * b * two_before.scale) *
                      (mass_[kB] * before.top[kB] + mass_[kC] * before.top[kC]);
  const double gained_c =
      detail::nearestDouble(top, sum * sum * two_before.scale * l * mass_scale_ * before.scale);
  return {0.0, detail::toDouble(-gained_c), gained_c};
}

}  // namespace paper
}  // namespace core
}  // namespace collision_lab
