// kill -9 in the middle of a run (crash_test.test): the bags of finished runs stay
// intact, the run in progress is left as <run_id>.bag.active, and the restarted node
// recovers it (reindexed, renamed <run_id>.bag) and lists the run as interrupted with the
// events its bag holds (the run index, issue 30); it never overwrites an existing bag: it
// serves a taken run_id as <run_id>.2. SIGINT during a burst: every bag handed to the writer is closed
// and complete. SIGINT during a run_scene call cancels the run first. A count parameter
// out of range stops the node at start-up, saying which.
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/ListRuns.h"
#include "collision_lab/RunScene.h"
#include "run_collector.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_test::makeInput;
using collision_lab_test::RunCollector;
using collision_lab_test::waitUntil;

constexpr char kNamespace[] = "crash";

/// Starts collision_lab_node in namespace `crash` with its bags in directory, and
/// parameter, if any, a further `_name:=value`; its stderr goes to stderr_path, if given.
pid_t startNode(const std::string& directory, const std::string& parameter = "",
                const std::string& stderr_path = "") {
  const pid_t pid = fork();
  if (pid == 0) {
    if (!stderr_path.empty() && !std::freopen(stderr_path.c_str(), "w", stderr)) _exit(126);
    // The binary itself (rosrun may find several in a source tree with many builds).
    const std::string bags = "_bag_directory:=" + directory;
    std::vector<const char*> args{COLLISION_LAB_NODE_PATH, "__ns:=crash", bags.c_str(), "_publish_markers:=false"};
    if (!parameter.empty()) args.push_back(parameter.c_str());
    args.push_back(nullptr);
    execv(COLLISION_LAB_NODE_PATH, const_cast<char* const*>(args.data()));
    _exit(127);
  }
  return pid;
}

/// Sends signal and returns the exit status (waitpid's).
int stop(pid_t pid, int signal) {
  kill(pid, signal);
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

std::size_t messageCount(const std::string& path) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  return rosbag::View(bag).size();
}

