// An exact event-driven reference written from first principles for the tests: exact
// rationals for the input doubles, times and positions included. It shares no code with
// the engine (not even core/exact.h): it finds the next impact among both pairs at every
// step instead of assuming that the pairs alternate, and applies the textbook impact
// formula v_l' = ((m_l - m_r) v_l + 2 m_r v_r) / (m_l + m_r) (v_l' = 2 v_wall - v_l
// against a wall).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_int.hpp>

#include "collision_lab/core/scene.h"
#include "rounding_checks.h"

namespace collision_lab {
namespace core {
namespace reference {

using Q = boost::multiprecision::cpp_rational;
/// Wide enough in exponent for any time or position of doubles (to compare against).
using Wide = boost::multiprecision::cpp_bin_float_50;

struct Impact {
  Pair pair = Pair::AB;
  Q time;                    ///< [s]
  Q position;                ///< contact point [m]
  std::array<Q, 3> positions;   ///< A, B, C at the impact [m]
  std::array<Q, 3> velocities;  ///< after the impact [m/s]
};

struct Run {
  std::vector<Impact> impacts;
  std::array<Q, 3> final_velocities;
  bool truncated = false;
};

inline Wide toWide(const Q& q) {
  return Wide(boost::multiprecision::numerator(q)) / Wide(boost::multiprecision::denominator(q));
}

/// The textbook impact rule for the pair of left body i and right body i + 1.
inline void applyImpact(const Scene& scene, int i, std::array<Q, 3>& v) {
  const double m_l = scene.masses[i], m_r = scene.masses[i + 1];
  const Q v_l = v[i], v_r = v[i + 1];
  if (std::isinf(m_l)) {
    v[i + 1] = 2 * v_l - v_r;
  } else if (std::isinf(m_r)) {
    v[i] = 2 * v_r - v_l;
  } else {
    const Q ml(m_l), mr(m_r);
    v[i] = ((ml - mr) * v_l + 2 * mr * v_r) / (ml + mr);
    v[i + 1] = ((mr - ml) * v_r + 2 * ml * v_l) / (ml + mr);
  }
}

/// The run of `scene`, at most `max_impacts` impacts. Throws on a triple collision.
inline Run simulate(const Scene& scene, std::size_t max_impacts) {
  std::array<Q, 3> x, v;
  for (int i = 0; i < 3; ++i) {
    x[i] = Q(scene.positions[i]);
    v[i] = Q(scene.velocities[i]);
  }
  Run run;
  Q now = 0;
  while (true) {
    // Time to contact of each approaching pair (left body i, right body i + 1).
    std::optional<Q> delay[2];
    for (int i = 0; i < 2; ++i) {
      if (v[i + 1] > v[i]) delay[i] = (x[i] - x[i + 1]) / (v[i + 1] - v[i]);
    }
    if (!delay[0] && !delay[1]) break;
    if (delay[0] && delay[1] && *delay[0] == *delay[1]) throw std::runtime_error("triple collision");
    const int i = !delay[1] || (delay[0] && *delay[0] < *delay[1]) ? 0 : 1;
    if (run.impacts.size() == max_impacts) {
      run.truncated = true;
      break;
    }
    const Q dt = *delay[i];
    for (int j = 0; j < 3; ++j) x[j] += v[j] * dt;
    now += dt;
    applyImpact(scene, i, v);
    run.impacts.push_back({i == 0 ? Pair::AB : Pair::BC, now, x[i], x, v});
  }
  run.final_velocities = v;
  return run;
}

/// The same run without times and positions (each impact holds its pair and velocities
/// only), for long runs whose exact positions grow too large. Positions decide the pair
/// only when both pairs approach, which the exact positions of the start settle; after an
/// impact its pair separates, so at most one pair approaches: checked at every step (throws
/// otherwise), not assumed.
inline Run simulateVelocities(const Scene& scene, std::size_t max_impacts) {
  std::array<Q, 3> v;
  for (int i = 0; i < 3; ++i) v[i] = Q(scene.velocities[i]);
  Run run;
  while (true) {
    const bool approaching[2] = {v[1] > v[0], v[2] > v[1]};
    if (!approaching[0] && !approaching[1]) break;
    int i = approaching[0] ? 0 : 1;
    if (approaching[0] && approaching[1]) {
      if (!run.impacts.empty()) throw std::logic_error("both pairs approach after an impact");
      i = simulate(scene, 1).impacts.front().pair == Pair::AB ? 0 : 1;
    }
    if (run.impacts.size() == max_impacts) {
      run.truncated = true;
      break;
    }
    applyImpact(scene, i, v);
    Impact impact;
    impact.pair = i == 0 ? Pair::AB : Pair::BC;
    impact.velocities = v;
    run.impacts.push_back(std::move(impact));
  }
  run.final_velocities = v;
  return run;
}

using testing_support::correctlyRounded;

/// Is the reported double `value` within `relative` of the exact `truth`? A truth beyond
/// the double range must be reported as the infinity of its sign; a truth below it may
/// round to zero or a subnormal (absolute tolerance: the smallest subnormal).
inline bool closeRelative(double value, const Q& truth, double relative) {
  const Wide exact = toWide(truth);
  const Wide magnitude = abs(exact);
  if (magnitude > Wide(std::numeric_limits<double>::max())) {
    return std::isinf(value) && (value > 0) == (exact > 0);
  }
  if (!std::isfinite(value)) return false;
  const Wide error = abs(Wide(value) - exact);
  return error <= Wide(relative) * magnitude || error <= Wide(std::numeric_limits<double>::denorm_min());
}

/// Is the reported position within `relative` times `length_scale` of the exact one (or,
/// for subnormal positions, within the smallest subnormal, the double's own spacing)?
inline bool closeOnScale(double value, const Q& truth, const Wide& length_scale, double relative) {
  if (!std::isfinite(value)) return false;
  const Wide error = abs(Wide(value) - toWide(truth));
  return error <= Wide(relative) * length_scale || error <= Wide(std::numeric_limits<double>::denorm_min());
}

}  // namespace reference
}  // namespace core
}  // namespace collision_lab
