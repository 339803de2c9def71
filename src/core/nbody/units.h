// The engine's working units (internal; not installed).
//
// Every quantity of a run is a product of powers of mass, length and velocity (time =
// length / velocity), and every operation of the engine is homogeneous in them. So one
// exact change of units, by powers of two, changes no rounding (short of subnormals, which
// it avoids): each scene runs in units that bring its largest mass, position and velocity
// to [1/2, 1), which keeps the numbers of a run far inside the tiers' range (tier.h,
// kMaxMagnitude) wherever the scene lies in the double range. Values go back to SI once,
// on output.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "collision_lab/core/nbody/scene.h"
#include "../float_ops.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {

/// x * 2^shift, rounded once, never -0: one multiplication by a double (exact, or rounded
/// once where the product is subnormal), or in long double where 2^shift is no double.
class PowerOfTwo {
 public:
  explicit PowerOfTwo(int shift = 0)
      : wide_(shift < -1022 || shift > 1023), factor_(wide_ ? 1.0 : std::ldexp(1.0, shift)),
        wide_factor_(std::ldexp(1.0L, shift)) {}
  double operator()(double value) const {
    const double x = wide_ ? static_cast<double>(value * wide_factor_) : value * factor_;
    return x == 0 ? 0.0 : x;
  }
  /// A long double rounded once to double.
  double operator()(long double value) const {
    const double x = static_cast<double>(value * wide_factor_);
    return x == 0 ? 0.0 : x;
  }

 private:
  bool wide_;
  double factor_;
  long double wide_factor_;
};

/// A scene in working units: a working value is its SI value times 2^shift, exactly.
struct WorkingUnits {
  explicit WorkingUnits(const Scene& si) : scene(si) {
    std::vector<double> lengths = si.positions;
    lengths.push_back(si.ring);
    mass_shift = detail::shiftTowardsOne(si.masses);
    velocity_shift = detail::shiftTowardsOne(si.velocities);
    position_shift = detail::shiftTowardsOne(lengths);
    lengthenShortTimes(si, lengths);
    const RestitutionModel& model = si.restitution_model;
    // The model's parameter must scale exactly too; where it cannot, the run keeps SI units.
    const auto keeps = [](double x, int s) { return std::ldexp(std::ldexp(x, s), -s) == x; };
    if (!keeps(model.tc, timeShift()) || !keeps(model.elastic_below, velocity_shift) ||
        !keeps(model.viscoelastic_speed, velocity_shift)) {
      mass_shift = velocity_shift = position_shift = 0;
    }
    for (double& m : scene.masses) m = std::ldexp(m, mass_shift);
    for (double& x : scene.positions) x = std::ldexp(x, position_shift);
    for (double& v : scene.velocities) v = std::ldexp(v, velocity_shift);
    scene.ring = std::ldexp(si.ring, position_shift);
    scene.restitution_model.tc = std::ldexp(model.tc, timeShift());
    scene.restitution_model.elastic_below = std::ldexp(model.elastic_below, velocity_shift);
    scene.restitution_model.viscoelastic_speed = std::ldexp(model.viscoelastic_speed, velocity_shift);
  }

  /// Keeps the scene's shortest time, its smallest gap over its largest speed, above
  /// 2^-kShortestTime in working units, where double-double keeps its digits: a gap of a few
  /// subnormal metres beside positions of 1e62 m (lengths that cannot shift down) must not
  /// make times subnormal. First lengths shift up (exact), while they stay below
  /// 2^kLongestLength and the longest time (extent over smallest speed) below
  /// 2^kLongestTime where it was; then velocities shift back towards SI (exact). Nothing
  /// changes where the shortest time is in range.
  void lengthenShortTimes(const Scene& si, const std::vector<double>& lengths) {
    constexpr int kShortestTime = 850, kLongestLength = 400, kLongestTime = 850;
    constexpr int kNone = std::numeric_limits<int>::max();
    int extent = -kNone, fastest = -kNone, slowest = kNone, shortest_gap = kNone;
    for (double x : lengths) {
      if (std::isfinite(x) && x != 0) extent = std::max(extent, std::ilogb(x));
    }
    for (double v : si.velocities) {
      if (!std::isfinite(v) || v == 0) continue;
      fastest = std::max(fastest, std::ilogb(v));
      slowest = std::min(slowest, std::ilogb(v));
    }
    for (std::size_t i = 0; i + 1 < si.positions.size(); ++i) {
      const double gap = si.positions[i] - si.positions[i + 1];  // exact where it matters: small
      if (std::isfinite(gap) && gap != 0) shortest_gap = std::min(shortest_gap, std::ilogb(gap));
    }
    if (extent == -kNone || fastest == -kNone || shortest_gap == kNone) return;
    int need = -kShortestTime - (shortest_gap + position_shift - (fastest + velocity_shift));
    if (need <= 0) return;
    // The longest time is an estimate; where it is already past the tiers' range it is no bound.
    const int longest_time = extent + position_shift - (slowest + velocity_shift);
    const int room = std::min(kLongestLength - (extent + position_shift),
                              longest_time <= kLongestTime ? kLongestTime - longest_time : kNone);
    const int lengths_up = std::max(0, std::min(need, room));
    position_shift += lengths_up;
    need -= lengths_up;
    velocity_shift -= std::max(0, std::min(need, velocity_shift));
  }

  /// The shifts of derived quantities: time = length / velocity, energy = m v^2, p = m v.
  int timeShift() const { return position_shift - velocity_shift; }
  int energyShift() const { return mass_shift + 2 * velocity_shift; }
  int momentumShift() const { return mass_shift + velocity_shift; }
  bool identity() const { return mass_shift == 0 && velocity_shift == 0 && position_shift == 0; }

  int mass_shift = 0, velocity_shift = 0, position_shift = 0;
  Scene scene;  ///< in working units
};

/// Working units back to SI, one rounding per value.
struct ToSi {
  explicit ToSi(const WorkingUnits& units)
      : time(-units.timeShift()),
        position(-units.position_shift),
        velocity(-units.velocity_shift),
        energy(-units.energyShift()) {}
  PowerOfTwo time, position, velocity, energy;
};

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
