// The paper's analytic model, done right (see shared/physics.md):
// the maps D_AB, D_BC, D = D_BC D_AB; the rotation angle theta = 2 alpha; the wedge in
// mass-weighted velocity space u = S v, S = diag(sqrt(m)); the O(1) closed-form state
// after n impacts; the exact impact count; and per-impact energy transfer. Walls (infinite A or C) are the m -> inf limits throughout.
#pragma once

#include <array>
#include <cmath>
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
/// light body's share of the mass-weighted velocities underflows; the rotation model
/// goes to HighPrecision there.
template <class Scalar>
class AnalyticModel {
 public:
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  using Mat3 = Eigen::Matrix<Scalar, 3, 3>;

  explicit AnalyticModel(const Scene& scene);

  Scalar alpha() const { return alpha_; }
  Scalar theta() const { return 2 * alpha_; }
  Scalar omega() const;

  /// Velocity maps of one impact (eq. 1.5, 1.6) and of one AB-then-BC cycle (eq. 1.8).
  Mat3 dAB() const { return pairMap(Pair::AB); }
  Mat3 dBC() const { return pairMap(Pair::BC); }
  Mat3 D() const { return dBC() * dAB(); }

  /// Which pair hits first (exact); empty when nothing collides.
  std::optional<Pair> firstPair() const { return first_pair_; }

  /// Velocities [m/s] after the first n impacts of this scene, in O(1) for any n.
  /// Meaningful for n <= the impact count; beyond it this is the algebraic
  /// continuation of the alternating maps, not the physics.
  Vec3 velocitiesAfter(std::uint64_t n) const;

  /// Kinetic energy gained by A, B, C [J] in impact n (1-based), from the closed form.
  std::array<Scalar, 3> energyTransfer(std::uint64_t n) const;

  /// Angle of u_perp from the escape cone's ray r_BC towards r_AB, in [0, 2 pi) [rad].
  Scalar psi() const { return psi_; }

  /// The start's u_perp = S (v0 - V 1) with S = diag(sqrt(m_i / m_max)) (0 for a wall),
  /// mass-weighted velocity scaled by 1/sqrt(m_max) [m/s]; and that S [1].
  const Vec3& uPerp() const { return w_; }
  const Vec3& sqrtMassScaled() const { return sqrt_mass_scaled_; }
  /// The centre-of-mass velocity V, or the wall's velocity [m/s]; and the unit s = S 1 [1].
  const Scalar& centreVelocity() const { return centre_velocity_(0); }
  const Vec3& sHat() const { return s_hat_; }

  /// energyTransfer(n) from the velocities before impact n, velocitiesAfter(n - 1)
  /// [m/s], when the caller has them already.
  std::array<Scalar, 3> energyTransfer(std::uint64_t n, const Vec3& before) const;

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

/// cos(k phi), sin(k phi) for k = 0, 1, 2, ... in turn, at a few multiply-adds each: one
/// step of the rotation per k, written as c + (c (cos phi - 1) - s sin phi) with
/// cos phi - 1 = -2 sin^2(phi / 2), so that a small phi adds no rounding of its own; and
/// recomputed directly, as cos(k phi) in double, every kResynchronizeEvery steps, so the
/// rounding of at most that many steps (each ~1e-16) never accumulates.
class RotationRecurrence {
 public:
  static constexpr std::uint64_t kResynchronizeEvery = 64;

  explicit RotationRecurrence(double step_angle)
      : phi_(step_angle), sin_step_(std::sin(step_angle)), cos_step_minus_one_(halfAngleTerm(step_angle)) {}

  /// Moves to step k: one step of the recurrence when k is the current step plus one
  /// and not a multiple of kResynchronizeEvery, else cos(k phi), sin(k phi) directly.
  void moveTo(std::uint64_t k) {
    if (k == k_) return;
    if (k == k_ + 1 && k % kResynchronizeEvery != 0) {
      const double c = cos_ + (cos_ * cos_step_minus_one_ - sin_ * sin_step_);
      sin_ = sin_ + (sin_ * cos_step_minus_one_ + cos_ * sin_step_);
      cos_ = c;
    } else {
      const double angle = static_cast<double>(k) * phi_;
      cos_ = std::cos(angle);
      sin_ = std::sin(angle);
    }
    k_ = k;
  }

  double cos() const { return cos_; }
  double sin() const { return sin_; }

 private:
  static double halfAngleTerm(double phi) {
    const double half = std::sin(phi / 2);
    return -2 * half * half;
  }

  double phi_, sin_step_, cos_step_minus_one_;
  std::uint64_t k_ = 0;
  double cos_ = 1.0, sin_ = 0.0;
};

/// The closed form's velocities after impacts n = 1, 2, 3, ... in turn, in double, at
/// a few nanoseconds each: v_n = V 1 + cos(k theta) a + sin(k theta) b with k = n / 2 and
/// the vectors a = S^-1 w, b = S^-1 (s_hat x w) (mapped once more by the first pair's map
/// for odd n), the rotation advanced by a RotationRecurrence. Within 1e-13 of the closed
/// form at every n in the energy norm |S dv| / |S v_0| (test_full_run_accuracy.cpp checks
/// it against 50 digits over 2.2e7 impacts). Any n may be asked; cheapest when each n
/// is the previous one or the one after it.
class ClosedFormSequence {
 public:
  explicit ClosedFormSequence(const AnalyticModel<double>& model);

  /// Velocities after impact n [m/s], as AnalyticModel<double>::velocitiesAfter(n).
  Eigen::Vector3d velocitiesAfter(std::uint64_t n) {
    rotation_.moveTo(n / 2);
    const int odd = static_cast<int>(n % 2);
    return centre_ + rotation_.cos() * cos_part_[odd] + rotation_.sin() * sin_part_[odd];
  }

  /// The largest over i < count of sum_j weight_j (v[i]_j - velocitiesAfter(first + i)_j)^2
  /// (0 when count is 0), the closed form's values the same as velocitiesAfter's: a long
  /// run's impacts against the closed form in one tight loop, two impacts per step of the
  /// rotation.
  double largestSquaredError(std::uint64_t first, const std::array<double, 3>* v, std::size_t count,
                             const std::array<double, 3>& weight);

 private:
  RotationRecurrence rotation_;
  Eigen::Vector3d centre_;
  std::array<Eigen::Vector3d, 2> cos_part_, sin_part_;  // for even, odd n
};

/// Angles in double, atan form (well conditioned for extreme mass ratios).
Angles anglesFor(const std::array<double, 3>& masses);

/// The exact number of impacts this scene will have: N = ceil(psi / alpha) - 1 for AB
/// first (psi' = (alpha - psi) mod 2 pi for BC first); 0 when nothing collides. A last
/// contact with exactly zero approach speed (psi / alpha an exact integer) does not count.
/// Exact for the given doubles: double, then 50 digits, then exact rationals where the
/// integer test needs them. Never rounded through a double: counts pass 2^53.
std::uint64_t predictedImpactCount(const Scene& scene);

/// The most impacts any start can give for these masses, ceil(pi / alpha)
/// (Galperin & Zemlyakov; OEIS A119661). Exact, including the kaleidoscopic masses where
/// pi / alpha is an integer. Empty when it exceeds 2^64 - 1, the largest count the lab
/// reports (validate() rejects such masses).
std::optional<std::uint64_t> checkedMaxPossibleImpactCount(const std::array<double, 3>& masses);

/// checkedMaxPossibleImpactCount for masses that validate() accepts.
std::uint64_t maxPossibleImpactCount(const std::array<double, 3>& masses);

}  // namespace core
}  // namespace collision_lab
