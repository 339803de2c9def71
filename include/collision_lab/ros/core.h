// The one way ROS-layer code includes the core.
//
// The generated messages live in namespace collision_lab (the package name), and so does
// the core, whose structs are named apart from the messages (AnalyticPrediction vs the
// Prediction message, and so on). This header exposes the core to the ROS layer as
// collision_lab_ros::core, under the names the messages mirror.
#pragma once

#include "collision_lab/core/lab_run.h"
#include "collision_lab/core/scene.h"

namespace collision_lab_ros {
namespace core {

using collision_lab::LabEvent;
using collision_lab::Pair;
using collision_lab::Reason;
using collision_lab::RunMode;
using collision_lab::RunOptions;
using collision_lab::RunResult;
using collision_lab::Scene;
using collision_lab::ValidationError;
using CollisionEvent = collision_lab::ImpactEvent;
using Prediction = collision_lab::AnalyticPrediction;
using RunSummary = collision_lab::LabRunSummary;

}  // namespace core
}  // namespace collision_lab_ros
