// A lab node killed (SIGKILL) and respawned by roslaunch (index_restart_test.test): its
// ~list_runs, read from the run index, still lists every run served before the crash, and
// its start-up recovery does not touch the .bag.active of a live node sharing the folder
// (lab_b, mid-run), whose run then ends normally with its bag complete; the run it was
// computing is interrupted, and the one waiting in its queue is served again. The respawned
// node serves while it reindexes a dead node's big bag (no window without an answer).
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <rosbag/bag.h>
#include <std_msgs/UInt64.h>

#include "collision_lab/Cancel.h"
#include "collision_lab/ListRuns.h"
#include "collision_lab/RunScene.h"
#include "run_collector.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_test::callService;
using collision_lab_test::makeInput;
using collision_lab_test::RunCollector;
using collision_lab_test::waitUntil;

/// The pid of a node, asked through the master (lookupNode) and the node's own XML-RPC
/// server (getPid); -1 while it is not registered or does not answer.
int nodePid(const std::string& node) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, false)) return -1;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(static_cast<std::string>(payload), host, port)) return -1;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue request, response;
  request[0] = ros::this_node::getName();
  if (!client.execute("getPid", request, response) || response.getType() != XmlRpc::XmlRpcValue::TypeArray ||
      response.size() < 3 || static_cast<int>(response[0]) != 1) {
    return -1;
  }
  return static_cast<int>(response[2]);
}

/// Kills node with SIGKILL and waits until roslaunch has respawned it (respawn_delay 1 s)
/// and the new process has registered.
void killAndAwaitRespawn(const std::string& node) {
  const int old_pid = nodePid(node);
  ASSERT_GT(old_pid, 0);
  ASSERT_EQ(::kill(old_pid, SIGKILL), 0);
  waitUntil([&] {
    const int pid = nodePid(node);
    return pid > 0 && pid != old_pid;
  }, "roslaunch to respawn " + node);
}

std::vector<collision_lab::ServedRun> listRuns(const std::string& lab) {
  collision_lab::ListRuns list;
  EXPECT_TRUE(callService("/" + lab + "/collision_lab_node/list_runs", list));
  return list.response.runs;
}

/// A bag as a node killed mid-run leaves it: its chunks written, never closed, so never
/// indexed (rosbag reindex reads it message by message). The Bag is not destroyed: its
/// destructor would close it.
void leaveUnfinishedBag(const std::string& path, std::uint64_t messages) {
  auto* bag = new rosbag::Bag(path, rosbag::bagmode::Write);
  std_msgs::UInt64 count;
  for (std::uint64_t k = 0; k < messages; ++k) {
    count.data = k;
    bag->write("/dead_lab/count", ros::Time(1.0 + 1e-6 * static_cast<double>(k)), count);
  }
}

const collision_lab::ServedRun* findRun(const std::vector<collision_lab::ServedRun>& runs, const std::string& run_id) {
  for (const auto& run : runs) {
    if (run.accepted.run_id == run_id) return &run;
  }
  return nullptr;
}

