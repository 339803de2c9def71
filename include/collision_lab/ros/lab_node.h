// collision_lab_node: serves InitialConditions with the core's runLab, publishes every
// output, records one bag per run and feeds the marker view.
//
// Threading: the subscriber callback only queues the input; one worker thread serves the
// inputs in arrival order and does all publishing, so a run's messages go out in the
// order predictions, (collision_events, velocities, energy_transfers) per collision,
// run_summaries, and runs never interleave.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <ros/ros.h>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/ros/marker_view.h"

namespace collision_lab_ros {

struct LabNodeParams {
  bool record = true;
  std::string bag_directory;  ///< "~" expanded
  std::uint64_t max_collisions = 0;
  std::uint64_t max_published_events = 0;
  bool publish_markers = true;
  double min_free_space_mb = 0.0;  ///< [MB] diagnostics warn below it

  /// Reads ~record, ~bag_directory, ~max_collisions, ~max_published_events,
  /// ~publish_markers and ~min_free_space_mb, with the defaults of node_constants.h.
  static LabNodeParams load(const ros::NodeHandle& private_nh);
};

/// Empty when run_id is safe as a bag file name; otherwise why not.
std::string runIdProblem(const std::string& run_id);

class LabNode {
 public:
  LabNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  /// Finishes the run in progress (closing its bag), drops queued inputs.
  ~LabNode();

 private:
  void onInitialConditions(const collision_lab::InitialConditions::ConstPtr& msg);
  void workerLoop();
  void serve(collision_lab::InitialConditions input);
  void reject(collision_lab::Rejected msg, const std::string& run_id);
  std::string newRunId();
  /// Publishes one DiagnosticArray: runs accepted and rejected, the last run's compute
  /// time, the recording state and the free space in bag_directory.
  void publishDiagnostics();

  ros::NodeHandle nh_;
  LabNodeParams params_;
  ros::Subscriber input_sub_;
  ros::Publisher predictions_pub_, events_pub_, velocities_pub_, energy_pub_,
      summaries_pub_, rejected_pub_;
  ros::Publisher diagnostics_pub_;
  ros::WallTimer diagnostics_timer_;
  std::unique_ptr<MarkerView> marker_view_;
  std::string run_id_prefix_;
  std::uint64_t run_counter_ = 0;

  // Written by the worker, read by the diagnostics timer.
  std::atomic<std::uint64_t> runs_accepted_{0};
  std::atomic<std::uint64_t> runs_rejected_{0};
  std::atomic<double> last_compute_time_{0.0};
  std::mutex recording_mutex_;
  std::string last_recording_error_;  ///< empty while recording works

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<collision_lab::InitialConditions::ConstPtr> inputs_;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace collision_lab_ros
