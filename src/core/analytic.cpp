#include "collision_lab/core/analytic.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Eigenvalues>
#include <boost/math/constants/constants.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/eigen.hpp>

#include "collision_lab/core/exact.h"
#include "collision_lab/core/precision.h"
#include "collision_lab/core/simulation.h"
#include "impact_energy.h"

namespace collision_lab {
namespace core {

namespace {

namespace mp = boost::multiprecision;

/// Precision of the last closed-form check, for counts too long to replay exactly.
using DeepPrecision = mp::number<mp::cpp_bin_float<500>>;

/// Longest replay the exact integer test of psi / alpha runs as rationals.
constexpr std::uint64_t kExactReplayLimit = 20000;
/// Longest run counted by exact simulation when no precision can place u_perp.
constexpr std::uint64_t kExactCountLimit = 2000;

template <class T>
T pi() {
  return boost::math::constants::pi<T>();
}

/// m_i / (m_i + m_j), wall-safe: 1 when i is a wall, 0 when j is.
template <class T>
T fraction(double m_i, double m_j) {
  if (std::isinf(m_i)) return T(1);
  if (std::isinf(m_j)) return T(0);
  return T(1) / (T(1) + T(m_j) / T(m_i));
}

/// alpha = atan(sqrt(m_B M / (m_A m_C))) written as ratios so that walls (inf) and
/// extreme masses stay finite: m_B M/(m_A m_C) = (m_B/m_A)(1 + m_B/m_C) + m_B/m_C.
template <class T>
T alphaOf(const std::array<double, 3>& m) {
  using std::atan;
  using std::sqrt;
  const T b_over_a = std::isinf(m[kA]) ? T(0) : T(m[kB]) / T(m[kA]);
  const T b_over_c = std::isinf(m[kC]) ? T(0) : T(m[kB]) / T(m[kC]);
  return atan(sqrt(b_over_a * (1 + b_over_c) + b_over_c));
}

template <class T>
Eigen::Matrix<T, 3, 1> cross(const Eigen::Matrix<T, 3, 1>& a, const Eigen::Matrix<T, 3, 1>& b) {
  return Eigen::Matrix<T, 3, 1>(a(1) * b(2) - a(2) * b(1), a(2) * b(0) - a(0) * b(2), a(0) * b(1) - a(1) * b(0));
}

template <class T>
T absOf(const T& x) {
  return x < 0 ? T(-x) : x;
}

/// q = psi / alpha (psi' / alpha for BC first) in precision T, with a bound on its
/// rounding error. The count is ceil(q) - 1.
template <class T>
struct Quotient {
  T q;
  T error_bound;
};

double largestFiniteMass(const ThreeBodyScene& scene) {
  double mass = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (!scene.isWall(i)) mass = std::max(mass, scene.masses[i]);
  }
  return mass;
}

template <class T>
Quotient<T> countQuotient(const ThreeBodyScene& scene, Pair first) {
  using std::sqrt;
  const AnalyticModel<T> model(scene);
  const T alpha = model.alpha();
  T angle = model.psi();
  if (first == Pair::BC) {
    angle = alpha - angle;
    if (angle < 0) angle += 2 * pi<T>();
  }
  // Rounding in w = S (v - V 1) is relative to the velocities, not to w itself, so a
  // nearly common velocity makes psi inaccurate: bound the angular error by |dw| / |w|,
  // both weighted by sqrt(m_i / m_max) as w is.
  const int wall = scene.wallIndex();
  const double mass_max = largestFiniteMass(scene);
  T velocity_scale = 0;
  for (int i = 0; i < 3; ++i) velocity_scale = std::max(velocity_scale, absOf(T(scene.velocities[i])));
  const T frame = wall >= 0 ? T(scene.velocities[wall]) : T(0);
  T centre = frame;
  if (wall < 0) {
    T mass_sum = 0, momentum = 0;
    for (int i = 0; i < 3; ++i) {
      mass_sum += T(scene.masses[i]) / T(mass_max);
      momentum += T(scene.masses[i]) / T(mass_max) * T(scene.velocities[i]);
    }
    centre = momentum / mass_sum;
  }
  T w_norm_sq = 0, w_error = 0;
  for (int i = 0; i < 3; ++i) {
    if (i == wall) continue;
    const T weight = sqrt(T(scene.masses[i]) / T(mass_max));
    const T w = weight * (T(scene.velocities[i]) - centre);
    w_norm_sq += w * w;
    w_error += weight * (absOf(T(scene.velocities[i])) + velocity_scale);
  }
  const T eps = std::numeric_limits<T>::epsilon();
  const T w_norm = sqrt(w_norm_sq);
  w_error *= 16 * eps;
  // Rounding is relative only above the normal range: closer to underflow, or when the
  // error may rival w itself, leave the decision to a type with more range or digits.
  if (!(w_norm > 64 * w_error) || w_norm < std::numeric_limits<T>::min() / eps) {
    return {T(0), std::numeric_limits<T>::infinity()};
  }
  const T angular_error = 4 * w_error / w_norm + 64 * eps;
  const T q = angle / alpha;
  return {q, angular_error / alpha + 16 * eps * q};
}

/// ceil(q) - 1 when q is safely away from an integer; empty when it is too close.
template <class T>
std::optional<std::uint64_t> countIfSeparated(const Quotient<T>& quotient) {
  using std::ceil;
  using std::round;
  const T nearest = round(quotient.q);
  // Written so that a NaN (a precision without the range for these masses) is not separated.
  if (!(absOf(T(quotient.q - nearest)) > 2 * quotient.error_bound)) return std::nullopt;
  const T count = ceil(quotient.q) - 1;
  return count < 0 ? 0 : static_cast<std::uint64_t>(count);  // never through a double: counts pass 2^53
}

std::array<std::complex<double>, 3> sortedByArgument(std::array<std::complex<double>, 3> values) {
  std::sort(values.begin(), values.end(),
            [](const std::complex<double>& a, const std::complex<double>& b) { return std::arg(a) < std::arg(b); });
  return values;
}

}  // namespace

template <class Scalar>
AnalyticModel<Scalar>::AnalyticModel(const ThreeBodyScene& scene) : masses_(scene.masses), wall_(scene.wallIndex()) {
  using std::atan2;
  using std::sqrt;
  f_ab_a_ = fraction<Scalar>(masses_[kA], masses_[kB]);
  f_ab_b_ = fraction<Scalar>(masses_[kB], masses_[kA]);
  f_bc_b_ = fraction<Scalar>(masses_[kB], masses_[kC]);
  f_bc_c_ = fraction<Scalar>(masses_[kC], masses_[kB]);
  alpha_ = alphaOf<Scalar>(masses_);
  first_pair_ = core::firstPair(scene);

  double mass_max = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (i != wall_) mass_max = std::max(mass_max, masses_[i]);
  }
  Scalar total = 0, momentum = 0;
  for (int i = 0; i < 3; ++i) {
    if (i == wall_) {
      sqrt_mass_scaled_(i) = 0;
      continue;
    }
    const Scalar scaled = Scalar(masses_[i]) / Scalar(mass_max);
    sqrt_mass_scaled_(i) = sqrt(scaled);
    total += scaled;
    momentum += scaled * Scalar(scene.velocities[i]);
  }
  const Scalar centre = wall_ >= 0 ? Scalar(scene.velocities[wall_]) : Scalar(momentum / total);
  centre_velocity_ = Vec3::Constant(centre);
  if (wall_ >= 0) {
    s_hat_ = Vec3::Zero();
    s_hat_(wall_) = 1;
  } else {
    s_hat_ = sqrt_mass_scaled_ / sqrt(total);
  }
  for (int i = 0; i < 3; ++i) w_(i) = sqrt_mass_scaled_(i) * (Scalar(scene.velocities[i]) - centre);

