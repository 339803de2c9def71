// The momentum and kinetic energy of a state of the finite masses, for a lab to compare
// before and after (the simulation's, the model's and the paper's final velocities): each
// the exact value of the given doubles correctly rounded, so that a difference shown is
// physics, never rounding.
#pragma once

#include <vector>

namespace collision_lab {
namespace core {

struct Totals {
  double momentum = 0.0;        ///< sum m_i v_i over the finite masses [kg m/s]
  double kinetic_energy = 0.0;  ///< sum m_i v_i^2 / 2 over the finite masses [J]
};

/// The totals of bodies of masses `masses` [kg] (inf: a wall, left out) at `velocities`
/// [m/s], one per body. Each is the exact sum rounded once to the nearest double (+-inf past
/// the double range). Precondition: the sizes agree and every finite mass and velocity is
/// finite.
Totals totalsOf(const std::vector<double>& masses, const std::vector<double>& velocities);

struct CentreOfMass {
  double mass = 0.0;      ///< sum m_i over the finite masses [kg]
  double position = 0.0;  ///< sum m_i x_i / sum m_i [m]
  double velocity = 0.0;  ///< sum m_i v_i / sum m_i [m/s]
};

/// The centre of mass of the finite masses (walls left out) at the given positions [m] and
/// velocities [m/s]: each value the exact one of the given doubles correctly rounded; NaN
/// position and velocity when no mass is finite. Precondition as totalsOf.
CentreOfMass centreOfMass(const std::vector<double>& masses, const std::vector<double>& positions,
                          const std::vector<double>& velocities);

/// Each body's kinetic energy m_i v_i^2 / 2 [J], the exact value correctly rounded; 0 for a
/// wall. Precondition as totalsOf.
std::vector<double> kineticEnergies(const std::vector<double>& masses, const std::vector<double>& velocities);

}  // namespace core
}  // namespace collision_lab
