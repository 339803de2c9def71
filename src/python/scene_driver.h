// The Python module's driver: one scene, given as collision_lab_cli's arguments, run in
// process and reported as the CLI's JSON (the same parser, core run and report writer), so
// that the Python API's keys and values are the CLI's by construction.
#pragma once

#include <atomic>
#include <string>
#include <vector>

namespace collision_lab {
namespace python {

/// The CLI's JSON report of the scene that `args` describe (collision_lab_cli's options
/// without --format, --scenario, --name and --list; the three lists or --bodies FILE), with
/// `name` as the scene's name. A rejected scene or option gives the CLI's JSON error
/// document, {"error": {"reason", "code", "field", "message"}}, instead of throwing.
/// `cancel` (may be null), when set, stops the run within 1024 impacts, marked cancelled.
/// Throws std::exception only for what the CLI calls an internal error or a failed output.
std::string runSceneJson(const std::vector<std::string>& args, const std::string& name,
                         const std::atomic<bool>* cancel);

}  // namespace python
}  // namespace collision_lab
