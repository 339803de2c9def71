// The body state of a run, rebuilt from the engine's notifications alone (engine.h: the
// ImpactRecord contract and CollapseVisitor): the one replay that the node's messages, the
// rviz record, bag_to_csv and the benches use. Each body keeps its velocity, the time and
// point of its last move, and its kinetic energy; the totals are running sums. O(N) memory,
// O(bodies moved) per notification.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {

/// Kinetic energy m v^2 / 2 [J] of a body of mass m [kg] at velocity v [m/s]; 0 for a wall
/// (m = inf), whose energy is not counted (engine.h, energy_relative_drift).
double kineticEnergy(double mass, double velocity);

class BodyStateReplay {
 public:
  /// The state at t = 0: masses [kg] (inf: a wall), positions [m], velocities [m/s]. Lists
  /// of unequal lengths are cut to the shortest.
  /// ring: the circumference of a ring [m] (Scene::ring), 0 for an open line.
  BodyStateReplay(std::vector<double> masses, std::vector<double> positions, std::vector<double> velocities,
                  double ring = 0.0);
  explicit BodyStateReplay(const Scene& scene);

  /// An impact: bodies first_moved..pair_index take velocities_after[0], pair_index + 1..
  /// last_moved velocities_after[1], all at the contact point at record.time; the heat grows
  /// by record.energy_lost. On a ring (a Scene with ring > 0) the seam pair N-1 moves bodies
  /// first_moved..N-1, then 0..last_moved. False, and nothing changes, when the record's
  /// bodies do not fit the scene (first_moved <= pair_index < last_moved < size(), or the
  /// seam's wrap).
  bool apply(const ImpactRecord& record);
  /// A resolved collapse: bodies first_body..last_body take collapse.velocity at its point
  /// and time; the heat grows by their kinetic energy before less after. False, and nothing
  /// changes, when first_body < last_body < size() does not hold.
  bool apply(const Collapse& collapse);

  /// Goes on from a state known at `time` [s] past notifications not applied (a sampled
  /// state): body i at positions[i] [m] with velocities[i] [m/s], heat so far [J]; the totals
  /// are summed again and the last notification is none. False, and nothing changes, when a
  /// list's length is not size().
  bool restart(const std::vector<double>& positions, const std::vector<double>& velocities, double time,
               double heat);

  std::size_t size() const { return velocities_.size(); }
  double mass(std::size_t body) const { return masses_[body]; }
  const std::vector<double>& masses() const { return masses_; }
  bool isWall(std::size_t body) const;
  const std::vector<double>& velocities() const { return velocities_; }
  /// Position of body at time t [s] (not before its last move) [m]: its last point plus
  /// its velocity times the time since; on a ring, wrapped into [0, L).
  double position(std::size_t body, double t) const;
  std::vector<double> positions(double t) const;
  /// Kinetic energy of a body now [J] (0 for a wall).
  double kinetic(std::size_t body) const { return kinetic_[body]; }
  const std::vector<double>& kineticEnergies() const { return kinetic_; }
  /// Sum of the kinetic energies [J] and of m v over the finite masses [kg m/s], as
  /// compensated running sums (no rounding builds up over the run).
  double totalKineticEnergy() const { return energy_.value(); }
  double momentum() const { return momentum_.value(); }
  /// Kinetic energy turned into heat so far [J]: the records' energy_lost and the collapses'.
  double heat() const { return heat_.value(); }

  /// The last notification applied (none yet: time 0, no bodies moved).
  std::uint64_t impacts() const { return impacts_; }  ///< impact records applied
  double time() const { return time_; }               ///< [s]
  std::size_t firstMoved() const { return first_moved_; }
  /// How many bodies the last notification moved (from firstMoved(), wrapping on a ring).
  std::size_t movedCount() const { return before_.size(); }
  /// Velocity of a body before the last notification [m/s] (its velocity now if it did not move).
  double velocityBefore(std::size_t body) const;
  /// Kinetic energy the body gained in the last notification [J] (0 if it did not move).
  double energyGained(std::size_t body) const;
  /// Heat of the last notification [J].
  double lastHeat() const { return last_heat_; }

 private:
  /// A sum with Neumaier's compensation.
  class Sum {
   public:
    void add(double x);
    double value() const { return sum_ + compensation_; }

   private:
    double sum_ = 0.0, compensation_ = 0.0;
  };
  void begin(std::size_t first, std::size_t count, double time);
  /// Place of body after firstMoved() in the last notification's range (mod size()).
  std::size_t offset(std::size_t body) const;
  void set(std::size_t body, double velocity, double position);

  std::vector<double> masses_, velocities_, points_, since_, kinetic_;
  Sum energy_, momentum_, heat_;
  std::uint64_t impacts_ = 0;
  double time_ = 0.0, last_heat_ = 0.0;
  double ring_ = 0.0;  ///< circumference of a ring [m]; 0: an open line
  std::size_t first_moved_ = 0;
  std::vector<double> before_, gained_;  ///< velocity before and energy gained of the bodies last moved
};

}  // namespace core
}  // namespace collision_lab
