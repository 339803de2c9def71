// What the lab node keeps of its recent runs: their list (for ~list_runs without the run
// index) and the recent durations of their recording hand-over (for /diagnostics).
#pragma once

#include <cstddef>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ServedRun.h"

namespace collision_lab_ros {

/// The runs a node accepted, the newest kServedRunsKept of them: ~list_runs's answer when
/// the run index cannot be opened.
/// Thread-safe: the worker adds each run as it accepts it, and whichever thread publishes
/// a run's summary completes it.
class ServedRuns {
 public:
  void accepted(const collision_lab::AcceptedRun& run);
  void finished(const collision_lab::RunSummary& summary);
  /// Oldest first; those of student, or every run when student is empty.
  std::vector<collision_lab::ServedRun> list(const std::string& student) const;

 private:
  mutable std::mutex mutex_;
  std::deque<collision_lab::ServedRun> runs_;
};

/// The newest kRecordingTimeWindow samples of a duration [s], thread-safe.
class RecentDurations {
 public:
  void add(double seconds);
  /// The q-quantile (q in [0, 1]) of the kept samples [s]; 0 when there are none.
  double quantile(double q) const;
  std::size_t size() const;

 private:
  mutable std::mutex mutex_;
  std::vector<double> samples_;
  std::size_t next_ = 0;
};

}  // namespace collision_lab_ros
