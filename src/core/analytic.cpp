#include "collision_lab/core/analytic.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include <boost/math/constants/constants.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/eigen.hpp>

#include "collision_lab/core/exact.h"
#include "collision_lab/core/precision.h"
#include "collision_lab/core/wedge.h"
#include "float_ops.h"
#include "impact_energy.h"

namespace collision_lab {
namespace core {

namespace {

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

using detail::absOf;

/// q = psi / alpha (psi' / alpha for BC first) in precision T, with a bound on its
/// rounding error. The count is ceil(q) - 1.
template <class T>
struct Quotient {
  T q;
  T error_bound;
};

template <class T>
Quotient<T> countQuotient(const Scene& scene, Pair first) {
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
  const int wall = wallIndex(scene);
  T velocity_scale = 0;
  for (int i = 0; i < 3; ++i) velocity_scale = std::max(velocity_scale, absOf(T(scene.velocities[i])));
  T w_norm_sq = 0, w_error = 0;
  for (int i = 0; i < 3; ++i) {
    if (i == wall) continue;
    const T w = model.uPerp()(i);
    w_norm_sq += w * w;
    w_error += model.sqrtMassScaled()(i) * (absOf(T(scene.velocities[i])) + velocity_scale);
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

}  // namespace

template <class Scalar>
AnalyticModel<Scalar>::AnalyticModel(const Scene& scene) : masses_(triple(scene.masses)), wall_(wallIndex(scene)) {
  using std::atan2;
  for (int i = 0; i < 2; ++i) {
    fractions_[i] = {fraction<Scalar>(masses_[i], masses_[i + 1]), fraction<Scalar>(masses_[i + 1], masses_[i])};
  }
  first_pair_ = core::firstPair(scene);
  const Wedge<Scalar> wedge = wedgeOf<Scalar>(masses_);
  alpha_ = wedge.alpha;
  sqrt_mass_scaled_ = wedge.sqrt_mass;
  s_hat_ = wedge.s_hat;
  const double mass_max = largestFiniteMass(masses_);
  Scalar momentum = 0;
  for (int i = 0; i < 3; ++i) {
    if (i != wall_) momentum += Scalar(masses_[i]) / Scalar(mass_max) * Scalar(scene.velocities[i]);
  }
  const Scalar centre = wall_ >= 0 ? Scalar(scene.velocities[wall_]) : Scalar(momentum / wedge.mass_sum);
  centre_velocity_ = Vec3::Constant(centre);
  for (int i = 0; i < 3; ++i) w_(i) = sqrt_mass_scaled_(i) * (Scalar(scene.velocities[i]) - centre);
  const std::array<Scalar, 2> u_perp = wedge.coordinates(w_);
  psi_ = atan2(u_perp[1], u_perp[0]);
  if (psi_ < 0) psi_ += 2 * pi<Scalar>();
}

template <class Scalar>
Scalar AnalyticModel<Scalar>::omega() const {
  return pi<Scalar>() - alpha_;
}

template <class Scalar>
typename AnalyticModel<Scalar>::Mat3 AnalyticModel<Scalar>::pairMap(Pair pair) const {
  const int i = pairIndex(pair);
  const auto& [f_i, f_j] = fractions_[i];
  Mat3 d = Mat3::Identity();
  d(i, i) = f_i - f_j;
  d(i, i + 1) = 2 * f_j;
  d(i + 1, i) = 2 * f_i;
  d(i + 1, i + 1) = f_j - f_i;
  return d;
}

template <class Scalar>
typename AnalyticModel<Scalar>::Vec3 AnalyticModel<Scalar>::applyPairMap(Pair pair, const Vec3& v) const {
  return pairMap(pair) * v;
}

/// V 1 + S^-1 R(angle) w, where R rotates about s_hat: cos w + sin (s_hat x w).
template <class Scalar>
typename AnalyticModel<Scalar>::Vec3 AnalyticModel<Scalar>::velocitiesOfRotated(const Vec3& w,
                                                                               const Scalar& angle) const {
  using std::cos;
  using std::sin;
  const Vec3 rotated = cos(angle) * w + sin(angle) * cross<Scalar>(s_hat_, w);
  Vec3 v = centre_velocity_;
  for (int i = 0; i < 3; ++i) {
    if (i != wall_) v(i) += rotated(i) / sqrt_mass_scaled_(i);
  }
  return v;
}

template <class Scalar>
typename AnalyticModel<Scalar>::Vec3 AnalyticModel<Scalar>::rotate(std::int64_t direction, std::uint64_t k) const {
  return velocitiesOfRotated(w_, Scalar(direction) * Scalar(k) * theta());
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
std::array<Scalar, 3> AnalyticModel<Scalar>::energyTransfer(std::uint64_t n) const {
  if (!first_pair_ || n == 0) return {Scalar(0), Scalar(0), Scalar(0)};
  return energyTransfer(n, velocitiesAfter(n - 1));
}

template <class Scalar>
std::array<Scalar, 3> AnalyticModel<Scalar>::energyTransfer(std::uint64_t n, const Vec3& before) const {
  std::array<Scalar, 3> gained{Scalar(0), Scalar(0), Scalar(0)};
  if (!first_pair_ || n == 0) return gained;
  const Pair pair = n % 2 == 1 ? *first_pair_ : otherPair(*first_pair_);
  const std::array<Scalar, 3> v{before(0), before(1), before(2)};
  const int i = pairIndex(pair);
  const int j = i + 1;
  const auto& [f_i, f_j] = fractions_[i];
  // Reduced mass m_i m_j / (m_i + m_j), and its wall limit (the finite mass).
  const Scalar reduced = i == wall_   ? Scalar(masses_[j])
                         : j == wall_ ? Scalar(masses_[i])
                                      : Scalar(masses_[i]) * f_j;
  using Energy = detail::EnergyType<Scalar>;
  const auto wide = detail::ImpactEnergy<Energy>::impactGains(pair, Energy(reduced), Energy(f_i), Energy(f_j), v,
                                                              Scalar(v[j] - v[i]));
  for (int body = 0; body < 3; ++body) {
    gained[body] = static_cast<Scalar>(wide[body]);
    if (gained[body] == 0) gained[body] = Scalar(0);  // an underflow keeps no sign
  }
  return gained;
}

ClosedFormSequence::ClosedFormSequence(const AnalyticModel<double>& model)
    : rotation_(model.firstPair() ? (*model.firstPair() == Pair::AB ? -1.0 : 1.0) * model.theta() : 0.0),
      centre_(Eigen::Vector3d::Constant(model.centreVelocity())) {
  // velocitiesAfter: V 1 + S^-1 (cos w + sin (s_hat x w)), turned by -theta per cycle for
  // AB first, +theta for BC first; an odd n adds the first pair's map, which is linear
  // and keeps V 1.
  const Eigen::Vector3d& w = model.uPerp();
  const Eigen::Vector3d x = cross<double>(model.sHat(), w);
  for (int i = 0; i < 3; ++i) {
    const double s = model.sqrtMassScaled()(i);
    cos_part_[0](i) = s > 0 ? w(i) / s : 0.0;  // a wall (s = 0) only has V
    sin_part_[0](i) = s > 0 ? x(i) / s : 0.0;
  }
  const Eigen::Matrix3d map = !model.firstPair()                  ? Eigen::Matrix3d::Identity()
                              : *model.firstPair() == Pair::AB ? model.dAB()
                                                                : model.dBC();
  cos_part_[1] = map * cos_part_[0];
  sin_part_[1] = map * sin_part_[0];
}

double ClosedFormSequence::largestSquaredError(std::uint64_t first, const std::array<double, 3>* v,
                                               std::size_t count, const std::array<double, 3>& weight) {
  using Triple = std::array<double, 3>;
  const auto parts = [](const Eigen::Vector3d& x) { return Triple{x(0), x(1), x(2)}; };
  const Triple centre = parts(centre_), cos_even = parts(cos_part_[0]), cos_odd = parts(cos_part_[1]),
               sin_even = parts(sin_part_[0]), sin_odd = parts(sin_part_[1]), w = weight;
  const auto error = [&](const Triple& run, const Triple& cos_part, const Triple& sin_part) {
    const double c = rotation_.cos();
    const double s = rotation_.sin();
    double norm_sq = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double d = run[j] - (centre[j] + c * cos_part[j] + s * sin_part[j]);
      norm_sq += w[j] * d * d;
    }
    return norm_sq;
  };
  double largest = 0.0;
  std::size_t i = 0;
  std::uint64_t n = first;
  // std::max(largest, e) keeps largest where e is NaN, as one impact at a time would.
  if (n % 2 == 1 && i < count) {
    rotation_.moveTo(n / 2);
    largest = std::max(largest, error(v[i++], cos_odd, sin_odd));
    ++n;
  }
  for (; i + 2 <= count; i += 2, n += 2) {  // n even, then n + 1 odd: one rotation step
    rotation_.moveTo(n / 2);
    largest = std::max(std::max(largest, error(v[i], cos_even, sin_even)), error(v[i + 1], cos_odd, sin_odd));
  }
  if (i < count) {
    rotation_.moveTo(n / 2);
    largest = std::max(largest, error(v[i], cos_even, sin_even));
  }
  return largest;
}

// The scalars analytic.h promises.
template class AnalyticModel<double>;
template class AnalyticModel<long double>;
template class AnalyticModel<HighPrecision>;
template class AnalyticModel<ReplayPrecision>;
template class AnalyticModel<DeepPrecision>;

Angles anglesFor(const std::array<double, 3>& masses) {
  Angles angles;
  angles.alpha = alphaOf<double>(masses);
  angles.theta = 2 * angles.alpha;
  angles.omega = pi<double>() - angles.alpha;
  return angles;
}

std::uint64_t predictedImpactCount(const Scene& scene) {
  const std::optional<Pair> first = firstPair(scene);
  if (!first) return 0;
  if (auto count = countIfSeparated(countQuotient<double>(scene, *first))) return *count;
  const Quotient<HighPrecision> precise = countQuotient<HighPrecision>(scene, *first);
  if (auto count = countIfSeparated(precise)) return *count;
  if (!(precise.error_bound < 0.25)) {
    // Even 50 digits cannot place u_perp (a body far lighter than the rest carries all the
    // relative motion): 500 digits, else count exactly when the run is short.
    if (auto count = countIfSeparated(countQuotient<DeepPrecision>(scene, *first))) return *count;
    if (maxPossibleImpactCount(triple(scene.masses)) <= kExactCountLimit) {
      return exact::walkVelocityMaps(scene, kExactCountLimit).impact_count;
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

std::optional<std::uint64_t> checkedMaxPossibleImpactCount(const std::array<double, 3>& m) {
  // pi / alpha is an integer only for alpha = pi/3, pi/4, pi/6, where
  // cos^2 alpha = m_A m_C / ((m_A + m_B)(m_B + m_C)) is the rational 1/4, 1/2, 3/4.
  // In double (no sum overflowing), cos^2 alpha in [0, 1] is within 1e-15 of the exact
  // value; only a value near 1/4, 1/2 or 3/4 needs the exact rationals, which cost about
  // as much as the rest of a short run.
  auto near_ratio = [](double mi, double mj) { return std::isinf(mi) ? 1.0 : mi / (mi + mj); };
  const double cos_sq_near = near_ratio(m[kA], m[kB]) * near_ratio(m[kC], m[kB]);
  const auto summable = [](double mass) { return std::isinf(mass) || mass < 1e300; };
  const bool may_be_kaleidoscopic = !(summable(m[kA]) && summable(m[kB]) && summable(m[kC])) ||
                                    !(std::fabs(cos_sq_near - 0.25) > 1e-9 && std::fabs(cos_sq_near - 0.5) > 1e-9 &&
                                      std::fabs(cos_sq_near - 0.75) > 1e-9);
  if (may_be_kaleidoscopic) {
    using exact::Rational;
    auto ratio = [](double mi, double mj) {
      return std::isinf(mi) ? Rational(1) : Rational(mi) / (Rational(mi) + Rational(mj));
    };
    const Rational cos_sq = ratio(m[kA], m[kB]) * ratio(m[kC], m[kB]);
    if (cos_sq == Rational(1, 4)) return 3;
    if (cos_sq == Rational(1, 2)) return 4;
    if (cos_sq == Rational(3, 4)) return 6;
  }
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

std::uint64_t maxPossibleImpactCount(const std::array<double, 3>& m) {
  return checkedMaxPossibleImpactCount(m).value_or(std::numeric_limits<std::uint64_t>::max());
}

}  // namespace core
}  // namespace collision_lab
