// One bag per run, written with the rosbag C++ API.
//
// The bag is written as <directory>/<run_id>.bag.active and renamed to <run_id>.bag when
// it is closed, so a finished run's bag is always complete, and the bag of a run cut
// short by a crash is left as .bag.active (recoverable with `rosbag reindex`).
// Recording never throws: a failure is kept in error() and later writes are skipped.
#pragma once

#include <memory>
#include <string>

#include <ros/time.h>
#include <rosbag/bag.h>

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
  /// The final path <directory>/<run_id>.bag.
  const std::string& path() const { return path_; }

 private:
  void fail(const std::string& what);

  std::string path_;
  std::string active_path_;
  std::string error_;
  std::unique_ptr<rosbag::Bag> bag_;
};

}  // namespace collision_lab_ros
