// Whether the lab takes a run (service/admission.h), on a disk the test sets: the bag
// folder's floor refuses the whole class and names the free space, a student over their
// quota is refused alone, a recording run stops at the floor counting the bytes still to be
// written, and a lab that records no bags refuses nothing. No root, no tmpfs (disk_test has
// the real disk).
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "collision_lab/service/admission.h"

namespace {

using collision_lab::service::Admission;
using collision_lab::service::Refusal;
using collision_lab::service::StudentQuota;

struct Disk {
  std::optional<double> free_mb;
  std::string asked;  ///< the folder last looked at
  Admission::FreeSpace probe() {
    return [this](const std::string& directory) {
      asked = directory;
      return free_mb;
    };
  }
};

Admission::Options lab(double floor_mb, double quota_mb = 0.0) {
  return Admission::Options{true, "/srv/bags", floor_mb, quota_mb};
}

TEST(Admission, UnderTheFloorEveryoneIsRefusedWithTheFreeSpaceNamed) {
  Disk disk{7.84};
  const Admission admission(lab(8.0), nullptr, disk.probe());
  const auto refusal = admission.check("ana");
  ASSERT_TRUE(refusal);
  EXPECT_EQ(refusal->reason, Refusal::Reason::kDiskSpace);
  EXPECT_EQ(refusal->field, "bag_directory");
  EXPECT_EQ(disk.asked, "/srv/bags");
  EXPECT_NE(refusal->message.find("/srv/bags has 7.8 MB free"), std::string::npos) << refusal->message;
  EXPECT_NE(refusal->message.find("~min_free_space_mb = 8"), std::string::npos) << refusal->message;
  EXPECT_TRUE(admission.check(""));  // anonymous runs too: the disk is the class's

  disk.free_mb = 8.0;  // at the floor: taken
  EXPECT_FALSE(admission.check("ana"));
  disk.free_mb = std::nullopt;  // a folder that cannot be read refuses nothing here (the bag says why)
  EXPECT_FALSE(admission.check("ana"));
}

TEST(Admission, NoFloorAndNoBagsRefuseNothing) {
  Disk disk{0.0};
  EXPECT_FALSE(Admission(lab(0.0), nullptr, disk.probe()).check("ana"));
  EXPECT_FALSE(Admission(lab(0.0), nullptr, disk.probe()).underFloor(1u << 30));
  auto not_recording = lab(100.0);
  not_recording.record = false;
  StudentQuota quota(1, [](const std::string&) { return std::uint64_t{1} << 40; });
  const Admission admission(not_recording, &quota, disk.probe());
  EXPECT_FALSE(admission.check("ana"));
  EXPECT_FALSE(admission.underFloor(0));
}

TEST(Admission, AStudentOverTheirQuotaIsRefusedAloneAndTheFloorComesFirst) {
  Disk disk{1000.0};
  std::map<std::string, std::uint64_t> bags = {{"ben", 2'500'000}, {"cy", 100}};
  StudentQuota quota(2'000'000, [&](const std::string& student) { return bags[student]; });
  const Admission admission(lab(100.0, 2.0), &quota, disk.probe());
  const auto refusal = admission.check("ben");
  ASSERT_TRUE(refusal);
  EXPECT_EQ(refusal->reason, Refusal::Reason::kStudentQuota);
  EXPECT_EQ(refusal->field, "student");
  EXPECT_NE(refusal->message.find("student 'ben' has 2.5 MB of bags"), std::string::npos) << refusal->message;
  EXPECT_NE(refusal->message.find("~max_student_bag_mb = 2.0 MB"), std::string::npos) << refusal->message;
  EXPECT_FALSE(admission.check("cy"));
  EXPECT_FALSE(admission.check(""));  // the lab's own runs have no quota

  disk.free_mb = 50.0;  // under the floor: the class's reason, whoever asks
  EXPECT_EQ(admission.check("ben")->reason, Refusal::Reason::kDiskSpace);
  EXPECT_EQ(admission.check("cy")->reason, Refusal::Reason::kDiskSpace);
}

TEST(Admission, ARecordingRunStopsAtTheFloorCountingWhatIsStillToBeWritten) {
  Disk disk{110.0};
  const Admission admission(lab(100.0), nullptr, disk.probe());
  EXPECT_FALSE(admission.underFloor(0));
  EXPECT_FALSE(admission.underFloor(9'999'999));  // 100.000001 MB left
  EXPECT_TRUE(admission.underFloor(10'000'001));  // 99.999999 MB left once written
  disk.free_mb = 99.0;
  EXPECT_TRUE(admission.underFloor(0));
  disk.free_mb = std::nullopt;
  EXPECT_FALSE(admission.underFloor(1u << 30));
}

TEST(Admission, FreeMegabytesReadsTheRealDisk) {
  const auto free_mb = collision_lab::service::freeMegabytes("/");
  ASSERT_TRUE(free_mb);
  EXPECT_GE(*free_mb, 0.0);
  EXPECT_FALSE(collision_lab::service::freeMegabytes("/no/such/folder/for/collision_lab"));
}

}  // namespace
