// Three labs on one bag folder (shared_folder_test.test), each sent the same 20 run_ids
// at once: every run gets a bag of its own, named after the run_id its summary reports,
// holding that run's messages; no report says recording failed; one bag per run. And a
// lab with no ~bag_directory records into its namespace's own default folder. Each bag
// says who recorded it, with what, as `rosbag record` would: the latched topics' connections
// carry callerid and latching=1, and run_parameters the effective collision cap and the
// package version (package.xml's, read here).
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/RunParameters.h"
#include "run_collector.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_test::makeInput;
using collision_lab_test::RunCollector;
using collision_lab_test::waitUntil;

std::string g_tmp;
const std::vector<std::string> kLabs = {"collision_lab", "lab2", "lab3"};
/// Each lab's ~max_collisions (shared_folder_test.test): the inputs ask for 0, the node's.
const std::vector<std::uint64_t> kMaxCollisions = {collision_lab_ros::kDefaultMaxCollisions,
                                                   collision_lab_ros::kDefaultMaxCollisions, 5000};

/// <version> of the package.xml.
std::string packageVersion() {
  std::ifstream in(ros::package::getPath("collision_lab") + "/package.xml");
  const std::string xml(std::istreambuf_iterator<char>(in), {});
  const auto begin = xml.find("<version>") + 9;
  return xml.substr(begin, xml.find("</version>") - begin);
}
constexpr int kRunIds = 20;

/// The input lab l is sent as run_id r<k>: a three-body scene that differs for every
/// (l, k), so a bag's input tells whose it is.
collision_lab::InitialConditions labInput(std::size_t l, int k) {
  return makeInput("r" + std::to_string(k), {1.0, 1.0 + 0.1 * k, 2.0 + static_cast<double>(l)},
                   {3.0, 2.0, 0.0}, {-1.0, 0.5 + 0.01 * k, 0.1 * static_cast<double>(l)});
}

/// The run_id an input asked for.
std::string requestedRunId(const collision_lab::RunSummary& s) {
  return s.requested_run_id.empty() ? s.run_id : s.requested_run_id;
}

template <class Message>
std::vector<Message> readTopic(rosbag::Bag& bag, const std::string& topic) {
  std::vector<Message> messages;
  for (const auto& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    const auto msg = m.instantiate<Message>();
    if (msg) messages.push_back(*msg);
  }
  return messages;
}

/// Failures of one run's checks, for the tally.
struct Tally {
  int reports_false = 0;
  int bags_not_theirs = 0;  ///< missing, unreadable, or holding another run's messages
};

/// Lab l's run s: its bag is the one its summary names, readable, and holds this run (its
/// input as lab l sent it, and its summary).
void checkRun(const std::string& dir, std::size_t l, const collision_lab::RunSummary& s, Tally& tally) {
  SCOPED_TRACE(kLabs[l] + ": run " + s.run_id);
  EXPECT_TRUE(s.recording_ok) << s.recording_error;
  tally.reports_false += !s.recording_ok;
  EXPECT_EQ(s.bag_path, dir + "/" + s.run_id + ".bag");
  const int k = std::stoi(requestedRunId(s).substr(1));
  ++tally.bags_not_theirs;  // until shown otherwise
  std::vector<collision_lab::InitialConditions> inputs;
  std::vector<collision_lab::RunSummary> recorded;
  std::vector<collision_lab::RunParameters> parameters;
  std::map<std::string, std::map<std::string, std::string>> headers;  // by topic
  try {
    rosbag::Bag bag(s.bag_path, rosbag::bagmode::Read);
    inputs = readTopic<collision_lab::InitialConditions>(bag, "/" + kLabs[l] + "/initial_conditions");
    recorded = readTopic<collision_lab::RunSummary>(bag, "/" + kLabs[l] + "/run_summaries");
    parameters = readTopic<collision_lab::RunParameters>(bag, "/" + kLabs[l] + "/run_parameters");
    for (const rosbag::ConnectionInfo* c : rosbag::View(bag).getConnections()) headers[c->topic] = *c->header;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "cannot read " << s.bag_path << ": " << e.what();
    return;
  }
  ASSERT_EQ(inputs.size(), 1u);
  EXPECT_EQ(inputs[0].run_id, s.run_id);
  EXPECT_EQ(inputs[0].masses, labInput(l, k).masses);
  ASSERT_EQ(inputs[0].velocities, labInput(l, k).velocities);
  ASSERT_EQ(recorded.size(), 1u);
  EXPECT_EQ(recorded[0].run_id, s.run_id);
  EXPECT_EQ(recorded[0].collision_count, s.collision_count);
  ASSERT_EQ(recorded[0].final_velocities, s.final_velocities);
  --tally.bags_not_theirs;
  // Who recorded it, with what.
  const std::string node = "/" + kLabs[l] + "/collision_lab_node";
  for (const char* topic : {"predictions", "run_summaries", "run_parameters"}) {
    const auto& header = headers["/" + kLabs[l] + "/" + topic];
    EXPECT_EQ(header.count("latching") ? header.at("latching") : "", "1") << topic;
    EXPECT_EQ(header.count("callerid") ? header.at("callerid") : "", node) << topic;
  }
  ASSERT_EQ(parameters.size(), 1u);
  EXPECT_EQ(parameters[0].run_id, s.run_id);
  EXPECT_EQ(parameters[0].node_name, node);
  EXPECT_EQ(parameters[0].package_version, packageVersion());
  EXPECT_EQ(parameters[0].max_collisions, kMaxCollisions[l]);
  EXPECT_EQ(parameters[0].max_published_events, collision_lab_ros::kDefaultMaxPublishedEvents);
  EXPECT_EQ(parameters[0].max_bodies, collision_lab_ros::kDefaultMaxBodies);
}

