#include "collision_lab/ros/run_recorder.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <utility>

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
  try {
    owned_ = std::make_unique<rosbag::Bag>();
  } catch (const std::exception& e) {
    fail(std::string("cannot create a bag: ") + e.what());
    return;
  }
  bag_ = owned_.get();
  open(directory);
}

RunRecorder::RunRecorder(const std::string& directory, const std::string& run_id, rosbag::Bag& reused)
    : path_(bagPath(directory, run_id)), active_path_(path_ + kActiveSuffix), bag_(&reused) {
  open(directory);
}

void RunRecorder::open(const std::string& directory) {
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec) {
    bag_ = nullptr;
    fail("cannot create bag directory " + directory + ": " + ec.message());
    return;
  }
  try {
    bag_->setCompression(rosbag::compression::LZ4);
    bag_->open(active_path_, rosbag::bagmode::Write);
  } catch (const std::exception& e) {
    bag_ = nullptr;
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
  bag_ = nullptr;
  if (ok()) {
    std::error_code ec;
    fs::rename(active_path_, path_, ec);
    if (ec) fail("cannot rename " + active_path_ + " to " + path_ + ": " + ec.message());
  }
  return ok();
}

RunBagWriter::RunBagWriter(std::string directory, Topics topics, std::size_t max_queued_messages)
    : directory_(std::move(directory)),
      topics_(std::move(topics)),
      max_queued_(std::max<std::size_t>(max_queued_messages, 1)),
      thread_(&RunBagWriter::loop, this) {}

RunBagWriter::~RunBagWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void RunBagWriter::push(RunBagBatch batch) {
  const std::size_t n = batch.messages();
  {
    std::unique_lock<std::mutex> lock(mutex_);
    // A batch larger than the bound still goes in, alone.
    changed_.wait(lock, [&] { return queued_messages_ == 0 || queued_messages_ + n <= max_queued_; });
    queued_messages_ += n;
    queue_.push_back(std::move(batch));
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
    write(batch);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queued_messages_ -= batch.messages();
    }
    changed_.notify_all();
  }
}

void RunBagWriter::write(RunBagBatch& batch) {
  if (batch.opens || !recorder_) recorder_.emplace(directory_, batch.run_id, bag_);
  if (batch.input) recorder_->write(topics_.inputs, batch.input->header.stamp, *batch.input);
  if (batch.prediction) recorder_->write(topics_.predictions, batch.prediction->header.stamp, *batch.prediction);
  for (const auto& event : batch.events) recorder_->write(topics_.events, event.header.stamp, event);
  if (!batch.summary) return;
  collision_lab::RunSummary& summary = *batch.summary;
  summary.bag_path = recorder_->path();
  summary.recording_ok = recorder_->ok();
  summary.recording_error = recorder_->error();
  recorder_->write(topics_.summaries, summary.header.stamp, summary);
  recorder_->close();
  summary.recording_ok = recorder_->ok();
  summary.recording_error = recorder_->error();
  recorder_.reset();
  if (batch.on_closed) batch.on_closed(summary);
}

void RunRecorder::fail(const std::string& what) {
  if (error_.empty()) error_ = what;
}

}  // namespace collision_lab_ros
