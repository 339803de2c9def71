// collision_lab_cli: runs scenes from the command line or a scenario file and prints a
// table, JSON or CSV report. Exit codes: 0 done (a truncated run included), 2 bad input
// (one line on stderr; with --format json also an {"error": ...} document on stdout),
// 1 internal error.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <optional>

#include "collision_lab/core/lab_run.h"
#include "collision_lab/io/report.h"
#include "collision_lab/io/scenario_file.h"
#include "command_line.h"
#include "progress.h"

namespace collision_lab {
namespace cli {
namespace {

constexpr int kExitBadInput = 2;
constexpr int kExitInternalError = 1;

/// The package's presets: the source tree's (devel space) or the installed copy.
std::string defaultScenarioPath() {
  for (const char* candidate : {COLLISION_LAB_SOURCE_SCENARIOS, COLLISION_LAB_INSTALLED_SCENARIOS}) {
    if (std::ifstream(candidate).good()) return candidate;
  }
  return COLLISION_LAB_SOURCE_SCENARIOS;
}

void validateOrThrow(const io::NamedScene& named) {
  if (const auto error = core::validate(named.scene)) {
    const std::string where = named.name.empty() ? "" : "scenario '" + named.name + "': ";
    throw CliError{core::reasonName(error->reason), static_cast<int>(error->reason), error->field,
                   where + error->message};
  }
}

std::vector<io::NamedScene> loadScenes(const std::string& path) {
  try {
    return io::loadScenarioFile(path);
  } catch (const io::ScenarioFileError& e) {
    throw makeCliError(CliReason::kScenarioFile, "scenario", e.what());
  }
}

/// The request's options, with a scene's own collision cap unless --max-collisions was given.
core::RunOptions optionsFor(const CliRequest& request, const io::NamedScene& named) {
  core::RunOptions options = request.options;
  if (!request.max_collisions_given && named.max_collisions > 0) options.max_collisions = named.max_collisions;
  return options;
}

/// Runs one validated scene. `on_event` (may be empty) sees every event; a progress line
/// is drawn on a terminal.
core::RunResult runWithProgress(const core::ThreeBodyScene& scene, const core::RunOptions& options, const core::LabEventVisitor& on_event) {
  std::optional<ProgressLine> progress;
  if (options.mode == core::RunMode::kFull && isatty(STDERR_FILENO)) {
    progress.emplace(stderr, std::min(core::predict(scene).collision_count, options.max_collisions));
  }
  if (!progress) return core::runLab(scene, options, on_event);
  return core::runLab(scene, options, [&](const core::LabEvent& event) {
    if (on_event) on_event(event);
    progress->onCollision(event.event.index);
  });
}

/// One scene, its events streamed to the report as they happen: nothing is kept.
void runOne(const CliRequest& request, const io::NamedScene& named) {
  validateOrThrow(named);
  const core::RunOptions shown_options = optionsFor(request, named);
  core::RunOptions run_options = shown_options;
  run_options.events = core::EventPolicy::none();

  const std::unique_ptr<io::RunReportWriter> writer = io::makeRunReportWriter(request.format, std::cout);
  writer->begin(named, shown_options);
  core::LabEventVisitor show_event;
  if (shown_options.events.kind != core::EventPolicy::Kind::kNone) {
    show_event = [&](const core::LabEvent& event) {
      if (shown_options.events.keeps(event.event.index)) writer->event(event);
    };
  }
  writer->end(runWithProgress(named.scene, run_options, show_event));
}

/// Every scene of a file: all are validated before any runs, then one batch report.
void runAll(const CliRequest& request, const std::vector<io::NamedScene>& scenes) {
  for (const io::NamedScene& named : scenes) validateOrThrow(named);
  std::vector<io::SceneOutcome> outcomes;
  for (const io::NamedScene& named : scenes) {
    const core::RunOptions options = optionsFor(request, named);
    outcomes.push_back({named, options, runWithProgress(named.scene, options, {})});
  }
  io::writeBatchReport(request.format, outcomes, std::cout);
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

void listScenes(const CliRequest& request, const std::vector<io::NamedScene>& scenes) {
  switch (request.format) {
    case io::ReportFormat::kJson: {
      io::Json list = io::Json::array();
      for (const io::NamedScene& named : scenes) list.push_back({{"name", named.name}, {"description", named.description}});
      std::cout << io::jsonText(io::Json{{"scenarios", list}}) << "\n";
      return;
    }
    case io::ReportFormat::kCsv:
      std::cout << "name,description\n";
      for (const io::NamedScene& named : scenes) std::cout << csvField(named.name) << "," << csvField(named.description) << "\n";
      return;
    case io::ReportFormat::kTable: {
      std::size_t width = 0;
      for (const io::NamedScene& named : scenes) width = std::max(width, named.name.size());
      for (const io::NamedScene& named : scenes) {
        std::cout << named.name << std::string(width + 2 - named.name.size(), ' ') << named.description << "\n";
      }
      return;
    }
  }
}

int run(const std::vector<std::string>& args) {
  const CliRequest request = parseCommandLine(args, defaultScenarioPath());
  switch (request.action) {
    case CliRequest::Action::kHelp:
      std::cout << request.help_text;
      return 0;
    case CliRequest::Action::kList:
      listScenes(request, loadScenes(request.scenario_path));
      return 0;
    case CliRequest::Action::kRunAll:
      runAll(request, loadScenes(request.scenario_path));
      return 0;
    case CliRequest::Action::kRunOne:
      break;
  }
  if (request.scene) {
    runOne(request, io::NamedScene{"", "", *request.scene, 0});
    return 0;
  }
  const std::vector<io::NamedScene> scenes = loadScenes(request.scenario_path);
  io::NamedScene named;
  try {
    named = io::findScenario(scenes, request.scenario_name);
  } catch (const io::ScenarioFileError& e) {
    throw makeCliError(CliReason::kUnknownScenario, "name", e.what());
  }
  runOne(request, named);
  return 0;
}

void reportBadInput(const CliError& error, io::ReportFormat format) {
  std::cerr << "collision_lab_cli: invalid " << error.field << " (" << error.reason << "): " << error.message
            << std::endl;
  if (format == io::ReportFormat::kJson) {
    std::cout << io::jsonText(io::errorJson(error.reason, error.code, error.field, error.message)) << std::endl;
  }
}

}  // namespace
}  // namespace cli
}  // namespace collision_lab

int main(int argc, char** argv) {
  using namespace collision_lab;
  std::ios::sync_with_stdio(false);
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    return cli::run(args);
  } catch (const cli::CliError& error) {
    cli::reportBadInput(error, cli::requestedFormat(args));
    return cli::kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "collision_lab_cli: internal error: " << e.what() << std::endl;
    return cli::kExitInternalError;
  }
}
