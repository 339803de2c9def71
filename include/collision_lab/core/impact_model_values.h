// The one optional block a model publishes beside an impact (ImpactRecord::model). The
// layers above (io's reports, the ROS messages) copy it as it is, without asking which
// model filled it: a field the block holds is printed, an absent block prints as null.
#pragma once

#include <array>

namespace collision_lab {
namespace core {

/// Values of one impact of a three-body scene that a model answers impact by impact (today
/// the rotation model: three elastic bodies). Per body A, B, C; a wall's entries as noted.
/// Every value is the double nearest to the one the run computed, never -0.
struct ImpactModelValues {
  /// Every body's state at and after the impact, as the model's run computes it: positions
  /// and totals from the last impacts in long double, rounded once (the engine's record
  /// holds only the pair's values).
  std::array<double, 3> positions{};             ///< A, B, C at the impact [m]
  std::array<double, 3> velocities_before{};     ///< [m/s]
  std::array<double, 3> velocities_after{};      ///< [m/s]
  std::array<double, 3> energy_transfer{};       ///< kinetic energy gained; a wall's: minus the other body's [J]
  std::array<double, 3> kinetic_energy_after{};  ///< per body [J]; 0 for a wall
  double total_energy = 0.0;                     ///< kinetic energy of the finite masses after [J]
  double total_momentum = 0.0;                   ///< momentum of the finite masses after [kg m/s]
  /// The model's values for the same impact.
  std::array<double, 3> predicted_velocities_after{};  ///< the closed form [m/s]
  std::array<double, 3> predicted_energy_transfer{};   ///< the closed form's energy gained [J]
  std::array<double, 3> paper_velocities_after{};      ///< the paper's eqs. (2.15)/(2.16) as printed [m/s]; NaN where undefined
  std::array<double, 3> paper_energy_transfer{};       ///< the paper's eqs. (4.4)-(4.7) as printed [J]; NaN where undefined
};

}  // namespace core
}  // namespace collision_lab
