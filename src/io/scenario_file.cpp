#include "collision_lab/io/scenario_file.h"

#include <filesystem>
#include <set>

#include <yaml-cpp/yaml.h>

#include "collision_lab/io/number_text.h"

namespace collision_lab {
namespace io {

namespace {

const char* const kVectorKeys[3] = {"masses", "positions", "velocities"};
const std::set<std::string> kKnownKeys = {"description", "masses", "positions", "velocities",
                                          "max_collisions"};

/// Reads the three numbers of `key` into `out`; `where` is "file: entry 'name'".
void readTriple(const YAML::Node& entry, const char* key, const std::string& where,
                std::array<double, 3>& out) {
  const YAML::Node list = entry[key];
  if (!list) throw ScenarioFileError(where + ": '" + key + "' is missing");
  if (!list.IsSequence() || list.size() != 3) {
    throw ScenarioFileError(where + ": '" + key + "' must be a list of 3 numbers [A, B, C]");
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string field = std::string(key) + "[" + std::to_string(i) + "]";
    if (!list[i].IsScalar()) throw ScenarioFileError(where + ": " + field + " is not a number");
    const ParsedNumber parsed = parseNumber(list[i].Scalar());
    if (!parsed.problem.empty()) {
      throw ScenarioFileError(where + ": " + field + " '" + list[i].Scalar() + "' " + parsed.problem);
    }
    out[i] = parsed.value;
  }
}

NamedScene readEntry(const std::string& name, const YAML::Node& entry, const std::string& path) {
  const std::string where = path + ": entry '" + name + "'";
  if (!entry.IsMap()) {
    throw ScenarioFileError(where + " must be a map with masses, positions and velocities");
  }
  for (const auto& item : entry) {
    const std::string key = item.first.Scalar();
    if (kKnownKeys.count(key) == 0) {
      throw ScenarioFileError(where + ": unknown key '" + key +
                              "' (known: description, masses, positions, velocities, max_collisions)");
    }
  }
  NamedScene named;
  named.name = name;
  if (const YAML::Node description = entry["description"]) {
    if (!description.IsScalar()) throw ScenarioFileError(where + ": 'description' must be text");
    named.description = description.Scalar();
  }
  readTriple(entry, kVectorKeys[0], where, named.scene.masses);
  readTriple(entry, kVectorKeys[1], where, named.scene.positions);
  readTriple(entry, kVectorKeys[2], where, named.scene.velocities);
  if (const YAML::Node cap = entry["max_collisions"]) {
    const ParsedCount value = cap.IsScalar() ? parseCount(cap.Scalar()) : ParsedCount{0, "is not a number"};
    if (value.problem.rfind("is too large", 0) == 0) {
      throw ScenarioFileError(where + ": 'max_collisions' " + cap.Scalar() + " " + value.problem);
    }
    if (!value.problem.empty() || value.value == 0) {
      throw ScenarioFileError(where + ": 'max_collisions' must be a positive integer");
    }
    named.max_collisions = value.value;
  }
  return named;
}

}  // namespace

std::vector<NamedScene> loadScenarioFile(const std::string& path) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) {
    throw ScenarioFileError(path + ": is a folder, not a scenario file");
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw ScenarioFileError(path + ": cannot open the scenario file");
  } catch (const YAML::Exception& e) {
    // e.mark is 0-based; people count lines from 1.
    throw ScenarioFileError(path + ": YAML syntax error at line " + std::to_string(e.mark.line + 1) +
                            ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  } catch (const std::exception& e) {  // read errors surface as std::ios_base::failure
    throw ScenarioFileError(path + ": cannot read the scenario file (" + e.what() + ")");
  }
  if (!root.IsMap() || root.size() == 0) {
    throw ScenarioFileError(path + ": expected a map of named scenarios (name: {masses, positions, velocities})");
  }
  std::vector<NamedScene> scenes;
  std::set<std::string> seen;
  for (const auto& item : root) {
    if (!item.first.IsScalar()) throw ScenarioFileError(path + ": a scenario name must be plain text");
    const std::string name = item.first.Scalar();
    if (!seen.insert(name).second) throw ScenarioFileError(path + ": scenario '" + name + "' appears twice");
    scenes.push_back(readEntry(name, item.second, path));
  }
  return scenes;
}

NamedScene findScenario(const std::vector<NamedScene>& scenes, const std::string& name) {
  std::string known;
  for (const NamedScene& scene : scenes) {
    if (scene.name == name) return scene;
    known += (known.empty() ? "" : ", ") + scene.name;
  }
  throw ScenarioFileError("no scenario named '" + name + "' (known: " + known + ")");
}

}  // namespace io
}  // namespace collision_lab