TEST(Crash, KillNineKeepsFinishedBagsAndNeverOverwrites) {
  char pattern[] = "/tmp/collision_lab_crash_XXXXXX";
  ASSERT_NE(mkdtemp(pattern), nullptr);
  const std::string dir = pattern;

  // A finished run, then a long one (2,221,441 collisions, under the default cap) that is
  // killed mid-way.
  const auto finished = makeInput("finished", {1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1});
  const auto long_run = makeInput("long_run", {1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0});
  {
    const pid_t node = startNode(dir);
    ASSERT_GT(node, 0);
    RunCollector client(kNamespace);
    client.waitForConnection();
    client.publish(finished);
    ASSERT_EQ(client.waitFor("finished").summaries.size(), 1u);
    client.publish(long_run);
    // In progress: 10,000 collisions published (the default ~max_published_events), and the
    // bag (written behind the run, on the writer thread) has flushed its first chunks (768 kB
    // each); the rest of the run goes on.
    const std::string active = dir + "/long_run.bag.active";
    const auto inProgress = [&client, &active] {
      const auto run = client.runs().find("long_run");
      std::error_code no_file;
      return run != client.runs().end() && run->second.events.size() >= 10000 &&
             fs::file_size(active, no_file) > 3 * 768 * 1024 && !no_file;
    };
    const auto over = [&client] {
      const auto run = client.runs().find("long_run");
      return run != client.runs().end() && !run->second.summaries.empty();
    };
    waitUntil([&] { return inProgress() || over(); }, "10,000 collisions of long_run, and 3 chunks of its bag");
    const bool killed_mid_run = fs::exists(active) && !over();
    stop(node, SIGKILL);
    ASSERT_TRUE(killed_mid_run);
  }

  const std::size_t finished_messages = messageCount(dir + "/finished.bag");
  EXPECT_EQ(finished_messages, 4 + 3u);  // parameters, input, prediction, one event per collision (3), summary
  EXPECT_FALSE(fs::exists(dir + "/long_run.bag"));
  ASSERT_TRUE(fs::exists(dir + "/long_run.bag.active"));

  // The interrupted bag is recoverable up to its last flushed chunk: reindex a copy and
  // read it (outside the bag folder: the restarted node recovers the bag itself).
  char copy_pattern[] = "/tmp/collision_lab_crash_copy_XXXXXX";
  ASSERT_NE(mkdtemp(copy_pattern), nullptr);
  const std::string recovered = std::string(copy_pattern) + "/long_run_recovered.bag";
  fs::copy_file(dir + "/long_run.bag.active", recovered);
  ASSERT_EQ(std::system(("rosbag reindex -q " + recovered + " > /dev/null").c_str()), 0);
  std::size_t events_in_bag = 0;
  {
    rosbag::Bag bag(recovered, rosbag::bagmode::Read);
    EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/crash/initial_conditions")).size(), 1u);
    EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/crash/predictions")).size(), 1u);
    events_in_bag = rosbag::View(bag, rosbag::TopicQuery("/crash/collision_events")).size();
    EXPECT_GT(events_in_bag, 0u);
    EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/crash/run_summaries")).size(), 0u);
  }
  fs::remove_all(copy_pattern);

  // A restarted node recovers the interrupted bag, serves both run_ids again under
  // the next free suffix, and touches neither the finished bag nor the recovered one.
  {
    const pid_t node = startNode(dir);
    ASSERT_GT(node, 0);
    RunCollector client(kNamespace);
    client.waitForConnection();
    // ~list_runs (the run index) lists both runs of the killed node: the finished one, and
    // the interrupted one with the events its bag holds, once recovered (in the background,
    // while the node serves).
    const std::string list_service = std::string("/") + kNamespace + "/collision_lab_node/list_runs";
    ASSERT_TRUE(ros::service::waitForService(list_service, ros::Duration(collision_lab_test::kWaitTimeout)));
    collision_lab::ListRuns list;
    waitUntil([&] {
      return ros::service::call(list_service, list) && list.response.runs.size() == 2u &&
             list.response.runs[1].finished;
    }, "the node to recover the interrupted run");
    ASSERT_FALSE(fs::exists(dir + "/long_run.bag.active"));
    ASSERT_TRUE(fs::exists(dir + "/long_run.bag"));
    EXPECT_EQ(messageCount(dir + "/long_run.bag"), 3 + events_in_bag);  // parameters, input, prediction, events
    ASSERT_EQ(list.response.runs.size(), 2u);
    EXPECT_EQ(list.response.runs[0].accepted.run_id, "finished");
    EXPECT_EQ(list.response.runs[0].stop_reason, "FINISHED");
    EXPECT_EQ(list.response.runs[0].collision_count, 3u);
    EXPECT_EQ(list.response.runs[1].accepted.run_id, "long_run");
    EXPECT_TRUE(list.response.runs[1].finished);
    EXPECT_EQ(list.response.runs[1].stop_reason, "INTERRUPTED");
    EXPECT_TRUE(list.response.runs[1].truncated);
    EXPECT_EQ(list.response.runs[1].collision_count, events_in_bag);
    EXPECT_EQ(list.response.runs[1].bag_path, dir + "/long_run.bag");
    const auto recovered_size = fs::file_size(dir + "/long_run.bag");
    auto short_run = finished;
    short_run.run_id = "long_run";
    for (const auto& input : {finished, short_run}) {
      client.publish(input);
      const auto& out = client.waitFor(input.run_id + ".2");
      ASSERT_EQ(out.summaries.size(), 1u) << input.run_id;
      EXPECT_EQ(out.summaries.front().requested_run_id, input.run_id);
      EXPECT_EQ(out.summaries.front().collision_count, 3u);
      EXPECT_EQ(messageCount(dir + "/" + input.run_id + ".2.bag"), finished_messages);
    }
    stop(node, SIGINT);
    EXPECT_EQ(fs::file_size(dir + "/long_run.bag"), recovered_size);
  }
  EXPECT_EQ(messageCount(dir + "/finished.bag"), finished_messages);
  EXPECT_FALSE(fs::exists(dir + "/long_run.bag.active"));
  fs::remove_all(dir);
}