  // The escape cone's ray r_BC lies on L_BC (orthogonal to n_BC within s-perp), on the
  // side where n_AB . u >= 0; psi is measured from it towards r_AB, which has a positive
  // n_BC component.
  auto inverse_sqrt = [this](int i) { return i == wall_ ? Scalar(0) : Scalar(1) / sqrt_mass_scaled_(i); };
  Vec3 n_ab(inverse_sqrt(kA), -inverse_sqrt(kB), Scalar(0));
  Vec3 n_bc(Scalar(0), inverse_sqrt(kB), -inverse_sqrt(kC));
  n_ab /= sqrt(n_ab.squaredNorm());
  n_bc /= sqrt(n_bc.squaredNorm());
  Vec3 ray_bc = cross<Scalar>(s_hat_, n_bc);
  ray_bc /= sqrt(ray_bc.squaredNorm());
  if (n_ab.dot(ray_bc) < 0) ray_bc = -ray_bc;
  psi_ = atan2(Scalar(w_.dot(n_bc)), Scalar(w_.dot(ray_bc)));
  if (psi_ < 0) psi_ += 2 * pi<Scalar>();
}

template <class Scalar>
Scalar AnalyticModel<Scalar>::omega() const {
  return pi<Scalar>() - alpha_;
}

template <class Scalar>
typename AnalyticModel<Scalar>::Mat3 AnalyticModel<Scalar>::dAB() const {
  Mat3 d = Mat3::Identity();
  d(0, 0) = f_ab_a_ - f_ab_b_;
  d(0, 1) = 2 * f_ab_b_;
  d(1, 0) = 2 * f_ab_a_;
  d(1, 1) = f_ab_b_ - f_ab_a_;
  return d;
}

