// Kinetic energy exchanged in one elastic impact: the one formula behind the simulated
// events' energy_transfer and the closed form's predicted one. Private to the core.
#pragma once

#include <array>
#include <cmath>
#include <type_traits>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {
namespace detail {

/// A type in which the energies of velocities in T cannot overflow on the way.
template <class T>
using EnergyType = std::conditional_t<std::is_floating_point_v<T>, long double, T>;

/// Energy gained by A, B, C [J] in elastic impacts between bodies of the given masses:
///   dE_left = 2 m_l m_r (v_r - v_l)(m_l v_l + m_r v_r) / (m_l + m_r)^2 (physics.md),
///   dE_right = -dE_left exactly, and exactly +0 for the body that takes no part.
/// A wall's entry is the m -> inf limit, minus what the ball gains: +0 for a resting wall.
/// In Calc = double the factors can overflow on their way to a representable energy (a
/// mass near 1e308, speeds near 1e300): callers check, or use EnergyType.
template <class Calc>
class ImpactEnergy {
 public:
  explicit ImpactEnergy(const std::array<double, 3>& masses) {
    for (int left : {kA, kB}) {
      const double m_l = masses[left], m_r = masses[left + 1];
      Coefficients& c = pairs_[left == kA ? 0 : 1];
      // Reduced mass m_l m_r / (m_l + m_r) and mass fractions, wall-safe.
      if (std::isinf(m_l)) {
        c = {Calc(m_r), Calc(1), Calc(0)};
      } else if (std::isinf(m_r)) {
        c = {Calc(m_l), Calc(0), Calc(1)};
      } else {
        const Calc f_r = Calc(1) / (Calc(1) + Calc(m_l) / Calc(m_r));
        c = {Calc(m_l) * f_r, Calc(1) / (Calc(1) + Calc(m_r) / Calc(m_l)), f_r};
      }
    }
  }

  /// The energies gained in an impact of `pair` from the velocities `before` [m/s],
  /// whose approach speed v_right - v_left is `approach` (passed apart, so a caller that
  /// knows it better than the difference of `before` can say so).
  template <class T>
  std::array<Calc, 3> gained(Pair pair, const std::array<T, 3>& before, const T& approach) const {
    const Coefficients& c = pairs_[pair == Pair::AB ? 0 : 1];
    return impactGains(pair, c.reduced, c.f_left, c.f_right, before, approach);
  }

  /// The same from the pair's reduced mass m_l m_r / (m_l + m_r) and mass fractions
  /// f_l = m_l / (m_l + m_r), f_r = 1 - f_l (their m -> inf limits for a wall).
  template <class T>
  static std::array<Calc, 3> impactGains(Pair pair, const Calc& reduced, const Calc& f_left, const Calc& f_right,
                                         const std::array<T, 3>& before, const T& approach) {
    const int left = pair == Pair::AB ? kA : kB;
    const Calc centre = f_left * Calc(before[left]) + f_right * Calc(before[left + 1]);
    const Calc gained_left = Calc(2) * reduced * Calc(approach) * centre;
    std::array<Calc, 3> gained{Calc(0), Calc(0), Calc(0)};
    if (gained_left != 0) {  // never a negative zero
      gained[left] = gained_left;
      gained[left + 1] = -gained_left;
    }
    return gained;
  }

 private:
  struct Coefficients {
    Calc reduced, f_left, f_right;
  };
  std::array<Coefficients, 2> pairs_;  // AB, BC
};

}  // namespace detail
}  // namespace core
}  // namespace collision_lab
