#include "collision_lab/ros/run_recorder.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace collision_lab_ros {

namespace fs = std::filesystem;

namespace {
constexpr char kActiveSuffix[] = ".active";
}

std::string bagPath(const std::string& directory, const std::string& run_id) {
  return (fs::path(directory) / (run_id + ".bag")).string();
}

bool bagExists(const std::string& directory, const std::string& run_id) {
  std::error_code ec;
  const std::string path = bagPath(directory, run_id);
  return fs::exists(path, ec) || fs::exists(path + kActiveSuffix, ec);
}

std::string expandUser(const std::string& path) {
  if (path.empty() || path[0] != '~') return path;
  const char* home = std::getenv("HOME");
  return std::string(home ? home : "") + path.substr(1);
}

RunRecorder::RunRecorder(const std::string& directory, const std::string& run_id)
    : path_(bagPath(directory, run_id)), active_path_(path_ + kActiveSuffix) {
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec) {
    fail("cannot create bag directory " + directory + ": " + ec.message());
    return;
  }
  try {
    bag_ = std::make_unique<rosbag::Bag>();
    bag_->setCompression(rosbag::compression::LZ4);
    bag_->open(active_path_, rosbag::bagmode::Write);
  } catch (const std::exception& e) {
    bag_.reset();
    fail("cannot open bag " + active_path_ + ": " + e.what());
  }
}

RunRecorder::~RunRecorder() { close(); }

bool RunRecorder::close() {
  if (!bag_) return ok();
  try {
    bag_->close();
  } catch (const std::exception& e) {
    fail(std::string("closing the bag failed: ") + e.what());
  }
  bag_.reset();
  if (ok()) {
    std::error_code ec;
    fs::rename(active_path_, path_, ec);
    if (ec) fail("cannot rename " + active_path_ + " to " + path_ + ": " + ec.message());
  }
  return ok();
}

void RunRecorder::fail(const std::string& what) {
  if (error_.empty()) error_ = what;
}

}  // namespace collision_lab_ros
