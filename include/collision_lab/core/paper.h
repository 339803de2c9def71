// The paper's printed formulas, implemented exactly as printed (arXiv 2509.02628).
// Several are wrong (shared/physics.md, Errata 1-4). They exist only so that a class can
// put them beside the simulation and see where they disagree. Predictions elsewhere use
// the correct formulas in analytic.h.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include <boost/multiprecision/cpp_int.hpp>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {
namespace paper {

/// Eqs. (2.15)/(2.16) of one scene, the velocities after n impacts (n = 2k and 2k + 1),
/// with the paper's c, d, nu^2 and the *initial* average vbar_AB, computed once. Written for
/// AB first.
class PrintedClosedForm {
 public:
  explicit PrintedClosedForm(const Scene& scene);

  /// The paper's theta = arg(lambda_+), eq. (2.2), as its formulas use it [rad].
  double theta() const { return theta_; }

  /// The velocities after impact n [m/s], given cos and sin of (n / 2) theta().
  std::array<double, 3> velocitiesAfter(std::uint64_t n, double cos_k_theta, double sin_k_theta) const;

 private:
  double c_, d_, nu_sq_, theta_;
  double vbar_, half_ba_, v_c_;  // the initial averages and velocities the formulas use [m/s]
  double m_ab_, odd_a_, odd_b_;  // M_AB, m_A - 3 m_B, m_B - 3 m_A [kg]
};

/// The exact values of eqs. (2.15)/(2.16) of a scene without a wall, each correctly rounded
/// [m/s]. lambda_+ of eq. (2.2) is (a + 2 i sqrt(D)) / q with a = m_A m_C - m_B M,
/// D = m_A m_B m_C M and q = M_AB M_BC (|lambda_+| = 1), so cos and sin of k theta are
/// P_k / q^k and sqrt(D) Q_k / q^k with integers P_k, Q_k, and d carries the same sqrt(D):
/// the printed velocities are rationals, computed in integers over one denominator. Impacts
/// n = 1, 2, 3, ... in turn are cheapest; an earlier n restarts the walk.
class ExactPrintedClosedForm {
 public:
  explicit ExactPrintedClosedForm(const Scene& scene);

  std::array<double, 3> velocitiesAfter(std::uint64_t n);

 private:
  using Integer = boost::multiprecision::cpp_int;
  void moveTo(std::uint64_t k);

  Integer a_, d_, q_;                // lambda_+ = (a + 2 i sqrt(D)) / q, masses scaled to integers
  Integer u_, h_, w_, g_, b_, l_;    // U, half_ba, W, vbar - v_C, vbar over the common denominator l_
  Integer m_ab_, odd_a_, odd_b_;     // M_AB, m_A - 3 m_B, m_B - 3 m_A, scaled
  Integer p_ = 1, s_ = 0, power_ = 1;  // P_k, Q_k, q^k
  std::uint64_t k_ = 0;
};

/// phi_BC of eq. (3.21): atan2(u1.n_BC, u1.l_BC) with u1 = u after the first AB impact
/// [rad], correctly rounded (its exact value, certified at 100 digits; `certified`, when
/// given, turns false where the bound does not decide and the double evaluation stands).
/// NaN with a wall (inf / inf as printed).
double phiBC(const Scene& scene, bool* certified = nullptr);

/// Omega as printed: arccos(n_AB . n_BC) [rad].
double omega(const std::array<double, 3>& masses);

/// n_max of eq. (3.22): 1 + floor((Omega - phi_BC)/theta) + ceil((Omega - phi_BC)/theta),
/// of the exact angles (decided at 100 digits; `certified`, when given, turns false where the
/// bound does not decide floor and ceil and the double evaluation stands). Empty when the
/// printed expression is not a finite number for this scene, or when it does not fit an int64.
std::optional<std::int64_t> impactCount(const Scene& scene, bool* certified = nullptr);

/// Energy gained by A, B, C [J] in impact n (1-based) by eqs. (4.4)-(4.7), with v_k
/// read as the paper defines it (against the *initial* vbar_AB). The equations give the
/// colliding pair's entries only; the third body, which the paper's impact does not touch,
/// gains 0. A wall in the pair makes its printed entries NaN (inf / inf), as does an
/// impact BC that comes first (4.6 and 4.7 refer to the impact before).
/// state_before: velocities just before impact n; state_two_before: just before
/// impact n-1 (used by the BC formulas 4.6, 4.7, which refer to v_{k-1}).
std::array<double, 3> energyTransfer(const Scene& scene, std::uint64_t n, Pair pair,
                                     const std::array<double, 3>& state_before,
                                     const std::array<double, 3>& state_two_before);

/// Velocities as integers over one positive common denominator: top[k] / scale [m/s].
struct ScaledState {
  std::array<boost::multiprecision::cpp_int, 3> top;
  boost::multiprecision::cpp_int scale = 1;
};

/// energyTransfer's exact value at exact states [J], each entry correctly rounded (NaN and 0
/// where energyTransfer gives them), in integers: no gcd per impact.
class ExactPrintedEnergy {
 public:
  explicit ExactPrintedEnergy(const Scene& scene);

  std::array<double, 3> transfer(std::uint64_t n, Pair pair, const ScaledState& state_before,
                                 const ScaledState& state_two_before) const;

 private:
  using Integer = boost::multiprecision::cpp_int;
  Scene scene_;
  std::array<Integer, 3> mass_;  // finite masses over mass_scale_; 0 for a wall
  Integer mass_scale_ = 1;
  Integer mean_top_, mean_scale_;  // the initial vbar_AB = mean_top_ / mean_scale_
};

}  // namespace paper
}  // namespace core
}  // namespace collision_lab
