// collision_lab_recording_bench (issue 13, "Recording"): the lab node records one long run
// whose every impact is published, while `rosbag record --lz4` (started here, on the same
// machine) records the same topics from the network. Both rates are messages written to
// the bag per second of wall time:
// - the lab node: the messages in its bag (run parameters, input, prediction, every event, summary)
//   divided by the time from publishing the input to receiving the run's summary, which
//   the node publishes only once the bag is closed (so it includes simulating, publishing
//   three topics per impact and writing);
// - rosbag record: the messages in its bag divided by the span of their receipt stamps
//   (rosbag record stamps each message when it receives it), first to last.
// Started by bench/node/recording_vs_rosbag.launch. Private parameters: ~target (the lab
// node's namespace, "/longrun"), ~masses, ~positions, ~velocities (the run), ~bag_directory
// (where rosbag record writes), ~timeout (s per wait, 300).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/node_constants.h"

namespace {

namespace fs = std::filesystem;
using namespace collision_lab_ros;

/// True when node_name subscribes to every topic in topics (asks the master).
bool subscribesAll(const std::string& node_name, const std::vector<std::string>& topics) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", args, result, payload, false)) return false;
  std::size_t found = 0;
  XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i) {
    const std::string topic = subscribers[i][0];
    for (int k = 0; k < subscribers[i][1].size(); ++k) {
      if (static_cast<std::string>(subscribers[i][1][k]) != node_name) continue;
      for (const auto& t : topics) found += t == topic;
    }
  }
  return found == topics.size();
}

bool waitFor(const std::function<bool()>& done, double timeout, const std::string& what) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (!done()) {
    if (!ros::ok() || ros::WallTime::now() > end) {
      ROS_ERROR_STREAM("gave up after " << timeout << " s waiting for " << what);
      return false;
    }
    ros::WallDuration(0.02).sleep();
  }
  return true;
}

/// Messages in the bag and the span of their stamps [s].
std::pair<std::size_t, double> bagContents(const std::string& path) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  return {view.size(), (view.getEndTime() - view.getBeginTime()).toSec()};
}

std::vector<double> param(const ros::NodeHandle& pnh, const std::string& name, std::vector<double> fallback) {
  pnh.getParam(name, fallback);
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_recording_bench");
  ros::NodeHandle nh, pnh("~");
  const std::string target = pnh.param<std::string>("target", "/longrun");
  const double timeout = pnh.param("timeout", 300.0);
  const std::string dir = pnh.param<std::string>("bag_directory", "/tmp");
  collision_lab::InitialConditions input;
  input.masses = param(pnh, "masses", {1e10, 1.0, 1e10});
  input.positions = param(pnh, "positions", {2.0, 1.0, 0.0});
  input.velocities = param(pnh, "velocities", {-1.0, 0.0, 0.0});
  input.run_id = "longrun_" + std::to_string(::getpid());
  fs::create_directories(dir);
  const std::string rosbag_path = dir + "/rosbag_record_" + std::to_string(::getpid()) + ".bag";
  const std::vector<std::string> topics = {target + "/" + kInitialConditionsTopic, target + "/" + kPredictionsTopic,
                                           target + "/" + kCollisionEventsTopic, target + "/" + kRunSummariesTopic};

  const std::string recorder_name = "/collision_lab_rosbag_record_" + std::to_string(::getpid());
  const pid_t recorder = fork();
  if (recorder == 0) {
    std::vector<std::string> words = {"rosbag", "record", "--lz4", "-O", rosbag_path,
                                      "__name:=" + recorder_name.substr(1)};
    words.insert(words.end(), topics.begin(), topics.end());
    std::vector<char*> argv_rosbag;
    for (auto& w : words) argv_rosbag.push_back(w.data());
    argv_rosbag.push_back(nullptr);
    execvp("rosbag", argv_rosbag.data());
    _exit(127);
  }
  ros::AsyncSpinner spinner(1);
  spinner.start();
  ros::Publisher pub = nh.advertise<collision_lab::InitialConditions>(topics[0], 1);
  std::atomic<bool> done{false};
  collision_lab::RunSummary summary;
  ros::WallTime finished;
  ros::Subscriber sub = nh.subscribe<collision_lab::RunSummary>(
      topics[3], kOutputQueueSize, [&](const collision_lab::RunSummary::ConstPtr& msg) {
        if (msg->run_id != input.run_id) return;
        finished = ros::WallTime::now();
        summary = *msg;
        done = true;
      });
  int code = 1;
  if (waitFor([&] { return subscribesAll(recorder_name, topics) && pub.getNumSubscribers() >= 2 &&
                           sub.getNumPublishers() > 0; }, 30.0, "rosbag record and the lab node to connect")) {
    const ros::WallTime start = ros::WallTime::now();
    pub.publish(input);
    if (waitFor([&] { return done.load(); }, timeout, "the run's summary")) {
      // rosbag record is done when its bag stops growing (it gets the summary last).
      const std::string active = rosbag_path + ".active";
      std::uintmax_t last_size = 0;
      ros::WallTime last_change = ros::WallTime::now();
      waitFor([&] {
        std::error_code ec;
        const auto size = fs::file_size(active, ec);
        if (size != last_size) last_size = size, last_change = ros::WallTime::now();
        return (ros::WallTime::now() - last_change).toSec() > 2.0;
      }, timeout, "rosbag record to write everything");
      kill(recorder, SIGINT);
      waitpid(recorder, nullptr, 0);
      // The rosbag script may exit before its recorder has closed the bag (renamed the
      // .active file): reading it earlier throws.
      waitFor([&] { return fs::exists(rosbag_path) && !fs::exists(active); }, timeout, "rosbag record to close its bag");
      const auto [node_messages, unused] = bagContents(summary.bag_path);
      const auto [rosbag_messages, rosbag_span] = bagContents(rosbag_path);
      const double node_seconds = (finished - start).toSec();
      const double node_rate = node_messages / node_seconds;
      const double rosbag_rate = rosbag_span > 0 ? rosbag_messages / rosbag_span : 0.0;
      std::printf("\nRecording one run of %lu collisions (masses %g, %g, %g), every event published:\n",
                  static_cast<unsigned long>(summary.collision_count), input.masses[0], input.masses[1],
                  input.masses[2]);
      std::printf("  lab node:       %zu messages in its bag, %.2f s from input to summary (bag closed): %.0f msg/s\n",
                  node_messages, node_seconds, node_rate);
      std::printf("  rosbag record:  %zu messages in its bag, %.2f s from first to last receipt: %.0f msg/s\n",
                  rosbag_messages, rosbag_span, rosbag_rate);
      const double ratio = rosbag_rate > 0 ? node_rate / rosbag_rate : 0.0;
      // The run's bag: its parameters, input, prediction, every event and its summary.
      const bool complete = node_messages == 4 + summary.collision_count;
      std::printf("goal: lab node recording a long run, messages/s written = %.0f against rosbag record --lz4 on "
                  "the same topics = %.0f (%.0f%%; goal >= 80%%, every message in the bag): %s\n",
                  node_rate, rosbag_rate, 100 * ratio, ratio >= 0.8 && complete ? "met" : "missed");
      fs::remove(rosbag_path);
      code = 0;
    }
  }
  if (code != 0) {
    kill(recorder, SIGINT);
    waitpid(recorder, nullptr, 0);
  }
  spinner.stop();
  return code;
}
