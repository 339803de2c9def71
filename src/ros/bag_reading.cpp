#include "collision_lab/ros/bag_reading.h"

#include <malloc.h>
#include <sys/stat.h>

#include <mutex>

#include <rosbag/bag.h>

namespace collision_lab_ros {
namespace {

std::mutex& pluginLoaderMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

std::unique_lock<std::mutex> lockBagLifecycle() { return std::unique_lock<std::mutex>(pluginLoaderMutex()); }

void LockedBagDeleter::operator()(rosbag::Bag* bag) const {
  std::lock_guard<std::mutex> lock(pluginLoaderMutex());
  delete bag;
}

void releaseMemoryAfterBag(const std::string& bag_path) {
  struct stat info {};
  if (::stat(bag_path.c_str(), &info) == 0 && static_cast<unsigned long long>(info.st_size) >= kReleaseAfterBagBytes) {
    malloc_trim(0);
  }
}

ReadableBag openBagForReading(const std::string& bag_path) {
  std::lock_guard<std::mutex> lock(pluginLoaderMutex());
  std::unique_ptr<rosbag::Bag> bag = std::make_unique<rosbag::Bag>();
  bag->open(bag_path, rosbag::bagmode::Read);
  return ReadableBag(bag.release());
}

}  // namespace collision_lab_ros
