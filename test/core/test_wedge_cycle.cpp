// The AB+BC cycle's eigen-directions (wedge.h, cycleEigenDirections) against the textbook
// impact rule applied to velocities: a state along such a direction comes back along it,
// shrunk, after one cycle of impacts; and the directions exist exactly when e <= r_c.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "collision_lab/core/wedge.h"

namespace collision_lab {
namespace core {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The textbook impact of bodies l and r with restitution e (a wall: m = inf).
void impact(const std::array<double, 3>& m, std::array<double, 3>& v, int l, double e) {
  const int r = l + 1;
  const double vl = v[l], vr = v[r];
  if (std::isinf(m[l])) {
    v[r] = vl - e * (vr - vl);
  } else if (std::isinf(m[r])) {
    v[l] = vr - e * (vl - vr);
  } else {
    const double p = m[l] * vl + m[r] * vr, total = m[l] + m[r];
    v[l] = (p + m[r] * e * (vr - vl)) / total;
    v[r] = (p + m[l] * e * (vl - vr)) / total;
  }
}

/// Velocities [m/s] whose u_perp has the wedge coordinates d (S v = d0 r_bc + d1 n_bc).
std::array<double, 3> velocitiesOf(const Wedge<double>& w, const std::array<double, 2>& d) {
  std::array<double, 3> v{};
  for (int i = 0; i < 3; ++i) {
    const double u = d[0] * w.r_bc(i) + d[1] * w.n_bc(i);
    v[i] = w.sqrt_mass(i) > 0 ? u / w.sqrt_mass(i) : 0.0;  // a wall stands still
  }
  return v;
}

std::array<double, 2> coordinatesOf(const Wedge<double>& w, const std::array<double, 3>& v) {
  Eigen::Vector3d u;
  for (int i = 0; i < 3; ++i) u(i) = w.sqrt_mass(i) * v[i];
  return w.coordinates(u);
}

void expectCycleKeepsDirections(const std::array<double, 3>& m, double e) {
  const Wedge<double> w = wedgeOf<double>(m);
  const auto directions = cycleEigenDirections(w, e, e);
  ASSERT_EQ(directions.size(), 2u) << "e = " << e;
  for (int which = 0; which < 2; ++which) {
    const auto& d = directions[which];
    EXPECT_NEAR(std::hypot(d[0], d[1]), 1.0, 1e-14);
    std::array<double, 3> v = velocitiesOf(w, d);
    // After a BC impact the cycle is AB then BC; after an AB impact, BC then AB.
    const int first = which == 0 ? 0 : 1;
    impact(m, v, first, e);
    impact(m, v, 1 - first, e);
    const auto after = coordinatesOf(w, v);
    const double cross = d[0] * after[1] - d[1] * after[0];
    const double along = d[0] * after[0] + d[1] * after[1];
    EXPECT_NEAR(cross, 0.0, 1e-12) << "e = " << e << ", direction " << which;
    EXPECT_GT(along, 0.0) << "e = " << e << ", direction " << which;    // the same way,
    EXPECT_LT(along, 1.0) << "e = " << e << ", direction " << which;    // shrunk
  }
}

TEST(WedgeCycle, EigenDirectionsComeBackAlongThemselvesAfterOneCycle) {
  // Equal masses: alpha = pi/3, r_c = tan^2(pi/12) = 0.0718; a wall and 1, 1: r_c = 0.1716.
  for (double e : {0.0, 0.03, 0.07}) expectCycleKeepsDirections({1, 1, 1}, e);
  for (double e : {0.0, 0.1, 0.17}) expectCycleKeepsDirections({kInf, 1, 1}, e);
  for (double e : {0.0, 0.2}) expectCycleKeepsDirections({1, 0.1, 1}, e);  // alpha = atan(sqrt(0.21))
}

TEST(WedgeCycle, NoDirectionsForTheSpiral) {
  // Above r_c the cycle rotates u_perp: no real eigenvalues, no directions.
  for (double e : {0.08, 0.5, 1.0}) EXPECT_TRUE(cycleEigenDirections(wedgeOf<double>({1, 1, 1}), e, e).empty()) << e;
  EXPECT_TRUE(cycleEigenDirections(wedgeOf<double>({kInf, 1, 1}), 0.18, 0.18).empty());
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
