#include "collision_lab/core/nbody/impact_rule.h"

#include "double_double.h"

namespace collision_lab {
namespace core {

double impactEnergyLost(double m_i, double m_j, double approach, double e) {
  if (e == 1.0) return 0.0;
  // mu = m_i m_j / (m_i + m_j), without overflow or inf / inf; a wall leaves the other mass.
  const double mu = std::isinf(m_i) ? m_j : (std::isinf(m_j) ? m_i : m_i / (1.0 + m_i / m_j));
  return 0.5 * (1.0 - e) * (1.0 + e) * mu * approach * approach;
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
