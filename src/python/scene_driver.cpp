#include "scene_driver.h"

#include <sstream>

#include "../cli/command_line.h"
#include "../cli/scene_runner.h"
#include "collision_lab/io/report.h"

namespace collision_lab {
namespace python {

std::string runSceneJson(const std::vector<std::string>& args, const std::string& name,
                         const std::atomic<bool>* cancel) {
  std::ostringstream out;
  try {
    // No default scenario file: the module passes the three lists or --bodies only.
    cli::CliRequest request = cli::parseCommandLine(args, "");
    request.format = io::ReportFormat::kJson;
    if (request.action != cli::CliRequest::Action::kRunOne || !request.scene) {
      throw cli::makeCliError(cli::CliReason::kUsage, "arguments", "give the three lists or --bodies FILE");
    }
    cli::reportEntry(request, io::SceneEntry{name, "", *request.scene, 0}, out, cancel);
  } catch (const cli::CliError& error) {
    return io::jsonText(io::errorJson(error.reason, error.code, error.field, error.message));
  }
  return out.str();
}

}  // namespace python
}  // namespace collision_lab
