// Shared helpers for the core tests: seeded random scenes and error norms.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <boost/multiprecision/cpp_int.hpp>

#include "collision_lab/core/scene.h"
#include "collision_lab/core/scene_run.h"

namespace collision_lab {
namespace core {
namespace testing_support {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// planScene and runScene of a valid scene in `mode` (every event kept in full mode), up to
/// `max_collisions` impacts.
inline SceneRunResult runInMode(const Scene& scene, RunMode mode,
                                std::uint64_t max_collisions = RunOptions{}.max_collisions) {
  SceneRunOptions options;
  options.lab.mode = mode;
  options.lab.max_collisions = max_collisions;
  return runScene(planScene(scene), options);
}

/// Heavy, light, heavy (a wall in every third): long runs, 10^(decades / 2) to 10^decades.
inline std::vector<Scene> heavyLightHeavy(std::mt19937_64& rng, double decades) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Scene> scenes;
  for (int k = 0; k < 12; ++k) {
    const double heavy = std::pow(10.0, decades * (0.5 + 0.5 * unit(rng)));
    Scene scene = threeBodies();
    scene.masses = {heavy * (1 + unit(rng)), 1 + unit(rng), k % 3 == 0 ? kInf : heavy * (1 + unit(rng))};
    scene.positions = {1 + unit(rng), 0.0, -1 - unit(rng)};
    scene.velocities = {-unit(rng), 2 * unit(rng) - 1, k % 3 == 0 ? 0.0 : unit(rng)};
    if (!validate(scene) && firstPair(scene)) scenes.push_back(scene);
  }
  return scenes;
}

/// The scene's masses, positions and velocities on one line, for failure messages.
inline std::string describe(const Scene& s) {
  std::string text;
  for (const auto* values : {&s.masses, &s.positions, &s.velocities}) {
    for (double x : *values) text += std::to_string(x) + " ";
    text += "| ";
  }
  return text;
}

/// A valid random scene: masses within 10^(+-decades), about one in six with a wall,
/// positions in order, velocities in [-1, 1]. Deterministic for a given generator.
/// Wider mass ranges mean longer runs and much larger exact rationals.
inline Scene randomScene(std::mt19937_64& rng, double decades_each_way = 1.0) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> decades(-decades_each_way, decades_each_way);
  std::uniform_int_distribution<int> wall_choice(0, 11);
  while (true) {
    Scene scene = threeBodies();
    for (double& m : scene.masses) m = std::pow(10.0, decades(rng));
    const int wall = wall_choice(rng);
    if (wall == 0) scene.masses[kA] = kInf;
    if (wall == 1) scene.masses[kC] = kInf;
    scene.positions = {2.0 + unit(rng), 0.5 * unit(rng), -2.0 + unit(rng)};
    for (double& v : scene.velocities) v = unit(rng);
    if (!validate(scene)) return scene;
  }
}

/// |S (v - exact)| / |S v0| with S = diag(sqrt(m)) in the wall's frame: the scale-free
/// norm in which every impact is an isometry.
/// `reference` holds exact velocities (e.g. from rational_reference.h).
inline double energyNormError(const Scene& scene, const std::array<double, 3>& v,
                              const std::array<boost::multiprecision::cpp_rational, 3>& reference) {
  double mass_max = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (!scene.isWall(i)) mass_max = std::max(mass_max, scene.masses[i]);
  }
  const int wall = wallIndex(scene);
  const double frame = wall >= 0 ? scene.velocities[wall] : 0.0;
  double error_sq = 0.0, norm_sq = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (i == wall) continue;
    const double w = scene.masses[i] / mass_max;
    const double d = static_cast<double>(boost::multiprecision::cpp_rational(v[i]) - reference[i]);
    error_sq += w * d * d;
    norm_sq += w * (scene.velocities[i] - frame) * (scene.velocities[i] - frame);
  }
  return norm_sq > 0 ? std::sqrt(error_sq / norm_sq) : std::sqrt(error_sq);
}

}  // namespace testing_support
}  // namespace core
}  // namespace collision_lab
