#include "collision_lab/ros/run_recorder.h"

#include "collision_lab/ros/bag_reading.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <ros/console.h>

namespace collision_lab_ros {

namespace fs = std::filesystem;

namespace {
constexpr char kActiveSuffix[] = ".active";

/// Renames from to to unless to exists (then fails with EEXIST). Returns 0 or an errno.
int renameNoReplace(const std::string& from, const std::string& to) {
  if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return 0;
  if (errno != EINVAL && errno != ENOSYS) return errno;
  // A file system without RENAME_NOREPLACE: link() never replaces either.
  if (::link(from.c_str(), to.c_str()) != 0) return errno;
  return ::unlink(from.c_str()) == 0 ? 0 : errno;
}

/// The claims this process holds: a claimed .bag.active path -> the descriptor that holds
/// its flock(LOCK_EX) until releaseBagClaim (the process's death releases every one).
std::mutex claims_mutex;
std::map<std::string, int>& heldClaims() {
  static std::map<std::string, int> claims;
  return claims;
}
}  // namespace

void releaseBagClaim(const std::string& active_path) {
  int fd = -1;
  {
    std::lock_guard<std::mutex> lock(claims_mutex);
    const auto it = heldClaims().find(active_path);
    if (it == heldClaims().end()) return;
    fd = it->second;
    heldClaims().erase(it);
  }
  ::close(fd);  // releases the flock
}

bool bagClaimHeld(const std::string& active_path) {
  std::lock_guard<std::mutex> lock(claims_mutex);
  return heldClaims().count(active_path) > 0;
}

std::string bagPath(const std::string& directory, const std::string& run_id) {
  return (fs::path(directory) / (run_id + ".bag")).string();
}

BagClaim claimBag(const std::string& directory, const std::string& run_id, std::string& error) {
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec) {
    error = "cannot create bag directory " + directory + ": " + ec.message();
    return BagClaim::kFailed;
  }
  const std::string path = bagPath(directory, run_id);
  const std::string active = path + kActiveSuffix;
  // The .active name appears already locked: the claim file is made and flock'ed under a
  // private name, then renamed to the .active name without replacing (EEXIST: taken). So a
  // recovering node (recoverActiveBags) never sees a live claim unlocked.
  static std::atomic<std::uint64_t> claims_made{0};
  const std::string pending =
      active + kClaimInfix + std::to_string(::getpid()) + "." + std::to_string(++claims_made);
  const int fd = ::open(pending.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    error = "cannot create " + pending + ": " + std::strerror(errno);
    return BagClaim::kFailed;
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    error = "cannot lock " + pending + ": " + std::strerror(errno);
    ::close(fd);
    ::unlink(pending.c_str());
    return BagClaim::kFailed;
  }
  const int renamed = renameNoReplace(pending, active);
  if (renamed != 0) {
    ::close(fd);
    ::unlink(pending.c_str());
    if (renamed == EEXIST) return BagClaim::kTaken;
    error = "cannot create " + active + ": " + std::strerror(renamed);
    return BagClaim::kFailed;
  }
  if (fs::symlink_status(path, ec).type() == fs::file_type::not_found) {
    std::lock_guard<std::mutex> lock(claims_mutex);
    const auto [it, inserted] = heldClaims().emplace(active, fd);
    if (!inserted) {  // a claim of this process whose file someone removed: keep the new one
      ::close(it->second);
      it->second = fd;
    }
    return BagClaim::kClaimed;
  }
  // A finished bag of that name (or its status unknown): give the name up.
  fs::remove(active, ec);
  ::close(fd);
  return BagClaim::kTaken;
}

std::string expandUser(const std::string& path) {
  if (path.empty() || path[0] != '~') return path;
  const char* home = std::getenv("HOME");
  return std::string(home ? home : "") + path.substr(1);
}

RunRecorder::RunRecorder(const std::string& directory, const std::string& run_id)
    : path_(bagPath(directory, run_id)), active_path_(path_ + kActiveSuffix) {
  try {
    const auto lifecycle = lockBagLifecycle();
    owned_ = std::make_unique<rosbag::Bag>();
  } catch (const std::exception& e) {
    fail(std::string("cannot create a bag: ") + e.what());
    return;
  }
  std::string error;
  switch (claimBag(directory, run_id, error)) {
    case BagClaim::kClaimed:
      bag_ = owned_.get();
      open();
      return;
    case BagClaim::kTaken:
      fail("a bag of run_id '" + run_id + "' exists in " + directory + " (" + path_ + " or " + active_path_ +
           "): not overwritten");
      return;
    case BagClaim::kFailed:
      fail(error);
      return;
  }
}

