// Whether the lab takes a new run now, and whether a recording run may go on (ROS-free):
// the free-space floor of the bag folder the class shares, and each student's quota of bags
// (StudentQuota). A refusal says why in a student's words, with its numbers and units; the
// node turns it into a Rejected (DISK_SPACE, STUDENT_QUOTA). A lab that records no bags
// refuses nothing here.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "collision_lab/service/student_quota.h"

namespace collision_lab::service {

/// [MB] free to an unprivileged writer in the file system of directory (statvfs); none when
/// it cannot be read.
std::optional<double> freeMegabytes(const std::string& directory);

struct Refusal {
  enum class Reason { kDiskSpace, kStudentQuota };
  Reason reason;
  std::string field;    ///< what it is about: "bag_directory" (the lab's) or "student"
  std::string message;  ///< why, and what frees it
};

class Admission {
 public:
  /// [MB] free in a directory, none when unknown: freeMegabytes, or a test's disk.
  using FreeSpace = std::function<std::optional<double>(const std::string& directory)>;

  struct Options {
    bool record = true;               ///< false: no bags, so neither the floor nor quotas apply
    std::string bag_directory;
    double min_free_space_mb = 0.0;   ///< [MB] the floor; 0: none
    double max_student_bag_mb = 0.0;  ///< [MB] the quota, as the message names it (quota holds it in bytes)
  };

  /// quota: each student's bags (null: no quotas); it outlives this.
  Admission(Options options, StudentQuota* quota, FreeSpace free_space = freeMegabytes);

  /// Why a new run of student is not taken now, if it is not: the floor first (it refuses
  /// the whole class), then the student's quota.
  std::optional<Refusal> check(const std::string& student) const;

  /// True when a recording run is to stop at the floor: the free space, less the
  /// `waiting_bytes` the bag writers hold and will write, is under it.
  bool underFloor(std::uint64_t waiting_bytes) const;

  /// [MB] free in the bag folder now; none when it cannot be read.
  std::optional<double> freeSpaceMb() const { return free_space_(options_.bag_directory); }
  const Options& options() const { return options_; }

 private:
  std::optional<Refusal> checkFreeSpace() const;
  std::optional<Refusal> checkQuota(const std::string& student) const;

  Options options_;
  StudentQuota* quota_;
  FreeSpace free_space_;
};

}  // namespace collision_lab::service
