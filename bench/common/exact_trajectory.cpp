#include "exact_trajectory.h"

#include <cmath>
#include <stdexcept>

#include <gmpxx.h>

namespace collision_lab {
namespace bench {

struct ExactTrajectory::State {
  std::array<mpq_class, 3> x;  // positions at time t [m]
  std::array<mpq_class, 3> v;  // velocities [m/s]
  mpq_class t;                 // time of the last collision [s]
};

namespace {

/// m_i / (m_i + m_j) exactly; 1 for a wall i, 0 when j is the wall.
mpq_class massFraction(double m_i, double m_j) {
  if (std::isinf(m_i)) return 1;
  if (std::isinf(m_j)) return 0;
  const mpq_class mi(m_i);
  return mpq_class(mi / (mi + mpq_class(m_j)));
}

}  // namespace

ExactTrajectory::ExactTrajectory(const core::ThreeBodyScene& scene, std::uint64_t max_collisions)
    : state_(std::make_unique<State>()) {
  auto& x = state_->x;
  auto& v = state_->v;
  auto& t = state_->t;
  for (int i = 0; i < 3; ++i) {
    x[i] = scene.positions[i];
    v[i] = scene.velocities[i];
  }
  t = 0;
  const auto& m = scene.masses;
  const std::array<mpq_class, 2> f_left = {massFraction(m[core::kA], m[core::kB]), massFraction(m[core::kB], m[core::kC])};
  const std::array<mpq_class, 2> f_right = {massFraction(m[core::kB], m[core::kA]), massFraction(m[core::kC], m[core::kB])};

  const bool ab = v[core::kB] > v[core::kA];
  const bool bc = v[core::kC] > v[core::kB];
  if (ab && bc) {
    // t_AB < t_BC  <=>  (x_A - x_B)(v_C - v_B) < (x_B - x_C)(v_B - v_A); triple excluded.
    const mpq_class lhs = (x[core::kA] - x[core::kB]) * (v[core::kC] - v[core::kB]);
    const mpq_class rhs = (x[core::kB] - x[core::kC]) * (v[core::kB] - v[core::kA]);
    if (lhs == rhs) throw std::invalid_argument("exact reference: triple collision");
    first_pair_ = lhs < rhs ? core::Pair::AB : core::Pair::BC;
  } else if (ab) {
    first_pair_ = core::Pair::AB;
  } else if (bc) {
    first_pair_ = core::Pair::BC;
  }
  if (!first_pair_) return;

  int pair = *first_pair_ == core::Pair::AB ? 0 : 1;
  mpq_class approach, dt;
  for (;;) {
    const int left = pair;  // AB: A=0, B=1; BC: B=1, C=2
    const int right = left + 1;
    approach = v[right] - v[left];
    if (sgn(approach) <= 0) break;
    if (collision_count_ == max_collisions) {
      truncated_ = true;
      break;
    }
    dt = (x[left] - x[right]) / approach;
    t += dt;
    for (int i = 0; i < 3; ++i) x[i] += v[i] * dt;
    v[left] += 2 * f_right[pair] * approach;
    v[right] -= 2 * f_left[pair] * approach;
    ++collision_count_;
    pair = 1 - pair;
  }
}

ExactTrajectory::~ExactTrajectory() = default;
ExactTrajectory::ExactTrajectory(ExactTrajectory&&) noexcept = default;
ExactTrajectory& ExactTrajectory::operator=(ExactTrajectory&&) noexcept = default;

std::array<double, 3> ExactTrajectory::finalVelocities() const {
  return {state_->v[0].get_d(), state_->v[1].get_d(), state_->v[2].get_d()};
}

double ExactTrajectory::lastCollisionTime() const { return state_->t.get_d(); }

std::array<double, 3> ExactTrajectory::positionsAt(double t) const {
  const mpq_class elapsed = mpq_class(t) - state_->t;
  if (sgn(elapsed) < 0) throw std::invalid_argument("exact reference: time before the last collision");
  std::array<double, 3> out{};
  for (int i = 0; i < 3; ++i) {
    const mpq_class xi = state_->x[i] + state_->v[i] * elapsed;
    out[i] = xi.get_d();
  }
  return out;
}

}  // namespace bench
}  // namespace collision_lab
