#include "collision_lab/ros/scenario_publisher.h"

#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <ros/ros.h>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/RunScene.h"
#include "collision_lab/io/scenario_file.h"

namespace collision_lab_ros {
namespace {

std::vector<std::string> splitNames(const std::string& text) {
  std::vector<std::string> names;
  std::string name;
  std::istringstream in(text);
  while (in >> name) {
    std::istringstream parts(name);
    std::string part;
    while (std::getline(parts, part, ',')) {
      if (!part.empty()) names.push_back(part);
    }
  }
  return names;
}

std::string utcStamp() {
  char buffer[32];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);  // not std::gmtime's shared buffer
  std::strftime(buffer, sizeof buffer, "%Y%m%dT%H%M%SZ", &utc);
  return buffer;
}

using Row = RunSceneClient::Row;

Row row(const std::string& scene, const collision_lab::RunScene::Response& response) {
  char buffer[1024];
  if (!response.ok) {
    std::snprintf(buffer, sizeof buffer, "%-20s FAILED: %s", scene.c_str(), response.message.c_str());
    return {buffer, true};
  }
  const auto& s = response.summary;
  const std::string collisions = std::to_string(s.collision_count) + (s.collapsed ? "+c" : "") +
                                 (s.cancelled ? " (cancelled)" : s.truncated ? "*" : "") +
                                 (s.simulated ? "" : " (n/s)");
  // Infinitely many: bodies between two walls (a ball or a box), a ring of ghosts, or a
  // predicted collapse.
  const std::string predicted = s.predicted_collision_count_defined ? std::to_string(s.predicted_collision_count)
                                : s.infinite_collisions              ? "inf"
                                                                     : "-";
  const std::string paper =
      s.paper_predicted_collision_count_defined ? std::to_string(s.paper_predicted_collision_count) : "-";
  const std::string bag = s.bag_path.empty()     ? std::string("(not recorded)")
                          : s.recording_ok        ? s.bag_path
                                                  : "FAILED: " + s.recording_error;
  std::snprintf(buffer, sizeof buffer, "%-20s %5u %-20s %14s %10s %8s %10.2e %10.3g  %s", scene.c_str(),
                s.body_count, s.model_name.c_str(), collisions.c_str(), predicted.c_str(), paper.c_str(),
                s.max_prediction_error, s.energy_lost, bag.c_str());
  return {buffer, !s.bag_path.empty() && !s.recording_ok};
}

/// True when our parent process is roslaunch (its command line names it).
bool startedByRoslaunch() {
  std::ifstream cmdline("/proc/" + std::to_string(getppid()) + "/cmdline");
  const std::string text((std::istreambuf_iterator<char>(cmdline)), std::istreambuf_iterator<char>());
  return text.find("roslaunch") != std::string::npos;
}

void printTable(const std::vector<Row>& rows) {
  std::ostringstream table;
  char header[256];
  std::snprintf(header, sizeof header, "%-20s %5s %-20s %14s %10s %8s %10s %10s  %s", "scene", "N", "model",
                "collisions", "predicted", "paper", "error", "heat [J]", "bag");
  table << "\n" << header << "\n" << std::string(130, '-') << "\n";
  for (const auto& r : rows) table << r.text << "\n";
  table << "(* truncated at the collision cap; +c: then an inelastic collapse; n/s: not simulated; inf: infinitely "
           "many; -: no formula;\n paper: eq. (3.22); error: the simulation against the closed form (RunSummary."
           "max_prediction_error; nan: no closed form); heat: kinetic energy lost)\n";
  std::cout << table.str() << std::flush;
}

}  // namespace

void sleepFor(double seconds) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < end) ros::WallDuration(0.05).sleep();
}

bool endLaunch() {
  if (!startedByRoslaunch()) {
    ROS_WARN("~end_launch_when_done: not started by roslaunch; just exiting");
    return false;
  }
  kill(getppid(), SIGINT);
  sleepFor(30.0);  // roslaunch stops us within its own ~15 s kill timeout
  return true;
}

