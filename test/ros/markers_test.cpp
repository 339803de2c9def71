// The marker view inside collision_lab_node (markers_test.test), as a class sees it in
// rviz: a hint before the first run, a rejected input with its reason and field, and on
// pi_digits_5 an animation whose collision counter reaches the true count, 31,415 (the
// first five digits of pi: m_A/m_B = 1e8 against a wall), never more. Both marker topics
// are latched, so an rviz opened late gets the last run's picture at once.
#include <cstdint>
#include <limits>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/markers/ids.h"
#include "marker_test_client.h"

namespace {

using namespace collision_lab_test;

constexpr double kTimeout = 120.0;  ///< [s] wall time for any one expected frame

collision_lab::InitialConditions input(const std::string& run_id, double m_a, const std::array<double, 3>& x) {
  collision_lab::InitialConditions msg;
  msg.run_id = run_id;
  msg.masses = {m_a, 1.0, std::numeric_limits<double>::infinity()};
  msg.positions = {x[0], x[1], x[2]};
  msg.velocities = {-1.0, 0.0, 0.0};
  return msg;
}

std::size_t longestLine(const visualization_msgs::MarkerArray& array) {
  std::size_t longest = 0;
  for (const auto& m : array.markers) {
    if (m.type == visualization_msgs::Marker::LINE_STRIP || m.type == visualization_msgs::Marker::LINE_LIST) {
      longest = std::max(longest, m.points.size());
    }
  }
  return longest;
}

TEST(Markers, HintRejectionAndTheTrueCountOnALongRun) {
  ros::NodeHandle nh("collision_lab");
  AnimationWatcher watcher(nh);
  std::size_t longest = 0;
  ros::Subscriber picture = nh.subscribe<visualization_msgs::MarkerArray>(
      collision_lab_ros::kMarkersTopic, 100,
      [&](const visualization_msgs::MarkerArray::ConstPtr& a) { longest = std::max(longest, longestLine(*a)); });

  ASSERT_TRUE(spinUntil([&] { return !watcher.hint.empty(); }, kTimeout)) << "no hint before the first run";
  EXPECT_NE(watcher.hint.find("rostopic pub"), std::string::npos) << watcher.hint;
  EXPECT_TRUE(watcher.is_latched);

  ros::Publisher inputs = nh.advertise<collision_lab::InitialConditions>(collision_lab_ros::kInitialConditionsTopic, 10);
  ASSERT_TRUE(spinUntil([&] { return inputs.getNumSubscribers() > 0; }, kTimeout)) << "the node never subscribed";

  inputs.publish(input("bad_order", 100.0, {0.0, 1.0, 2.0}));
  ASSERT_TRUE(spinUntil([&] { return !watcher.banner.empty(); }, kTimeout)) << "no banner for a rejected input";
  EXPECT_NE(watcher.banner.find("POSITIONS_NOT_ORDERED"), std::string::npos) << watcher.banner;
  EXPECT_NE(watcher.banner.find("bad_order"), std::string::npos) << watcher.banner;

  inputs.publish(input("pi_digits_5_markers", 1.0e8, {2.0, 1.0, 0.0}));
  const std::string done = "collisions 31,415 of 31,415";
  ASSERT_TRUE(spinUntil([&] { return watcher.status.find(done) != std::string::npos; }, kTimeout))
      << "the counter never reached the true count; last shown: " << watcher.status;
  EXPECT_EQ(watcher.largest_count, 31415);
  EXPECT_LE(longest, collision_lab_ros::kRvizMaxLinePoints);

  // An rviz opened now gets the last run's picture from the latch.
  bool late_latched = false;
  std::string late_title;
  ros::NodeHandle late("collision_lab");
  ros::Subscriber late_sub =
      late.subscribe<visualization_msgs::MarkerArray, const MarkerEvent&>(collision_lab_ros::kMarkersTopic, 1, MarkerEventCallback([&](const MarkerEvent& event) {
                       late_latched = latched(event);
                       for (const auto& m : event.getMessage()->markers) {
                         if (m.ns == collision_lab_ros::markers::ns::kTitle) late_title = m.text;
                       }
                     }));
  ASSERT_TRUE(spinUntil([&] { return !late_title.empty(); }, kTimeout)) << "a late subscriber got no picture";
  EXPECT_TRUE(late_latched);
  EXPECT_NE(late_title.find("pi_digits_5_markers"), std::string::npos) << late_title;
  EXPECT_NE(late_title.find("simulated 31,415"), std::string::npos) << late_title;
}

// With recording on, a run's summary goes out only once its bag is closed (bags are written
// behind the run), so a long run's summary can come after the next run has started. The
// view must stay on the newest run.
TEST(Markers, ALateSummaryOfTheRunBeforeDoesNotTakeTheViewBack) {
  ros::NodeHandle nh("collision_lab_recording");
  AnimationWatcher watcher(nh);
  std::string title;
  ros::Subscriber picture = nh.subscribe<visualization_msgs::MarkerArray>(
      collision_lab_ros::kMarkersTopic, 100, [&](const visualization_msgs::MarkerArray::ConstPtr& a) {
        for (const auto& m : a->markers) {
          if (m.ns == collision_lab_ros::markers::ns::kTitle) title = m.text;
        }
      });
  std::set<std::string> summaries;
  ros::Subscriber summary_sub = nh.subscribe<collision_lab::RunSummary>(
      collision_lab_ros::kRunSummariesTopic, 10,
      [&](const collision_lab::RunSummary::ConstPtr& s) { summaries.insert(s->run_id); });
  ros::Publisher inputs = nh.advertise<collision_lab::InitialConditions>(collision_lab_ros::kInitialConditionsTopic, 10);
  ASSERT_TRUE(spinUntil([&] { return inputs.getNumSubscribers() > 0 && summary_sub.getNumPublishers() > 0; }, kTimeout))
      << "the recording node never connected";

  // 31,415 collisions to write into its bag, then at once a run of 31 (m_A/m_B = 100).
  inputs.publish(input("long_before", 1.0e8, {2.0, 1.0, 0.0}));
  inputs.publish(input("right_after", 100.0, {2.0, 1.0, 0.0}));
  ASSERT_TRUE(spinUntil([&] { return summaries.count("long_before") && summaries.count("right_after"); }, kTimeout))
      << "both runs' summaries never came";
  const std::string done = "collisions 31 of 31";
  ASSERT_TRUE(spinUntil([&] { return watcher.status.find(done) != std::string::npos; }, kTimeout))
      << "the view left the newest run; last shown: " << watcher.status << " / " << title;
  ASSERT_TRUE(spinUntil([&] { return title.find("simulated 31,") == std::string::npos &&
                                     title.find("simulated 31") != std::string::npos; }, kTimeout))
      << title;
  EXPECT_NE(title.find("right_after"), std::string::npos) << title;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "markers_test");
  return RUN_ALL_TESTS();
}
