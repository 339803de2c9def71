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
                                 std::vector<double> velocities)
    : masses_(std::move(masses)), velocities_(std::move(velocities)), points_(std::move(positions)) {
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
    : BodyStateReplay(scene.masses, scene.positions, scene.velocities) {}

bool BodyStateReplay::isWall(std::size_t body) const { return std::isinf(masses_[body]); }

double BodyStateReplay::position(std::size_t body, double t) const {
  return points_[body] + velocities_[body] * (t - since_[body]);
}

std::vector<double> BodyStateReplay::positions(double t) const {
  std::vector<double> out(size());
  for (std::size_t i = 0; i < size(); ++i) out[i] = position(i, t);
  return out;
}

double BodyStateReplay::velocityBefore(std::size_t body) const {
  return body >= first_moved_ && body < endMoved() ? before_[body - first_moved_] : velocities_[body];
}

double BodyStateReplay::energyGained(std::size_t body) const {
  return body >= first_moved_ && body < endMoved() ? gained_[body - first_moved_] : 0.0;
}

void BodyStateReplay::begin(std::size_t first, std::size_t last, double time) {
  time_ = time;
  first_moved_ = first;
  before_.assign(velocities_.begin() + first, velocities_.begin() + last + 1);
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
  const std::size_t p = record.pair_index;
  if (!(record.first_moved <= p && p < record.last_moved && record.last_moved < size())) return false;
  begin(record.first_moved, record.last_moved, record.time);
  for (std::size_t i = record.first_moved; i <= record.last_moved; ++i) {
    set(i, record.velocities_after[i <= p ? 0 : 1], record.position);
  }
  ++impacts_;
  last_heat_ = record.energy_lost;
  heat_.add(last_heat_);
  return true;
}

bool BodyStateReplay::apply(const Collapse& collapse) {
  if (!(collapse.first_body < collapse.last_body && collapse.last_body < size())) return false;
  begin(collapse.first_body, collapse.last_body, collapse.time);
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