TEST(IndexRestart, AKilledNodeRespawnsListingEveryRunAndLeavesALiveNodesBagAlone) {
  ros::NodeHandle private_nh("~");
  std::string bags;
  ASSERT_TRUE(private_nh.getParam("bag_directory", bags));
  RunCollector lab_a("lab_a"), lab_b("lab_b");
  lab_a.waitForConnection();
  lab_b.waitForConnection();

  // Three students' pi runs (31 impacts each) on lab_a, before the crash.
  const std::vector<std::string> students{"ana", "ben", "eva"};
  for (const auto& student : students) {
    auto input = makeInput("pi", {100, 1, std::numeric_limits<double>::infinity()}, {2, 1, 0}, {-1, 0, 0});
    input.student = student;
    lab_a.publish(input);
    ASSERT_EQ(lab_a.waitFor(student + ".pi").summaries.at(0).collision_count, 31u);
  }

  // A long run on lab_b (about 22 million impacts), recording while lab_a crashes.
  auto long_input = makeInput("long_b", {1e14, 1, 1e14}, {2, 1, 0}, {-1, 0, 0});
  long_input.max_collisions = 1000000000;
  lab_b.publish(long_input);
  const std::string live_active = bags + "/long_b.bag.active";
  waitUntil([&] {
    const auto run = lab_b.runs().find("long_b");
    return run != lab_b.runs().end() && run->second.events.size() >= 1000 && fs::exists(live_active);
  }, "1,000 impacts of lab_b's long run and its .bag.active");

  // On lab_a, a long run computing and one waiting behind it (its one worker that takes
  // long runs is busy): the waiting one is served again after the crash.
  for (const std::string& student : {std::string("gus"), std::string("fay")}) {
    auto input = makeInput("long_a", {1e14, 1, 1e14}, {2, 1, 0}, {-1, 0, 0});
    input.student = student;
    input.max_collisions = 1000000000;
    lab_a.publish(input);
  }
  waitUntil([&] {
    const auto running = lab_a.runs().find("gus.long_a");
    const auto* queued = findRun(listRuns("lab_a"), "fay.long_a");
    return running != lab_a.runs().end() && !running->second.events.empty() && queued && !queued->finished;
  }, "lab_a computing gus's long run with fay's queued");

  // A big bag of another dead node in the folder: the respawned lab_a reindexes it.
  const std::string dead_active = bags + "/dead_run.bag.active";
  leaveUnfinishedBag(dead_active, 50000);

  ASSERT_NO_FATAL_FAILURE(killAndAwaitRespawn("/lab_a/collision_lab_node"));
  // It serves while it reindexes the dead bag. (Failed before: its services came up only
  // once every dead bag was reindexed.)
  const std::string run_scene = "/lab_a/collision_lab_node/run_scene";
  ASSERT_TRUE(ros::service::waitForService(run_scene, ros::Duration(collision_lab_test::kWaitTimeout)));
  collision_lab::RunScene pi;
  pi.request.run_id = "after_crash";
  pi.request.student = "hal";
  pi.request.masses = {100, 1, std::numeric_limits<double>::infinity()};
  pi.request.positions = {2, 1, 0};
  pi.request.velocities = {-1, 0, 0};
  const auto asked = std::chrono::steady_clock::now();
  ASSERT_TRUE(callService(run_scene, pi));
  const double answered_after = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
  const bool still_reindexing = fs::exists(dead_active);
  EXPECT_TRUE(pi.response.ok) << pi.response.message;
  EXPECT_EQ(pi.response.summary.collision_count, 31u);
  EXPECT_TRUE(still_reindexing) << "lab_a served its first run only once the dead bag was reindexed";
  ASSERT_TRUE(ros::service::waitForService("/lab_a/collision_lab_node/list_runs",
                                           ros::Duration(collision_lab_test::kWaitTimeout)));
  waitUntil([&] {
    const auto listed = listRuns("lab_a");
    const auto* dead = findRun(listed, "dead_run");
    const auto* crashed = findRun(listed, "gus.long_a");
    return dead && dead->finished && crashed && crashed->finished;
  }, "the dead bags to be reindexed, and their runs ended, in the background");
  const double recovered_after = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
  EXPECT_FALSE(fs::exists(dead_active));
  EXPECT_TRUE(fs::exists(bags + "/dead_run.bag"));
  std::printf("the respawned lab answered a pi run in %.3f s; it ended the dead runs %.1f s after it was asked\n",
              answered_after, recovered_after);

  // The respawned node lists every earlier run, finished, with its bag.
  const auto runs = listRuns("lab_a");
  for (const auto& student : students) {
    const auto* run = findRun(runs, student + ".pi");
    ASSERT_NE(run, nullptr) << student << ".pi is not listed after the restart";
    EXPECT_TRUE(run->finished);
    EXPECT_EQ(run->accepted.student, student);
    EXPECT_EQ(run->collision_count, 31u);
    EXPECT_EQ(run->stop_reason, "FINISHED");
    EXPECT_TRUE(run->recording_ok);
    EXPECT_EQ(run->bag_path, bags + "/" + student + ".pi.bag");
  }
  // ana's alone, by student.
  collision_lab::ListRuns ana;
  ana.request.student = "ana";
  ASSERT_TRUE(callService("/lab_a/collision_lab_node/list_runs", ana));
  ASSERT_EQ(ana.response.runs.size(), 1u);
  EXPECT_EQ(ana.response.runs[0].accepted.run_id, "ana.pi");

  // gus's run, computing at the crash, is interrupted; fay's, queued, is served again under
  // its run_id. (Failed before: both "interrupted, 0 events".) The dead bag's run, unknown
  // to the index, is interrupted too.
  for (const std::string run_id : {"gus.long_a", "dead_run"}) {
    const auto* crashed = findRun(runs, run_id);
    ASSERT_NE(crashed, nullptr) << run_id;
    EXPECT_TRUE(crashed->finished) << run_id;
    EXPECT_EQ(crashed->stop_reason, "INTERRUPTED") << run_id;
  }
  waitUntil([&] {
    const auto again = lab_a.runs().find("fay.long_a");
    return again != lab_a.runs().end() && !again->second.events.empty();
  }, "fay's run, served again, to compute");
  collision_lab::Cancel stop_fay;
  stop_fay.request.run_id = "fay.long_a";
  EXPECT_TRUE(waitUntil([&] { return callService("/lab_a/collision_lab_node/cancel", stop_fay) && stop_fay.response.ok; },
                        "fay's run, served again, to be stopped"));
  // Its summary (its first messages may have gone out before this test's subscribers met
  // the respawned node: it starts at once).
  waitUntil([&] {
    const auto again = lab_a.runs().find("fay.long_a");
    return again != lab_a.runs().end() && !again->second.summaries.empty();
  }, "fay's run, stopped, to end");
  const auto& fay = lab_a.runs().at("fay.long_a");
  ASSERT_EQ(fay.summaries.size(), 1u);
  EXPECT_EQ(fay.summaries[0].stop_reason, "CANCELLED");
  EXPECT_GT(fay.summaries[0].collision_count, 0u);
  EXPECT_TRUE(fay.summaries[0].recording_ok) << fay.summaries[0].recording_error;
  EXPECT_TRUE(fs::exists(bags + "/fay.long_a.bag"));

  // lab_b's run is in the shared index, still running, and its bag was not taken.
  const auto* live = findRun(runs, "long_b");
  ASSERT_NE(live, nullptr);
  ASSERT_FALSE(live->finished) << "lab_b's run ended before lab_a restarted: the test proves nothing";
  EXPECT_TRUE(fs::exists(live_active));
  EXPECT_FALSE(fs::exists(bags + "/long_b.bag"));

  // Stopped on lab_b, it ends normally: bag closed by its owner, complete.
  collision_lab::Cancel cancel;
  cancel.request.run_id = "long_b";
  ASSERT_TRUE(callService("/lab_b/collision_lab_node/cancel", cancel));
  EXPECT_TRUE(cancel.response.ok) << cancel.response.message;
  const auto& long_out = lab_b.waitFor("long_b");
  ASSERT_EQ(long_out.summaries.size(), 1u);
  EXPECT_TRUE(long_out.summaries[0].recording_ok) << long_out.summaries[0].recording_error;
  EXPECT_TRUE(fs::exists(bags + "/long_b.bag"));
  EXPECT_FALSE(fs::exists(live_active));
  const auto after = listRuns("lab_a");
  const auto* ended = findRun(after, "long_b");
  ASSERT_NE(ended, nullptr);
  EXPECT_TRUE(ended->finished);
  EXPECT_EQ(ended->collision_count, long_out.summaries[0].collision_count);
}

