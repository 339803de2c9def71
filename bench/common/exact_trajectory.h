// Exact reference trajectory for the benchmarks: velocities, impact times and positions of
// N point masses on a line (walls, per-pair restitution) tracked in GMP rationals (mpq),
// exact for the input doubles (each e is the exact value of its double). Independent of the
// core's own code, so the core is measured against something it did not compute. Each step
// scans every pair (O(N) per impact) and the rationals grow with every impact: fine for a
// few thousand impacts of a few bodies.
#pragma once

#include <cmath>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "collision_lab/core/nbody/scene.h"
#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace bench {

class ExactTrajectory {
 public:
  /// Runs a validated scene exactly: every impact up to and including time `until` [s]
  /// (none after it; +inf: to the end), or to max_collisions. Disjoint pairs that meet at one instant are
  /// all resolved (in pair order); throws std::invalid_argument on a multiple collision
  /// (two impacts sharing a body at one instant), whose outcome is undefined.
  ExactTrajectory(const core::Scene& scene, std::uint64_t max_collisions, double until = HUGE_VAL);
  ~ExactTrajectory();
  ExactTrajectory(ExactTrajectory&&) noexcept;
  ExactTrajectory& operator=(ExactTrajectory&&) noexcept;

  std::uint64_t impactCount() const { return collision_count_; }
  /// Stopped by max_collisions with an impact still due.
  bool truncated() const { return truncated_; }
  /// No pair approaches after the last impact: the scene has ended (false when stopped by
  /// `until` or the cap).
  bool finished() const { return finished_; }
  /// Pair index of the first impact (0 = AB, 1 = BC, ...), also when the run stopped before it.
  std::optional<std::size_t> firstPairIndex() const { return first_pair_; }
  /// The same for three bodies, as core::Pair.
  std::optional<core::Pair> firstPair() const;
  /// After the last impact, rounded to double [m/s].
  std::vector<double> finalVelocities() const;
  /// Time of the last impact, rounded to double (0 without any) [s].
  double lastCollisionTime() const;
  /// Exact positions at time t >= lastCollisionTime(), rounded to double [m]. Beyond
  /// `until` the impacts not simulated are missing: ask only for t <= until, or when finished().
  std::vector<double> positionsAt(double t) const;

 private:
  struct State;
  void run(std::uint64_t max_collisions, double until);
  std::unique_ptr<State> state_;
  std::uint64_t collision_count_ = 0;
  bool truncated_ = false;
  bool finished_ = false;
  std::optional<std::size_t> first_pair_;
};

}  // namespace bench
}  // namespace collision_lab
