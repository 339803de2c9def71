#include "collision_lab/core/wedge.h"

#include <optional>

namespace collision_lab {
namespace core {
namespace {

using Matrix2 = std::array<std::array<double, 2>, 2>;

/// One impact's map of u_perp, u' = u - (1 + e)(n.u) n, for a unit normal n.
Matrix2 impactMap(const std::array<double, 2>& n, double e) {
  Matrix2 m;
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < 2; ++k) m[r][k] = (r == k ? 1.0 : 0.0) - (1 + e) * n[r] * n[k];
  }
  return m;
}

Matrix2 product(const Matrix2& a, const Matrix2& b) {
  Matrix2 m{};
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < 2; ++k) m[r][k] = a[r][0] * b[0][k] + a[r][1] * b[1][k];
  }
  return m;
}

/// The unit eigenvector of the larger eigenvalue of m, when both are real.
std::optional<std::array<double, 2>> dominantDirection(const Matrix2& m) {
  const double trace = m[0][0] + m[1][1];
  const double det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
  const double discriminant = trace * trace - 4 * det;
  if (discriminant < 0) return std::nullopt;
  const double lambda = (trace + std::sqrt(discriminant)) / 2;
  // (m - lambda I) v = 0: v is orthogonal to the larger row of m - lambda I.
  const std::array<double, 2> r0{m[0][0] - lambda, m[0][1]}, r1{m[1][0], m[1][1] - lambda};
  const auto& row = std::hypot(r0[0], r0[1]) >= std::hypot(r1[0], r1[1]) ? r0 : r1;
  const double norm = std::hypot(row[0], row[1]);
  if (!(norm > 0)) return std::nullopt;
  return std::array<double, 2>{-row[1] / norm, row[0] / norm};
}

}  // namespace

std::vector<std::array<double, 2>> cycleEigenDirections(const Wedge<double>& wedge, double e_ab, double e_bc) {
  const Matrix2 ab = impactMap(wedge.coordinates(wedge.n_ab), e_ab);
  const Matrix2 bc = impactMap(wedge.coordinates(wedge.n_bc), e_bc);
  std::vector<std::array<double, 2>> directions;
  for (const Matrix2& cycle : {product(bc, ab), product(ab, bc)}) {
    if (const auto d = dominantDirection(cycle)) directions.push_back(*d);
  }
  return directions;
}

}  // namespace core
}  // namespace collision_lab
