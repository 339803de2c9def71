// Bags on any thread.
//
// rosbag::Bag loads its encryptor plugin through pluginlib when it is made and opened, and
// unloads it when it is destroyed; pluginlib's class loader is not thread-safe, so bags made
// on several threads at once crash the process (the web node, rebuilding runs while HTTP
// threads export CSVs, did; so did the lab node's bag writers, one per worker). Every bag
// of a multi-threaded process is made, opened, closed and destroyed under one process-wide
// lock (lockBagLifecycle): bags read come from openBagForReading, which does so; the
// recorder (run_recorder.cpp) takes the lock itself. Reading or writing an open bag needs no
// lock.
#pragma once

#include <memory>
#include <mutex>
#include <string>

namespace rosbag {
class Bag;
}

namespace collision_lab_ros {

/// The process-wide lock around making, opening, closing and destroying a rosbag::Bag.
std::unique_lock<std::mutex> lockBagLifecycle();

/// Destroys a bag under lockBagLifecycle.
struct LockedBagDeleter {
  void operator()(rosbag::Bag* bag) const;
};
using ReadableBag = std::unique_ptr<rosbag::Bag, LockedBagDeleter>;

/// Writing or reading a long run's bag grows the heap by hundreds of MB (rosbag indexes
/// every message), and glibc keeps the freed pages: after a bag of at least
/// kReleaseAfterBagBytes, releaseMemoryAfterBag returns them to the system (malloc_trim), so
/// a node's resident memory does not keep a big run's high-water mark. Call it once the bag
/// is closed; smaller bags cost nothing.
constexpr unsigned long long kReleaseAfterBagBytes = 16ULL << 20;  ///< [bytes]
void releaseMemoryAfterBag(const std::string& bag_path);

/// The bag at bag_path, open for reading. Throws rosbag::BagException (a
/// std::runtime_error) when it cannot be opened.
ReadableBag openBagForReading(const std::string& bag_path);

}  // namespace collision_lab_ros