template <class Scalar>
typename AnalyticModel<Scalar>::Mat3 AnalyticModel<Scalar>::dBC() const {
  Mat3 d = Mat3::Identity();
  d(1, 1) = f_bc_b_ - f_bc_c_;
  d(1, 2) = 2 * f_bc_c_;
  d(2, 1) = 2 * f_bc_b_;
  d(2, 2) = f_bc_c_ - f_bc_b_;
  return d;
}

template <class Scalar>
typename AnalyticModel<Scalar>::Vec3 AnalyticModel<Scalar>::applyPairMap(Pair pair, const Vec3& v) const {
  return (pair == Pair::AB ? dAB() : dBC()) * v;
}

/// V 1 + S^-1 R(angle) w, where R rotates about s_hat: cos w + sin (s_hat x w).
template <class Scalar>
typename AnalyticModel<Scalar>::Vec3 AnalyticModel<Scalar>::rotate(std::int64_t direction, std::uint64_t k) const {
  using std::cos;
  using std::sin;
  const Scalar angle = Scalar(direction) * Scalar(k) * theta();
  const Vec3 rotated = cos(angle) * w_ + sin(angle) * cross<Scalar>(s_hat_, w_);
  Vec3 v = centre_velocity_;
  for (int i = 0; i < 3; ++i) {
    if (i != wall_) v(i) += rotated(i) / sqrt_mass_scaled_(i);
  }
  return v;
}

template <class Scalar>
typename AnalyticModel<Scalar>::Vec3 AnalyticModel<Scalar>::velocitiesAfter(std::uint64_t n) const {
  if (!first_pair_) return rotate(0, 0);
  // Each AB-then-BC cycle turns w by theta about s_hat: by -theta for AB first, by
  // +theta for BC first (the reflections come in the opposite order).
  const Pair first = *first_pair_;
  const Vec3 even = rotate(first == Pair::AB ? -1 : 1, n / 2);
  return n % 2 == 0 ? even : applyPairMap(first, even);
}

