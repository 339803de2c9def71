// A burst of 1,000 inputs, valid and bad mixed, published as fast as possible
// (burst_test.test): exactly one run_summaries or rejected per input, matched by run_id,
// every announced per-collision message, and one readable bag per valid run.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "run_collector.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_test::makeInput;
using collision_lab_test::RunCollector;

std::string g_bag_directory;
constexpr int kInputs = 1000;

TEST(Burst, OneAnswerPerInputAndOneBagPerValidRun) {
  std::mt19937 rng(20261122);
  std::uniform_real_distribution<double> mass(0.5, 5.0), gap(0.5, 2.0), speed(-2.0, 2.0);
  std::vector<std::pair<std::string, bool>> sent;  // run_id, valid
  std::vector<collision_lab::InitialConditions> inputs;
  for (int i = 0; i < kInputs; ++i) {
    char run_id[32];
    std::snprintf(run_id, sizeof run_id, "burst_%04d", i);
    const double x_b = gap(rng);
    auto input = makeInput(run_id, {mass(rng), mass(rng), mass(rng)}, {x_b + gap(rng), x_b, 0.0},
                           {speed(rng), speed(rng), speed(rng)});
    bool valid = true;
    switch (rng() % 10) {
      case 7: input.velocities[1] = std::nan(""), valid = false; break;
      case 8: input.masses[2] = -input.masses[2], valid = false; break;
      case 9: std::swap(input.positions[0], input.positions[2]), valid = false; break;
      default: break;
    }
    inputs.push_back(input);
    sent.emplace_back(run_id, valid);
  }

  RunCollector node("collision_lab");
  node.waitForConnection();
  for (const auto& input : inputs) node.publish(input);

  int valid_runs = 0;
  for (const auto& [run_id, valid] : sent) {
    SCOPED_TRACE(run_id);
    const auto& out = node.waitFor(run_id);
    ASSERT_EQ(out.summaries.size() + out.rejections.size(), 1u);
    ASSERT_EQ(out.summaries.size(), valid ? 1u : 0u);
    if (!valid) {
      EXPECT_TRUE(out.predictions.empty());
      EXPECT_FALSE(fs::exists(g_bag_directory + "/" + run_id + ".bag"));
      continue;
    }
    ++valid_runs;
    const auto& summary = out.summaries.front();
    EXPECT_EQ(out.predictions.size(), 1u);
    EXPECT_EQ(summary.collision_count, summary.predicted_collision_count);
    EXPECT_EQ(out.events.size(), summary.collision_count);
    EXPECT_EQ(out.velocities.size(), summary.collision_count);
    EXPECT_EQ(out.energies.size(), summary.collision_count);
    ASSERT_TRUE(summary.recording_ok) << summary.recording_error;

    rosbag::Bag bag(summary.bag_path, rosbag::bagmode::Read);
    rosbag::View summaries(bag, rosbag::TopicQuery("/collision_lab/run_summaries"));
    EXPECT_EQ(summaries.size(), 1u);
    EXPECT_EQ(rosbag::View(bag).size(), 3 + summary.collision_count);  // one event per collision
  }
  EXPECT_EQ(node.runs().size(), static_cast<std::size_t>(kInputs));

  std::size_t bags = 0;
  for (const auto& entry : fs::directory_iterator(g_bag_directory)) {
    bags += entry.path().extension() == ".bag";
  }
  EXPECT_EQ(bags, static_cast<std::size_t>(valid_runs));
  RecordProperty("valid_runs", valid_runs);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "burst_test");
  if (!ros::NodeHandle("~").getParam("bag_directory", g_bag_directory)) {
    ADD_FAILURE() << "~bag_directory must be set";
    return 1;
  }
  const int result = RUN_ALL_TESTS();
  std::error_code ec;
  fs::remove_all(fs::path(g_bag_directory).parent_path(), ec);
  return result;
}
