// Certified final velocities of three elastic bodies (elastic_triple.h): the product of the
// run's impact maps.
//
// In mass-weighted coordinates u_k = sqrt(m_k) (v_k - v_wall) (a wall's coordinate stays 0)
// every elastic impact is an orthogonal reflection, and the impacts alternate between the
// two pairs from the first, p. After n = 2k + r impacts the state is R_p^r (R_q R_p)^k
// applied to the start: the paper's powers of D, taken here by repeated squaring in 100
// digits. Every operation's rounding is bounded (2-norm, against the exact orthogonal
// product), so each velocity is known within an interval; when both ends of the interval
// round to the same nonzero double, that double is the correctly rounded exact velocity.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "arithmetic.h"
#include "elastic_triple.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {
namespace {

constexpr double kUnit = Arithmetic<Float100>::kOpError;  // one 100-digit operation, relative, with margin
constexpr double kUp = 1.0 + 0x1p-40;  // the rounding of evaluating a bound in double
constexpr double kMultiplyError = 10 * kUnit;  // ||fl(AB) - AB||_2 <= 3 gamma_3 ||A||_2 ||B||_2 for 3x3

/// A 3x3 matrix in 100 digits with `error`, a bound on its 2-norm distance from the exact
/// orthogonal matrix it stands for (so its own norm is at most 1 + error).
struct Product {
  std::array<Float100, 9> a;
  double error = 0.0;
  const Float100& operator()(int row, int column) const { return a[3 * row + column]; }
  Float100& operator()(int row, int column) { return a[3 * row + column]; }
};

Product identity() {
  Product m;
  for (int k = 0; k < 3; ++k) m(k, k) = 1;
  return m;
}

Product multiply(const Product& x, const Product& y) {
  Product m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = x(r, 0) * y(0, c) + x(r, 1) * y(1, c) + x(r, 2) * y(2, c);
  }
  // ||XY - xy|| <= e_x ||Y|| + ||x|| e_y, plus the rounding of the product.
  m.error = (x.error * (1 + y.error) + y.error + kMultiplyError * (1 + x.error) * (1 + y.error)) * kUp;
  return m;
}

/// The reflection of pair p (bodies p, p + 1) in weighted coordinates: [[a, c], [c, -a]] with
/// a = (m_p - m_{p+1}) / M, c = 2 sqrt(m_p m_{p+1}) / M; a free body against a wall: -1.
Product reflection(const Scene& scene, std::size_t p, const std::array<Float100, 3>& mass) {
  Product m = identity();
  const int i = static_cast<int>(p), j = i + 1;
  if (scene.isWall(p) || scene.isWall(p + 1)) {
    m(scene.isWall(p) ? j : i, scene.isWall(p) ? j : i) = -1;
    return m;  // exact
  }
  const Float100 total = mass[i] + mass[j];
  const Float100 a = (mass[i] - mass[j]) / total;
  const Float100 c = 2 * boost::multiprecision::sqrt(mass[i] * mass[j]) / total;
  m(i, i) = a;
  m(i, j) = c;
  m(j, i) = c;
  m(j, j) = -a;
  m.error = 16 * kUnit;  // each entry within 8 units: Frobenius norm of the four
  return m;
}

Product power(Product base, std::uint64_t exponent) {
  Product result = identity();
  while (exponent != 0) {
    if (exponent & 1) result = multiply(result, base);
    exponent >>= 1;
    if (exponent != 0) base = multiply(base, base);
  }
  return result;
}

double upperDouble(const Float100& x) { return std::fabs(toDoubleNearest(x)) * kUp; }

/// A weighted state (velocities or intercepts) in 100 digits, with the 2-norm bound on its
/// distance from the exact one.
struct WeightedState {
  std::array<Float100, 3> u;
  double error = 0.0;
};

