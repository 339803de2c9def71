// The headless demo runs to the end and ends cleanly, or, when a run fails, says so
// visibly; its bags carry the simulated timeline; replaying the newest bag (bag:=latest)
// at rate 4 regenerates the markers (demo_test.test). Every wait has a timeout.
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <rosgraph_msgs/Clock.h>
#include <visualization_msgs/MarkerArray.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/RunSummary.h"

namespace {

namespace fs = std::filesystem;

/// Guards against hangs, not a performance limit: the demo of three presets takes ~10 s.
constexpr double kTimeout = 180.0;  ///< [s] wall time

/// A fresh directory, removed at the end of the test.
struct TempDir {
  TempDir() {
    char pattern[] = "/tmp/collision_lab_demo_XXXXXX";
    if (mkdtemp(pattern)) path = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string path;
};

/// Starts a command in its own process, stdout and stderr to log; returns its pid.
pid_t spawn(const std::vector<std::string>& args, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (!freopen(log.c_str(), "w", stdout) || dup2(fileno(stdout), STDERR_FILENO) < 0) _exit(126);
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

/// The exit code of pid, or -1 (and a failure) when it has not ended after kTimeout (it
/// is then stopped with SIGINT).
int waitExit(pid_t pid, const std::string& what) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kTimeout);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (ros::WallTime::now() > end) {
      ADD_FAILURE() << what << " did not end within " << kTimeout << " s";
      kill(pid, SIGINT);
      waitpid(pid, &status, 0);
      return -1;
    }
    ros::WallDuration(0.1).sleep();
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// pi_digits_3 last, so that its bag is the newest (bag:=latest).
const std::vector<std::string> kScenes = {"equal_masses", "moving_wall", "pi_digits_3"};

TEST(Demo, HeadlessDemoEndsCleanlyAndReplayOfTheLatestBagDrawsMarkers) {
  TempDir bags;
  ASSERT_FALSE(bags.path.empty());
  const std::string log = bags.path + ".log";  // beside the folder: it holds bags only
  const pid_t demo = spawn({"roslaunch", "collision_lab", "demo.launch", "rviz:=false",
                            "bag_directory:=" + bags.path,
                            "scenarios:=" + kScenes[0] + "," + kScenes[1] + "," + kScenes[2]},
                           log);
  ASSERT_GT(demo, 0);
  EXPECT_EQ(waitExit(demo, "the headless demo"), 0);
  const std::string output = readFile(log);
  fs::remove(log);
  // A clean ending: the final plain line, and no red REQUIRED message.
  EXPECT_NE(output.find("demo finished: 3 runs, bags in " + bags.path), std::string::npos) << output;
  EXPECT_EQ(output.find("REQUIRED process"), std::string::npos) << output;
  EXPECT_EQ(output.find("FAILED"), std::string::npos) << output;

  // One readable bag per preset, each with its summary, on its simulated timeline.
  std::map<std::string, std::string> bag_of_scene;
  for (const auto& entry : fs::directory_iterator(bags.path)) {
    const std::string name = entry.path().filename().string();
    ASSERT_EQ(entry.path().extension(), ".bag") << name;
    for (const auto& scene : kScenes) {
      if (name.rfind(scene + "_", 0) == 0) bag_of_scene[scene] = entry.path().string();
    }
  }
  ASSERT_EQ(bag_of_scene.size(), kScenes.size());
  std::uint64_t pi_collisions = 0;
  for (const auto& [scene, path] : bag_of_scene) {
    rosbag::Bag bag(path, rosbag::bagmode::Read);
    rosbag::View view(bag, rosbag::TopicQuery("/collision_lab/run_summaries"));
    ASSERT_EQ(view.size(), 1u) << path;
    const auto summary = view.begin()->instantiate<collision_lab::RunSummary>();
    ASSERT_TRUE(summary);
    EXPECT_TRUE(summary->recording_ok);
    EXPECT_EQ(summary->collision_count, summary->predicted_collision_count) << scene;
    if (scene != "pi_digits_3") continue;
    pi_collisions = summary->collision_count;
    rosbag::View events(bag, rosbag::TopicQuery("/collision_lab/collision_events"));
    double last_time = 0.0;
    for (const auto& m : events) last_time = m.instantiate<collision_lab::CollisionEvent>()->time;
    rosbag::View all(bag);
    EXPECT_NEAR((all.getEndTime() - all.getBeginTime()).toSec(), last_time, 1e-9);
    EXPECT_GT(last_time, 1.0);  // rosbag info shows the run's duration, not 0.0 s
  }
  EXPECT_EQ(pi_collisions, 314u);

  // Replay of the newest bag: the marker node redraws the run from the bag alone, on a
  // clock that follows the run's timeline.
  bool title_seen = false, full_plot_seen = false;
  ros::Time last_clock;
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe<visualization_msgs::MarkerArray>(
      "/collision_lab/markers", 100, [&](const visualization_msgs::MarkerArray::ConstPtr& array) {
        for (const auto& m : array->markers) {
          if (m.ns == "title" && m.text.find("pi_digits_3") != std::string::npos &&
              m.text.find("simulated 314") != std::string::npos) {
            title_seen = true;
          }
          // The index axis of the velocity plot ends at the last collision drawn.
          if (m.ns == "plot" && m.type == visualization_msgs::Marker::TEXT_VIEW_FACING && m.text == "314") {
            full_plot_seen = true;
          }
        }
      });
  ros::Subscriber clock_sub = nh.subscribe<rosgraph_msgs::Clock>(
      "/clock", 10, [&](const rosgraph_msgs::Clock::ConstPtr& c) { last_clock = c->clock; });
  const std::string replay_log = log + ".replay";
  const pid_t replay = spawn({"roslaunch", "collision_lab", "replay.launch", "rviz:=false",
                              "bag:=latest", "bag_directory:=" + bags.path, "rate:=4"},
                             replay_log);
  ASSERT_GT(replay, 0);
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(kTimeout);
  while (ros::ok() && !(title_seen && full_plot_seen) && ros::WallTime::now() < end) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  }
  kill(replay, SIGINT);
  waitExit(replay, "the replay");
  const std::string replay_output = readFile(replay_log);
  fs::remove(replay_log);
  EXPECT_TRUE(title_seen) << replay_output;
  EXPECT_TRUE(full_plot_seen) << replay_output;
  EXPECT_NE(replay_output.find("replaying " + bag_of_scene.at("pi_digits_3")), std::string::npos)
      << replay_output;
  // The replayed clock reached the run's last collision, 7.9 bag seconds after its start.
  rosbag::Bag bag(bag_of_scene.at("pi_digits_3"), rosbag::bagmode::Read);
  rosbag::View all(bag);
  EXPECT_GE(last_clock, all.getEndTime() - ros::Duration(0.1));
}

TEST(Demo, AFailedRunIsVisibleAtTheEnd) {
  TempDir dir;
  ASSERT_FALSE(dir.path.empty());
  const std::string scenes = dir.path + "/scenes.yaml";
  std::ofstream(scenes) << "good:\n  description: \"fine\"\n  masses: [1, 1, 1]\n"
                           "  positions: [2, 1, -1]\n  velocities: [-1, 0, 1]\n"
                           "bad_order:\n  description: \"positions not ordered\"\n"
                           "  masses: [1, 1, 1]\n  positions: [0, 1, 2]\n  velocities: [-1, 0, 0]\n";
  const std::string log = dir.path + "/demo.log";
  const pid_t demo = spawn({"roslaunch", "collision_lab", "demo.launch", "rviz:=false",
                            "bag_directory:=" + dir.path + "/bags", "scenario_file:=" + scenes},
                           log);
  ASSERT_GT(demo, 0);
  waitExit(demo, "the failing demo");
  const std::string output = readFile(log);
  EXPECT_NE(output.find("demo FAILED: 1 of 2 runs failed"), std::string::npos) << output;
  EXPECT_NE(output.find("POSITIONS_NOT_ORDERED"), std::string::npos) << output;
  EXPECT_NE(output.find("REQUIRED process [collision_lab/scenario_publisher"), std::string::npos)
      << output;
  EXPECT_EQ(output.find("demo finished"), std::string::npos) << output;
}

TEST(Demo, ReplayOfAMissingBagSaysWhy) {
  TempDir empty;
  const std::string log = empty.path + "/play_run.log";
  const std::string command = std::string(COLLISION_LAB_SOURCE_DIR "/scripts/play_run latest ") +
                              empty.path + " > " + log + " 2>&1";
  EXPECT_NE(std::system(command.c_str()), 0);
  EXPECT_NE(readFile(log).find("found no finished bag (*.bag) in " + empty.path), std::string::npos)
      << readFile(log);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "demo_test");
  return RUN_ALL_TESTS();
}
