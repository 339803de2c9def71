// The run timeline (no master): the scale rule of RunSummary.msg, nanosecond stamps and
// saturation. Expected values are written out by hand from the rule.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "collision_lab/ros/run_timeline.h"

namespace {

using collision_lab_ros::chooseTimelineScale;
using collision_lab_ros::firstContactTime;
using collision_lab_ros::RunTimeline;
namespace core = collision_lab::core;
constexpr double kInf = std::numeric_limits<double>::infinity();

collision_lab::core::Scene scene(std::vector<double> x, std::vector<double> v) {
  return {std::vector<double>(x.size(), 1.0), x, v, {}};
}

TEST(FirstContactTime, GapOverClosingSpeedOfTheFirstPair) {
  EXPECT_EQ(firstContactTime(scene({2, 0, -2}, {-1, 0.5, 1})), 2.0 / 1.5);  // AB: 2 m at 1.5 m/s; BC never
  EXPECT_EQ(firstContactTime(scene({3, 1, 0}, {-0.5, 0, 2})), 0.5);         // BC: 1 m at 2 m/s; AB after 4 s
  EXPECT_FALSE(firstContactTime(scene({2, 1, 0}, {1, 0, -1})));
  EXPECT_EQ(firstContactTime(scene({9, 5, 4, 0}, {0, 0, -1, 1})), 2.0);  // the last pair: 4 m at 2 m/s
  EXPECT_FALSE(firstContactTime(scene({0}, {1})));
}

TEST(TimelineScale, OneForOrdinaryScenesAPowerOfTenOtherwise) {
  EXPECT_EQ(chooseTimelineScale(std::nullopt), 1.0);  // nothing collides
  EXPECT_EQ(chooseTimelineScale(1e-3), 1.0);
  EXPECT_EQ(chooseTimelineScale(1.0), 1.0);
  EXPECT_EQ(chooseTimelineScale(1e3), 1.0);
  // Outside [1e-3, 1e3] s: the first contact lands 1 to 10 bag seconds after the start.
  EXPECT_EQ(chooseTimelineScale(9.99e-4), 1e4);
  EXPECT_EQ(chooseTimelineScale(1e-9), 1e9);
  EXPECT_EQ(chooseTimelineScale(5e-7), 1e7);
  EXPECT_EQ(chooseTimelineScale(1000.5), 1e-3);
  EXPECT_EQ(chooseTimelineScale(3e12), 1e-12);
  // The exponent is clamped to +-300: the most that 10^k keeps normal.
  EXPECT_EQ(chooseTimelineScale(1e-320), 1e300);
  EXPECT_EQ(chooseTimelineScale(0.0), 1e300);
  EXPECT_EQ(chooseTimelineScale(kInf), 1e-300);
}

TEST(RunTimeline, StampsAreStartPlusScaledTimeToTheNanosecond) {
  const ros::Time start(1'700'000'000, 999'999'999);
  RunTimeline timeline(start, 1.0);
  EXPECT_EQ(timeline.stamp(0.0), start);
  EXPECT_EQ(timeline.stamp(0.25), ros::Time(1'700'000'001, 249'999'999));
  EXPECT_EQ(timeline.stamp(1.0 + 1e-9), ros::Time(1'700'000'002, 0));
  EXPECT_EQ(timeline.stamp(4e-10), start);  // rounds to the nanosecond
  EXPECT_EQ(timeline.stamp(6e-10), ros::Time(1'700'000'001, 0));
  EXPECT_FALSE(timeline.saturated());

  RunTimeline fast(start, 1e9);  // a nanosecond scene
  EXPECT_EQ(fast.stamp(2.5e-9), ros::Time(1'700'000'003, 499'999'999));
}

TEST(RunTimeline, SaturatesAtAThousandMillionSecondsAndSaysSo) {
  const ros::Time start(1'700'000'000, 0);
  RunTimeline timeline(start, 1.0);
  EXPECT_EQ(timeline.stamp(1e9), ros::Time(2'700'000'000, 0));
  EXPECT_FALSE(timeline.saturated());
  EXPECT_EQ(timeline.stamp(1e15), ros::Time(2'700'000'000, 0));
  EXPECT_TRUE(timeline.saturated());
  RunTimeline nan(start, 1.0);
  EXPECT_EQ(nan.stamp(std::nan("")), ros::Time(2'700'000'000, 0));
  EXPECT_TRUE(nan.saturated());
  // Near the end of ros::Time, the end of ros::Time is the limit.
  RunTimeline late(ros::Time(4'000'000'000u, 0), 1.0);
  EXPECT_EQ(late.stamp(5e8), ros::TIME_MAX);
  EXPECT_TRUE(late.saturated());
}

}  // namespace