template <class Scalar>
typename AnalyticModel<Scalar>::Vec3 AnalyticModel<Scalar>::initialVelocitiesFrom(const Vec3& after,
                                                                                 std::uint64_t n) const {
  using std::cos;
  using std::sin;
  if (!first_pair_ || n == 0) return after;
  const Pair first = *first_pair_;
  const Vec3 even = n % 2 == 0 ? after : applyPairMap(first, after);  // the maps are involutions
  const Scalar centre = centre_velocity_(0);
  Vec3 w_after;
  for (int i = 0; i < 3; ++i) w_after(i) = i == wall_ ? Scalar(0) : sqrt_mass_scaled_(i) * (even(i) - centre);
  const Scalar angle = Scalar(first == Pair::AB ? 1 : -1) * Scalar(n / 2) * theta();
  const Vec3 w0 = cos(angle) * w_after + sin(angle) * cross<Scalar>(s_hat_, w_after);
  Vec3 v = centre_velocity_;
  for (int i = 0; i < 3; ++i) {
    if (i != wall_) v(i) += w0(i) / sqrt_mass_scaled_(i);
  }
  return v;
}

template <class Scalar>
std::array<Scalar, 3> AnalyticModel<Scalar>::energyTransfer(std::uint64_t n) const {
  std::array<Scalar, 3> gained{Scalar(0), Scalar(0), Scalar(0)};
  if (!first_pair_ || n == 0) return gained;
  const Pair pair = n % 2 == 1 ? *first_pair_ : otherPair(*first_pair_);
  const Vec3 before = velocitiesAfter(n - 1);
  const std::array<Scalar, 3> v{before(0), before(1), before(2)};
  const int left = pair == Pair::AB ? kA : kB;
  const int right = left + 1;
  const Scalar f_left = pair == Pair::AB ? f_ab_a_ : f_bc_b_;
  const Scalar f_right = pair == Pair::AB ? f_ab_b_ : f_bc_c_;
  // Reduced mass m_l m_r / (m_l + m_r), and its wall limit (the finite mass).
  const Scalar reduced = left == wall_    ? Scalar(masses_[right])
                         : right == wall_ ? Scalar(masses_[left])
                                          : Scalar(masses_[left]) * f_right;
  using Energy = detail::EnergyType<Scalar>;
  const auto wide = detail::ImpactEnergy<Energy>::impactGains(pair, Energy(reduced), Energy(f_left), Energy(f_right), v,
                                                              Scalar(v[right] - v[left]));
  for (int i = 0; i < 3; ++i) {
    gained[i] = static_cast<Scalar>(wide[i]);
    if (gained[i] == 0) gained[i] = Scalar(0);  // an underflow keeps no sign
  }
  return gained;
}

template class AnalyticModel<double>;
template class AnalyticModel<long double>;
template class AnalyticModel<HighPrecision>;
template class AnalyticModel<mp::cpp_bin_float_100>;
template class AnalyticModel<DeepPrecision>;

Angles anglesFor(const std::array<double, 3>& masses) {
  Angles angles;
  angles.alpha = alphaOf<double>(masses);
  angles.theta = 2 * angles.alpha;
  angles.omega = pi<double>() - angles.alpha;
  return angles;
}

EigenCheck eigenCheck(const std::array<double, 3>& masses) {
  ThreeBodyScene scene;
  scene.masses = masses;
  scene.positions = {2, 1, 0};
  const AnalyticModel<double> model(scene);
  const Eigen::Matrix3d d = model.D();
  Eigen::EigenSolver<Eigen::Matrix3d> solver(d, false);
  EigenCheck check;
  for (int i = 0; i < 3; ++i) check.eigen_solver[i] = solver.eigenvalues()(i);
  check.eigen_solver = sortedByArgument(check.eigen_solver);
  const double theta = model.theta();
  check.closed_form = sortedByArgument({std::complex<double>(1, 0), std::polar(1.0, theta), std::polar(1.0, -theta)});
  for (int i = 0; i < 3; ++i) {
    check.max_difference = std::max(check.max_difference, std::abs(check.eigen_solver[i] - check.closed_form[i]));
  }
  check.determinant = d.determinant();
  return check;
}

