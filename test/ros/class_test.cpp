// A class of twenty on one collision_lab_node (class_test.test), issue 22's "done when":
// twenty students publish InitialConditions at once, each naming themselves, most asking
// for run_ids that collide (ten type the same `pi_by_hand`, twice). Each student finds an
// AcceptedRun with their own name and a run id no one else got, by the documented rule
// (<student>.<run_id>, <student> without a run_id, then .2 when taken), and ~list_runs
// lists each student's runs by name, finished, with the count of the paper's example
// (m_A/m_B = 100 against a wall: 31 collisions, the first two digits of pi) and a bag. A
// student with a bad name, and one with a bad scene, find their rejection by name. The
// teacher's scripts/list_runs, which reads the bags, lists the same runs.
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/ListRuns.h"
#include "collision_lab/ros/node_constants.h"
#include "run_collector.h"

namespace {

using collision_lab_test::callService;
using collision_lab_test::makeInput;
using collision_lab_test::waitUntil;

constexpr int kStudents = 20;
constexpr int kRunsEach = 2;
constexpr char kListRuns[] = "/collision_lab/collision_lab_node/list_runs";

std::string student(int k) { return "s" + std::to_string(100 + k); }

/// Students 0-9 type `pi_by_hand`, 10-14 name no run, 15-19 type `mine`.
std::string requested(int k) {
  if (k < 10) return "pi_by_hand";
  return k < 15 ? "" : "mine";
}

/// stdout of command.
std::string output(const std::string& command) {
  std::string text;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return text;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) text += buffer;
  pclose(pipe);
  return text;
}

/// The documented rule: <student>.<run_id> (or <student>), then .2 for the second.
std::string expectedRunId(int k, int run) {
  const std::string base = requested(k).empty() ? student(k) : student(k) + "." + requested(k);
  return run == 0 ? base : base + "." + std::to_string(run + 1);
}

