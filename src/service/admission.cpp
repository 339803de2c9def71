#include "collision_lab/service/admission.h"

#include <sys/statvfs.h>

#include <iomanip>
#include <sstream>
#include <utility>

namespace collision_lab::service {

std::optional<double> freeMegabytes(const std::string& directory) {
  struct statvfs space {};
  if (::statvfs(directory.c_str(), &space) != 0) return std::nullopt;
  return static_cast<double>(space.f_bavail) * static_cast<double>(space.f_frsize) / 1e6;
}

Admission::Admission(Options options, StudentQuota* quota, FreeSpace free_space)
    : options_(std::move(options)), quota_(quota), free_space_(std::move(free_space)) {}

std::optional<Refusal> Admission::check(const std::string& student) const {
  if (!options_.record) return std::nullopt;
  if (auto refusal = checkFreeSpace()) return refusal;
  return checkQuota(student);
}

bool Admission::underFloor(std::uint64_t waiting_bytes) const {
  if (!options_.record || options_.min_free_space_mb <= 0) return false;
  const auto free_mb = freeSpaceMb();
  return free_mb && *free_mb - 1e-6 * static_cast<double>(waiting_bytes) < options_.min_free_space_mb;
}

std::optional<Refusal> Admission::checkFreeSpace() const {
  if (options_.min_free_space_mb <= 0) return std::nullopt;
  const auto free_mb = freeSpaceMb();
  if (!free_mb || *free_mb >= options_.min_free_space_mb) return std::nullopt;
  std::ostringstream message;
  message << "the lab's bag folder " << options_.bag_directory << " has " << std::fixed << std::setprecision(1)
          << *free_mb << " MB free, under the node's floor ~min_free_space_mb = " << options_.min_free_space_mb
          << " MB: no run starts until space is freed (ask the teacher), so that no bag is cut short";
  return Refusal{Refusal::Reason::kDiskSpace, "bag_directory", message.str()};
}

std::optional<Refusal> Admission::checkQuota(const std::string& student) const {
  if (!quota_ || !quota_->applies(student)) return std::nullopt;
  const std::uint64_t used = quota_->admissionUse(student);
  if (used < quota_->maxBytes()) return std::nullopt;
  std::ostringstream message;
  message << "student '" << student << "' has " << std::fixed << std::setprecision(1) << 1e-6 * static_cast<double>(used)
          << " MB of bags in this lab, the node's ~max_student_bag_mb = " << options_.max_student_bag_mb
          << " MB or more: no run of theirs starts until the teacher deletes some of their bags";
  return Refusal{Refusal::Reason::kStudentQuota, "student", message.str()};
}

}  // namespace collision_lab::service
