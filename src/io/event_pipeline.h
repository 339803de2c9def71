// Three-body events formatted on worker threads while the run goes on. Internal to
// collision_lab_io.
#pragma once

#include <algorithm>
#include <array>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <ostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "collision_lab/core/nbody/engine.h"
#include "text_sink.h"

namespace collision_lab {
namespace io {

/// Copies each event into a block of kBlockEvents; full blocks are formatted by up to two
/// worker threads (each with its own TextSink) and written to `out` strictly in order. The
/// run's thread only copies, so formatting costs the run little when a core is free.
/// Memory is fixed: kBlocks blocks and one buffer per worker, reused; nothing per event.
/// finish() (or the destructor) writes every event before it returns; only then may the
/// owner write to `out` again. An exception on a worker (from `format` or the stream) stops
/// the writing there: later blocks are dropped, the run goes on, and finish() throws
/// std::runtime_error saying what failed.
class EventPipeline {
 public:
  /// Appends one event's text; `first` is true for the run's first event only.
  using Format = void (*)(TextSink& sink, const core::ImpactRecord& event, bool first);

  EventPipeline(std::ostream& out, Format format) : out_(out), format_(format) {
    for (Block& block : blocks_) {
      block.events.reserve(kBlockEvents);
      free_.push_back(&block);
    }
    current_ = takeFree();
  }
  ~EventPipeline() { stop(); }
  EventPipeline(const EventPipeline&) = delete;
  EventPipeline& operator=(const EventPipeline&) = delete;

  void push(const core::ImpactRecord& event) {
    current_->events.push_back(event);
    if (current_->events.size() == kBlockEvents) {
      submit(current_);
      current_ = takeFree();
    }
  }

  /// Formats and writes the events pushed so far; the workers end. Throws
  /// std::runtime_error when a worker failed.
  void finish() {
    stop();
    if (!error_.empty()) throw std::runtime_error("writing the events failed: " + error_);
  }

 private:
  static constexpr std::size_t kBlockEvents = 1024;
  static constexpr std::size_t kBlocks = 4;
  struct Block {
    std::vector<core::ImpactRecord> events;
    std::uint64_t sequence = 0;
  };

  /// finish() without the throw (the destructor's).
  void stop() {
    if (current_ && !current_->events.empty()) submit(current_);
    current_ = nullptr;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    changed_.notify_all();
    for (std::thread& worker : workers_) worker.join();
    workers_.clear();
  }

  Block* takeFree() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !free_.empty(); });
    Block* block = free_.back();
    free_.pop_back();
    return block;
  }

  void submit(Block* block) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      block->sequence = submitted_++;
      ready_.push_back(block);  // capacity kBlocks, reserved: no allocation
    }
    changed_.notify_all();
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    if (workers_.size() < std::min(2u, cores)) workers_.emplace_back([this] { work(); });
  }

  void work() {
    TextSink sink(out_, /*auto_flush=*/false);
    while (Block* block = nextReady()) {
      // Every block still takes its turn and goes back to free_, so that nothing waits for
      // ever after a failure.
      const bool format = !failed();
      if (format) guarded(sink, [&] {
        for (std::size_t i = 0; i < block->events.size(); ++i) {
          format_(sink, block->events[i], block->sequence == 0 && i == 0);
        }
      });
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return written_ == block->sequence; });
      }
      // The only writer now: earlier blocks are out, later ones wait. A block formatted
      // while an earlier one failed is dropped, not left in the sink (whose destructor
      // would write it after the failed block's gap).
      if (format && failed()) sink.discard();
      if (format && !failed()) guarded(sink, [&] { sink.flush(); });
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++written_;
        block->events.clear();
        free_.push_back(block);
      }
      changed_.notify_all();
    }
  }

  bool failed() {
    std::lock_guard<std::mutex> lock(mutex_);
    return !error_.empty();
  }

  /// Runs f; an exception becomes error_ (the first one is kept) and sink is emptied.
  template <class F>
  void guarded(TextSink& sink, F&& f) {
    std::string what;
    try {
      f();
      return;
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
      what = "an exception of unknown type";
    }
    sink.discard();
    std::lock_guard<std::mutex> lock(mutex_);
    if (error_.empty()) error_ = what.empty() ? "an exception without a message" : what;
  }

  /// The oldest submitted block, or nullptr when finish() was called and none is left.
  Block* nextReady() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !ready_.empty() || done_; });
    if (ready_.empty()) return nullptr;
    Block* block = ready_.front();
    ready_.erase(ready_.begin());
    return block;
  }

  std::ostream& out_;
  Format format_;
  std::array<Block, kBlocks> blocks_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Block*> free_ = reservedList();
  std::vector<Block*> ready_ = reservedList();  ///< in submission order
  Block* current_ = nullptr;
  std::uint64_t submitted_ = 0;
  std::uint64_t written_ = 0;
  bool done_ = false;
  std::string error_;  ///< the first worker failure; empty while none
  std::vector<std::thread> workers_;

  static std::vector<Block*> reservedList() {
    std::vector<Block*> list;
    list.reserve(kBlocks);
    return list;
  }
};

}  // namespace io
}  // namespace collision_lab
