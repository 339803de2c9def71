// The headless demo runs to the end and ends cleanly, or, when a run fails, says so
// visibly; its bags carry the simulated timeline; replaying the newest bag (bag:=latest)
// at rate 4 regenerates the markers; the N-body presets give bags whose summaries match
// hand-derived physics, and bag_to_csv rebuilds a 100-body run's final state
// (demo_test.test). Every wait has a timeout.
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
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
#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/bag_csv.h"

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

/// Whether a node of that name is registered with the master.
bool nodeIsUp(const std::string& name) {
  std::vector<std::string> nodes;
  return ros::master::getNodes(nodes) && std::find(nodes.begin(), nodes.end(), name) != nodes.end();
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
    if (name.rfind("runs.sqlite", 0) == 0) continue;  // the run index and its WAL files
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
  while (ros::ok() && !(title_seen && full_plot_seen && nodeIsUp("/sim_time_guard")) &&
         ros::WallTime::now() < end) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  }
  bool sim_time = false;
  EXPECT_TRUE(ros::param::get("/use_sim_time", sim_time) && sim_time);
  kill(replay, SIGINT);
  waitExit(replay, "the replay");
  // The replay leaves the master as it found it: without simulated time.
  EXPECT_FALSE(ros::param::has("/use_sim_time"));
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

/// The bags of a finished demo, by preset name (<preset>_<suffix>.bag).
std::map<std::string, std::string> bagsOfScenes(const std::string& dir, const std::vector<std::string>& scenes) {
  std::map<std::string, std::string> bags;
  for (const auto& entry : fs::directory_iterator(dir)) {
    for (const auto& scene : scenes) {
      if (entry.path().filename().string().rfind(scene + "_", 0) == 0) bags[scene] = entry.path().string();
    }
  }
  return bags;
}

collision_lab::RunSummary summaryOf(const std::string& bag_path) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery("/collision_lab/run_summaries"));
  EXPECT_EQ(view.size(), 1u) << bag_path;
  const auto summary = view.size() ? view.begin()->instantiate<collision_lab::RunSummary>() : nullptr;
  EXPECT_TRUE(summary) << bag_path;
  return summary ? *summary : collision_lab::RunSummary();
}

/// The velocity of every body after the last row of bodies.csv that has it [m/s].
std::vector<double> lastVelocities(const std::string& bodies_csv, std::size_t n) {
  std::vector<double> v(n, std::nan(""));
  std::ifstream in(bodies_csv);
  std::string line;
  std::getline(in, line);  // run_id,index,time_s,body,body_name,moved,mass_kg,x_m,v_before_m_s,v_m_s,...
  while (std::getline(in, line)) {
    std::vector<std::string> cells(1);
    for (char c : line) {
      if (c == ',') {
        cells.emplace_back();
      } else {
        cells.back().push_back(c);
      }
    }
    v.at(std::stoul(cells.at(3))) = std::stod(cells.at(9));
  }
  return v;
}

