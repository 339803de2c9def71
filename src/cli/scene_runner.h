// Running scenes of any size for collision_lab_cli: validation, the model's run (the
// three-body path or the N-body models, core/scene_run.h), the report while it runs, a
// progress line on a terminal and Ctrl-C.
#pragma once

#include <atomic>
#include <vector>

#include "collision_lab/io/scenario_file.h"
#include "command_line.h"

namespace collision_lab {
namespace cli {

/// One scene, its events streamed to the report as they happen: nothing is kept. Ctrl-C
/// (SIGINT) during an event-engine run stops it, and the partial summary is printed.
/// Throws CliError for an invalid scene.
void runEntry(const CliRequest& request, const io::SceneEntry& entry);

/// Every scene of a file: all are validated before any runs, then one batch report.
void runEntries(const CliRequest& request, const std::vector<io::SceneEntry>& entries);

}  // namespace cli
}  // namespace collision_lab
