// What the lab node tells an in-process viewer of its runs, message by message, in the order
// it publishes them. The node library defines it; the views library implements it
// (MarkerView), so the node does not depend on the views: the collision_lab_node executable
// wires the two together (~publish_markers).
#pragma once

#include <functional>
#include <memory>
#include <string>

#include <ros/node_handle.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"

namespace collision_lab_ros {

/// Called from the node's worker, bag writer, topic and service threads: implementations
/// are thread-safe. The node feeds one run at a time live (the first that starts while no
/// run is drawn and that the observer follows); a run's summary may come after the next
/// run has started (its bag closed first).
class RunObserver {
 public:
  virtual ~RunObserver() = default;
  /// True when the observer shows runs of run_id (the node does not feed it the others).
  virtual bool follows(const std::string& run_id) const = 0;
  virtual void onInitialConditions(const collision_lab::InitialConditions& msg) = 0;
  virtual void onPrediction(const collision_lab::Prediction& msg) = 0;
  virtual void onCollisionEvent(const collision_lab::CollisionEvent& msg) = 0;
  virtual void onRunSummary(const collision_lab::RunSummary& msg) = 0;
  virtual void onRejected(const collision_lab::Rejected& msg) = 0;
};

/// Makes the observer of a node from its node handles (nh, private_nh).
using RunObserverFactory = std::function<std::unique_ptr<RunObserver>(ros::NodeHandle, ros::NodeHandle)>;

}  // namespace collision_lab_ros
