// Seeded random N-body scenes for the tests.
#pragma once

#include <cmath>
#include <limits>
#include <random>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {
namespace testing_support {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// The restitution values the issue asks for.
constexpr double kRestitutions[] = {0.0, 0.3, 0.5, 0.8, 0.95, 1.0};

struct SceneMix {
  double mass_decades = 1.0;  ///< masses 10^U(-d, d) [kg]
  bool walls = true;          ///< about 1 in 4 scenes gets one wall, 1 in 12 two
  bool restitution = true;    ///< a third elastic, a third one e for all, a third per pair
};

/// A valid random scene of n bodies, listed right to left with gaps in [0.2, 2] m and
/// velocities in [-1, 1] m/s. Deterministic for a given generator.
inline Scene randomScene(std::mt19937_64& rng, std::size_t n, const SceneMix& mix = {}) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), gap(0.2, 2.0), decades(-mix.mass_decades, mix.mass_decades);
  std::uniform_int_distribution<int> wall_choice(0, 11), restitution_choice(0, 2), value_choice(0, 5);
  while (true) {
    Scene scene;
    scene.positions.assign(n, 0.0);
    scene.positions[n - 1] = unit(rng);
    for (std::size_t k = n - 1; k-- > 0;) scene.positions[k] = scene.positions[k + 1] + gap(rng);
    for (std::size_t k = 0; k < n; ++k) {
      scene.masses.push_back(std::pow(10.0, decades(rng)));
      scene.velocities.push_back(unit(rng));
    }
    const int wall = mix.walls ? wall_choice(rng) : 11;
    if (wall == 0 || wall == 1 || (wall == 2 && n >= 3)) scene.masses[0] = kInf;
    if (wall == 3 || wall == 4 || (wall == 2 && n >= 3)) scene.masses[n - 1] = kInf;
    if (wall <= 4 && wall % 2 == 0) {
      for (std::size_t k : {std::size_t{0}, n - 1}) {
        if (std::isinf(scene.masses[k])) scene.velocities[k] = 0.0;  // most walls stand still
      }
    }
    const int how = mix.restitution ? restitution_choice(rng) : 0;
    if (how == 1) scene.restitution = {kRestitutions[value_choice(rng)]};
    if (how == 2) {
      for (std::size_t p = 0; p + 1 < n; ++p) scene.restitution.push_back(kRestitutions[value_choice(rng)]);
    }
    if (!validate(scene)) return scene;
  }
}

}  // namespace testing_support
}  // namespace core
}  // namespace collision_lab
