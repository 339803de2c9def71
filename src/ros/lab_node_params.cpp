#include "collision_lab/ros/lab_node_params.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <ros/package.h>
#include <ros/this_node.h>

#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_recorder.h"

namespace collision_lab_ros {
namespace {

/// $ROS_HOME/collision_lab/runs followed by the node's namespace, so that labs in other
/// namespaces never share a folder by default: /collision_lab -> .../runs/collision_lab,
/// /lab2 -> .../runs/lab2, /a/b -> .../runs/a/b, / -> .../runs.
std::string defaultBagDirectory() {
  const char* ros_home = std::getenv("ROS_HOME");
  const std::string base = ros_home && *ros_home ? ros_home : expandUser("~/.ros");
  const std::string& ns = ros::this_node::getNamespace();
  return base + "/" + kDefaultBagSubdirectory + (ns == "/" ? std::string() : ns);
}

/// The count parameter `name`, or fallback when it is not set. Throws std::invalid_argument
/// when it is set to anything but a whole number in countParameter's range.
std::uint64_t getUint64(const ros::NodeHandle& nh, const std::string& name,
                        std::uint64_t fallback) {
  // XmlRpc integers are 32-bit; large values come as doubles. Read as they are: the typed
  // getParam rounds a double to int (2.5 -> 3, 1e30 -> undefined).
  XmlRpc::XmlRpcValue param;
  if (!nh.getParam(name, param)) return fallback;
  double value = 0.0;
  if (param.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    value = static_cast<int>(param);
  } else if (param.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    value = static_cast<double>(param);
  } else {
    throw std::invalid_argument("~" + name + " is not a number; " + kCountParameterRange);
  }
  const CountParameter count = countParameter(name, value);
  if (!count.error.empty()) throw std::invalid_argument(count.error);
  return count.value;
}

}  // namespace

CountParameter countParameter(const std::string& name, double value) {
  // 2^64, exactly: every double below it converts to std::uint64_t without overflow.
  constexpr double kTwoTo64 = 18446744073709551616.0;
  if (value >= 0 && value < kTwoTo64 && value == std::floor(value)) return {static_cast<std::uint64_t>(value), {}};
  std::ostringstream error;
  error << "~" << name << " = " << value << " is out of range; " << kCountParameterRange;
  return {0, error.str()};
}

LabNodeParams LabNodeParams::load(const ros::NodeHandle& private_nh) {
  LabNodeParams params;
  private_nh.param("record", params.record, true);
  private_nh.param("bag_directory", params.bag_directory, defaultBagDirectory());
  params.bag_directory = expandUser(params.bag_directory);
  params.max_collisions = getUint64(private_nh, "max_collisions", kDefaultMaxCollisions);
  private_nh.param("simulate_to_cap", params.simulate_to_cap, false);
  params.max_published_events =
      getUint64(private_nh, "max_published_events", kDefaultMaxPublishedEvents);
  private_nh.param("progress_period", params.progress_period, kDefaultProgressPeriod);
  if (!std::isfinite(params.progress_period) || params.progress_period <= 0) {
    std::ostringstream error;
    error << "~progress_period = " << params.progress_period << " is out of range; expected a finite number of "
          << "seconds > 0";
    throw std::invalid_argument(error.str());
  }
  params.progress_every_events = getUint64(private_nh, "progress_every_events", 0);
  private_nh.param("publish_markers", params.publish_markers, true);
  private_nh.param("log_runs", params.log_runs, true);
  params.max_bodies = getUint64(private_nh, "max_bodies", kDefaultMaxBodies);
  private_nh.param("min_free_space_mb", params.min_free_space_mb, kDefaultMinFreeSpaceMb);
  private_nh.param("max_student_bag_mb", params.max_student_bag_mb, 0.0);
  private_nh.param("scenario_file", params.scenario_file,
                   ros::package::getPath("collision_lab") + "/" + kDefaultScenarioFile);
  params.scenario_file = expandUser(params.scenario_file);
  const std::uint64_t hardware_threads = std::thread::hardware_concurrency();
  params.workers = getUint64(private_nh, "workers", std::max(kMinDefaultWorkers, hardware_threads));
  params.short_lane_workers = getUint64(private_nh, "short_lane_workers", kDefaultShortLaneWorkers);
  if (params.workers == 0 || params.workers > kMaxWorkers) {
    throw std::invalid_argument("~workers = " + std::to_string(params.workers) + " is out of range; expected 1 to " +
                                std::to_string(kMaxWorkers));
  }
  if (params.short_lane_workers >= params.workers) {
    throw std::invalid_argument("~short_lane_workers = " + std::to_string(params.short_lane_workers) +
                                " must be below ~workers = " + std::to_string(params.workers) +
                                ": at least one worker takes long runs");
  }
  params.lanes.short_max_collisions = getUint64(private_nh, "short_max_collisions", kDefaultShortMaxCollisions);
  private_nh.param("short_max_seconds", params.lanes.short_max_seconds, kDefaultShortMaxSeconds);
  private_nh.param("max_run_seconds", params.max_run_seconds, kDefaultMaxRunSeconds);
  if (!std::isfinite(params.max_run_seconds) || params.max_run_seconds < 0) {
    std::ostringstream error;
    error << "~max_run_seconds = " << params.max_run_seconds << " is out of range; expected a finite number of "
          << "seconds >= 0 (0: no time limit)";
    throw std::invalid_argument(error.str());
  }
  params.max_bag_bytes = getUint64(private_nh, "max_bag_bytes", kDefaultMaxBagBytes);
  private_nh.param("fail_runs_of_student", params.fail_runs_of_student, std::string());
  return params;
}

}  // namespace collision_lab_ros