RunRecorder::RunRecorder(const std::string& directory, const std::string& run_id, rosbag::Bag& reused,
                         const std::string& claim_error)
    : path_(bagPath(directory, run_id)), active_path_(path_ + kActiveSuffix) {
  if (!claim_error.empty()) {
    fail(claim_error);
    return;
  }
  bag_ = &reused;
  open();
}

void RunRecorder::open() {
  try {
    const auto lifecycle = lockBagLifecycle();
    bag_->setCompression(rosbag::compression::LZ4);
    bag_->open(active_path_, rosbag::bagmode::Write);
  } catch (const std::exception& e) {
    fail("cannot open bag " + active_path_ + ": " + e.what());
    closeIntoNull();  // a bag whose first writes failed is open
    bag_ = nullptr;
    releaseBagClaim(active_path_);
  }
}

RunRecorder::~RunRecorder() {
  close();
  const auto lifecycle = lockBagLifecycle();
  keepIfClosable(owned_);
  owned_.reset();
}

void keepIfClosable(std::unique_ptr<rosbag::Bag>& bag) {
  if (!bag || !bag->isOpen()) return;
  ROS_ERROR("a bag that could not be closed is left open (its file is /dev/null now) and a new one used");
  (void)bag.release();
}

bool RunRecorder::close() {
  if (!bag_) {
    releaseBagClaim(active_path_);
    return ok();
  }
  try {
    const auto lifecycle = lockBagLifecycle();
    bag_->close();
  } catch (const std::exception& e) {
    fail(std::string("closing the bag failed: ") + e.what());
    closeIntoNull();
  }
  bag_ = nullptr;
  if (ok()) {
    const int error = renameNoReplace(active_path_, path_);
    if (error == EEXIST) {
      fail(path_ + " exists, written by someone else: not overwritten; this run's bag stays " + active_path_);
    } else if (error != 0) {
      fail("cannot rename " + active_path_ + " to " + path_ + ": " + std::strerror(error));
    }
  }
  // The bag is no longer written: a bag left .active may now be recovered.
  releaseBagClaim(active_path_);
  return ok();
}

RunBagWriter::RunBagWriter(std::string directory, Topics topics, std::size_t max_queued_messages)
    : directory_(std::move(directory)),
      topics_(std::move(topics)),
      max_queued_(std::max<std::size_t>(max_queued_messages, 1)),
      parameters_header_(headerFor<collision_lab::RunParameters>(topics_.parameters)),
      input_header_(headerFor<collision_lab::InitialConditions>(topics_.inputs)),
      prediction_header_(headerFor<collision_lab::Prediction>(topics_.predictions)),
      summary_header_(headerFor<collision_lab::RunSummary>(topics_.summaries)),
      thread_(&RunBagWriter::loop, this) {}

RunBagWriter::~RunBagWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
  recorder_.reset();
  const auto lifecycle = lockBagLifecycle();
  keepIfClosable(bag_);
  bag_.reset();
}

namespace {
std::atomic<std::uint64_t> bytes_waiting_for_bags{0};
}  // namespace

std::uint64_t RunBagWriter::bytesWaiting() { return bytes_waiting_for_bags.load(std::memory_order_relaxed); }

void RunBagWriter::push(RunBagBatch batch) {
  const std::size_t n = batch.messages();
  {
    std::unique_lock<std::mutex> lock(mutex_);
    // A batch larger than the bound still goes in, alone.
    changed_.wait(lock, [&] { return queued_messages_ == 0 || queued_messages_ + n <= max_queued_; });
    const std::uint64_t bytes = batch.bytes;
    queue_.push_back(std::move(batch));
    queued_messages_ += n;
    bytes_waiting_for_bags += bytes;  // once queued: the writer subtracts them after writing
  }
  changed_.notify_all();
}

void RunBagWriter::loop() {
  for (;;) {
    RunBagBatch batch;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and everything is written
      batch = std::move(queue_.front());
      queue_.pop_front();
    }
    try {
      write(batch);
    } catch (const std::exception& e) {
      recover(batch, e.what());
    } catch (...) {
      recover(batch, "an exception of unknown type");
    }
    bytes_waiting_for_bags -= batch.bytes;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queued_messages_ -= batch.messages();
    }
    changed_.notify_all();
  }
}

template <class Message>
boost::shared_ptr<ros::M_string> RunBagWriter::headerFor(const std::string& topic) const {
  if (std::find(topics_.latched.begin(), topics_.latched.end(), topic) == topics_.latched.end()) return {};
  return connectionHeader<Message>(topic, topics_.callerid, true);
}

