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
#include <utility>

namespace collision_lab {
namespace core {

/// The impact map of one pair in arithmetic T. It is linear, so it applies alike to
/// velocities and to the intercepts b = x - v t of the bodies' lines (the contact point of
/// the two lines stays on both). Written as the heavier body's small increment c_h d
/// (d = q_j - q_i) and the lighter body's value from the scaled reversal
/// q_i' - q_j' = e d: the heavy body, whose error costs the most energy, gets the small
/// coefficient, and e = 0 leaves both bodies with bit-identical values (they move together).
/// The signs are folded into the coefficients, so applying the map takes no branch on
/// which body is heavier.
template <class T>
struct ImpactMap {
  bool heavy_is_i = true;     ///< the right body of the pair is the heavier (or equal) one
  bool exchange = false;      ///< equal masses and e = 1: the two bodies swap values, exactly
  T heavy_gain{};             ///< +-c_h, c_h = (1 + e) m_light / (m_i + m_j) [1]; 0 for a wall
  double light_factor = -1.0;  ///< -+e [1]: q_light' = q_heavy' + light_factor d
};

/// Coefficients for masses m_i, m_j [kg] (+inf = wall; not both) and e in [0, 1].
/// T(double) must be exact (double, double-double, 100-digit float, rational).
template <class T>
ImpactMap<T> makeImpactMap(double m_i, double m_j, double e) {
  ImpactMap<T> map;
  map.heavy_is_i = m_i >= m_j;
  map.exchange = m_i == m_j && !std::isinf(m_i) && e == 1.0;
  const double heavy = map.heavy_is_i ? m_i : m_j;
  const double light = map.heavy_is_i ? m_j : m_i;
  if (!std::isinf(heavy)) map.heavy_gain = (T(1) + T(e)) * T(light) / (T(heavy) + T(light));
  // q_h' = q_h + c_h d when h = i, q_h - c_h d when h = j; q_i' - q_j' = e d.
  if (!map.heavy_is_i) map.heavy_gain = -map.heavy_gain;
  map.light_factor = map.heavy_is_i ? -e : e;
  return map;
}

/// Coefficients for two clusters of total masses m_i, m_j [kg] in arithmetic T (sums need
/// not be doubles); wall_i / wall_j: that side holds a wall (infinite mass; not both).
/// i_heavier: side i is the heavier (a rounded comparison is fine: it only picks which
/// side gets the small coefficient).
template <class T>
ImpactMap<T> makeClusterImpactMap(const T& m_i, bool wall_i, const T& m_j, bool wall_j, double e, bool i_heavier) {
  ImpactMap<T> map;
  map.heavy_is_i = wall_i || (!wall_j && i_heavier);
  const T& heavy = map.heavy_is_i ? m_i : m_j;
  const T& light = map.heavy_is_i ? m_j : m_i;
  if (!wall_i && !wall_j) map.heavy_gain = (T(1) + T(e)) * light / (heavy + light);
  if (!map.heavy_is_i) map.heavy_gain = -map.heavy_gain;
  map.light_factor = map.heavy_is_i ? -e : e;
  return map;
}

/// What an impact did to one pair of quantities, in arithmetic T.
template <class T>
struct ImpactChange {
  T difference{};       ///< q_j - q_i before the impact (the approach speed for velocities)
  T heavy_increment{};  ///< q_h' - q_h of the heavier body; 0 for a wall
};

/// Applies the map to q_i, q_j (velocities [m/s] or intercepts [m]). A wall gets an
/// increment of exactly 0. Never throws (for double, double-double, 100-digit float,
/// rational).
template <class T>
ImpactChange<T> applyImpactMap(const ImpactMap<T>& map, T& q_i, T& q_j) {
  ImpactChange<T> change;
  change.difference = q_j - q_i;
  if (map.exchange) {  // what the general form gives in exact arithmetic, without rounding
    change.heavy_increment = change.difference;
    std::swap(q_i, q_j);
    return change;
  }
  T& heavy = map.heavy_is_i ? q_i : q_j;
  T& light = map.heavy_is_i ? q_j : q_i;
  change.heavy_increment = map.heavy_gain * change.difference;
  heavy = heavy + change.heavy_increment;
  // e = 1 (the common case) needs no product; e = 0 gives light = heavy exactly.
  if (map.light_factor == -1.0) {
    light = heavy - change.difference;
  } else if (map.light_factor == 1.0) {
    light = heavy + change.difference;
  } else {
    light = heavy + T(change.difference * map.light_factor);
  }
  return change;
}

/// The viscoelastic law (Brilliantov, Spahn, Hertzsch and Poschel, PRE 53, 1996), truncated
/// after the second order in s = (v / v*)^(1/5): e = 1 - C1 s + C2 s^2, C1 = 1.15344,
/// C2 = 0.79826 (the decimals), clamped to [0, 1]: the correctly rounded value of that
/// formula at the exact speed. speed: the approach speed v >= 0 [m/s]; v_star > 0 [m/s].
/// The truncation holds for s well below 1; it reaches its minimum 0.583 at s = 0.72 and
/// comes back to 1 at s = C1 / C2 (v = 6.3 v*), where the clamp keeps e = 1.
double viscoelasticRestitution(double speed, double v_star);

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
