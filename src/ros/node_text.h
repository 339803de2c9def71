// Text the lab node's files share (internal to src/ros).
#pragma once

#include <string>

#include "collision_lab/RunSummary.h"

namespace collision_lab_ros {

/// Now, in UTC, as format (strftime). Thread-safe.
std::string utcStamp(const char* format);
/// "predicted 31", or why there is no count ("no count predicted by event_engine"), and the
/// collapse when there is one.
std::string predictedText(const collision_lab::RunSummary& summary);

}  // namespace collision_lab_ros