TEST(Crash, SigintDuringAServiceCallCancelsTheRunFirst) {
  char pattern[] = "/tmp/collision_lab_sigint_call_XXXXXX";
  ASSERT_NE(mkdtemp(pattern), nullptr);
  const std::string dir = pattern;
  constexpr std::uint64_t kPredicted = 2221441;  // masses 1e12, 1, 1e12 (docs/physics.md)
  const pid_t node = startNode(dir);
  ASSERT_GT(node, 0);
  RunCollector client(kNamespace);
  client.waitForConnection();
  const std::string service = std::string("/") + kNamespace + "/collision_lab_node/run_scene";
  ASSERT_TRUE(ros::service::waitForService(service, ros::Duration(collision_lab_test::kWaitTimeout)));
  // A service call waits for its run: the node must cancel the run before it shuts its
  // services down (and before ros::shutdown, which waits for the calls in progress).
  collision_lab::RunScene call;
  const auto input = makeInput("long_call", {1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0});
  call.request.run_id = input.run_id;
  call.request.masses = input.masses;
  call.request.positions = input.positions;
  call.request.velocities = input.velocities;
  std::thread caller([service, call]() mutable { ros::service::call(service, call); });
  const auto over = [&client] {
    const auto run = client.runs().find("long_call");
    return run != client.runs().end() && !run->second.summaries.empty();
  };
  waitUntil([&] {
    const auto run = client.runs().find("long_call");
    return over() || (run != client.runs().end() && run->second.events.size() >= 1000);
  }, "1,000 collisions of long_call");
  const bool signalled_mid_run = !over();
  const int status = stop(node, SIGINT);
  caller.join();
  ASSERT_TRUE(signalled_mid_run);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "wait status " << status;

  // The bag is closed, and its summary (written last) says the run was cancelled.
  ASSERT_TRUE(fs::exists(dir + "/long_call.bag"));
  EXPECT_FALSE(fs::exists(dir + "/long_call.bag.active"));
  rosbag::Bag bag(dir + "/long_call.bag", rosbag::bagmode::Read);
  rosbag::View summaries(bag, rosbag::TopicQuery("/crash/run_summaries"));
  ASSERT_EQ(summaries.size(), 1u);
  const auto summary = summaries.begin()->instantiate<collision_lab::RunSummary>();
  ASSERT_NE(summary, nullptr);
  EXPECT_TRUE(summary->cancelled);
  EXPECT_EQ(summary->predicted_collision_count, kPredicted);
  EXPECT_LT(summary->collision_count, kPredicted);
  EXPECT_TRUE(summary->recording_ok) << summary->recording_error;
  EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/crash/collision_events")).size(), summary->collision_count);
  std::printf("SIGINT during a run_scene call: cancelled after %llu of %llu collisions\n",
              static_cast<unsigned long long>(summary->collision_count), static_cast<unsigned long long>(kPredicted));
  bag.close();
  fs::remove_all(dir);
}

TEST(Crash, ACountParameterOutOfRangeStopsTheNodeAtStartUp) {
  char pattern[] = "/tmp/collision_lab_params_XXXXXX";
  ASSERT_NE(mkdtemp(pattern), nullptr);
  const std::string dir = pattern;
  const std::string log = dir + "/stderr.txt";
  // roscpp reads `_name:=value` as an int, else a double (boost::lexical_cast), else a string.
  for (const auto& [name, value, message] :
       {std::tuple<std::string, std::string, std::string>{"max_bodies", "1.0e+30", "~max_bodies = 1e+30 is out of range"},
        {"max_collisions", "inf", "~max_collisions = inf is out of range"},
        {"max_collisions", "nan", "~max_collisions = nan is out of range"},
        {"max_published_events", "-1", "~max_published_events = -1 is out of range"},
        {"max_published_events", "2.5", "~max_published_events = 2.5 is out of range"},
        {"max_bodies", "many", "~max_bodies is not a number"}}) {
    const std::string parameter = "_" + name + ":=" + value;
    SCOPED_TRACE(parameter);
    const pid_t node = startNode(dir, parameter, log);
    ASSERT_GT(node, 0);
    int status = 0;
    // A node that starts anyway serves until killed: stop it after the wait gives up.
    const bool exited = waitUntil([&] { return waitpid(node, &status, WNOHANG) == node; }, "the node to exit");
    if (!exited) status = stop(node, SIGKILL);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << "wait status " << status;
    std::ifstream text(log);
    const std::string printed((std::istreambuf_iterator<char>(text)), std::istreambuf_iterator<char>());
    EXPECT_NE(printed.find(message), std::string::npos) << printed;
    EXPECT_NE(printed.find("from 0 to 18446744073709551615"), std::string::npos) << printed;
    ros::param::del(std::string("/") + kNamespace + "/collision_lab_node/" + name);  // the next node's default
  }
  fs::remove_all(dir);
}