// Needs the N-body node (branch `node`): until it lands the node rejects these presets.
// Expected values by hand (docs/physics.md): two 1 kg carts at -1 and +1 m/s with e = 0.8
// part at +0.8 and -0.8 m/s, heat (1 - 0.64) * 0.5 kg * (2 m/s)^2 / 2 = 0.36 J; the cradle
// gives 4 impacts and leaves (0, 0, 0, 0, -1) m/s; three equal masses with e = 0.05 collapse
// and move on at -1/3 m/s, heat 1/2 - 3/18 = 1/3 J; 100 equal masses (elastic) end with
// their initial velocities sorted, the fastest rightward on the right (body 0), after as
// many impacts as inversions, 2441.
TEST(Demo, NBodyPresetsLeaveBagsWithTheirExactSummaries) {
  TempDir bags;
  ASSERT_FALSE(bags.path.empty());
  const std::vector<std::string> scenes = {"two_carts_inelastic", "cradle_5", "collapse_equal", "equal_masses_100"};
  const std::string log = bags.path + ".log";
  const pid_t demo = spawn({"roslaunch", "collision_lab", "demo.launch", "rviz:=false", "bag_directory:=" + bags.path,
                            "scenarios:=two_carts_inelastic,cradle_5,collapse_equal,equal_masses_100"},
                           log);
  ASSERT_GT(demo, 0);
  EXPECT_EQ(waitExit(demo, "the N-body demo"), 0);
  const std::string output = readFile(log);
  fs::remove(log);
  EXPECT_NE(output.find("demo finished: 4 runs, bags in " + bags.path), std::string::npos) << output;
  const auto bag_of = bagsOfScenes(bags.path, scenes);
  ASSERT_EQ(bag_of.size(), scenes.size()) << output;

  const auto carts = summaryOf(bag_of.at("two_carts_inelastic"));
  EXPECT_EQ(carts.body_count, 2u);
  EXPECT_EQ(carts.collision_count, 1u);
  EXPECT_NEAR(carts.energy_lost, 0.36, 1e-15);
  ASSERT_EQ(carts.final_velocities.size(), 2u);
  EXPECT_NEAR(carts.final_velocities[0], 0.8, 1e-15);
  EXPECT_NEAR(carts.final_velocities[1], -0.8, 1e-15);

  const auto cradle = summaryOf(bag_of.at("cradle_5"));
  EXPECT_EQ(cradle.collision_count, 4u);
  EXPECT_EQ(cradle.final_velocities, (std::vector<double>{0, 0, 0, 0, -1}));
  EXPECT_EQ(cradle.energy_lost, 0.0);

  const auto collapse = summaryOf(bag_of.at("collapse_equal"));
  EXPECT_TRUE(collapse.collapsed);
  EXPECT_GE(collapse.collapse_count, 1u);
  EXPECT_NEAR(collapse.energy_lost, 1.0 / 3.0, 1e-12);
  ASSERT_EQ(collapse.final_velocities.size(), 3u);
  for (double v : collapse.final_velocities) EXPECT_NEAR(v, -1.0 / 3.0, 1e-12);

  // 100 bodies: the events carry the pair fields only (more than FULL_STATE_MAX_BODIES);
  // bag_to_csv rebuilds the final state from them and the input.
  const std::string gas_bag = bag_of.at("equal_masses_100");
  const auto ghosts = summaryOf(gas_bag);
  const auto preset = collision_lab::io::findScene(
      collision_lab::io::loadScenes(COLLISION_LAB_SOURCE_DIR "/config/scenarios.yaml"), "equal_masses_100");
  std::vector<double> sorted = preset.scene.velocities;
  std::sort(sorted.begin(), sorted.end(), std::greater<double>());
  EXPECT_EQ(ghosts.body_count, 100u);
  EXPECT_EQ(ghosts.collision_count, 2441u);
  EXPECT_EQ(ghosts.final_velocities, sorted);
  {
    rosbag::Bag bag(gas_bag, rosbag::bagmode::Read);
    rosbag::View events(bag, rosbag::TopicQuery("/collision_lab/collision_events"));
    EXPECT_EQ(events.size(), 2441u);
    for (const auto& m : events) {
      ASSERT_TRUE(m.instantiate<collision_lab::CollisionEvent>()->velocities_after.empty());
    }
  }
  const std::string csv = bags.path + "_csv";
  collision_lab_ros::bagToCsv(gas_bag, csv);
  EXPECT_EQ(lastVelocities(csv + "/bodies.csv", 100), sorted);
  fs::remove_all(csv);
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

// docs/ros.md's `scripts/play_run seven`: no folder given, the run id is looked up below the
// node's runs folder ($ROS_HOME/collision_lab/runs, one folder per lab namespace); of two
// labs' bags of that name the newest plays, and play_run names both. rosbag play's --help
// ends the player before it opens the (empty) bag.
TEST(Demo, PlayRunFindsARunIdBelowTheRunsFolder) {
  TempDir home;
  ASSERT_FALSE(home.path.empty());
  const std::string runs = home.path + "/collision_lab/runs";
  fs::create_directories(runs + "/lab2");
  fs::create_directories(runs + "/lab3");
  std::ofstream(runs + "/lab2/seven.bag");
  std::ofstream(runs + "/lab3/seven.bag");
  fs::last_write_time(runs + "/lab2/seven.bag", fs::last_write_time(runs + "/lab3/seven.bag") - std::chrono::hours(1));
  const std::string log = home.path + "/play_run.log";
  const std::string play_run = "ROS_HOME=" + home.path + " " COLLISION_LAB_SOURCE_DIR "/scripts/play_run ";
  EXPECT_EQ(std::system((play_run + "seven --help > " + log + " 2>&1").c_str()), 0) << readFile(log);
  const std::string output = readFile(log);
  EXPECT_NE(output.find("replaying " + runs + "/lab3/seven.bag\n"), std::string::npos) << output;
  EXPECT_NE(output.find("2 bags named seven.bag under " + runs), std::string::npos) << output;
  EXPECT_NE(output.find("  " + runs + "/lab2/seven.bag\n"), std::string::npos) << output;

  fs::remove(runs + "/lab3/seven.bag");
  EXPECT_EQ(std::system((play_run + "seven --help > " + log + " 2>&1").c_str()), 0) << readFile(log);
  EXPECT_NE(readFile(log).find("replaying " + runs + "/lab2/seven.bag\n"), std::string::npos) << readFile(log);
  EXPECT_NE(std::system((play_run + "nine > " + log + " 2>&1").c_str()), 0);
  EXPECT_NE(readFile(log).find("no bag 'nine' (nor nine.bag under " + runs + ")"), std::string::npos)
      << readFile(log);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "demo_test");
  return RUN_ALL_TESTS();
}
