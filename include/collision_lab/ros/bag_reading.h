// Bags opened for reading on any thread.
//
// rosbag::Bag loads its encryptor plugin through pluginlib when it is made and opened, and
// unloads it when it is destroyed; pluginlib's class loader is not thread-safe, so bags made
// on several threads at once crash the process (the web node, rebuilding runs while HTTP
// threads export CSVs, did). Every bag that a multi-threaded process reads comes from
// openBagForReading, which makes, opens and destroys it under one process-wide lock; reading
// the opened bag needs no lock.
#pragma once

#include <memory>
#include <string>

namespace rosbag {
class Bag;
}

namespace collision_lab_ros {

/// Destroys a bag under the lock of openBagForReading.
struct LockedBagDeleter {
  void operator()(rosbag::Bag* bag) const;
};
using ReadableBag = std::unique_ptr<rosbag::Bag, LockedBagDeleter>;

/// The bag at bag_path, open for reading. Throws rosbag::BagException (a
/// std::runtime_error) when it cannot be opened.
ReadableBag openBagForReading(const std::string& bag_path);

}  // namespace collision_lab_ros
