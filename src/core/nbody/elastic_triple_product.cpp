// Certified final velocities of three elastic bodies (elastic_triple.h): the product of the
// run's impact maps.
//
// In the wedge's mass-weighted coordinates u = S (v - v_wall) (wedge.h; a wall's coordinate
// stays 0) every elastic impact is the reflection R = I - 2 n n^T across its pair's plane,
// and the impacts alternate between the pairs from the first, p. After n = 2k + r impacts
// the state is R_p^r (R_q R_p)^k applied to the start: the paper's powers of D, taken here
// by repeated squaring in 100 digits. Every operation's rounding is bounded (2-norm, against
// the exact orthogonal product), so each velocity is known within an interval; when both
// ends of the interval round to the same nonzero double, that double is the correctly
// rounded exact velocity.
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "arithmetic.h"
#include "collision_lab/core/wedge.h"
#include "elastic_triple.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {
namespace {

using Vec3 = Eigen::Matrix<Float100, 3, 1>;
using Mat3 = Eigen::Matrix<Float100, 3, 3>;

constexpr double kUnit = Arithmetic<Float100>::kOpError;  // one 100-digit operation, relative, with margin
constexpr double kUp = 1.0 + 0x1p-40;                     // the rounding of evaluating a bound in double
// ||fl(A B) - A B||_2 <= 3 gamma_3 ||A||_2 ||B||_2 for 3x3 (and for a matrix times a vector).
constexpr double kProductError = 10 * kUnit;
// ||R~ - R||_2 for R = I - 2 n n^T from the wedge's unit normal: each component of n is
// within 10 units of its own size (square roots, quotients, the normalization), so
// ||n~ - n|| <= 10 units, and 2 (||n~|| + ||n||) of that plus forming 2 n n^T stays below 64.
constexpr double kReflectionError = 64 * kUnit;

/// A 3x3 matrix in 100 digits and a bound on its 2-norm distance from the exact orthogonal
/// matrix it stands for (so its own norm is at most 1 + error).
struct Product {
  Mat3 matrix;
  double error = 0.0;
};

Product multiply(const Product& x, const Product& y) {
  // ||X~ Y~ - X Y|| <= e_x ||Y~|| + ||X|| e_y, plus the rounding of the product.
  return {x.matrix * y.matrix,
          (x.error * (1 + y.error) + y.error + kProductError * (1 + x.error) * (1 + y.error)) * kUp};
}

Product power(Product base, std::uint64_t exponent) {
  Product result{Mat3::Identity(), 0.0};
  while (exponent != 0) {
    if (exponent & 1) result = multiply(result, base);
    exponent >>= 1;
    if (exponent != 0) base = multiply(base, base);
  }
  return result;
}

double upperDouble(const Float100& x) { return std::fabs(toDoubleNearest(x)) * kUp; }

double upperNorm(const Vec3& u) {
  double squares = 0.0;
  for (int k = 0; k < 3; ++k) squares += upperDouble(u(k)) * upperDouble(u(k));
  return std::sqrt(squares) * kUp;
}

}  // namespace

std::array<std::optional<double>, 3> certifiedVelocityComponentsAfter(const Scene& scene, std::uint64_t impacts,
                                                                      std::size_t first_pair) {
  std::array<std::optional<double>, 3> result;
  if (impacts == 0 || (scene.isWall(0) && scene.isWall(2))) return result;
  const int wall = scene.isWall(0) ? 0 : scene.isWall(2) ? 2 : -1;
  const std::array<double, 3> masses = triple(scene.masses);
  const Mirrors<Float100> mirrors = mirrorsOf<Float100>(masses);
  const double mass_max = largestFiniteMass(masses);
  const double reference = wall >= 0 ? scene.velocities[wall] : 0.0;  // the wall's frame
  // The start, weighted: each component within 8 units of its own size (the difference, the
  // square root, the product).
  Vec3 u = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    if (k != wall) u(k) = mirrors.sqrt_mass(k) * (Float100(scene.velocities[k]) - reference);
  }
  const double start_norm = upperNorm(u);
  const double start_error = 8 * kUnit * start_norm;
  const double exact_norm = (start_norm + start_error) * kUp;  // conserved by every impact
  const Product reflections[2] = {{Mat3::Identity() - 2 * mirrors.n_ab * mirrors.n_ab.transpose(), kReflectionError},
                                  {Mat3::Identity() - 2 * mirrors.n_bc * mirrors.n_bc.transpose(), kReflectionError}};
  const Product& first = reflections[first_pair];
  Product all = power(multiply(reflections[first_pair ^ 1], first), impacts / 2);
  if (impacts % 2 == 1) all = multiply(first, all);
  const Vec3 end = all.matrix * u;
  // ||M~ u~ - M u|| <= e_M ||u|| + ||M~|| e_u, plus the rounding of the product.
  const double end_error =
      (all.error * exact_norm + (1 + all.error) * start_error + kProductError * (1 + all.error) * start_norm) * kUp;
  for (int k = 0; k < 3; ++k) {
    if (k == wall) {
      result[k] = scene.velocities[k];
      continue;
    }
    const Float100 relative = end(k) / mirrors.sqrt_mass(k);
    const Float100 v = relative + reference;
    // S's entry sqrt(m_k / m_max) from below, in double: the quotient and root with margin.
    const double sqrt_mass_below = std::sqrt(scene.masses[k] / mass_max) * (1 - 0x1p-40);
    const double error =
        (end_error / sqrt_mass_below + 8 * kUnit * (upperDouble(relative) + upperDouble(v))) * kUp;
    const Float100 margin = error + 32 * kUnit * upperDouble(v);  // and the rounding of the ends
    const double low = toDoubleNearest(Float100(v - margin));
    const double high = toDoubleNearest(Float100(v + margin));
    if (low != high || !(std::fabs(low) >= std::numeric_limits<double>::min()) || std::isinf(low)) {
      continue;  // not certified (or zero, subnormal, overflowing)
    }
    result[k] = low;
  }
  return result;
}

std::optional<std::array<double, 3>> certifiedVelocitiesAfter(const Scene& scene, std::uint64_t impacts,
                                                              std::size_t first_pair) {
  const std::array<std::optional<double>, 3> components = certifiedVelocityComponentsAfter(scene, impacts, first_pair);
  if (!components[0] || !components[1] || !components[2]) return std::nullopt;
  return std::array<double, 3>{*components[0], *components[1], *components[2]};
}

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
