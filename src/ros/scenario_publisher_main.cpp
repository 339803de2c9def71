// scenario_publisher: serves preset scenes of any size (N bodies, restitution) one at a time
// through collision_lab_node's ~run_scene service (so each is published, recorded and drawn
// like any input), prints a table, and ends with one plain line: "demo finished: N runs,
// bags in DIR", or "demo FAILED: ..." naming the failed runs. It reads the scenario files
// the CLI reads (collision_lab/io/scenario_file.h).
//
// Private parameters:
//   ~scenario_file (string, required)  YAML file of named scenes (config/scenarios.yaml)
//   ~scenarios (string, default "")    names to run, separated by spaces or commas; empty: all
//   ~mode (int, default 0)             InitialConditions.MODE_* for every run
//   ~run_id_suffix (string, default: UTC start time)  run_id = <scene name>_<suffix>
//   ~service (string, default "collision_lab_node/run_scene")  the node's service
//   ~wait_timeout (double, default 60) [s]  how long to wait for that service to appear
//   ~dwell (double, default 0) [s]     wall time each run stays on screen before the next
//   ~exit_when_done (bool, default true)  exit after the last run; false: stay until shut down
//   ~end_launch_when_done (bool, default false)  after a demo without failures, shut down the
//       roslaunch that started this node as Ctrl-C does (SIGINT), so that a headless demo
//       ends cleanly; after a failure, exit 1 instead, which roslaunch reports in red for a
//       required node.
#include <optional>
#include <vector>

#include <ros/ros.h>

#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/scenario_publisher.h"

using namespace collision_lab_ros;

int main(int argc, char** argv) {
  ros::init(argc, argv, "scenario_publisher");
  ros::NodeHandle nh, private_nh("~");
  const std::optional<ScenarioPublisherOptions> options = ScenarioPublisherOptions::load(private_nh);
  if (!options) return 1;
  std::vector<collision_lab::io::SceneEntry> scenes;
  try {
    scenes = selectScenes(options->scenario_file, options->selection);
  } catch (const collision_lab::io::ScenarioFileError& e) {
    ROS_FATAL_STREAM(e.what());
    return 1;
  }
  RunSceneClient client(nh.resolveName(options->service), options->mode, options->suffix);
  if (!client.connect(options->wait_timeout)) return 1;
  for (std::size_t i = 0; i < scenes.size() && ros::ok(); ++i) {
    client.send(scenes[i]);
    if (options->dwell > 0 && i + 1 < scenes.size()) {
      ROS_INFO_STREAM("showing " << scenes[i].name << " for " << options->dwell << " s");
      sleepFor(options->dwell);
    }
  }
  if (!client.finish(scenes.size())) return 1;
  if (options->end_launch_when_done && endLaunch()) return 0;
  if (!options->exit_when_done) ros::waitForShutdown();
  return 0;
}