/// The run_id `lab` served scene `run_id` under (pi, 31 impacts), through ~run_scene.
std::string servedRunId(const std::string& run_id, const std::string& lab = "lab_c") {
  collision_lab::RunScene pi;
  pi.request.run_id = run_id;
  pi.request.masses = {100, 1, std::numeric_limits<double>::infinity()};
  pi.request.positions = {2, 1, 0};
  pi.request.velocities = {-1, 0, 0};
  EXPECT_TRUE(callService("/" + lab + "/collision_lab_node/run_scene", pi));
  EXPECT_TRUE(pi.response.ok) << pi.response.message;
  EXPECT_EQ(pi.response.summary.collision_count, 31u);
  return pi.response.summary.run_id;
}

// A lab that records no bags (lab_c) shares the index: a run_id of an ended run there
// holds nothing once its node is gone, so a class running the same scene after a restart
// gets the run_id it typed (failed with "any run_id the index lists is taken": "again.3");
// a run_id whose bag another lab recorded is taken there too, and that lab's run stays
// listed with its bag (failed with "only an unended run holds its run_id": lab_c served
// "kept" and its row replaced lab_b's).
TEST(IndexRestart, ALabWithoutBagsServesAnEndedRunsIdAsTypedAndNeverARecordedOne) {
  ros::NodeHandle private_nh("~");
  std::string bags;
  ASSERT_TRUE(private_nh.getParam("bag_directory", bags));
  const std::string run_scene = "/lab_c/collision_lab_node/run_scene";
  ASSERT_TRUE(ros::service::waitForService(run_scene, ros::Duration(collision_lab_test::kWaitTimeout)));
  ASSERT_TRUE(ros::service::waitForService("/lab_b/collision_lab_node/run_scene",
                                           ros::Duration(collision_lab_test::kWaitTimeout)));
  ASSERT_EQ(servedRunId("kept", "lab_b"), "kept");  // recorded by lab_b
  EXPECT_EQ(servedRunId("kept"), "kept.2");
  EXPECT_EQ(servedRunId("again"), "again");
  EXPECT_EQ(servedRunId("again"), "again.2");  // the same process served "again"

  ASSERT_NO_FATAL_FAILURE(killAndAwaitRespawn("/lab_c/collision_lab_node"));
  ASSERT_TRUE(ros::service::waitForService(run_scene, ros::Duration(collision_lab_test::kWaitTimeout)));
  EXPECT_EQ(servedRunId("again"), "again");

  const auto runs = listRuns("lab_c");
  const auto* again = findRun(runs, "again");
  ASSERT_NE(again, nullptr);
  EXPECT_TRUE(again->finished);
  EXPECT_EQ(again->bag_path, "");
  EXPECT_NE(findRun(runs, "again.2"), nullptr);
  EXPECT_EQ(servedRunId("kept"), "kept.2");  // kept.2 was lab_c's own, ended, without a bag: free again
  const auto after = listRuns("lab_c");
  const auto* kept = findRun(after, "kept");
  ASSERT_NE(kept, nullptr);
  EXPECT_EQ(kept->bag_path, bags + "/kept.bag");
  EXPECT_TRUE(fs::exists(bags + "/kept.bag"));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "index_restart_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