std::vector<collision_lab::io::SceneEntry> selectScenes(const std::string& file, const std::string& selection) {
  const auto all = collision_lab::io::loadScenes(file);
  const auto names = splitNames(selection);
  if (names.empty()) return all;
  std::vector<collision_lab::io::SceneEntry> scenes;
  for (const auto& name : names) scenes.push_back(collision_lab::io::findScene(all, name));
  return scenes;
}

std::optional<ScenarioPublisherOptions> ScenarioPublisherOptions::load(const ros::NodeHandle& private_nh) {
  ScenarioPublisherOptions o;
  if (!private_nh.getParam("scenario_file", o.scenario_file)) {
    ROS_FATAL("~scenario_file is not set");
    return std::nullopt;
  }
  int mode = 0;
  private_nh.param("scenarios", o.selection, std::string());
  private_nh.param("mode", mode, 0);
  private_nh.param("run_id_suffix", o.suffix, utcStamp());
  private_nh.param("service", o.service, std::string("collision_lab_node/run_scene"));
  private_nh.param("wait_timeout", o.wait_timeout, 60.0);
  private_nh.param("dwell", o.dwell, 0.0);
  private_nh.param("exit_when_done", o.exit_when_done, true);
  private_nh.param("end_launch_when_done", o.end_launch_when_done, false);
  if (mode < collision_lab::InitialConditions::MODE_FULL ||
      mode > collision_lab::InitialConditions::MODE_SUMMARY_ONLY) {
    ROS_FATAL_STREAM("~mode = " << mode << " is not one of InitialConditions.MODE_* (0, 1, 2)");
    return std::nullopt;
  }
  o.mode = static_cast<std::uint8_t>(mode);
  return o;
}

RunSceneClient::RunSceneClient(std::string service, std::uint8_t mode, std::string suffix)
    : service_(std::move(service)), mode_(mode), suffix_(std::move(suffix)) {}

bool RunSceneClient::connect(double timeout) const {
  ROS_INFO_STREAM("waiting up to " << timeout << " s for " << service_);
  if (ros::service::waitForService(service_, ros::Duration(timeout))) return true;
  if (ros::ok()) {
    ROS_FATAL_STREAM("no service " << service_ << " after " << timeout
                     << " s: is collision_lab_node running (rosnode list, rosservice list)?");
  }
  return false;
}

void RunSceneClient::send(const collision_lab::io::SceneEntry& scene) {
  collision_lab::RunScene call;
  call.request.run_id = scene.name + "_" + suffix_;
  call.request.mode = mode_;
  call.request.masses = scene.scene.masses;
  call.request.positions = scene.scene.positions;
  call.request.velocities = scene.scene.velocities;
  call.request.restitution = scene.scene.restitution;
  call.request.max_collisions = scene.max_collisions;
  ROS_INFO_STREAM("running " << scene.name << " (" << scene.scene.size() << " bodies: " << scene.description
                  << ") as run " << call.request.run_id);
  if (!ros::service::call(service_, call)) {
    call.response.ok = false;
    call.response.message = "the call to " + service_ + " failed (did collision_lab_node die?)";
  }
  rows_.push_back(row(scene.name, call.response));
  failed_ += rows_.back().failed;
  if (bag_directory_.empty() && !call.response.summary.bag_path.empty()) {
    bag_directory_ = std::filesystem::path(call.response.summary.bag_path).parent_path().string();
  }
}

bool RunSceneClient::finish(std::size_t expected) const {
  printTable(rows_);
  const bool complete = rows_.size() == expected;
  if (failed_ > 0 || !complete) {
    std::cout << "demo FAILED: " << failed_ << " of " << rows_.size() << " runs failed"
              << (complete ? "" : ", the demo was cut short") << " (see the table above)"
              << std::endl;
    return false;
  }
  std::cout << "demo finished: " << rows_.size() << " runs, bags in "
            << (bag_directory_.empty() ? std::string("(not recorded)") : bag_directory_)
            << std::endl;
  return true;
}

}  // namespace collision_lab_ros
