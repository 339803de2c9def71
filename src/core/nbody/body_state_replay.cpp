#include "collision_lab/core/nbody/body_state_replay.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace collision_lab {
namespace core {

double kineticEnergy(double mass, double velocity) {
  return std::isinf(mass) ? 0.0 : 0.5 * mass * velocity * velocity;
}

void BodyStateReplay::Sum::add(double x) {
  const double t = sum_ + x;
  compensation_ += std::fabs(sum_) >= std::fabs(x) ? (sum_ - t) + x : (x - t) + sum_;
  sum_ = t;
}

BodyStateReplay::BodyStateReplay(std::vector<double> masses, std::vector<double> positions,
                                 std::vector<double> velocities, double ring)
    : masses_(std::move(masses)), velocities_(std::move(velocities)), points_(std::move(positions)), ring_(ring) {
  const std::size_t n = std::min({masses_.size(), points_.size(), velocities_.size()});
  masses_.resize(n), velocities_.resize(n), points_.resize(n);
  since_.assign(n, 0.0);
  kinetic_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    kinetic_[i] = kineticEnergy(masses_[i], velocities_[i]);
    energy_.add(kinetic_[i]);
    if (!isWall(i)) momentum_.add(masses_[i] * velocities_[i]);
  }
}

BodyStateReplay::BodyStateReplay(const Scene& scene)
    : BodyStateReplay(scene.masses, scene.positions, scene.velocities, scene.ring) {}

bool BodyStateReplay::restart(const std::vector<double>& positions, const std::vector<double>& velocities,
                              double time, double heat) {
  if (positions.size() != size() || velocities.size() != size()) return false;
  energy_ = Sum();
  momentum_ = Sum();
  heat_ = Sum();
  heat_.add(heat);
  for (std::size_t i = 0; i < size(); ++i) {
    points_[i] = positions[i];
    velocities_[i] = velocities[i];
    since_[i] = time;
    kinetic_[i] = kineticEnergy(masses_[i], velocities_[i]);
    energy_.add(kinetic_[i]);
    if (!isWall(i)) momentum_.add(masses_[i] * velocities_[i]);
  }
  time_ = time;
  last_heat_ = 0.0;
  first_moved_ = 0;
  before_.clear();
  gained_.clear();
  return true;
}

bool BodyStateReplay::isWall(std::size_t body) const { return std::isinf(masses_[body]); }

double BodyStateReplay::position(std::size_t body, double t) const {
  const double x = points_[body] + velocities_[body] * (t - since_[body]);
  if (ring_ == 0.0) return x;
  const double wrapped = std::fmod(x, ring_);
  return wrapped < 0.0 ? wrapped + ring_ : wrapped;
}

std::size_t BodyStateReplay::offset(std::size_t body) const {
  return (body + size() - first_moved_) % size();
}

std::vector<double> BodyStateReplay::positions(double t) const {
  std::vector<double> out(size());
  for (std::size_t i = 0; i < size(); ++i) out[i] = position(i, t);
  return out;
}

double BodyStateReplay::velocityBefore(std::size_t body) const {
  return offset(body) < before_.size() ? before_[offset(body)] : velocities_[body];
}

double BodyStateReplay::energyGained(std::size_t body) const {
  return offset(body) < gained_.size() ? gained_[offset(body)] : 0.0;
}

void BodyStateReplay::begin(std::size_t first, std::size_t count, double time) {
  time_ = time;
  first_moved_ = first;
  before_.clear();
  for (std::size_t k = 0; k < count; ++k) before_.push_back(velocities_[(first + k) % size()]);
  gained_.clear();
}

void BodyStateReplay::set(std::size_t body, double velocity, double position) {
  const double before = kinetic_[body];
  if (!isWall(body)) {
    momentum_.add(-masses_[body] * velocities_[body]);
    momentum_.add(masses_[body] * velocity);
  }
  velocities_[body] = velocity;
  points_[body] = position;
  since_[body] = time_;
  kinetic_[body] = kineticEnergy(masses_[body], velocity);
  energy_.add(-before);
  energy_.add(kinetic_[body]);
  gained_.push_back(kinetic_[body] - before);
}

bool BodyStateReplay::apply(const ImpactRecord& record) {
  const std::size_t p = record.pair_index, n = size();
  const bool seam = ring_ != 0.0 && n >= 2 && p == n - 1;  // a ring's seam: body N-1 meets body 0
  const bool fits = seam ? record.first_moved <= p && record.last_moved < record.first_moved
                         : record.first_moved <= p && p < record.last_moved && record.last_moved < n;
  if (!fits) return false;
  const std::size_t right = p - record.first_moved + 1;  // bodies first_moved..p
  const std::size_t count = right + (record.last_moved + n - (p + 1)) % n + 1;
  begin(record.first_moved, count, record.time);
  for (std::size_t k = 0; k < count; ++k) {
    set((record.first_moved + k) % n, record.velocities_after[k < right ? 0 : 1], record.position);
  }
  ++impacts_;
  last_heat_ = record.energy_lost;
  heat_.add(last_heat_);
  return true;
}

bool BodyStateReplay::apply(const Collapse& collapse) {
  if (!(collapse.first_body < collapse.last_body && collapse.last_body < size())) return false;
  begin(collapse.first_body, collapse.last_body - collapse.first_body + 1, collapse.time);
  last_heat_ = 0.0;
  for (std::size_t i = collapse.first_body; i <= collapse.last_body; ++i) {
    set(i, collapse.velocity, collapse.position);
    last_heat_ -= gained_.back();
  }
  heat_.add(last_heat_);
  return true;
}

}  // namespace core
}  // namespace collision_lab
