// Named scenes from YAML files (config/scenarios.yaml). ROS-free; uses yaml-cpp.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace io {

struct NamedScene {
  std::string name;         ///< unique key, e.g. "pi_digits_3"
  std::string description;  ///< one line for people
  core::ThreeBodyScene scene;              ///< masses may be written inf / .inf in the file
  std::uint64_t max_collisions = 0;  ///< 0: the caller's default
};

/// A malformed file or entry. what() names the file, the entry and the field.
struct ScenarioFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Loads every scene of a scenario file, in file order. Throws ScenarioFileError.
/// Does not validate the physics (call validate() on each scene).
std::vector<NamedScene> loadScenarioFile(const std::string& path);

/// The entry called `name`; throws ScenarioFileError listing the known names if absent.
NamedScene findScenario(const std::vector<NamedScene>& scenes, const std::string& name);

}  // namespace io
}  // namespace collision_lab
