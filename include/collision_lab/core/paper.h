// The paper's printed formulas, implemented exactly as printed (arXiv 2509.02628).
// Several are wrong (shared/physics.md, Errata 1-4). They exist only so that a class can
// put them beside the simulation and see where they disagree. Predictions elsewhere use
// the correct formulas in analytic.h.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

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

/// phi_BC of eq. (3.21): atan2(u1.n_BC, u1.l_BC) with u1 = u after the first AB impact [rad].
double phiBC(const Scene& scene);

/// Omega as printed: arccos(n_AB . n_BC) [rad].
double omega(const std::array<double, 3>& masses);

/// n_max of eq. (3.22): 1 + floor((Omega - phi_BC)/theta) + ceil((Omega - phi_BC)/theta).
/// Empty when the printed expression is not a finite number for this scene, or when it
/// does not fit an int64.
std::optional<std::int64_t> impactCount(const Scene& scene);

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

}  // namespace paper
}  // namespace core
}  // namespace collision_lab
