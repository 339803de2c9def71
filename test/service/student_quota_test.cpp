// A student's share of the lab's disk (service/student_quota.h): bags on disk counted at the
// student's first run and again when they seem over (deleted bags come back), running runs'
// bytes counted as they record, and given way to the bag's size when the run ends.
#include <cstdint>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "collision_lab/service/student_quota.h"

namespace {

using collision_lab::service::StudentQuota;

TEST(StudentQuota, BagsOnDiskAndRunningRunsCountUntilTheQuota) {
  std::map<std::string, std::uint64_t> on_disk = {{"ana", 600}, {"ben", 0}};
  int counts = 0;
  StudentQuota quota(1000, [&](const std::string& student) {
    ++counts;
    return on_disk[student];
  });
  EXPECT_EQ(quota.admissionUse("ana"), 600u);  // counted from disk at the first run
  EXPECT_EQ(counts, 1);
  EXPECT_FALSE(quota.recorded("ana", 300));  // a running run: 900 of 1,000
  EXPECT_EQ(quota.admissionUse("ana"), 900u);
  EXPECT_EQ(counts, 1);  // under the quota: not counted again
  EXPECT_TRUE(quota.recorded("ana", 100));  // 1,000: over
  EXPECT_FALSE(quota.recorded("ben", 100));  // a classmate has a share of their own

  // The run ends: its 400 recorded (serialized) bytes give way to its bag's 150 on disk,
  // without a count on disk (ana is under the quota).
  quota.ended("ana", 400, 150);
  EXPECT_EQ(quota.admissionUse("ana"), 750u);
  EXPECT_EQ(counts, 1);
}

TEST(StudentQuota, AStudentOverTheQuotaIsCountedAgainSoDeletedBagsComeBack) {
  using namespace std::chrono_literals;
  std::uint64_t ana_on_disk = 1200;
  int counts = 0;
  StudentQuota quota(
      1000,
      [&](const std::string&) {
        ++counts;
        return ana_on_disk;
      },
      1s);
  const auto t0 = StudentQuota::Clock::now();
  EXPECT_GE(quota.admissionUse("ana", t0), quota.maxBytes());
  ana_on_disk = 200;  // the teacher deleted some of ana's bags
  EXPECT_EQ(quota.admissionUse("ana", t0 + 500ms), 1200u);  // a burst of sends reads no files
  EXPECT_EQ(counts, 1);
  EXPECT_EQ(quota.admissionUse("ana", t0 + 1s), 200u);
  EXPECT_EQ(counts, 2);
}

TEST(StudentQuota, AnonymousRunsAndAQuotaOfZeroCountNothing) {
  int counts = 0;
  StudentQuota none(0, [&](const std::string&) { return ++counts, std::uint64_t{5000}; });
  EXPECT_FALSE(none.applies("ana"));
  EXPECT_EQ(none.admissionUse("ana"), 0u);
  EXPECT_FALSE(none.recorded("ana", 1u << 30));
  StudentQuota quota(1000, [&](const std::string&) { return ++counts, std::uint64_t{5000}; });
  EXPECT_FALSE(quota.applies(""));
  EXPECT_EQ(quota.admissionUse(""), 0u);
  EXPECT_FALSE(quota.recorded("", 1u << 30));
  EXPECT_EQ(counts, 0);
}

}  // namespace