TEST(Class, TwentyStudentsAtOnceEachFindTheirOwnRunsByName) {
  ros::NodeHandle nh("collision_lab");
  std::string bag_directory;
  ASSERT_TRUE(ros::NodeHandle("~").getParam("bag_directory", bag_directory));
  std::map<std::string, std::vector<collision_lab::AcceptedRun>> accepted;  // by student
  std::map<std::string, std::vector<collision_lab::Rejected>> rejected;    // by student
  std::size_t summaries = 0;
  ros::Subscriber accepted_sub = nh.subscribe<collision_lab::AcceptedRun>(
      collision_lab_ros::kAcceptedRunsTopic, 1000,
      [&](const collision_lab::AcceptedRun::ConstPtr& m) { accepted[m->student].push_back(*m); });
  ros::Subscriber rejected_sub = nh.subscribe<collision_lab::Rejected>(
      collision_lab_ros::kRejectedTopic, 1000,
      [&](const collision_lab::Rejected::ConstPtr& m) { rejected[m->student].push_back(*m); });
  ros::Subscriber summary_sub = nh.subscribe<collision_lab::RunSummary>(
      collision_lab_ros::kRunSummariesTopic, 1000, [&](const collision_lab::RunSummary::ConstPtr&) { ++summaries; });
  ros::Publisher inputs =
      nh.advertise<collision_lab::InitialConditions>(collision_lab_ros::kInitialConditionsTopic, 1000);
  ASSERT_TRUE(waitUntil([&] {
    return inputs.getNumSubscribers() > 0 && accepted_sub.getNumPublishers() > 0 &&
           rejected_sub.getNumPublishers() > 0 && summary_sub.getNumPublishers() > 0;
  }, "the node to connect"));

  // Everyone at once: no input waits for another's answer.
  for (int run = 0; run < kRunsEach; ++run) {
    for (int k = 0; k < kStudents; ++k) {
      auto input = makeInput(requested(k), {100.0, 1.0, std::numeric_limits<double>::infinity()}, {2.0, 1.0, 0.0},
                             {-1.0, 0.0, 0.0});
      input.student = student(k);
      inputs.publish(input);
    }
  }
  auto bad_name = makeInput("", {1, 1, 1}, {2, 1, 0}, {-1, 0, 0});
  bad_name.student = "dot.ted";
  inputs.publish(bad_name);
  auto bad_scene = makeInput("oops", {1, 1, 1}, {0, 1, 2}, {-1, 0, 0});
  bad_scene.student = "zoe";
  inputs.publish(bad_scene);

  const std::size_t runs = kStudents * kRunsEach;
  ASSERT_TRUE(waitUntil([&] { return summaries == runs && rejected.size() == 2; }, "every run's summary and both rejections"));

  std::set<std::string> run_ids;
  for (int k = 0; k < kStudents; ++k) {
    SCOPED_TRACE(student(k));
    const auto& mine = accepted[student(k)];
    ASSERT_EQ(mine.size(), static_cast<std::size_t>(kRunsEach));
    for (int run = 0; run < kRunsEach; ++run) {
      EXPECT_EQ(mine[run].student, student(k));
      EXPECT_EQ(mine[run].requested_run_id, requested(k));
      EXPECT_EQ(mine[run].run_id, expectedRunId(k, run));
      EXPECT_TRUE(run_ids.insert(mine[run].run_id).second) << mine[run].run_id << " given twice";
    }
  }
  EXPECT_EQ(accepted.size(), static_cast<std::size_t>(kStudents)) << "an AcceptedRun names no student of the class";

  ASSERT_EQ(rejected["dot.ted"].size(), 1u);
  EXPECT_EQ(rejected["dot.ted"][0].reason, collision_lab::Rejected::INVALID_STUDENT);
  EXPECT_EQ(rejected["dot.ted"][0].field, "student");
  ASSERT_EQ(rejected["zoe"].size(), 1u);
  EXPECT_EQ(rejected["zoe"][0].reason, collision_lab::Rejected::POSITIONS_NOT_ORDERED);
  EXPECT_EQ(rejected["zoe"][0].run_id, "oops");

  // The teacher lists each student's runs by name.
  for (int k = 0; k < kStudents; ++k) {
    SCOPED_TRACE(student(k));
    collision_lab::ListRuns list;
    list.request.student = student(k);
    ASSERT_TRUE(callService(kListRuns, list));
    ASSERT_EQ(list.response.runs.size(), static_cast<std::size_t>(kRunsEach));
    for (int run = 0; run < kRunsEach; ++run) {
      const auto& listed = list.response.runs[run];
      EXPECT_EQ(listed.accepted.student, student(k));
      EXPECT_EQ(listed.accepted.run_id, expectedRunId(k, run));
      EXPECT_TRUE(listed.finished);
      EXPECT_EQ(listed.collision_count, 31u);
      EXPECT_EQ(listed.stop_reason, "FINISHED");
      EXPECT_EQ(listed.bag_path, bag_directory + "/" + expectedRunId(k, run) + ".bag");
      EXPECT_TRUE(listed.recording_ok);
      EXPECT_TRUE(std::filesystem::is_regular_file(listed.bag_path)) << listed.bag_path;
    }
  }
  // After a restart the node's record is gone; scripts/list_runs reads the bags.
  for (int k : {0, 12, 19}) {
    std::string expected = "run_id\tstudent\tcollisions\tstop_reason\tbag\n";
    for (int run = 0; run < kRunsEach; ++run) {
      expected += expectedRunId(k, run) + "\t" + student(k) + "\t31\tFINISHED\t" + bag_directory + "/" +
                  expectedRunId(k, run) + ".bag\n";
    }
    EXPECT_EQ(output(COLLISION_LAB_SOURCE_DIR "/scripts/list_runs --student " + student(k) + " " + bag_directory), expected);
  }
  collision_lab::ListRuns everyone;
  ASSERT_TRUE(callService(kListRuns, everyone));
  EXPECT_EQ(everyone.response.runs.size(), runs);
  collision_lab::ListRuns nobody;
  nobody.request.student = "zoe";  // rejected only: no runs
  ASSERT_TRUE(callService(kListRuns, nobody));
  EXPECT_TRUE(nobody.response.runs.empty());
  std::filesystem::remove_all(std::filesystem::path(bag_directory).parent_path());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "class_test");
  return RUN_ALL_TESTS();
}
