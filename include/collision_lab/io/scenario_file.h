// Named scenes from YAML files (config/scenarios.yaml). ROS-free; uses yaml-cpp.
//
// An entry holds a scene of any size N >= 1: either the lists masses, positions and
// velocities (N items each, listed right to left), or `bodies: FILE`, a CSV file in the
// format of --bodies (see bodies_csv.h), its path relative to the YAML file's folder.
// Optional keys: description, restitution (one number for every pair, or a list of N-1),
// max_collisions (a positive integer).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "collision_lab/core/nbody/scene.h"
#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace io {

/// A scene of any size from a scenario file.
struct SceneEntry {
  std::string name;         ///< unique key, e.g. "cradle_5"
  std::string description;  ///< one line for people
  core::Scene scene;        ///< masses may be written inf / .inf in the file
  std::uint64_t max_collisions = 0;  ///< 0: the caller's default
};

/// A malformed file or entry. what() names the file, the entry and the field.
struct ScenarioFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Loads every scene of a scenario file, in file order. Throws ScenarioFileError.
/// Does not validate the physics (core::planScene validates each scene).
std::vector<SceneEntry> loadScenes(const std::string& path);


/// The entry called `name`; throws ScenarioFileError listing the known names if absent.
SceneEntry findScene(const std::vector<SceneEntry>& scenes, const std::string& name);

}  // namespace io
}  // namespace collision_lab