/// The run_ids of the bags in directory, and whether any is still .bag.active.
std::vector<std::string> bagsIn(const std::string& directory, bool& any_active) {
  std::vector<std::string> run_ids;
  any_active = false;
  for (const auto& entry : fs::directory_iterator(directory)) {
    if (entry.path().extension() == ".active") any_active = true;
    if (entry.path().extension() == ".bag") run_ids.push_back(entry.path().stem().string());
  }
  return run_ids;
}

TEST(Crash, SigintDuringABurstClosesEveryBagStarted) {
  char pattern[] = "/tmp/collision_lab_sigint_XXXXXX";
  ASSERT_NE(mkdtemp(pattern), nullptr);
  const std::string dir = pattern;
  constexpr int kRuns = 400;
  std::size_t summaries_seen = 0;
  {
    const pid_t node = startNode(dir);
    ASSERT_GT(node, 0);
    RunCollector client(kNamespace);
    client.waitForConnection();
    // Three collisions each (masses 1, 2, 3), bags written behind the runs by the writer.
    for (int i = 0; i < kRuns; ++i) {
      client.publish(makeInput("burst_" + std::to_string(i), {1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1}));
    }
    waitUntil([&client] { return !client.runs().empty(); }, "the first output of the burst");
    stop(node, SIGINT);
    // A summary goes out only once its bag is closed.
    for (const auto& [run_id, out] : client.runs()) {
      summaries_seen += out.summaries.size();
      if (!out.summaries.empty()) {
        EXPECT_TRUE(fs::exists(dir + "/" + run_id + ".bag")) << run_id;
      }
    }
  }
  bool any_active = false;
  const std::vector<std::string> bags = bagsIn(dir, any_active);
  EXPECT_FALSE(any_active) << "a bag handed to the writer was left open";
  EXPECT_GE(bags.size(), summaries_seen);
  EXPECT_GT(bags.size(), 0u);
  for (const auto& run_id : bags) {
    SCOPED_TRACE(run_id);
    rosbag::Bag bag(dir + "/" + run_id + ".bag", rosbag::bagmode::Read);
    rosbag::View summaries(bag, rosbag::TopicQuery("/crash/run_summaries"));
    ASSERT_EQ(summaries.size(), 1u);
    const auto summary = summaries.begin()->instantiate<collision_lab::RunSummary>();
    ASSERT_NE(summary, nullptr);
    EXPECT_EQ(summary->run_id, run_id);
    EXPECT_TRUE(summary->recording_ok) << summary->recording_error;
    // Served to the end or cancelled by the shutdown: its bag holds what it counted.
    if (!summary->cancelled) {
      EXPECT_EQ(summary->collision_count, 3u);
    }
    EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/crash/collision_events")).size(), summary->collision_count);
    EXPECT_EQ(rosbag::View(bag).size(), 4 + summary->collision_count);  // with parameters, input, prediction, summary
  }
  std::printf("SIGINT during a burst of %d: %zu bags closed, %zu summaries seen before the signal\n", kRuns,
              bags.size(), summaries_seen);
  fs::remove_all(dir);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "crash_test");
  ros::NodeHandle nh;  // starts ROS for the whole test
  return RUN_ALL_TESTS();
}
