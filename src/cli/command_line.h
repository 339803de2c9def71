// collision_lab_cli's command line: argv -> a request, or one CliError naming the field.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/report.h"

namespace collision_lab {
namespace cli {

/// Reason codes of input the CLI rejects before the core sees a scene. The core's
/// validation reasons (nbody/scene.h, codes 0-13) are reported with their own names and codes.
enum class CliReason {
  kUsage = 100,            ///< unknown option, stray argument, conflicting options
  kMalformedNumber = 101,  ///< a list item that is not a number, or beyond a double
  kWrongCount = 102,       ///< a --bodies line without exactly 3 values
  kMissingInput = 103,     ///< no --masses / --positions / --velocities and no --scenario
  kInvalidOption = 104,    ///< a bad value for --max-collisions, --events, --format, ...
  kUnknownScenario = 105,  ///< --name not in the scenario file
  kScenarioFile = 106,     ///< unreadable or malformed scenario file
  kBodiesFile = 107,       ///< --bodies: unreadable file, or no header mass,position,velocity
};
const char* cliReasonName(CliReason reason);

/// One rejected input: what exits with code 2 and one line on stderr.
struct CliError {
  std::string reason;  ///< e.g. "MALFORMED_NUMBER", "NON_POSITIVE_MASS"
  int code = 0;
  std::string field;   ///< e.g. "masses[1]", "max-collisions", "name"
  std::string message;
};

/// Line breaks in `message` (from CLI11 or yaml-cpp) become blanks: one line on stderr.
CliError makeCliError(CliReason reason, std::string field, std::string message);

struct CliRequest {
  enum class Action { kHelp, kList, kRunOne, kRunAll };
  Action action = Action::kRunOne;
  std::string help_text;
  io::ReportFormat format = io::ReportFormat::kTable;
  core::RunOptions options;
  bool max_collisions_given = false;  ///< else a scenario's own cap applies, if it has one
  /// --simulate-to-cap: simulate up to the cap even when the model predicts more impacts
  /// (core::SceneRunOptions::simulate_to_cap).
  bool simulate_to_cap = false;
  std::string scenario_path;          ///< for kList, kRunAll, and kRunOne from a file
  std::string scenario_name;          ///< kRunOne from a file
  std::optional<core::Scene> scene;   ///< kRunOne from --masses/--positions/--velocities or --bodies
  /// --restitution: replaces every scene's restitution (one value, or one per pair).
  std::optional<std::vector<double>> restitution;
  /// --temperature-csv: the file to write T(t) to (kRunOne, full mode only).
  std::optional<std::string> temperature_csv;
  /// --restitution-model with its parameter (--tc, --elastic-below, --viscoelastic-speed):
  /// replaces every scene's model (core::RestitutionModel).
  std::optional<core::RestitutionModel> restitution_model;
  /// --ring L: every scene on a ring of circumference L [m] (core::Scene::ring).
  std::optional<double> ring;
};

/// The format asked for on the command line, found before full parsing so that even a
/// parse error can be reported as JSON. Table when absent or not understood.
io::ReportFormat requestedFormat(const std::vector<std::string>& args);

/// Parses the arguments (without argv[0]). Throws CliError.
/// `default_scenario_path` is used by --name and --list when --scenario is absent.
CliRequest parseCommandLine(const std::vector<std::string>& args, const std::string& default_scenario_path);

}  // namespace cli
}  // namespace collision_lab