std::uint64_t predictedCollisionCount(const ThreeBodyScene& scene) {
  const std::optional<Pair> first = firstPair(scene);
  if (!first) return 0;
  if (auto count = countIfSeparated(countQuotient<double>(scene, *first))) return *count;
  const Quotient<HighPrecision> precise = countQuotient<HighPrecision>(scene, *first);
  if (auto count = countIfSeparated(precise)) return *count;
  if (!(precise.error_bound < 0.25)) {
    // Even 50 digits cannot place u_perp (a body far lighter than the rest carries all the
    // relative motion): 500 digits, else count exactly when the run is short.
    if (auto count = countIfSeparated(countQuotient<DeepPrecision>(scene, *first))) return *count;
    if (maxPossibleCollisionCount(scene.masses) <= kExactCountLimit) {
      return exact::simulate(scene, kExactCountLimit).collision_count;
    }
  }
  // psi / alpha is an integer Q to 50 digits. If it is exactly Q, contact Q grazes with
  // zero approach speed and does not count: decide by the exact state before contact Q.
  using std::round;
  const auto nearest = static_cast<std::uint64_t>(round(precise.q));
  if (nearest == 0) return 0;
  const Pair contact_pair = (nearest - 1) % 2 == 0 ? *first : otherPair(*first);
  if (nearest - 1 <= kExactReplayLimit) {
    const exact::RationalState before = exact::velocitiesAfter(scene, *first, nearest - 1);
    return exact::approachSpeed(contact_pair, before) > 0 ? nearest : nearest - 1;
  }
  const Quotient<DeepPrecision> deep = countQuotient<DeepPrecision>(scene, *first);
  if (auto count = countIfSeparated(deep)) return *count;
  return nearest - 1;  // an integer to 500 digits: a grazing last contact
}

std::optional<std::uint64_t> checkedMaxPossibleCollisionCount(const std::array<double, 3>& m) {
  // pi / alpha is an integer only for alpha = pi/3, pi/4, pi/6, where
  // cos^2 alpha = m_A m_C / ((m_A + m_B)(m_B + m_C)) is the rational 1/4, 1/2, 3/4.
  using exact::Rational;
  auto ratio = [](double mi, double mj) {
    return std::isinf(mi) ? Rational(1) : Rational(mi) / (Rational(mi) + Rational(mj));
  };
  const Rational cos_sq = ratio(m[kA], m[kB]) * ratio(m[kC], m[kB]);
  if (cos_sq == Rational(1, 4)) return 3;
  if (cos_sq == Rational(1, 2)) return 4;
  if (cos_sq == Rational(3, 4)) return 6;
  // Otherwise pi / alpha is irrational. In double, far enough below 2^53 and from an
  // integer; else at 50 digits, or 500 when even 50 cannot tell the integer above it.
  const double quotient = pi<double>() / alphaOf<double>(m);
  if (std::fabs(quotient - std::round(quotient)) > 64 * std::numeric_limits<double>::epsilon() * quotient) {
    return static_cast<std::uint64_t>(std::ceil(quotient));
  }
  using std::ceil;
  using std::round;
  HighPrecision precise = pi<HighPrecision>() / alphaOf<HighPrecision>(m);
  if (absOf(HighPrecision(precise - round(precise))) < HighPrecision(1e-40) * precise) {
    precise = static_cast<HighPrecision>(pi<DeepPrecision>() / alphaOf<DeepPrecision>(m));
  }
  const HighPrecision count = ceil(precise);
  if (count > HighPrecision(std::numeric_limits<std::uint64_t>::max())) return std::nullopt;
  // alpha < pi / 2 for finite masses, so pi / alpha > 2 even when it rounds to 2.
  return std::max<std::uint64_t>(3, static_cast<std::uint64_t>(count));
}

std::uint64_t maxPossibleCollisionCount(const std::array<double, 3>& m) {
  return checkedMaxPossibleCollisionCount(m).value_or(std::numeric_limits<std::uint64_t>::max());
}

}  // namespace core
}  // namespace collision_lab