TEST(SharedFolder, ThreeLabsWithTheSameRunIdsEachRunGetsItsOwnBag) {
  const std::string dir = g_tmp + "/bags";
  std::vector<std::unique_ptr<RunCollector>> labs;
  for (const auto& ns : kLabs) labs.push_back(std::make_unique<RunCollector>(ns));
  for (auto& lab : labs) lab->waitForConnection();
  // At once: run_id r<k> goes to the three labs back to back.
  for (int k = 0; k < kRunIds; ++k) {
    for (std::size_t l = 0; l < labs.size(); ++l) labs[l]->publish(labInput(l, k));
  }
  const auto summaries = [&](std::size_t l) {
    std::vector<collision_lab::RunSummary> found;
    for (const auto& [run_id, out] : labs[l]->runs()) found.insert(found.end(), out.summaries.begin(), out.summaries.end());
    return found;
  };
  for (std::size_t l = 0; l < labs.size(); ++l) {
    waitUntil([&] { return summaries(l).size() >= kRunIds; }, kLabs[l] + "'s 20 summaries");
  }

  Tally tally;
  std::set<std::string> bag_paths;
  for (std::size_t l = 0; l < labs.size(); ++l) {
    std::set<std::string> requested;
    for (const auto& s : summaries(l)) {
      EXPECT_TRUE(bag_paths.insert(s.bag_path).second) << s.bag_path << ": reported by two runs";
      EXPECT_TRUE(requested.insert(requestedRunId(s)).second) << kLabs[l] << ": two summaries for " << requestedRunId(s);
      checkRun(dir, l, s, tally);
    }
    EXPECT_EQ(requested.size(), static_cast<std::size_t>(kRunIds)) << kLabs[l];
  }
  std::size_t bags = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    // The labs' shared run index (runs.sqlite and its WAL files) is expected there.
    if (entry.path().filename().string().rfind("runs.sqlite", 0) == 0) continue;
    EXPECT_EQ(entry.path().extension(), ".bag") << entry.path() << " left behind";
    bags += entry.path().extension() == ".bag";
  }
  EXPECT_EQ(bags, kLabs.size() * kRunIds);
  std::printf("%zu runs: %zu bags, %d reports recording_ok false, %d runs without a readable bag of their own\n",
              bag_paths.size(), bags, tally.reports_false, tally.bags_not_theirs);
  RecordProperty("bags", static_cast<int>(bags));
  RecordProperty("reports_false", tally.reports_false);
  RecordProperty("bags_not_theirs", tally.bags_not_theirs);
}

TEST(SharedFolder, ALabWithoutBagDirectoryRecordsIntoItsNamespacesFolder) {
  RunCollector lab("lab4");
  lab.waitForConnection();
  lab.publish(labInput(4, 0));
  const auto& out = lab.waitFor("r0");
  ASSERT_EQ(out.summaries.size(), 1u);
  EXPECT_TRUE(out.summaries[0].recording_ok) << out.summaries[0].recording_error;
  EXPECT_EQ(out.summaries[0].bag_path, g_tmp + "/ros_home/collision_lab/runs/lab4/r0.bag");
  EXPECT_TRUE(fs::is_regular_file(g_tmp + "/ros_home/collision_lab/runs/lab4/r0.bag"));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "shared_folder_test");
  if (!ros::NodeHandle("~").getParam("tmp", g_tmp)) {
    ADD_FAILURE() << "~tmp must be set";
    return 1;
  }
  const int result = RUN_ALL_TESTS();
  std::error_code ec;
  fs::remove_all(g_tmp, ec);
  return result;
}
