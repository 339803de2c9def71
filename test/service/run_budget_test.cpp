// A run's budget (service/run_budget.h): the lab's ceilings lowered, never raised, by the
// input, and the ending the service gives a run it stopped, in the words the node publishes
// (docs/ros.md "Service limits").
#include "collision_lab/service/run_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace collision_lab::service {
namespace {

TEST(RunBudget, AnInputMayLowerTheLabsLimitsNeverRaiseThem) {
  const Budget lab{1000, 60.0, 1 << 20};
  const RunLimits lower = limitsOf(lab, {10, 1.5, 4096});
  EXPECT_EQ(lower.max_collisions, 10u);
  EXPECT_FALSE(lower.collision_ceiling);
  EXPECT_EQ(lower.max_run_seconds, 1.5);
  EXPECT_TRUE(lower.time_from_input);
  EXPECT_EQ(lower.max_bag_bytes, 4096u);
  EXPECT_TRUE(lower.bag_from_input);

  const RunLimits higher = limitsOf(lab, {5000, 600.0, 1 << 30});
  EXPECT_EQ(higher.max_collisions, 1000u);
  EXPECT_TRUE(higher.collision_ceiling) << "the lab's ceiling lowered the input's cap";
  EXPECT_EQ(higher.max_run_seconds, 60.0);
  EXPECT_FALSE(higher.time_from_input);
  EXPECT_EQ(higher.max_bag_bytes, std::uint64_t{1} << 20);
  EXPECT_FALSE(higher.bag_from_input);
}

TEST(RunBudget, ZeroAndNonsenseAskNothing) {
  const RunLimits asked_nothing = limitsOf({1000, 60.0, 4096}, {0, 0.0, 0});
  EXPECT_EQ(asked_nothing.max_collisions, 1000u);
  EXPECT_FALSE(asked_nothing.collision_ceiling) << "a cap of 0 takes the lab's, it is not lowered";
  EXPECT_EQ(asked_nothing.max_run_seconds, 60.0);
  EXPECT_EQ(asked_nothing.max_bag_bytes, 4096u);
  for (double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    EXPECT_EQ(limitsOf({0, 60.0, 0}, {0, bad, 0}).max_run_seconds, 60.0) << bad;
  }
  // A lab without limits takes the input's.
  const RunLimits open = limitsOf({0, 0.0, 0}, {7, 2.0, 100});
  EXPECT_EQ(open.max_collisions, 7u);
  EXPECT_EQ(open.max_run_seconds, 2.0);
  EXPECT_EQ(open.max_bag_bytes, 100u);
  const RunLimits none = limitsOf({0, 0.0, 0}, {0, 0.0, 0});
  EXPECT_EQ(none.max_collisions, 0u);
  EXPECT_EQ(none.max_run_seconds, 0.0);
  EXPECT_EQ(none.max_bag_bytes, 0u);
}

TEST(RunBudget, EachStopSaysItsLimitAndWhoseItWas) {
  const RunLimits limits = limitsOf({1000, 60.0, 20000}, {0, 0.5, 0});
  const RunEnd cancelled{"CANCELLED", "cancelled after 77 collisions", 77};
  StopContext context;
  context.stopped_by = "the teacher";
  context.student = "ana";
  context.min_free_space_mb = 100;
  context.max_student_bag_mb = 50;

  const auto time = serviceStop(StopCause::kTimeLimit, limits, cancelled, context);
  ASSERT_TRUE(time);
  EXPECT_EQ(time->stop_reason, "SERVICE_TIME_LIMIT");
  EXPECT_EQ(time->truncation_reason,
            "stopped by the time limit of 0.5 s (the input's max_run_seconds) after 77 collisions, at its last "
            "certified impact");
  EXPECT_FALSE(time->cancelled);

  const auto bag = serviceStop(StopCause::kBagLimit, limits, cancelled, context);
  ASSERT_TRUE(bag);
  EXPECT_EQ(bag->stop_reason, "SERVICE_BAG_LIMIT");
  EXPECT_NE(bag->truncation_reason.find("20000 bytes (the node's ~max_bag_bytes)"), std::string::npos)
      << bag->truncation_reason;

  const auto disk = serviceStop(StopCause::kDiskSpace, limits, cancelled, context);
  ASSERT_TRUE(disk);
  EXPECT_EQ(disk->stop_reason, "SERVICE_DISK_SPACE");
  EXPECT_NE(disk->truncation_reason.find("~min_free_space_mb = 100 MB"), std::string::npos);

  const auto quota = serviceStop(StopCause::kStudentQuota, limits, cancelled, context);
  ASSERT_TRUE(quota);
  EXPECT_EQ(quota->stop_reason, "SERVICE_STUDENT_QUOTA");
  EXPECT_NE(quota->truncation_reason.find("student 'ana''s bags passed the node's ~max_student_bag_mb = 50 MB"),
            std::string::npos);

  const auto cancel = serviceStop(StopCause::kCancel, limits, cancelled, context);
  ASSERT_TRUE(cancel);
  EXPECT_EQ(cancel->stop_reason, "CANCELLED");
  EXPECT_TRUE(cancel->cancelled);
  EXPECT_EQ(cancel->truncation_reason, "cancelled after 77 collisions (cancelled by the teacher)");
}

TEST(RunBudget, ACapIsTheServicesOnlyWhenItsCeilingLoweredTheInputs) {
  StopContext context;
  context.asked_max_collisions = 5000;
  const RunEnd capped{"CAP", "stopped at the cap", 1000};
  const auto ceiling = serviceStop(StopCause::kNone, limitsOf({1000, 0, 0}, {5000, 0, 0}), capped, context);
  ASSERT_TRUE(ceiling);
  EXPECT_EQ(ceiling->stop_reason, "SERVICE_COLLISION_LIMIT");
  EXPECT_EQ(ceiling->truncation_reason,
            "stopped at the node's ~max_collisions = 1000, which lowered the input's max_collisions = 5000");
  // The input's own cap, and a run that ended by itself, are not the service's.
  EXPECT_FALSE(serviceStop(StopCause::kNone, limitsOf({1000, 0, 0}, {500, 0, 0}), capped, context));
  EXPECT_FALSE(serviceStop(StopCause::kTimeLimit, limitsOf({0, 1.0, 0}, {}), {"FINISHED", "", 31}, context))
      << "a run that finished as its time ran out finished";
}

}  // namespace
}  // namespace collision_lab::service
