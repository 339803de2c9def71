#include "collision_lab/core/totals.h"

#include <cmath>
#include <cstddef>

#include "correct_rounding.h"

namespace collision_lab {
namespace core {

Totals totalsOf(const std::vector<double>& masses, const std::vector<double>& velocities) {
  // Products and sums of doubles are dyadic rationals: exact, then rounded once.
  detail::ExactRational momentum = 0, twice_energy = 0;
  for (std::size_t i = 0; i < masses.size() && i < velocities.size(); ++i) {
    if (!std::isfinite(masses[i])) continue;
    const detail::ExactRational mv = detail::ExactRational(masses[i]) * detail::ExactRational(velocities[i]);
    momentum += mv;
    twice_energy += mv * detail::ExactRational(velocities[i]);
  }
  return {detail::nearestDouble(momentum), detail::nearestDouble(twice_energy / 2)};
}

}  // namespace core
}  // namespace collision_lab