WeightedState apply(const Product& m, const WeightedState& x, double exact_norm) {
  WeightedState y;
  double norm = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double size = upperDouble(x.u[k]);
    norm += size * size;
  }
  for (int r = 0; r < 3; ++r) y.u[r] = m(r, 0) * x.u[0] + m(r, 1) * x.u[1] + m(r, 2) * x.u[2];
  // ||M~x~ - Mx|| <= e_M ||x|| + ||M~|| e_x, plus the rounding of the product.
  y.error =
      (m.error * exact_norm + (1 + m.error) * x.error + kMultiplyError * (1 + m.error) * std::sqrt(norm) * kUp) * kUp;
  return y;
}

/// The bodies' velocities in the wall's frame, weighted, and their exact norm's upper bound.
struct Frame {
  WeightedState state;
  double norm = 0.0;  // upper bound of the exact weighted state's 2-norm
  double reference = 0.0;  // the wall's value (0 without a wall)
};

Frame weigh(const Scene& scene, const std::vector<double>& values, double reference,
            const std::array<Float100, 3>& sqrt_mass) {
  Frame frame;
  frame.reference = reference;
  double norm = 0.0;
  for (int k = 0; k < 3; ++k) {
    if (scene.isWall(static_cast<std::size_t>(k))) continue;  // 0 in the wall's frame
    frame.state.u[k] = sqrt_mass[k] * (Float100(values[k]) - reference);
    const double size = upperDouble(frame.state.u[k]);
    norm += size * size;
  }
  norm = std::sqrt(norm) * kUp;
  frame.state.error = 8 * kUnit * norm;  // the difference, the square root and the product
  frame.norm = (norm + frame.state.error) * kUp;
  return frame;
}

/// Body k's velocity from a weighted state: the 100-digit value and a bound on its
/// distance from the exact value.
struct Value {
  Float100 value;
  double error = 0.0;
};

Value unweigh(const WeightedState& x, const Frame& frame, int k, const std::array<Float100, 3>& sqrt_mass,
              const std::array<double, 3>& sqrt_mass_below) {
  Value v;
  const Float100 relative = x.u[k] / sqrt_mass[k];
  v.value = relative + frame.reference;
  v.error = (x.error / sqrt_mass_below[k] + 8 * kUnit * (upperDouble(relative) + upperDouble(v.value))) * kUp;
  return v;
}

}  // namespace

std::optional<std::array<double, 3>> certifiedVelocitiesAfter(const Scene& scene, std::uint64_t impacts,
                                                              std::size_t first_pair) {
  if (impacts == 0 || (scene.isWall(0) && scene.isWall(2))) return std::nullopt;
  const int wall = scene.isWall(0) ? 0 : scene.isWall(2) ? 2 : -1;
  std::array<Float100, 3> mass, sqrt_mass;
  std::array<double, 3> sqrt_mass_below{};  // lower bounds of sqrt(m_k), free bodies
  for (int k = 0; k < 3; ++k) {
    if (k == wall) continue;
    mass[k] = scene.masses[k];
    sqrt_mass[k] = boost::multiprecision::sqrt(mass[k]);
    sqrt_mass_below[k] = std::sqrt(scene.masses[k]) * (1 - 0x1p-50);
  }
  const Frame velocities = weigh(scene, scene.velocities, wall >= 0 ? scene.velocities[wall] : 0.0, sqrt_mass);
  const std::size_t p = first_pair, q = p ^ 1;
  const Product first = reflection(scene, p, mass);
  Product all = power(multiply(reflection(scene, q, mass), first), impacts / 2);
  if (impacts % 2 == 1) all = multiply(first, all);
  const WeightedState end = apply(all, velocities.state, velocities.norm);
  std::array<double, 3> result{};
  for (int k = 0; k < 3; ++k) {
    if (k == wall) {
      result[k] = scene.velocities[k];
      continue;
    }
    const Value v = unweigh(end, velocities, k, sqrt_mass, sqrt_mass_below);
    const Float100 margin = v.error + 32 * kUnit * upperDouble(v.value);  // and the rounding of the ends
    const double low = toDoubleNearest(Float100(v.value - margin));
    const double high = toDoubleNearest(Float100(v.value + margin));
    if (low != high || !(std::fabs(low) >= std::numeric_limits<double>::min()) || std::isinf(low)) {
      return std::nullopt;  // not certified (or zero, subnormal, overflowing)
    }
    result[k] = low;
  }
  return result;
}

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
