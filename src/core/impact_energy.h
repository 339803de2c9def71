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

/// Energy gained by A, B, C [J] in elastic impacts between bodies of the given masses.
/// For pair i (bodies i and i + 1, i = j - 1):
///   dE_i = 2 m_i m_j (v_j - v_i)(m_i v_i + m_j v_j) / (m_i + m_j)^2 (physics.md),
///   dE_j = -dE_i exactly, and exactly +0 for the body that takes no part.
/// A wall's entry is the m -> inf limit, minus what the ball gains: +0 for a resting wall.
/// In Calc = double the factors can overflow on their way to a representable energy (a
/// mass near 1e308, speeds near 1e300): callers check, or use EnergyType.
template <class Calc>
class ImpactEnergy {
 public:
  explicit ImpactEnergy(const std::array<double, 3>& masses) {
    for (int i = 0; i < 2; ++i) {
      const double m_i = masses[i], m_j = masses[i + 1];
      Coefficients& c = pairs_[i];
      // Reduced mass m_i m_j / (m_i + m_j) and mass fractions, wall-safe.
      if (std::isinf(m_i)) {
        c = {Calc(m_j), Calc(1), Calc(0)};
      } else if (std::isinf(m_j)) {
        c = {Calc(m_i), Calc(0), Calc(1)};
      } else {
        const Calc f_j = Calc(1) / (Calc(1) + Calc(m_i) / Calc(m_j));
        c = {Calc(m_i) * f_j, Calc(1) / (Calc(1) + Calc(m_j) / Calc(m_i)), f_j};
      }
    }
  }

  /// The energies gained in an impact of pair i from the velocities `before` [m/s],
  /// whose approach speed v[i + 1] - v[i] is `approach` (passed apart, so a caller that
  /// knows it better than the difference of `before` can say so).
  template <class T>
  std::array<Calc, 3> gained(Pair pair, const std::array<T, 3>& before, const T& approach) const {
    const Coefficients& c = pairs_[pairIndex(pair)];
    return impactGains(pair, c.reduced, c.f_i, c.f_j, before, approach);
  }

  /// The same from the pair's reduced mass m_i m_j / (m_i + m_j) and mass fractions
  /// f_i = m_i / (m_i + m_j), f_j = 1 - f_i (their m -> inf limits for a wall).
  template <class T>
  static std::array<Calc, 3> impactGains(Pair pair, const Calc& reduced, const Calc& f_i, const Calc& f_j,
                                         const std::array<T, 3>& before, const T& approach) {
    const int i = pairIndex(pair);
    const Calc centre = f_i * Calc(before[i]) + f_j * Calc(before[i + 1]);
    const Calc gained_i = Calc(2) * reduced * Calc(approach) * centre;
    std::array<Calc, 3> gained{Calc(0), Calc(0), Calc(0)};
    if (gained_i != 0) {  // never a negative zero
      gained[i] = gained_i;
      gained[i + 1] = -gained_i;
    }
    return gained;
  }

 private:
  struct Coefficients {
    Calc reduced, f_i, f_j;
  };
  std::array<Coefficients, 2> pairs_;  // AB, BC
};

}  // namespace detail
}  // namespace core
}  // namespace collision_lab
