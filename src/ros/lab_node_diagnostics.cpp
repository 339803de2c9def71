// The lab node's /diagnostics: runs accepted and rejected, workers, the queue, recording
// and the bag folder's free space.
#include "collision_lab/ros/lab_node.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_recorder.h"

namespace collision_lab_ros {

void LabNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  status.summary(diagnostic_msgs::DiagnosticStatus::OK, "serving");
  status.add("runs accepted", std::to_string(runs_accepted_.load()));
  status.add("runs rejected", std::to_string(runs_rejected_.load()));
  status.add("last run compute time [s]", std::to_string(last_compute_time_.load()));
  std::size_t waiting = 0, running = 0;
  {
    const auto lock = pool_->lock();
    waiting = pool_->waiting();
    running = pool_->running();
  }
  status.add("workers", std::to_string(params_.workers));
  status.add("runs running", std::to_string(running));
  status.add("runs waiting", std::to_string(waiting));
  status.add("recording", params_.record ? "on" : "off");
  status.add("bag directory", params_.bag_directory);
  if (params_.record) addRecordingStatus(status);
}

void LabNode::addRecordingStatus(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::string recording_error;
  {
    std::lock_guard<std::mutex> lock(recording_mutex_);
    recording_error = last_recording_error_;
  }
  status.add("last recording error", recording_error);
  status.add("recording hand-over per run, runs sampled", std::to_string(recording_times_.size()));
  status.add("recording hand-over per run, median [us]", std::to_string(1e6 * recording_times_.quantile(0.5)));
  status.add("recording hand-over per run, p99 [us]", std::to_string(1e6 * recording_times_.quantile(0.99)));
  if (!recording_error.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "recording failed: " + recording_error);
  }
  const auto free_mb = admission_->freeSpaceMb();
  if (!free_mb) {
    status.add("free space in bag directory [MB]", "unknown (directory not readable)");
    return;
  }
  status.add("free space in bag directory [MB]", std::to_string(*free_mb));
  status.add("free space floor [MB]", std::to_string(params_.min_free_space_mb));
  const std::string free_text = std::to_string(*free_mb) + " MB free for bags";
  if (*free_mb < params_.min_free_space_mb) {
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::ERROR,
                        free_text + ", under the floor: runs are refused (DISK_SPACE)");
  } else if (*free_mb < kFreeSpaceWarnFactor * params_.min_free_space_mb &&
             status.level == diagnostic_msgs::DiagnosticStatus::OK) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "low free space: " + free_text);
  }
}

}  // namespace collision_lab_ros