void RunBagWriter::write(RunBagBatch& batch) {
  if (batch.opens) {
    recorder_.reset();  // closes a run left open by a failure before its bag is replaced
    {
      const auto lifecycle = lockBagLifecycle();
      keepIfClosable(bag_);
    }
    // A reopened rosbag::Bag keeps some memory of every bag it wrote (6 KB for 40 small
    // messages, about 38 KB per run of the node): a new one every kBagReuses bags keeps
    // the writer's memory flat.
    if (!bag_ || ++bag_reuses_ == kBagReuses) {
      const auto lifecycle = lockBagLifecycle();
      bag_ = std::make_unique<rosbag::Bag>();
      bag_reuses_ = 0;
    }
    recorder_.emplace(directory_, batch.run_id, *bag_, batch.claim_error);
  }
  // Only after a failure that lost the run's recorder (recover()).
  if (!recorder_) throw std::runtime_error("no bag is open for this batch");
  if (batch.parameters && !topics_.parameters.empty()) {
    recorder_->write(topics_.parameters, batch.parameters->header.stamp, *batch.parameters, parameters_header_);
  }
  if (batch.input) recorder_->write(topics_.inputs, batch.input->header.stamp, *batch.input, input_header_);
  if (batch.prediction) {
    recorder_->write(topics_.predictions, batch.prediction->header.stamp, *batch.prediction, prediction_header_);
  }
  for (const auto& event : batch.events) recorder_->write(topics_.events, event.header.stamp, event);
  if (!batch.summary) return;
  collision_lab::RunSummary& summary = *batch.summary;
  summary.bag_path = recorder_->path();
  summary.recording_ok = recorder_->ok();
  summary.recording_error = recorder_->error();
  recorder_->write(topics_.summaries, summary.header.stamp, summary, summary_header_);
  recorder_->close();
  summary.recording_ok = recorder_->ok();
  summary.recording_error = recorder_->error();
  recorder_.reset();
  releaseMemoryAfterBag(summary.bag_path);
  // Taken out first: when it throws, recover() must not call it again.
  const auto on_closed = std::exchange(batch.on_closed, nullptr);
  if (on_closed) on_closed(summary);
}

void RunBagWriter::recover(RunBagBatch& batch, const std::string& what) {
  const std::string error = "the bag writer failed: " + what;
  ROS_ERROR_STREAM("run " << batch.run_id << ": " << error);
  // The rest of the run is not written, and its bag keeps the .active name.
  if (recorder_) recorder_->fail(error);
  if (!batch.summary || !batch.on_closed) return;
  collision_lab::RunSummary& summary = *batch.summary;
  summary.bag_path = bagPath(directory_, batch.run_id);
  recorder_.reset();
  summary.recording_ok = false;
  summary.recording_error = error;
  const auto on_closed = std::exchange(batch.on_closed, nullptr);
  try {
    on_closed(summary);
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM("run " << batch.run_id << ": the bag writer failed again, reporting it: " << e.what());
  } catch (...) {
    ROS_ERROR_STREAM("run " << batch.run_id << ": the bag writer failed again, reporting it");
  }
}

void RunRecorder::closeIntoNull() {
  if (!bag_ || !bag_->isOpen()) return;
  int claim_fd = -1;
  {
    std::lock_guard<std::mutex> lock(claims_mutex);
    const auto it = heldClaims().find(active_path_);
    if (it != heldClaims().end()) claim_fd = it->second;
  }
  // The bag's own descriptor is the other one open on the claimed file (same inode, even
  // where the folder is reached through a symlink or the file was deleted).
  struct stat claimed {};
  if (claim_fd < 0 || ::fstat(claim_fd, &claimed) != 0) {
    ROS_ERROR_STREAM("the failed bag " << active_path_ << " stays open: its claim is not held");
    return;
  }
  int bag_fd = -1;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/proc/self/fd", ec)) {
    const int fd = std::atoi(entry.path().filename().c_str());
    struct stat file {};
    if (fd != claim_fd && ::fstat(fd, &file) == 0 && file.st_dev == claimed.st_dev && file.st_ino == claimed.st_ino) {
      bag_fd = fd;
      break;
    }
  }
  const int null_fd = bag_fd < 0 ? -1 : ::open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (null_fd < 0 || ::dup2(null_fd, bag_fd) < 0) {
    ROS_ERROR_STREAM("the failed bag " << active_path_ << " stays open: its descriptor was not found or not replaced");
    if (null_fd >= 0) ::close(null_fd);
    return;
  }
  ::close(null_fd);
  try {
    const auto lifecycle = lockBagLifecycle();
    bag_->close();
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM("the failed bag " << active_path_ << " did not close into /dev/null: " << e.what());
  }
}

void RunRecorder::fail(const std::string& what) {
  if (error_.empty()) error_ = what;
}

}  // namespace collision_lab_ros
