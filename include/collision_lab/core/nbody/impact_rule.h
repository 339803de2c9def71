// The impact rule: one two-body impact with restitution e, the one home of the formula
// (shared/physics.md, "Restitution"). Used by the two-body closed form and by every
// arithmetic tier of the event engine. ROS-free.
//
// For bodies i (right) and j (left) with approach speed A = v_j - v_i, the impact keeps
// momentum and reverses the relative velocity scaled by e:
//   v_i' = v_i + c_i A,  v_j' = v_j - c_j A,  c_i = (1+e) m_j / M,  c_j = (1+e) m_i / M,
// i.e. v_i' = V - e m_j (v_i - v_j)/M and v_j' = V + e m_i (v_i - v_j)/M with V the pair's
// centre-of-mass velocity. A wall (infinite mass) keeps its velocity and the other body
// leaves at v_wall + e (v_wall - v). The kinetic energy lost is (1 - e^2) mu A^2 / 2 with
// mu = m_i m_j / M (mu = m of the finite body against a wall).
#pragma once

#include <cmath>

namespace collision_lab {
namespace core {

/// The impact map of one pair in arithmetic T. It is linear, so it applies alike to
/// velocities and to the intercepts b = x - v t of the bodies' lines (the contact point of
/// the two lines stays on both). Written as the heavier body's small increment c_h d
/// (d = q_j - q_i) and the lighter body's value from the scaled reversal
/// q_i' - q_j' = e d: the heavy body, whose error costs the most energy, gets the small
/// coefficient, and e = 0 leaves both bodies with bit-identical values (they move together).
template <class T>
struct ImpactMap {
  bool heavy_is_i = true;   ///< the right body of the pair is the heavier (or equal) one
  bool heavy_is_wall = false;
  T heavy_gain{};           ///< c_h = (1 + e) m_light / (m_i + m_j) [1]; 0 for a wall
  double restitution = 1.0;  ///< e [1]
};

/// Coefficients for masses m_i, m_j [kg] (+inf = wall; not both) and e in [0, 1].
/// T(double) must be exact (double, double-double, 100-digit float, rational).
template <class T>
ImpactMap<T> makeImpactMap(double m_i, double m_j, double e) {
  ImpactMap<T> map;
  map.heavy_is_i = m_i >= m_j;
  map.restitution = e;
  const double heavy = map.heavy_is_i ? m_i : m_j;
  const double light = map.heavy_is_i ? m_j : m_i;
  map.heavy_is_wall = std::isinf(heavy);
  if (!map.heavy_is_wall) map.heavy_gain = (T(1) + T(e)) * T(light) / (T(heavy) + T(light));
  return map;
}

/// What an impact did to one pair of quantities, in arithmetic T.
template <class T>
struct ImpactChange {
  T difference{};       ///< q_j - q_i before the impact (the approach speed for velocities)
  T heavy_increment{};  ///< q_h' - q_h of the heavier body; 0 for a wall
};

/// Applies the map to q_i, q_j (velocities [m/s] or intercepts [m]). A wall's value is
/// never written. Never throws (for double, double-double, 100-digit float, rational).
template <class T>
ImpactChange<T> applyImpactMap(const ImpactMap<T>& map, T& q_i, T& q_j) {
  ImpactChange<T> change;
  change.difference = q_j - q_i;
  const T& d = change.difference;
  T& heavy = map.heavy_is_i ? q_i : q_j;
  T& light = map.heavy_is_i ? q_j : q_i;
  if (!map.heavy_is_wall) {
    const T increment = map.heavy_gain * d;
    change.heavy_increment = map.heavy_is_i ? increment : T(-increment);
    heavy = map.heavy_is_i ? T(heavy + increment) : T(heavy - increment);
  }
  // q_i' - q_j' = e d, solved for the light body.
  const double e = map.restitution;
  if (e == 0.0) {
    light = heavy;
  } else {
    const T scaled = e == 1.0 ? d : T(d * e);
    light = map.heavy_is_i ? T(heavy - scaled) : T(heavy + scaled);
  }
  return change;
}

/// Outcome of one impact in double.
struct ImpactOutcome {
  double velocity_i = 0.0;   ///< v_i' [m/s]
  double velocity_j = 0.0;   ///< v_j' [m/s]
  double energy_lost = 0.0;  ///< (1 - e^2) mu (v_j - v_i)^2 / 2 [J], 0 when e = 1
};

/// Kinetic energy an impact with approach speed `approach` [m/s] turns into heat [J]:
/// (1 - e^2) mu A^2 / 2. Never throws; 0 for e = 1.
double impactEnergyLost(double m_i, double m_j, double approach, double e);

/// One impact of bodies i (right) and j (left) in double, rounded from double-double
/// arithmetic. Precondition: masses > 0 (+inf = wall, not both), e in [0, 1]. The rule
/// applies whether or not the bodies approach; the caller decides that. Never throws.
ImpactOutcome impact(double m_i, double m_j, double v_i, double v_j, double e);

}  // namespace core
}  // namespace collision_lab
