#include "collision_lab/io/scenario_file.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include <yaml-cpp/yaml.h>

#include "collision_lab/io/bodies_csv.h"
#include "collision_lab/io/number_text.h"

namespace collision_lab {
namespace io {

namespace {

const char* const kVectorKeys[3] = {"masses", "positions", "velocities"};
const std::set<std::string> kKnownKeys = {"description", "masses",      "positions",     "velocities",
                                          "bodies",      "restitution", "max_collisions", "restitution_model",
                                          "tc",          "elastic_below", "viscoelastic_speed", "ring"};

double readNumber(const YAML::Node& node, const std::string& where, const std::string& field) {
  if (!node.IsScalar()) throw ScenarioFileError(where + ": " + field + " is not a number");
  const ParsedNumber parsed = parseNumber(node.Scalar());
  if (!parsed.problem.empty()) {
    throw ScenarioFileError(where + ": " + field + " '" + node.Scalar() + "' " + parsed.problem);
  }
  return parsed.value;
}

/// Reads the list `key` (one number per body, N >= 1) into `out`; `where` is "file: entry 'name'".
void readList(const YAML::Node& entry, const char* key, const std::string& where, std::vector<double>& out) {
  const YAML::Node list = entry[key];
  if (!list) throw ScenarioFileError(where + ": '" + key + "' is missing");
  if (!list.IsSequence() || list.size() == 0) {
    throw ScenarioFileError(where + ": '" + key + "' must be a list of numbers, one per body, right to left");
  }
  out.reserve(list.size());
  for (std::size_t i = 0; i < list.size(); ++i) {
    out.push_back(readNumber(list[i], where, std::string(key) + "[" + std::to_string(i) + "]"));
  }
}

/// `restitution: e` (every pair) or `restitution: [e_0, ..., e_N-2]`.
std::vector<double> readRestitution(const YAML::Node& node, const std::string& where) {
  if (node.IsScalar()) return {readNumber(node, where, "restitution")};
  if (!node.IsSequence()) throw ScenarioFileError(where + ": 'restitution' must be a number or a list of numbers");
  std::vector<double> values;
  for (std::size_t i = 0; i < node.size(); ++i) {
    values.push_back(readNumber(node[i], where, "restitution[" + std::to_string(i) + "]"));
  }
  return values;
}

/// The bodies of `bodies: FILE`, the path relative to the scenario file's folder.
core::Scene readBodiesEntry(const YAML::Node& node, const std::string& where, const std::string& path) {
  if (!node.IsScalar()) throw ScenarioFileError(where + ": 'bodies' must be a file name");
  const std::filesystem::path file = std::filesystem::path(path).parent_path() / node.Scalar();
  try {
    return readBodiesFile(file.string());
  } catch (const BodiesFileError& e) {
    throw ScenarioFileError(where + ": bodies file '" + file.string() + "', " + e.field + ": " + e.what());
  }
}

void readScene(const YAML::Node& entry, const std::string& where, const std::string& path, core::Scene& scene) {
  if (const YAML::Node bodies = entry["bodies"]) {
    for (const char* key : kVectorKeys) {
      if (entry[key]) throw ScenarioFileError(where + ": give either 'bodies' or '" + key + "', not both");
    }
    scene = readBodiesEntry(bodies, where, path);
  } else {
    readList(entry, kVectorKeys[0], where, scene.masses);
    readList(entry, kVectorKeys[1], where, scene.positions);
    readList(entry, kVectorKeys[2], where, scene.velocities);
  }
  if (const YAML::Node restitution = entry["restitution"]) scene.restitution = readRestitution(restitution, where);
}

/// `restitution_model: tc|threshold|viscoelastic|constant` with its parameter (`tc: t_c`
/// [s], `elastic_below: v_0` [m/s], `viscoelastic_speed: v*` [m/s]), and `ring: L` [m].
void readSceneOptions(const YAML::Node& entry, const std::string& where, core::Scene& scene) {
  if (const YAML::Node model = entry["restitution_model"]) {
    bool known = false;
    for (auto kind : {core::RestitutionModelKind::kConstant, core::RestitutionModelKind::kTc,
                      core::RestitutionModelKind::kThreshold, core::RestitutionModelKind::kViscoelastic}) {
      if (model.IsScalar() && model.Scalar() == core::restitutionModelName(kind)) {
        scene.restitution_model.kind = kind, known = true;
      }
    }
    if (!known) throw ScenarioFileError(where + ": 'restitution_model' must be constant, tc, threshold or viscoelastic");
  }
  const std::pair<const char*, core::RestitutionModelKind> parameters[] = {
      {"tc", core::RestitutionModelKind::kTc},
      {"elastic_below", core::RestitutionModelKind::kThreshold},
      {"viscoelastic_speed", core::RestitutionModelKind::kViscoelastic}};
  for (const auto& [key, kind] : parameters) {
    const YAML::Node node = entry[key];
    if (!node) continue;
    if (scene.restitution_model.kind != kind) {
      throw ScenarioFileError(where + ": '" + key + "' belongs to restitution_model: " + core::restitutionModelName(kind));
    }
    const double value = readNumber(node, where, key);
    core::RestitutionModel& model = scene.restitution_model;
    (kind == core::RestitutionModelKind::kTc ? model.tc
                                             : (kind == core::RestitutionModelKind::kThreshold ? model.elastic_below
                                                                                               : model.viscoelastic_speed)) =
        value;
  }
  if (const YAML::Node ring = entry["ring"]) scene.ring = readNumber(ring, where, "ring");
}

SceneEntry readEntry(const std::string& name, const YAML::Node& entry, const std::string& path) {
  const std::string where = path + ": entry '" + name + "'";
  if (!entry.IsMap()) {
    throw ScenarioFileError(where + " must be a map with masses, positions and velocities (or bodies)");
  }
  for (const auto& item : entry) {
    const std::string key = item.first.Scalar();
    if (kKnownKeys.count(key) == 0) {
      throw ScenarioFileError(where + ": unknown key '" + key +
                              "' (known: description, masses, positions, velocities, bodies, restitution, "
                              "max_collisions, restitution_model, tc, elastic_below, viscoelastic_speed, ring)");
    }
  }
  SceneEntry named;
  named.name = name;
  if (const YAML::Node description = entry["description"]) {
    if (!description.IsScalar()) throw ScenarioFileError(where + ": 'description' must be text");
    named.description = description.Scalar();
  }
  readScene(entry, where, path, named.scene);
  readSceneOptions(entry, where, named.scene);
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

std::vector<SceneEntry> loadScenes(const std::string& path) {
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
  std::vector<SceneEntry> scenes;
  std::set<std::string> seen;
  for (const auto& item : root) {
    if (!item.first.IsScalar()) throw ScenarioFileError(path + ": a scenario name must be plain text");
    const std::string name = item.first.Scalar();
    if (!seen.insert(name).second) throw ScenarioFileError(path + ": scenario '" + name + "' appears twice");
    scenes.push_back(readEntry(name, item.second, path));
  }
  return scenes;
}

namespace {
template <class Entry>
Entry findByName(const std::vector<Entry>& scenes, const std::string& name) {
  std::string known;
  for (const Entry& scene : scenes) {
    if (scene.name == name) return scene;
    known += (known.empty() ? "" : ", ") + scene.name;
  }
  throw ScenarioFileError("no scenario named '" + name + "' (known: " + known + ")");
}
}  // namespace

SceneEntry findScene(const std::vector<SceneEntry>& scenes, const std::string& name) {
  return findByName(scenes, name);
}

}  // namespace io
}  // namespace collision_lab
