// What the lab node's files share (internal to src/ros): stamps, text and a run's core options.
#pragma once

#include <cstdint>
#include <string>

#include <ros/time.h>

#include "collision_lab/RunSummary.h"
#include "collision_lab/core/scene_run.h"

namespace collision_lab_ros {

/// Now, in UTC, as format (strftime). Thread-safe.
std::string utcStamp(const char* format);
/// "predicted 31", or why there is no count ("no count predicted by event_engine"), and the
/// collapse when there is one.
std::string predictedText(const collision_lab::RunSummary& summary);

/// Message stamps double as bag times, which must be >= ros::TIME_MIN: under
/// use_sim_time without a clock, ROS time is 0, so this falls back to wall time.
ros::Time stampNow();

/// The core's options of a run in `mode`: what the lane chosen at intake (core::plannedImpacts)
/// and the worker's run both follow. Events are streamed to the visitors, never kept; asking
/// for them makes a closed-form scene simulated too (its events are published), as the CLI
/// does when it shows events. Without simulate_to_cap the model answers over the cap.
collision_lab::core::SceneRunOptions sceneRunOptions(collision_lab::core::RunMode mode, std::uint64_t max_collisions,
                                                     bool simulate_to_cap);

}  // namespace collision_lab_ros
