// Each student's share of the lab's disk (ROS-free, thread-safe): the bytes of their bags as
// they stand on disk, plus what their running runs have recorded so far. A student over
// max_bytes starts no run, and their running runs stop, so that one student's bags cannot
// take the disk the class shares (the free-space floor would then refuse everyone).
// Anonymous runs (no student name) are the lab's own and have no quota.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>

namespace collision_lab::service {

class StudentQuota {
 public:
  /// [bytes] of a student's bags on disk, counted afresh (e.g. from the run index).
  using CountOnDisk = std::function<std::uint64_t(const std::string& student)>;

  using Clock = std::chrono::steady_clock;

  /// max_bytes: per student [bytes], 0 for no quota. A student over it is counted on disk
  /// again at most once per recount_after (a burst of their inputs reads no more files).
  StudentQuota(std::uint64_t max_bytes, CountOnDisk count_on_disk, Clock::duration recount_after = std::chrono::seconds(1))
      : max_bytes_(max_bytes), count_on_disk_(std::move(count_on_disk)), recount_after_(recount_after) {}

  std::uint64_t maxBytes() const { return max_bytes_; }
  bool applies(const std::string& student) const { return max_bytes_ > 0 && !student.empty(); }

  /// [bytes] the student uses, for a new run's admission: their bags on disk, counted afresh
  /// at their first run and when they seem over (bags may have been deleted), plus what
  /// their running runs have recorded.
  std::uint64_t admissionUse(const std::string& student, Clock::time_point now = Clock::now()) {
    if (!applies(student)) return 0;
    bool count = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const Use& use = uses_[student];
      count = !use.counted || (use.on_disk + use.recording >= max_bytes_ && now - use.counted_at >= recount_after_);
    }
    if (count) {
      const std::uint64_t on_disk = count_on_disk_ ? count_on_disk_(student) : 0;  // outside the lock: it reads files
      std::lock_guard<std::mutex> lock(mutex_);
      Use& use = uses_[student];
      use.on_disk = on_disk;
      use.counted = true;
      use.counted_at = now;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    const Use& use = uses_[student];
    return use.on_disk + use.recording;
  }

  /// A running run of student recorded `bytes` more. Returns true when the student is now
  /// over the quota.
  bool recorded(const std::string& student, std::uint64_t bytes) {
    if (!applies(student)) return false;
    std::lock_guard<std::mutex> lock(mutex_);
    Use& use = uses_[student];
    use.recording += bytes;
    return use.on_disk + use.recording >= max_bytes_;
  }

  /// A run of student ended: the `recorded` bytes it counted give way to its bag's size on disk.
  void ended(const std::string& student, std::uint64_t recorded, std::uint64_t bag_bytes) {
    if (!applies(student)) return;
    std::lock_guard<std::mutex> lock(mutex_);
    Use& use = uses_[student];
    use.recording -= std::min(use.recording, recorded);
    use.on_disk += bag_bytes;
  }

 private:
  struct Use {
    std::uint64_t on_disk = 0;    ///< [bytes] of ended runs' bags
    std::uint64_t recording = 0;  ///< [bytes] recorded by running runs (serialized: at least their share of the disk)
    bool counted = false;         ///< on_disk was counted from disk once
    Clock::time_point counted_at;
  };

  const std::uint64_t max_bytes_;
  const CountOnDisk count_on_disk_;
  const Clock::duration recount_after_;
  std::mutex mutex_;
  std::map<std::string, Use> uses_;
};

}  // namespace collision_lab::service
