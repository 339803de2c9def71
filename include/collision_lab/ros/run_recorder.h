// One bag per run, written with the rosbag C++ API.
//
// The bag is written as <directory>/<run_id>.bag.active and renamed to <run_id>.bag when
// it is closed, so a finished run's bag is always complete, and the bag of a run cut
// short by a crash is left as .bag.active (recoverable with `rosbag reindex`).
// Recording never throws: a failure is kept in error() and later writes are skipped.
//
// RunBagWriter writes those bags on a thread of its own, so that a run's publisher only
// hands its messages over (see its contract below).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <ros/time.h>
#include <rosbag/bag.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/RunSummary.h"

namespace collision_lab_ros {

/// <directory>/<run_id>.bag
std::string bagPath(const std::string& directory, const std::string& run_id);

/// True when a bag (finished or in progress) for run_id exists in directory.
bool bagExists(const std::string& directory, const std::string& run_id);

/// Expands a leading "~" to $HOME.
std::string expandUser(const std::string& path);

class RunRecorder {
 public:
  /// Creates directory if needed and opens the run's bag (LZ4-compressed).
  RunRecorder(const std::string& directory, const std::string& run_id);
  /// The same in reused, a closed Bag that outlives this recorder: constructing a
  /// rosbag::Bag loads its encryption plugin (milliseconds), reopening one does not.
  RunRecorder(const std::string& directory, const std::string& run_id, rosbag::Bag& reused);
  ~RunRecorder();
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  /// Writes msg on topic at stamp (which must be >= ros::TIME_MIN).
  template <class Message>
  void write(const std::string& topic, const ros::Time& stamp, const Message& msg) {
    if (!ok()) return;
    try {
      bag_->write(topic, stamp, msg);
    } catch (const std::exception& e) {
      fail(std::string("writing ") + topic + " failed: " + e.what());
    }
  }

  /// Closes the bag and gives it its final name. Returns ok().
  bool close();

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  /// Marks the recording failed, keeping the first error: later writes are skipped and
  /// close() keeps the .active name.
  void fail(const std::string& what);
  /// The final path <directory>/<run_id>.bag.
  const std::string& path() const { return path_; }

 private:
  void open(const std::string& directory);

  std::string path_;
  std::string active_path_;
  std::string error_;
  std::unique_ptr<rosbag::Bag> owned_;  ///< null when the bag is reused
  rosbag::Bag* bag_ = nullptr;          ///< the open bag; null once closed or failed
};

/// A part of one run's bag, in recording order: the input, the prediction, the events,
/// then the summary. Each message is written at its header.stamp.
struct RunBagBatch {
  std::string run_id;
  bool opens = false;  ///< the run's first batch: its bag is opened first
  std::optional<collision_lab::InitialConditions> input;
  std::optional<collision_lab::Prediction> prediction;
  std::vector<collision_lab::CollisionEvent> events;
  /// The run's last batch: its summary is written with bag_path, recording_ok and
  /// recording_error as they stand before closing, then the bag is closed, and on_closed
  /// gets the summary with the recording fields as they stand after closing.
  std::optional<collision_lab::RunSummary> summary;
  std::function<void(collision_lab::RunSummary&)> on_closed;

  std::size_t messages() const { return input.has_value() + prediction.has_value() + events.size() + summary.has_value(); }
};

/// Writes per-run bags (RunRecorder) on its own thread.
/// Contract: batches are written in the order handed over, one run at a time (a run's
/// batches are contiguous). push() blocks while more than max_queued_messages messages
/// wait (backpressure: nothing is ever dropped). The destructor writes everything handed
/// over and closes every bag, calling each on_closed, before it returns. on_closed runs
/// on the writer's thread. An exception while writing a batch (on_closed's included) is
/// logged (ROS_ERROR) and ends only that run's recording: its bag stays .bag.active, its
/// on_closed, if not yet called, gets recording_ok false and recording_error saying so,
/// and the writer serves the next runs.
class RunBagWriter {
 public:
  struct Topics {
    std::string inputs, predictions, events, summaries;
  };
  RunBagWriter(std::string directory, Topics topics, std::size_t max_queued_messages);
  ~RunBagWriter();
  RunBagWriter(const RunBagWriter&) = delete;
  RunBagWriter& operator=(const RunBagWriter&) = delete;

  void push(RunBagBatch batch);

 private:
  void loop();
  void write(RunBagBatch& batch);
  /// After write(batch) threw `what`: see the contract above.
  void recover(RunBagBatch& batch, const std::string& what);

  const std::string directory_;
  const Topics topics_;
  const std::size_t max_queued_;
  rosbag::Bag bag_;                       ///< the writer thread's, reopened for every run
  std::optional<RunRecorder> recorder_;  ///< the writer thread's: the run being written

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<RunBagBatch> queue_;
  std::size_t queued_messages_ = 0;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace collision_lab_ros
