// The one way ROS-layer code includes the core.
//
// The generated messages live in namespace collision_lab (the package name), and so does
// the core. Three core structs share a message's name (Prediction, RunSummary,
// CollisionEvent), so a translation unit cannot declare both as they are. This header
// includes the core with those three renamed to Core*, and exposes the core to the ROS
// layer as collision_lab_ros::core. Include it instead of any collision_lab/core header.
// Should the core move to its own namespace, only this header changes.
#pragma once

#define Prediction CorePrediction
#define RunSummary CoreRunSummary
#define CollisionEvent CoreCollisionEvent
#include "collision_lab/core/lab_run.h"
#include "collision_lab/core/scene.h"
#undef CollisionEvent
#undef RunSummary
#undef Prediction

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
using CollisionEvent = collision_lab::CoreCollisionEvent;
using Prediction = collision_lab::CorePrediction;
using RunSummary = collision_lab::CoreRunSummary;

}  // namespace core
}  // namespace collision_lab_ros
