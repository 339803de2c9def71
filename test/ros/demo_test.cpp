// The headless demo runs to the end and leaves one readable bag per preset; replaying
// one of those bags regenerates the markers (demo_test.test).
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <visualization_msgs/MarkerArray.h>

#include "collision_lab/RunSummary.h"

namespace {

namespace fs = std::filesystem;

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

/// Starts a command in its own process; returns its pid.
pid_t spawn(const std::vector<std::string>& args) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

int waitExit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

const std::vector<std::string> kScenes = {"equal_masses", "pi_digits_3", "moving_wall"};

TEST(Demo, HeadlessDemoRunsToTheEndAndReplayDrawsMarkers) {
  TempDir bags;
  ASSERT_FALSE(bags.path.empty());
  const pid_t demo = spawn({"roslaunch", "collision_lab", "demo.launch", "rviz:=false",
                            "bag_directory:=" + bags.path,
                            "scenarios:=" + kScenes[0] + "," + kScenes[1] + "," + kScenes[2]});
  ASSERT_GT(demo, 0);
  EXPECT_EQ(waitExit(demo), 0);

  // One readable bag per preset, each with its summary.
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
    if (scene == "pi_digits_3") pi_collisions = summary->collision_count;
  }
  EXPECT_EQ(pi_collisions, 314u);

  // Replay: the marker node redraws the run from the bag alone.
  bool title_seen = false, full_plot_seen = false;
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
  const pid_t replay = spawn({"roslaunch", "collision_lab", "replay.launch", "rviz:=false",
                              "bag:=" + bag_of_scene.at("pi_digits_3")});
  ASSERT_GT(replay, 0);
  while (ros::ok() && !(title_seen && full_plot_seen)) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  }
  kill(replay, SIGINT);
  waitExit(replay);
  EXPECT_TRUE(title_seen);
  EXPECT_TRUE(full_plot_seen);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "demo_test");
  return RUN_ALL_TESTS();
}
