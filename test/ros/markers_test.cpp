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
#include "collision_lab/Rejected.h"
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
  const std::string done = "collisions 31,415     run: 31,415 collisions, finished";
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
  const std::string done = "collisions 31     run: 31 collisions, finished";
  ASSERT_TRUE(spinUntil([&] { return watcher.status.find(done) != std::string::npos; }, kTimeout))
      << "the view left the newest run; last shown: " << watcher.status << " / " << title;
  ASSERT_TRUE(spinUntil([&] { return title.find("simulated 31,") == std::string::npos &&
                                     title.find("simulated 31") != std::string::npos; }, kTimeout))
      << title;
  EXPECT_NE(title.find("right_after"), std::string::npos) << title;
}

// A student's own view in a class (~follow_student ana): another student's runs and
// rejections never show, and ana's rejection stays on screen until ana's next run (it used
// to vanish after 6 s, before a student had read it).
TEST(Markers, AViewThatFollowsAStudentShowsTheirRunsAndKeepsTheirRejection) {
  ros::NodeHandle nh("collision_lab_follow");
  AnimationWatcher watcher(nh);
  bool banner_visible = false;
  std::set<std::string> banners, titles;
  ros::Subscriber animated = nh.subscribe<visualization_msgs::MarkerArray>(
      collision_lab_ros::kAnimatedMarkersTopic, 100, [&](const visualization_msgs::MarkerArray::ConstPtr& a) {
        for (const auto& m : a->markers) {
          if (m.action == visualization_msgs::Marker::DELETEALL) banner_visible = false;
          if (m.ns != collision_lab_ros::markers::ns::kRejected) continue;
          banner_visible = m.action == visualization_msgs::Marker::ADD;
          if (banner_visible && !m.text.empty()) banners.insert(m.text);
        }
      });
  ros::Subscriber picture = nh.subscribe<visualization_msgs::MarkerArray>(
      collision_lab_ros::kMarkersTopic, 100, [&](const visualization_msgs::MarkerArray::ConstPtr& a) {
        for (const auto& m : a->markers) {
          if (m.ns == collision_lab_ros::markers::ns::kTitle) titles.insert(m.text);
        }
      });
  std::set<std::string> summaries, rejections;
  ros::Subscriber summary_sub = nh.subscribe<collision_lab::RunSummary>(
      collision_lab_ros::kRunSummariesTopic, 10,
      [&](const collision_lab::RunSummary::ConstPtr& s) { summaries.insert(s->run_id); });
  ros::Subscriber rejected_sub = nh.subscribe<collision_lab::Rejected>(
      collision_lab_ros::kRejectedTopic, 10,
      [&](const collision_lab::Rejected::ConstPtr& r) { rejections.insert(r->student); });
  ros::Publisher inputs = nh.advertise<collision_lab::InitialConditions>(collision_lab_ros::kInitialConditionsTopic, 10);
  ASSERT_TRUE(spinUntil([&] { return inputs.getNumSubscribers() > 0 && summary_sub.getNumPublishers() > 0 &&
                                     rejected_sub.getNumPublishers() > 0; }, kTimeout))
      << "the following node never connected";
  ASSERT_TRUE(spinUntil([&] { return !watcher.hint.empty(); }, kTimeout)) << "no hint before the first run";
  EXPECT_NE(watcher.hint.find("Following student 'ana'"), std::string::npos) << watcher.hint;

  // Ben's run and Ben's rejection: not ana's, never drawn.
  auto bens_run = input("bens_run", 100.0, {2.0, 1.0, 0.0});
  bens_run.student = "ben";
  auto bens_mistake = input("bens_mistake", 100.0, {0.0, 1.0, 2.0});
  bens_mistake.student = "ben";
  inputs.publish(bens_run);
  inputs.publish(bens_mistake);
  ASSERT_TRUE(spinUntil([&] { return summaries.count("ben.bens_run") && rejections.count("ben"); }, kTimeout))
      << "ben's run or rejection never came";

  auto anas_mistake = input("anas_mistake", 100.0, {0.0, 1.0, 2.0});
  anas_mistake.student = "ana";
  inputs.publish(anas_mistake);
  ASSERT_TRUE(spinUntil([&] { return banner_visible; }, kTimeout)) << "no banner for ana's rejected input";
  // Frames go out in order: ben's run or banner would have come before ana's banner.
  EXPECT_EQ(banners.size(), 1u);
  for (const auto& text : banners) EXPECT_NE(text.find("anas_mistake"), std::string::npos) << text;
  for (const auto& text : titles) EXPECT_EQ(text.find("ben"), std::string::npos) << text;
  EXPECT_NE(watcher.hint.find("Following student 'ana'"), std::string::npos) << "the view left its hint";

  // Longer than the 6 s the banner used to stay: still there.
  const ros::WallTime shown = ros::WallTime::now();
  ASSERT_TRUE(spinUntil([&] { return !banner_visible || ros::WallTime::now() - shown > ros::WallDuration(8.0); }, kTimeout));
  EXPECT_TRUE(banner_visible) << "ana's rejection left the screen before her next run";

  // Ana's next run takes its place.
  auto anas_run = input("anas_run", 100.0, {2.0, 1.0, 0.0});
  anas_run.student = "ana";
  inputs.publish(anas_run);
  ASSERT_TRUE(spinUntil([&] { return watcher.status.find("collisions 31     run: 31 collisions, finished") != std::string::npos; }, kTimeout))
      << "ana's run never drawn; last shown: " << watcher.status;
  EXPECT_FALSE(banner_visible) << "the rejection stayed over ana's next run";
  bool titled = false;
  for (const auto& text : titles) titled = titled || text.find("ana.anas_run") != std::string::npos;
  EXPECT_TRUE(titled);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "markers_test");
  return RUN_ALL_TESTS();
}
