// The wedge: the geometry the masses alone fix in mass-weighted velocity space u = S v,
// S = diag(sqrt(m)) (physics.md). Each impact reflects u across a plane with normal n_AB
// or n_BC; both normals are orthogonal to s = S 1; the escape cone {n_AB.u >= 0,
// n_BC.u >= 0} in the plane s-perp opens by alpha. The one home of this geometry: the
// closed form (analytic.h), the paper's printed angles (paper.h) and the rviz wedge all
// take it from here. Walls (infinite A or C) are the m -> inf limits.
#pragma once

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <boost/multiprecision/eigen.hpp>  // Eigen traits of the multiprecision scalars

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {

/// alpha = atan(sqrt(m_B M / (m_A m_C))) [rad], the cone's opening, written as ratios so
/// that walls (inf) and extreme masses stay finite: m_B M/(m_A m_C) = (m_B/m_A)(1 + m_B/m_C)
/// + m_B/m_C. Better conditioned than the acos form for extreme mass ratios.
template <class T>
T alphaOf(const std::array<double, 3>& m) {
  using std::atan;
  using std::sqrt;
  const T b_over_a = std::isinf(m[kA]) ? T(0) : T(m[kB]) / T(m[kA]);
  const T b_over_c = std::isinf(m[kC]) ? T(0) : T(m[kB]) / T(m[kC]);
  return atan(sqrt(b_over_a * (1 + b_over_c) + b_over_c));
}

/// a x b, written out (Eigen's cross needs its own scalar traits for every T).
template <class T>
Eigen::Matrix<T, 3, 1> cross(const Eigen::Matrix<T, 3, 1>& a, const Eigen::Matrix<T, 3, 1>& b) {
  return Eigen::Matrix<T, 3, 1>(a(1) * b(2) - a(2) * b(1), a(2) * b(0) - a(0) * b(2), a(0) * b(1) - a(1) * b(0));
}

/// The mirrors of the impact maps in mass-weighted velocity space, in precision T: what an
/// impact's reflection needs, without the cone's angle (whose arctangent costs, at 100
/// digits, more than the rest). S is scaled by 1/sqrt(m_max) (m_max the largest finite
/// mass) so that no mass overflows; directions do not depend on that scale.
template <class T>
struct Mirrors {
  using Vec3 = Eigen::Matrix<T, 3, 1>;

  Vec3 sqrt_mass;  ///< sqrt(m_i / m_max); 0 for a wall
  T mass_sum = 0;  ///< sum of m_i / m_max over the finite masses
  Vec3 s_hat;      ///< unit s = S 1; with a wall its limit, the wall's axis
  Vec3 n_ab;       ///< unit normal of the AB plane, along (1/sqrt m_A, -1/sqrt m_B, 0)
  Vec3 n_bc;       ///< unit normal of the BC plane, along (0, 1/sqrt m_B, -1/sqrt m_C)
};

/// The wedge of one set of masses in precision T: its mirrors and the cone they bound.
template <class T>
struct Wedge : Mirrors<T> {
  using Vec3 = typename Mirrors<T>::Vec3;

  /// The cone's boundary ray on L_BC (in s-perp, orthogonal to n_BC), on the side
  /// n_AB . r_bc >= 0. With n_bc it is a basis of s-perp in which the other ray, r_AB,
  /// lies at the angle +alpha.
  Vec3 r_bc;
  T alpha = 0;  ///< opening of the cone [rad], alphaOf

  /// Coordinates of a vector of s-perp in the basis (r_bc, n_bc): atan2 of them is its
  /// angle psi from r_BC towards r_AB.
  std::array<T, 2> coordinates(const Vec3& u_perp) const { return {T(u_perp.dot(r_bc)), T(u_perp.dot(this->n_bc))}; }
};

template <class T>
Mirrors<T> mirrorsOf(const std::array<double, 3>& masses) {
  using std::sqrt;
  using Vec3 = typename Mirrors<T>::Vec3;
  Mirrors<T> mirrors;
  const double mass_max = largestFiniteMass(masses);
  int wall = -1;
  for (int i = 0; i < 3; ++i) {
    if (std::isinf(masses[i])) {
      wall = i;
      mirrors.sqrt_mass(i) = 0;
      continue;
    }
    const T scaled = T(masses[i]) / T(mass_max);
    mirrors.sqrt_mass(i) = sqrt(scaled);
    mirrors.mass_sum += scaled;
  }
  if (wall >= 0) {
    mirrors.s_hat = Vec3::Zero();
    mirrors.s_hat(wall) = 1;
  } else {
    mirrors.s_hat = mirrors.sqrt_mass / sqrt(mirrors.mass_sum);
  }
  auto inverse_sqrt = [&](int i) { return i == wall ? T(0) : T(1) / mirrors.sqrt_mass(i); };
  mirrors.n_ab = Vec3(inverse_sqrt(kA), -inverse_sqrt(kB), T(0));
  mirrors.n_bc = Vec3(T(0), inverse_sqrt(kB), -inverse_sqrt(kC));
  mirrors.n_ab /= sqrt(mirrors.n_ab.squaredNorm());
  mirrors.n_bc /= sqrt(mirrors.n_bc.squaredNorm());
  return mirrors;
}

template <class T>
Wedge<T> wedgeOf(const std::array<double, 3>& masses) {
  using std::sqrt;
  Wedge<T> wedge;
  static_cast<Mirrors<T>&>(wedge) = mirrorsOf<T>(masses);
  wedge.r_bc = cross<T>(wedge.s_hat, wedge.n_bc);
  wedge.r_bc /= sqrt(wedge.r_bc.squaredNorm());
  if (wedge.n_ab.dot(wedge.r_bc) < 0) wedge.r_bc = -wedge.r_bc;
  wedge.alpha = alphaOf<T>(masses);
  return wedge;
}

/// The directions that u_perp approaches in a collapse (e <= r_c): the eigenvectors of the
/// larger eigenvalue of the AB+BC cycle's map u' = u - (1 + e)(n.u) n per impact, in the
/// wedge's coordinates (r_bc, n_bc), unit length. The first for the states after a BC impact
/// (the cycle AB then BC), the second after an AB impact (BC then AB); each only when that
/// cycle's eigenvalues are real (none for the spiral, e > r_c). Restitution e_ab, e_bc [1].
std::vector<std::array<double, 2>> cycleEigenDirections(const Wedge<double>& wedge, double e_ab, double e_bc);

}  // namespace core
}  // namespace collision_lab
