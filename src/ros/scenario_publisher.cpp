// scenario_publisher: sends preset scenes to collision_lab_node one at a time, waits for
// each run's summary (or rejection), matched by run_id, and prints a table.
//
// Private parameters:
//   ~scenario_file (string, required)  YAML file of named scenes (config/scenarios.yaml)
//   ~scenarios (string, default "")    names to run, separated by spaces or commas; empty: all
//   ~mode (int, default 0)             InitialConditions.MODE_* for every run
//   ~run_id_suffix (string, default: UTC start time)  run_id = <scene name>_<suffix>
//   ~exit_when_done (bool, default true)  shut down after the last run
#include <cstdio>
#include <ctime>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/node_constants.h"

namespace {

using collision_lab_ros::core::RunMode;

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
  std::strftime(buffer, sizeof buffer, "%Y%m%dT%H%M%SZ", std::gmtime(&now));
  return buffer;
}

/// The answer to one input: its summary or its rejection.
struct Outcome {
  std::optional<collision_lab::RunSummary> summary;
  std::optional<collision_lab::Rejected> rejected;
  bool done() const { return summary || rejected; }
};

std::string row(const std::string& scene, const Outcome& outcome) {
  char buffer[512];
  if (outcome.rejected) {
    std::snprintf(buffer, sizeof buffer, "%-22s rejected: %s (%s)", scene.c_str(),
                  outcome.rejected->reason_name.c_str(), outcome.rejected->message.c_str());
    return buffer;
  }
  const auto& s = *outcome.summary;
  const std::string collisions =
      std::to_string(s.collision_count) + (s.truncated ? "*" : "") + (s.simulated ? "" : " (n/s)");
  const std::string paper =
      s.paper_prediction_defined ? std::to_string(s.paper_predicted_collision_count) : "undef.";
  const std::string bag = s.bag_path.empty()     ? std::string("(not recorded)")
                          : s.recording_ok        ? s.bag_path
                                                  : "FAILED: " + s.recording_error;
  std::snprintf(buffer, sizeof buffer, "%-22s %12s %12llu %12s %10.2e  %s", scene.c_str(),
                collisions.c_str(), static_cast<unsigned long long>(s.predicted_collision_count),
                paper.c_str(), s.max_prediction_error, bag.c_str());
  return buffer;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "scenario_publisher");
  ros::NodeHandle nh, private_nh("~");

  std::string scenario_file, selection, suffix;
  int mode = 0;
  bool exit_when_done = true;
  if (!private_nh.getParam("scenario_file", scenario_file)) {
    ROS_FATAL("~scenario_file is not set");
    return 1;
  }
  private_nh.param("scenarios", selection, std::string());
  private_nh.param("mode", mode, 0);
  private_nh.param("run_id_suffix", suffix, utcStamp());
  private_nh.param("exit_when_done", exit_when_done, true);
  const auto run_mode = collision_lab_ros::toRunMode(static_cast<std::uint8_t>(mode));
  if (mode < 0 || mode > 255 || !run_mode) {
    ROS_FATAL_STREAM("~mode = " << mode << " is not one of InitialConditions.MODE_*");
    return 1;
  }

  std::vector<collision_lab::io::NamedScene> scenes;
  try {
    const auto all = collision_lab::io::loadScenarioFile(scenario_file);
    const auto names = splitNames(selection);
    if (names.empty()) {
      scenes = all;
    } else {
      for (const auto& name : names) scenes.push_back(collision_lab::io::findScenario(all, name));
    }
  } catch (const collision_lab::io::ScenarioFileError& e) {
    ROS_FATAL_STREAM(e.what());
    return 1;
  }

  std::map<std::string, Outcome> outcomes;  // by run_id
  ros::Publisher input_pub = nh.advertise<collision_lab::InitialConditions>(
      collision_lab_ros::kInitialConditionsTopic, collision_lab_ros::kInputQueueSize);
  ros::Subscriber summary_sub = nh.subscribe<collision_lab::RunSummary>(
      collision_lab_ros::kRunSummariesTopic, collision_lab_ros::kOutputQueueSize,
      [&outcomes](const collision_lab::RunSummary::ConstPtr& m) {
        if (outcomes.count(m->run_id)) outcomes[m->run_id].summary = *m;
      });
  ros::Subscriber rejected_sub = nh.subscribe<collision_lab::Rejected>(
      collision_lab_ros::kRejectedTopic, collision_lab_ros::kOutputQueueSize,
      [&outcomes](const collision_lab::Rejected::ConstPtr& m) {
        if (outcomes.count(m->run_id)) outcomes[m->run_id].rejected = *m;
      });

  // Wait until the node listens to us and we listen to it: a message published before
  // the connection is up is lost.
  const auto spinFor = [] { ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1)); };
  ROS_INFO_STREAM("waiting for " << input_pub.getTopic() << " to be served");
  while (ros::ok() && (input_pub.getNumSubscribers() == 0 || summary_sub.getNumPublishers() == 0 ||
                       rejected_sub.getNumPublishers() == 0)) {
    spinFor();
  }

  std::vector<std::string> rows;
  for (const auto& scene : scenes) {
    if (!ros::ok()) break;
    collision_lab::InitialConditions input =
        collision_lab_ros::toInitialConditions(scene.scene, *run_mode, scene.max_collisions);
    input.header.stamp = ros::Time::now();
    input.run_id = scene.name + "_" + suffix;
    outcomes[input.run_id] = Outcome{};
    ROS_INFO_STREAM("sending " << scene.name << " (" << scene.description << ") as run "
                    << input.run_id);
    input_pub.publish(input);
    while (ros::ok() && !outcomes[input.run_id].done()) spinFor();
    if (!ros::ok()) break;
    rows.push_back(row(scene.name, outcomes[input.run_id]));
  }

  std::ostringstream table;
  char header[256];
  std::snprintf(header, sizeof header, "%-22s %12s %12s %12s %10s  %s", "scene", "collisions",
                "predicted", "paper (3.22)", "error", "bag");
  table << "\n" << header << "\n" << std::string(110, '-') << "\n";
  for (const auto& r : rows) table << r << "\n";
  table << "(* truncated at the collision cap; n/s: not simulated; error: max |S (v_sim - v_pred)| / "
           "|S v_0|, S = diag(sqrt m))\n";
  std::cout << table.str() << std::flush;

  if (!exit_when_done) ros::spin();
  return rows.size() == scenes.size() ? 0 : 1;
}
