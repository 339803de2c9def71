// The paper's analytic model, done right (see shared/physics.md):
// the maps D_AB, D_BC, D = D_BC D_AB; the rotation angle theta = 2 alpha; the wedge in
// mass-weighted velocity space u = S v, S = diag(sqrt(m)); the O(1) closed-form state
// after n collisions; the exact collision count; per-collision energy transfer; and the
// inverse map. Walls (infinite A or C) are the m -> inf limits throughout.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <optional>

#include <Eigen/Core>
#include <boost/multiprecision/eigen.hpp>  // Eigen traits of the multiprecision scalars

#include "collision_lab/core/precision.h"
#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {

/// Angles fixed by the masses alone [rad].
struct Angles {
  double alpha = 0.0;  ///< opening angle of the escape cone, atan(sqrt(m_B M / (m_A m_C)))
  double theta = 0.0;  ///< rotation per AB+BC cycle, 2 alpha = arg(lambda_+)
  double omega = 0.0;  ///< angle between the normals n_AB and n_BC, pi - alpha
};

/// Closed-form model of one scene in precision Scalar: a working precision (double, long
/// double, HighPrecision) or an escalation tier (ReplayPrecision, DeepPrecision), the
/// scalars analytic.cpp instantiates (declared below). Precondition: validate(scene)
/// passed. In double it needs finite-mass ratios up to about 2^1000, beyond which the
/// light body's share of the mass-weighted velocities underflows; predict() and runLab()
/// go to HighPrecision there.
template <class Scalar>
class AnalyticModel {
 public:
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  using Mat3 = Eigen::Matrix<Scalar, 3, 3>;

  explicit AnalyticModel(const ThreeBodyScene& scene);

  Scalar alpha() const { return alpha_; }
  Scalar theta() const { return 2 * alpha_; }
  Scalar omega() const;

  /// Velocity maps of one impact (eq. 1.5, 1.6) and of one AB-then-BC cycle (eq. 1.8).
  Mat3 dAB() const { return pairMap(Pair::AB); }
  Mat3 dBC() const { return pairMap(Pair::BC); }
  Mat3 D() const { return dBC() * dAB(); }

  /// Which pair hits first (exact); empty when nothing collides.
  std::optional<Pair> firstPair() const { return first_pair_; }

  /// Velocities [m/s] after the first n collisions of this scene, in O(1) for any n.
  /// Meaningful for n <= the collision count; beyond it this is the algebraic
  /// continuation of the alternating maps, not the physics.
  Vec3 velocitiesAfter(std::uint64_t n) const;

  /// Inverse: the initial velocities [m/s], recovered from the velocities after n
  /// collisions of a run whose first pair is this scene's.
  Vec3 initialVelocitiesFrom(const Vec3& after, std::uint64_t n) const;

  /// Kinetic energy gained by A, B, C [J] in collision n (1-based), from the closed form.
  std::array<Scalar, 3> energyTransfer(std::uint64_t n) const;

  /// Angle of u_perp from the escape cone's ray r_BC towards r_AB, in [0, 2 pi) [rad].
  Scalar psi() const { return psi_; }

  /// The start's u_perp = S (v0 - V 1) with S = diag(sqrt(m_i / m_max)) (0 for a wall),
  /// mass-weighted velocity scaled by 1/sqrt(m_max) [m/s]; and that S [1].
  const Vec3& uPerp() const { return w_; }
  const Vec3& sqrtMassScaled() const { return sqrt_mass_scaled_; }

 private:
  Vec3 rotate(std::int64_t direction, std::uint64_t k) const;
  Vec3 velocitiesOfRotated(const Vec3& w, const Scalar& angle) const;
  Mat3 pairMap(Pair pair) const;
  Vec3 applyPairMap(Pair pair, const Vec3& v) const;

  std::array<double, 3> masses_{};
  int wall_ = -1;
  // By pair index i: {m_i, m_i+1} / (m_i + m_i+1), wall-safe.
  std::array<std::array<Scalar, 2>, 2> fractions_{};
  Scalar alpha_ = 0;
  Scalar psi_ = 0;
  Vec3 centre_velocity_;    // V 1: centre-of-mass velocity, or the wall's velocity
  Vec3 sqrt_mass_scaled_;   // sqrt(m_i / m_max); 0 for a wall
  Vec3 s_hat_;              // unit s = S 1 (the limit (1,0,0) or (0,0,1) with a wall)
  Vec3 w_;                  // S (v0 - V 1) / sqrt(m_max), orthogonal to s_hat_
  std::optional<Pair> first_pair_;
};

extern template class AnalyticModel<double>;
extern template class AnalyticModel<long double>;
extern template class AnalyticModel<HighPrecision>;
extern template class AnalyticModel<ReplayPrecision>;
extern template class AnalyticModel<DeepPrecision>;

/// Angles in double, atan form (well conditioned for extreme mass ratios).
Angles anglesFor(const std::array<double, 3>& masses);

/// Eigenvalues of D: Eigen's general solver, and the closed form 1, exp(+-i theta).
struct EigenCheck {
  std::array<std::complex<double>, 3> eigen_solver;  ///< sorted by argument
  std::array<std::complex<double>, 3> closed_form;   ///< 1, exp(i theta), exp(-i theta) sorted alike
  double max_difference = 0.0;
  double determinant = 0.0;
};
EigenCheck eigenCheck(const std::array<double, 3>& masses);

/// The exact number of collisions this scene will have: N = ceil(psi / alpha) - 1 for AB
/// first (psi' = (alpha - psi) mod 2 pi for BC first); 0 when nothing collides. A last
/// contact with exactly zero approach speed (psi / alpha an exact integer) does not count.
/// Exact for the given doubles: double, then 50 digits, then exact rationals where the
/// integer test needs them. Never rounded through a double: counts pass 2^53.
std::uint64_t predictedCollisionCount(const ThreeBodyScene& scene);

/// The most collisions any start can give for these masses, ceil(pi / alpha)
/// (Galperin & Zemlyakov; OEIS A119661). Exact, including the kaleidoscopic masses where
/// pi / alpha is an integer. Empty when it exceeds 2^64 - 1, the largest count the lab
/// reports (validate() rejects such masses).
std::optional<std::uint64_t> checkedMaxPossibleCollisionCount(const std::array<double, 3>& masses);

/// checkedMaxPossibleCollisionCount for masses that validate() accepts.
std::uint64_t maxPossibleCollisionCount(const std::array<double, 3>& masses);

}  // namespace core
}  // namespace collision_lab
