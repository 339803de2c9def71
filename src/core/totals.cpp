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

CentreOfMass centreOfMass(const std::vector<double>& masses, const std::vector<double>& positions,
                          const std::vector<double>& velocities) {
  detail::ExactRational mass = 0, moment = 0, momentum = 0;
  for (std::size_t i = 0; i < masses.size() && i < positions.size() && i < velocities.size(); ++i) {
    if (!std::isfinite(masses[i])) continue;
    const detail::ExactRational m(masses[i]);
    mass += m;
    moment += m * detail::ExactRational(positions[i]);
    momentum += m * detail::ExactRational(velocities[i]);
  }
  if (mass == 0) return {0.0, std::nan(""), std::nan("")};
  return {detail::nearestDouble(mass), detail::nearestDouble(moment / mass), detail::nearestDouble(momentum / mass)};
}

std::vector<double> kineticEnergies(const std::vector<double>& masses, const std::vector<double>& velocities) {
  std::vector<double> out;
  for (std::size_t i = 0; i < masses.size() && i < velocities.size(); ++i) {
    out.push_back(std::isfinite(masses[i]) ? totalsOf({masses[i]}, {velocities[i]}).kinetic_energy : 0.0);
  }
  return out;
}

}  // namespace core
}  // namespace collision_lab
