// A seeded one-dimensional granular gas (issue 21), the same on every platform: shared by
// the core tests and the gas benchmark (bench/bench_gas.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {
namespace testing_support {

/// A double uniform in [0, 1): the top 53 bits of one std::mt19937_64 draw times 2^-53.
/// (std::uniform_real_distribution's output is implementation-defined; this is not.)
inline double unitDraw(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1p-53; }

/// n bodies 1 m apart (body k at n - k [m], listed right to left), no walls, one restitution
/// e for every pair. From std::mt19937_64(seed), per body in order: mass 1 + u [kg], then
/// velocity 2u - 1 [m/s], each u one unitDraw().
inline Scene granularGas(std::size_t n, double e, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Scene s;
  for (std::size_t k = 0; k < n; ++k) {
    s.masses.push_back(1.0 + unitDraw(rng));
    s.velocities.push_back(2.0 * unitDraw(rng) - 1.0);
    s.positions.push_back(static_cast<double>(n - k));
  }
  s.restitution = {e};
  return s;
}

}  // namespace testing_support
}  // namespace core
}  // namespace collision_lab
