// collision_lab_cli: runs scenes from the command line or a scenario file and prints a
// table, JSON or CSV report. Exit codes: 0 done (a truncated run included), 2 bad input
// (one line on stderr; with --format json also an {"error": ...} document on stdout),
// 1 internal error, 3 the output (standard output or --temperature-csv's file) could not be
// written (one line on stderr).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "collision_lab/io/report.h"
#include "collision_lab/io/scenario_file.h"
#include "collision_lab/io/temperature_csv.h"
#include "command_line.h"
#include "scene_runner.h"

namespace collision_lab {
namespace cli {
namespace {

constexpr int kExitBadInput = 2;
constexpr int kExitInternalError = 1;
constexpr int kExitOutputFailed = 3;

/// The package's presets. An installed CLI (<prefix>/lib/collision_lab/) reads its own
/// install's copy (<prefix>/share/collision_lab/config/), found from where the executable
/// is, so that a moved install works too; a CLI of the devel space has none there and reads
/// the source tree's.
std::string defaultScenarioPath() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path installed =
        (exe.parent_path() / COLLISION_LAB_BIN_TO_SHARE / "config" / "scenarios.yaml").lexically_normal();
    if (std::ifstream(installed).good()) return installed.string();
  }
  return COLLISION_LAB_SOURCE_SCENARIOS;
}

std::vector<io::SceneEntry> loadScenes(const std::string& path) {
  try {
    return io::loadScenes(path);
  } catch (const io::ScenarioFileError& e) {
    throw makeCliError(CliReason::kScenarioFile, "scenario", e.what());
  }
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

void listScenes(const CliRequest& request, const std::vector<io::SceneEntry>& scenes) {
  switch (request.format) {
    case io::ReportFormat::kJson: {
      io::Json list = io::Json::array();
      for (const io::SceneEntry& named : scenes) list.push_back({{"name", named.name}, {"description", named.description}});
      std::cout << io::jsonText(io::Json{{"scenarios", list}}) << "\n";
      return;
    }
    case io::ReportFormat::kCsv:
      std::cout << "name,description\n";
      for (const io::SceneEntry& named : scenes) std::cout << csvField(named.name) << "," << csvField(named.description) << "\n";
      return;
    case io::ReportFormat::kTable: {
      std::size_t width = 0;
      for (const io::SceneEntry& named : scenes) width = std::max(width, named.name.size());
      for (const io::SceneEntry& named : scenes) {
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
      runEntries(request, loadScenes(request.scenario_path));
      return 0;
    case CliRequest::Action::kRunOne:
      break;
  }
  if (request.scene) {
    runEntry(request, io::SceneEntry{"", "", *request.scene, 0});
    return 0;
  }
  const std::vector<io::SceneEntry> scenes = loadScenes(request.scenario_path);
  io::SceneEntry named;
  try {
    named = io::findScene(scenes, request.scenario_name);
  } catch (const io::ScenarioFileError& e) {
    throw makeCliError(CliReason::kUnknownScenario, "name", e.what());
  }
  runEntry(request, named);
  return 0;
}

void reportBadInput(const CliError& error, io::ReportFormat format) {
  std::cerr << "collision_lab_cli: invalid " << error.field << " (" << error.reason << "): " << error.message
            << std::endl;
  if (format == io::ReportFormat::kJson) {
    std::cout << io::jsonText(io::errorJson(error.reason, error.code, error.field, error.message)) << std::endl;
  }
}

/// code, or kExitOutputFailed (and one line on stderr) when standard output lost any of
/// what was written to it: a full disk must not pass for a finished report.
int checkedOutput(int code) {
  std::cout.flush();
  if (std::cout) return code;
  // No errno: the failed write may have been a report thread's (errno is per thread).
  std::cerr << "collision_lab_cli: cannot write to standard output; the output is incomplete" << std::endl;
  return kExitOutputFailed;
}

}  // namespace
}  // namespace cli
}  // namespace collision_lab

int main(int argc, char** argv) {
  using namespace collision_lab;
  std::ios::sync_with_stdio(false);
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    return cli::checkedOutput(cli::run(args));
  } catch (const cli::CliError& error) {
    cli::reportBadInput(error, cli::requestedFormat(args));
    return cli::kExitBadInput;
  } catch (const io::OutputFailed& e) {
    std::cerr << "collision_lab_cli: " << e.what() << std::endl;
    return cli::kExitOutputFailed;
  } catch (const std::exception& e) {
    std::cerr << "collision_lab_cli: internal error: " << e.what() << std::endl;
    return cli::kExitInternalError;
  }
}
