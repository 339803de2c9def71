// The scenario publisher's parts (tools library): its parameters, the client of
// collision_lab_node's ~run_scene service that serves scenes one at a time and keeps the
// table of outcomes, and the scene selection. The executable is src/ros/scenario_publisher_main.cpp,
// whose top comment lists the parameters.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <ros/node_handle.h>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/io/scenario_file.h"

namespace collision_lab_ros {

/// The publisher's private parameters (scenario_publisher_main.cpp).
struct ScenarioPublisherOptions {
  std::string scenario_file, selection, suffix, service;
  std::uint8_t mode = collision_lab::InitialConditions::MODE_FULL;
  double wait_timeout = 60.0;  ///< [s]
  double dwell = 0.0;          ///< [s]
  bool exit_when_done = true, end_launch_when_done = false;

  /// Empty with a ROS_FATAL when ~scenario_file is missing or ~mode is not a MODE_*.
  static std::optional<ScenarioPublisherOptions> load(const ros::NodeHandle& private_nh);
};

/// The scenes of file named in selection (separated by spaces or commas; empty: all), in
/// that order. Throws io::ScenarioFileError.
std::vector<collision_lab::io::SceneEntry> selectScenes(const std::string& file, const std::string& selection);

/// Sleeps seconds of wall time, or less when ROS shuts down.
void sleepFor(double seconds);

/// Asks the roslaunch that started us to shut down, as Ctrl-C does; roslaunch then stops
/// every node (us too) and ends with plain lines. Returns false when not started by roslaunch.
bool endLaunch();

/// A client of collision_lab_node's ~run_scene service: waits for it, sends scenes one at
/// a time, and keeps the table of their outcomes.
class RunSceneClient {
 public:
  RunSceneClient(std::string service, std::uint8_t mode, std::string suffix);

  /// Waits up to timeout [s] for the service; false (with a ROS_FATAL) when it is not there.
  bool connect(double timeout) const;
  /// Serves scene as run <name>_<suffix> and adds its row to the table.
  void send(const collision_lab::io::SceneEntry& scene);
  /// Prints the table and the last line; true when all of expected runs were served
  /// without failure.
  bool finish(std::size_t expected) const;

  /// A run's row in the table, and whether it failed.
  struct Row {
    std::string text;
    bool failed = false;
  };

 private:
  std::string service_;
  std::uint8_t mode_;
  std::string suffix_;
  std::vector<Row> rows_;
  std::size_t failed_ = 0;
  std::string bag_directory_;
};

}  // namespace collision_lab_ros
