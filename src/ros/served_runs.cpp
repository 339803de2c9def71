#include "collision_lab/ros/served_runs.h"

#include <algorithm>

#include "collision_lab/ros/node_constants.h"

namespace collision_lab_ros {

void RecentDurations::add(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (samples_.size() < kRecordingTimeWindow) {
    samples_.push_back(seconds);
  } else {
    samples_[next_] = seconds;
    next_ = (next_ + 1) % kRecordingTimeWindow;
  }
}

double RecentDurations::quantile(double q) const {
  std::vector<double> sorted;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sorted = samples_;
  }
  if (sorted.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1) + 0.5);
  std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
  return sorted[k];
}

std::size_t RecentDurations::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return samples_.size();
}

void ServedRuns::accepted(const collision_lab::AcceptedRun& run) {
  collision_lab::ServedRun served;
  served.accepted = run;
  std::lock_guard<std::mutex> lock(mutex_);
  if (runs_.size() == kServedRunsKept) runs_.pop_front();
  runs_.push_back(std::move(served));
}

void ServedRuns::finished(const collision_lab::RunSummary& summary) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Summaries come in the order of the runs, so the run is one of the newest.
  const auto it = std::find_if(runs_.rbegin(), runs_.rend(), [&](const collision_lab::ServedRun& run) {
    return run.accepted.run_id == summary.run_id;
  });
  if (it == runs_.rend()) return;  // no longer kept
  it->finished = true;
  it->collision_count = summary.collision_count;
  it->truncated = summary.truncated;
  it->stop_reason = summary.stop_reason;
  it->bag_path = summary.bag_path;
  it->recording_ok = summary.recording_ok;
}

std::vector<collision_lab::ServedRun> ServedRuns::list(const std::string& student) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<collision_lab::ServedRun> listed;
  for (const auto& run : runs_) {
    if (student.empty() || run.accepted.student == student) listed.push_back(run);
  }
  return listed;
}

}  // namespace collision_lab_ros
