// Publishes `markers` (visualization_msgs/MarkerArray) for the newest run. Fed either
// directly by collision_lab_node, or from the node's topics (collision_lab_markers, used
// on bag replay): markers are not recorded in bags, replay regenerates them.
#pragma once

#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "collision_lab/ros/marker_builder.h"

namespace collision_lab_ros {

struct MarkerViewParams {
  double time_scale = 0.0;   ///< simulated s per wall s; <= 0: auto
  double marker_rate = 0.0;  ///< [Hz]
  std::size_t max_plotted_events = 0;
  std::string frame_id;

  /// Reads ~time_scale, ~marker_rate, ~max_plotted_events and ~frame_id, with the
  /// defaults of node_constants.h.
  static MarkerViewParams load(const ros::NodeHandle& private_nh);
};

class MarkerView {
 public:
  MarkerView(ros::NodeHandle nh, const MarkerViewParams& params);

  /// Subscribes to the run topics in nh's namespace (for replay).
  void subscribe();

  /// A message of a new run_id starts a new picture. Topics are not ordered against each
  /// other, so a run's messages may arrive before its InitialConditions; it is drawn once
  /// those arrive. Thread-safe.
  void onInitialConditions(const collision_lab::InitialConditions& msg);
  void onPrediction(const collision_lab::Prediction& msg);
  void onCollisionEvent(const collision_lab::CollisionEvent& msg);
  void onVelocities(const collision_lab::Velocities& msg);
  void onEnergyTransfer(const collision_lab::EnergyTransfer& msg);
  void onRunSummary(const collision_lab::RunSummary& msg);

 private:
  void onTimer(const ros::WallTimerEvent& event);
  /// The record of run_id, started afresh when run_id is not the current run. Call with
  /// mutex_ held.
  RunRecord& select(const std::string& run_id);

  ros::NodeHandle nh_;
  MarkerViewParams params_;
  ros::Publisher markers_pub_;
  ros::WallTimer timer_;
  std::vector<ros::Subscriber> subscribers_;

  std::mutex mutex_;
  RunRecord run_;
  std::string current_run_id_;
  bool has_run_ = false;
  bool run_changed_ = false;     // the previous run's markers must be deleted
  bool static_dirty_ = false;    // the static markers must be rebuilt
  ros::WallTime run_start_;
  ros::WallTime last_static_publish_;
};

}  // namespace collision_lab_ros
