// Exact reference trajectory for the benchmarks: velocities, collision times and
// positions tracked in GMP rationals (mpq), exact for the input doubles. Independent of
// the core's own code, so the core is measured against something it did not compute.
// Cost grows with the size of the rationals; fine for a few thousand collisions.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace bench {

class ExactTrajectory {
 public:
  /// Runs a validated scene exactly, to its end or to max_collisions.
  ExactTrajectory(const core::ThreeBodyScene& scene, std::uint64_t max_collisions);
  ~ExactTrajectory();
  ExactTrajectory(ExactTrajectory&&) noexcept;
  ExactTrajectory& operator=(ExactTrajectory&&) noexcept;

  std::uint64_t collisionCount() const { return collision_count_; }
  bool truncated() const { return truncated_; }
  std::optional<core::Pair> firstPair() const { return first_pair_; }
  /// After the last collision, rounded to double [m/s].
  std::array<double, 3> finalVelocities() const;
  /// Time of the last collision, rounded to double (0 without any) [s].
  double lastCollisionTime() const;
  /// Exact positions at time t >= lastCollisionTime(), rounded to double [m].
  std::array<double, 3> positionsAt(double t) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  std::uint64_t collision_count_ = 0;
  bool truncated_ = false;
  std::optional<core::Pair> first_pair_;
};

}  // namespace bench
}  // namespace collision_lab
