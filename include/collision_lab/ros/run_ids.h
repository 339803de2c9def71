// The run_id an input message asks for (service/envelope.h's requestedRunId of its fields);
// which one it is served under is service/run_ids.h's.
#pragma once

#include <string>

#include "collision_lab/InitialConditions.h"

namespace collision_lab_ros {

/// The run_id input asks for: <student>.<run_id>, <student>, run_id, or empty (the node
/// assigns one). A taken one is then served as <that>.N, except a numbered run
/// (service::numberedRunId): that one as the next free number.
std::string requestedRunId(const collision_lab::InitialConditions& input);

}  // namespace collision_lab_ros
