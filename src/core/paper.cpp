// Transcriptions of the paper's printed equations. Walls make the printed expressions
// inf/inf; they come out as NaN ("not defined as printed"), never as a guessed limit.
#include "collision_lab/core/paper.h"

#include <cmath>
#include <limits>

#include <boost/math/constants/constants.hpp>

#include "collision_lab/core/wedge.h"
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

double phiBC(const Scene& scene) {
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

double omega(const std::array<double, 3>& m) {
  const Wedge<double> wedge = wedgeOf<double>(m);
  return std::acos(wedge.n_ab.dot(wedge.n_bc));
}

std::optional<std::int64_t> impactCount(const Scene& scene) {
  const double x = (omega(triple(scene.masses)) - phiBC(scene)) / constantsOf(triple(scene.masses)).theta;
  // Evaluated in double as printed; 1 + floor(x) + ceil(x) must fit the int64 it is reported in.
  if (!std::isfinite(x) || std::fabs(x) > 4e18) return std::nullopt;
  return 1 + static_cast<std::int64_t>(std::floor(x)) + static_cast<std::int64_t>(std::ceil(x));  // eq. (3.22)
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

}  // namespace paper
}  // namespace core
}  // namespace collision_lab
