// Per-run bags without a master: final name only when closed, failures reported.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <ros/time.h>
#include <rosbag/view.h>

#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/run_recorder.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_ros::bagExists;
using collision_lab_ros::RunRecorder;

/// A fresh directory per test, removed afterwards.
class RunRecorderTest : public testing::Test {
 protected:
  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/collision_lab_recorder_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

TEST_F(RunRecorderTest, WritesUnderActiveNameAndRenamesOnClose) {
  const ros::Time stamp(1.5e9);
  collision_lab::RunSummary summary;
  summary.run_id = "r1";
  summary.collision_count = 7;
  {
    RunRecorder recorder(dir_ + "/nested", "r1");
    ASSERT_TRUE(recorder.ok()) << recorder.error();
    EXPECT_EQ(recorder.path(), dir_ + "/nested/r1.bag");
    recorder.write("/collision_lab/run_summaries", stamp, summary);
    EXPECT_TRUE(fs::exists(dir_ + "/nested/r1.bag.active"));
    EXPECT_FALSE(fs::exists(dir_ + "/nested/r1.bag"));
    EXPECT_TRUE(bagExists(dir_ + "/nested", "r1"));
    EXPECT_TRUE(recorder.close());
  }
  EXPECT_FALSE(fs::exists(dir_ + "/nested/r1.bag.active"));
  ASSERT_TRUE(fs::exists(dir_ + "/nested/r1.bag"));
  EXPECT_TRUE(bagExists(dir_ + "/nested", "r1"));
  EXPECT_FALSE(bagExists(dir_ + "/nested", "r2"));

  rosbag::Bag bag(dir_ + "/nested/r1.bag", rosbag::bagmode::Read);
  rosbag::View view(bag);
  ASSERT_EQ(view.size(), 1u);
  const auto m = *view.begin();
  EXPECT_EQ(m.getTopic(), "/collision_lab/run_summaries");
  EXPECT_EQ(m.getTime(), stamp);
  EXPECT_EQ(m.instantiate<collision_lab::RunSummary>()->collision_count, 7u);
}

TEST_F(RunRecorderTest, UncreatableDirectoryIsReportedNotThrown) {
  std::ofstream(dir_ + "/file") << "x";
  RunRecorder recorder(dir_ + "/file/bags", "r1");
  EXPECT_FALSE(recorder.ok());
  EXPECT_NE(recorder.error().find(dir_ + "/file/bags"), std::string::npos) << recorder.error();
  recorder.write("/t", ros::Time(1.5e9), collision_lab::RunSummary());
  EXPECT_FALSE(recorder.close());
}

TEST_F(RunRecorderTest, WriteAtTimeZeroFailsCleanly) {
  RunRecorder recorder(dir_, "r0");
  ASSERT_TRUE(recorder.ok());
  recorder.write("/t", ros::Time(0), collision_lab::RunSummary());
  EXPECT_FALSE(recorder.ok());
  EXPECT_FALSE(recorder.close());
  EXPECT_FALSE(fs::exists(dir_ + "/r0.bag"));
}

TEST(ExpandUser, ExpandsLeadingTildeOnly) {
  setenv("HOME", "/home/lab", 1);
  EXPECT_EQ(collision_lab_ros::expandUser("~/.ros/x"), "/home/lab/.ros/x");
  EXPECT_EQ(collision_lab_ros::expandUser("/a/~b"), "/a/~b");
}

}  // namespace
