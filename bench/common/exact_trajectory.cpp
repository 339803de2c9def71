#include "exact_trajectory.h"

#include <cmath>
#include <stdexcept>

#include <gmpxx.h>

namespace collision_lab {
namespace bench {

struct ExactTrajectory::State {
  std::vector<mpq_class> x;  // positions at time t [m]
  std::vector<mpq_class> v;  // velocities [m/s]
  mpq_class t;               // time of the last impact [s]
  // Pair p's impulse: v_p += k_right[p] (v_{p+1} - v_p), v_{p+1} -= k_left[p] (v_{p+1} - v_p).
  std::vector<mpq_class> k_left, k_right;
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

ExactTrajectory::ExactTrajectory(const core::Scene& scene, std::uint64_t max_collisions, double until)
    : state_(std::make_unique<State>()) {
  const std::size_t n = scene.size();
  auto& s = *state_;
  s.x.assign(scene.positions.begin(), scene.positions.end());
  s.v.assign(scene.velocities.begin(), scene.velocities.end());
  s.t = 0;
  for (std::size_t p = 0; p + 1 < n; ++p) {
    const mpq_class one_plus_e = 1 + mpq_class(scene.restitutionOf(p));
    s.k_left.push_back(one_plus_e * massFraction(scene.masses[p], scene.masses[p + 1]));
    s.k_right.push_back(one_plus_e * massFraction(scene.masses[p + 1], scene.masses[p]));
  }
  run(max_collisions, until);
}

void ExactTrajectory::run(std::uint64_t max_collisions, double until) {
  auto& s = *state_;
  const std::size_t pairs = s.k_left.size();
  const bool bounded = std::isfinite(until);
  const mpq_class end = bounded ? mpq_class(until) : mpq_class(0);
  std::vector<std::size_t> next;  // the pairs that meet first, in pair order
  mpq_class dt_min, dt, approach;
  for (;;) {
    next.clear();
    for (std::size_t p = 0; p < pairs; ++p) {
      approach = s.v[p + 1] - s.v[p];
      if (sgn(approach) <= 0) continue;
      dt = (s.x[p] - s.x[p + 1]) / approach;
      if (next.empty() || dt < dt_min) {
        next.assign(1, p);
        dt_min = dt;
      } else if (dt == dt_min) {
        if (next.back() + 1 == p) throw std::invalid_argument("exact reference: multiple collision");
        next.push_back(p);
      }
    }
    if (next.empty()) {
      finished_ = true;
      return;
    }
    if (!first_pair_) first_pair_ = next.front();
    if (collision_count_ + next.size() > max_collisions) {
      truncated_ = true;
      return;
    }
    s.t += dt_min;  // then compared: t's denominator grows fast, so no extra sum per impact
    if (bounded && s.t > end) {
      s.t -= dt_min;
      return;
    }
    for (std::size_t i = 0; i < s.x.size(); ++i) s.x[i] += s.v[i] * dt_min;
    for (std::size_t p : next) {
      approach = s.v[p + 1] - s.v[p];
      s.v[p] += s.k_right[p] * approach;
      s.v[p + 1] -= s.k_left[p] * approach;
    }
    collision_count_ += next.size();
  }
}

ExactTrajectory::~ExactTrajectory() = default;
ExactTrajectory::ExactTrajectory(ExactTrajectory&&) noexcept = default;
ExactTrajectory& ExactTrajectory::operator=(ExactTrajectory&&) noexcept = default;

std::optional<core::Pair> ExactTrajectory::firstPair() const {
  if (!first_pair_) return std::nullopt;
  return *first_pair_ == 0 ? core::Pair::AB : core::Pair::BC;
}

std::vector<double> ExactTrajectory::finalVelocities() const {
  std::vector<double> out;
  for (const auto& v : state_->v) out.push_back(v.get_d());
  return out;
}

double ExactTrajectory::lastCollisionTime() const { return state_->t.get_d(); }

std::vector<double> ExactTrajectory::positionsAt(double t) const {
  const mpq_class elapsed = mpq_class(t) - state_->t;
  if (sgn(elapsed) < 0) throw std::invalid_argument("exact reference: time before the last collision");
  std::vector<double> out;
  for (std::size_t i = 0; i < state_->x.size(); ++i) {
    const mpq_class xi = state_->x[i] + state_->v[i] * elapsed;
    out.push_back(xi.get_d());
  }
  return out;
}

}  // namespace bench
}  // namespace collision_lab
