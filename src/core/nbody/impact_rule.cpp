#include "collision_lab/core/nbody/impact_rule.h"

#include <algorithm>
#include <cmath>

#include "double_double.h"

namespace collision_lab {
namespace core {

double impactEnergyLost(double m_i, double m_j, double approach, double e) {
  if (e == 1.0) return 0.0;
  // mu = m_i m_j / (m_i + m_j), without overflow or inf / inf; a wall leaves the other mass,
  // and so does a mass heavier past the double range's ratio (m_i / m_j = inf: mu = m_j).
  const double ratio = m_i / m_j;
  const double mu = std::isinf(m_i) ? m_j : std::isinf(m_j) ? m_i : std::isinf(ratio) ? m_j : m_i / (1.0 + ratio);
  return 0.5 * (1.0 - e) * (1.0 + e) * mu * approach * approach;
}

double viscoelasticRestitution(double speed, double v_star) {
  constexpr double kC1 = 1.15344, kC2 = 0.79826;
  const double s = std::pow(speed / v_star, 0.2);
  const double e = 1.0 - kC1 * s + kC2 * s * s;
  return std::min(1.0, std::max(0.0, e));
}

ImpactOutcome impact(double m_i, double m_j, double v_i, double v_j, double e) {
  using nbody_detail::DD;
  const ImpactMap<DD> map = makeImpactMap<DD>(m_i, m_j, e);
  DD q_i(v_i), q_j(v_j);
  applyImpactMap(map, q_i, q_j);
  return ImpactOutcome{q_i.hi, q_j.hi, impactEnergyLost(m_i, m_j, v_j - v_i, e)};
}

}  // namespace core
}  // namespace collision_lab
