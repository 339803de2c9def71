// Reports of lab runs for people (aligned table) and programs (JSON, CSV). ROS-free.
// Used by collision_lab_cli; the JSON pieces are free functions so that other front ends
// (the ROS node, scripts) print exactly the same keys.
//
// Conventions: SI units throughout (the JSON "units" object lists them); doubles are
// printed so that they read back to the same double (JSON: shortest round-trip form,
// CSV: the same via std::to_chars), a zero always as 0, never -0; NaN and infinities are
// JSON null, with walls named in scene.walls; counts are integers (uint64), never doubles.
// A NaN summary value means "not measured" (a run that was not simulated). Values from the paper's printed formulas carry the prefix "paper_".
#pragma once

#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "collision_lab/core/scene_run.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/scenario_file.h"

namespace collision_lab {
namespace io {

enum class ReportFormat { kTable, kJson, kCsv };

/// Option spellings shared by the CLI's parser and the reports that echo them.
std::optional<ReportFormat> parseReportFormat(const std::string& text);   ///< table|json|csv
std::optional<core::RunMode> parseRunMode(const std::string& text);             ///< full|predict|summary
/// all | none | first:N (N a non-negative integer).
std::optional<core::EventPolicy> parseEventPolicy(const std::string& text);
std::string runModeText(core::RunMode mode);
std::string eventPolicyText(const core::EventPolicy& policy);

using Json = nlohmann::ordered_json;

/// Compact JSON text; never throws (invalid UTF-8 in names or messages is replaced).
std::string jsonText(const Json& json);

Json unitsJson();
/// name, description, masses, positions, velocities, walls (["A"], ["C"] or []).
Json sceneJson(const SceneEntry& scene);
/// max_collisions, events, mode, and "precision": always "double", kept for readers of the
/// format (every run is exact; --precision was removed).
Json optionsJson(const core::RunOptions& options);
/// One impact with a model block in the one event record of every scene (docs/cli.md
/// "Events"): the simulation's full state, the closed-form prediction and the paper's
/// printed values. Precondition: impact.model.
Json eventJson(const core::ImpactRecord& impact);
/// The summary of a run next to its predictions (see docs/cli_section.md for the keys), for
/// a run whose prediction carries the rotation model's values (core::hasRotationValues).
/// "escalation.decisions": one sign decision per impact and a final one (0 when not
/// simulated); "high_precision" counts the decisions taken at 100 digits or more, the
/// exact ones ("exact_rational") among them.
Json summaryJson(const core::SceneRunResult& result);
/// {"error": {"reason", "code", "field", "message"}}.
Json errorJson(const std::string& reason, int code, const std::string& field, const std::string& message);

}  // namespace io
}  // namespace collision_lab
