// The run service's workers (ROS-free): the fair queue of accepted runs (FairScheduler),
// worker threads that serve them, the first short_lane_workers of which take only short
// runs, a watchdog that stops a run at its deadline, and notices of the queue's state,
// coalesced on a thread of their own.
//
// Threading contract:
// - One mutex (lock()) guards the scheduler, every worker's current run and stopping().
//   The owner holds it to push a run together with its own bookkeeping (the lab node
//   claims the run_id and announces the run under it, so that announcements go out in
//   the order of the queue). Members marked "lock held" expect it.
// - Hooks::serve runs on a worker's thread without the lock, one run at a time per worker;
//   it must not throw. Hooks::taken and Hooks::ended run with the lock held.
// - A stop asked of a running run (stopRunning, the watchdog, stop()) sets its worker's
//   cancel flag, which the core polls, and the first cause asked for; Hooks::serve reads them.
// - Hooks::changed gets the queue's state on the notice thread, without the lock, at most
//   Options::notice_period_s apart: a burst of changes is one notice, the newest state
//   always the last one.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "collision_lab/service/fair_scheduler.h"
#include "collision_lab/service/run_budget.h"

namespace collision_lab::service {

/// What the queue lists of a run, and the limit the watchdog keeps.
struct RunFacts {
  std::uint64_t predicted_collisions = 0;  ///< [1] the model's count; 0: none
  std::uint32_t body_count = 0;            ///< [1]
  double max_run_seconds = 0.0;            ///< [s] wall-clock limit; <= 0: none
};

/// A run of the queue, waiting or running.
struct QueuedRunState {
  std::string run_id;
  std::string student;
  Lane lane = Lane::kLong;
  bool running = false;
  std::uint64_t predicted_collisions = 0;  ///< [1]
  std::uint32_t body_count = 0;            ///< [1]
};

/// The run a worker computes (guarded by the pool's mutex).
struct RunningRun {
  QueuedRunState run;  ///< run.run_id empty: idle
  std::optional<std::chrono::steady_clock::time_point> deadline;
  std::string stopped_by;  ///< who asked it to stop (kCancel)
};

/// Job: the owner's accepted run. Slot: a worker's own state (its buffers, its bag writer),
/// set up by the owner before start().
template <class Job, class Slot>
class WorkerPool {
 public:
  using Scheduler = FairScheduler<Job>;
  using Entry = typename Scheduler::Entry;

  struct Worker {
    bool short_only = false;  ///< a short-lane worker
    Slot slot;
    std::atomic<bool> cancel{false};  ///< polled by the core
    std::atomic<int> cause{static_cast<int>(StopCause::kNone)};
    RunningRun current;  ///< lock held
    std::thread thread;

    StopCause stopCause() const { return static_cast<StopCause>(cause.load()); }
  };

  struct Options {
    std::size_t workers = 1;
    std::size_t short_lane_workers = 0;  ///< of workers, those that take only short runs
    double watchdog_period_s = 0.1;      ///< [s] between deadline checks
    double notice_period_s = 0.1;        ///< [s] at least between two notices of the queue
    std::size_t listed = std::numeric_limits<std::size_t>::max();  ///< waiting runs a notice lists
  };

  struct Hooks {
    std::function<RunFacts(const Job&)> facts;            ///< lock held (the queue's notices list up to `listed`)
    std::function<void(Worker&, Entry&)> serve;           ///< the run, on the worker, no lock
    std::function<void(Worker&, const Entry&)> taken;     ///< lock held; may be empty
    std::function<void(Worker&)> ended;                   ///< lock held; may be empty
    std::function<void()> idle;                           ///< nothing waits or runs; no lock; may be empty
    std::function<void(const std::vector<QueuedRunState>&)> changed;  ///< the notice thread; may be empty
  };

  explicit WorkerPool(Options options) : options_(options) {
    for (std::size_t i = 0; i < options_.workers; ++i) {
      workers_.push_back(std::make_unique<Worker>());
      workers_.back()->short_only = i < options_.short_lane_workers;
    }
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  /// Stops and joins, dropping the runs still waiting.
  ~WorkerPool() {
    stop(std::string());
    join();
  }

  /// The workers, to set up their slots before start().
  std::vector<std::unique_ptr<Worker>>& workers() { return workers_; }

  /// Starts the threads; the empty queue's state is noticed first.
  void start(Hooks hooks) {
    hooks_ = std::move(hooks);
    {
      std::lock_guard<std::mutex> guard(mutex_);
      noteChange();
    }
    notices_ = std::thread([this] { noticeLoop(); });
    for (auto& worker : workers_) worker->thread = std::thread([this, &w = *worker] { workerLoop(w); });
    watchdog_ = std::thread([this] { watchdogLoop(); });
  }

  std::unique_lock<std::mutex> lock() { return std::unique_lock<std::mutex>(mutex_); }

  /// True once stop() was called. Lock held.
  bool stopping() const { return stopping_; }

  /// Queues entry and wakes a worker; returns the runs ahead of it in its lane. Lock held.
  std::size_t push(Entry entry) {
    const std::size_t ahead = scheduler_.push(std::move(entry));
    noteChange();
    wake_.notify_all();
    return ahead;
  }

  /// Takes the waiting run run_id out of the queue; empty when none such waits. Lock held.
  std::optional<Entry> remove(const std::string& run_id) {
    auto entry = scheduler_.remove(run_id);
    if (entry) noteChange();
    return entry;
  }

  /// Asks the running run run_id (empty: every running run) to stop with cause, asked by
  /// `by`; returns the run_ids asked. Lock held.
  std::vector<std::string> stopRunning(const std::string& run_id, StopCause cause, const std::string& by) {
    std::vector<std::string> stopped;
    for (auto& worker : workers_) {
      const std::string& current = worker->current.run.run_id;
      if (current.empty() || (!run_id.empty() && run_id != current)) continue;
      stopWorker(*worker, cause, by);
      stopped.push_back(current);
    }
    return stopped;
  }

  /// Asks worker's run to stop with cause (the first cause asked is kept). Lock held.
  static void stopWorker(Worker& worker, StopCause cause, const std::string& by) {
    int none = static_cast<int>(StopCause::kNone);
    if (worker.cause.compare_exchange_strong(none, static_cast<int>(cause))) worker.current.stopped_by = by;
    worker.cancel = true;  // the core stops within 1024 impacts, at its last certified one
  }

  /// [1] waiting and running runs. Lock held.
  std::size_t waiting() const { return scheduler_.size(); }
  std::size_t running() const {
    return static_cast<std::size_t>(std::count_if(workers_.begin(), workers_.end(),
                                                  [](const auto& w) { return !w->current.run.run_id.empty(); }));
  }

  /// Takes no run any more: the waiting runs are taken out and returned (the owner ends
  /// them), every running run is asked to stop (kShutdown, by `by`). Idempotent.
  std::vector<Entry> stop(const std::string& by) {
    std::vector<Entry> waiting;
    {
      std::lock_guard<std::mutex> guard(mutex_);
      if (stopping_) return waiting;
      stopping_ = true;
      waiting = scheduler_.drain();
      stopRunning(std::string(), StopCause::kShutdown, by);
      noteChange();
    }
    wake_.notify_all();
    watchdog_wake_.notify_all();
    return waiting;
  }

  /// After stop(): waits for the workers' runs and the watchdog, then for the last notice.
  void join() {
    for (auto& worker : workers_) {
      if (worker->thread.joinable()) worker->thread.join();
    }
    if (watchdog_.joinable()) watchdog_.join();
    {
      std::lock_guard<std::mutex> guard(mutex_);
      notices_stop_ = true;
    }
    notice_wake_.notify_one();
    if (notices_.joinable()) notices_.join();
  }

 private:
  /// The queue changed: its state goes out on the notice thread. Lock held.
  void noteChange() {
    changed_ = true;
    notice_wake_.notify_one();
  }

  void workerLoop(Worker& worker) {
    for (;;) {
      std::optional<Entry> entry;
      {
        std::unique_lock<std::mutex> guard(mutex_);
        wake_.wait(guard, [&] { return stopping_ || scheduler_.ready(worker.short_only); });
        if (stopping_) return;
        entry = scheduler_.pop(worker.short_only);
        worker.cancel = false;
        worker.cause = static_cast<int>(StopCause::kNone);
        worker.current = runningOf(*entry);
        if (hooks_.taken) hooks_.taken(worker, *entry);
        noteChange();
      }
      hooks_.serve(worker, *entry);
      bool idle = false;
      {
        std::lock_guard<std::mutex> guard(mutex_);
        worker.current = RunningRun();
        if (hooks_.ended) hooks_.ended(worker);
        noteChange();
        idle = scheduler_.size() == 0 && running() == 0;
      }
      if (idle && hooks_.idle) hooks_.idle();
    }
  }

  RunningRun runningOf(const Entry& entry) const {
    const RunFacts facts = hooks_.facts(entry.job);
    RunningRun running;
    running.run = stateOf(entry, facts);
    running.run.running = true;
    const double seconds = facts.max_run_seconds;
    if (seconds > 0) {
      running.deadline = std::chrono::steady_clock::now() +
                         std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
    }
    return running;
  }

  static QueuedRunState stateOf(const Entry& entry, const RunFacts& facts) {
    return QueuedRunState{entry.run_id, entry.student, entry.lane, false, facts.predicted_collisions, facts.body_count};
  }

  void watchdogLoop() {
    std::unique_lock<std::mutex> guard(mutex_);
    while (!stopping_) {
      watchdog_wake_.wait_for(guard, std::chrono::duration<double>(options_.watchdog_period_s));
      const auto now = std::chrono::steady_clock::now();
      for (auto& worker : workers_) {
        const RunningRun& current = worker->current;
        if (!current.run.run_id.empty() && current.deadline && now >= *current.deadline) {
          stopWorker(*worker, StopCause::kTimeLimit, std::string());
        }
      }
    }
  }

  /// The running runs, then the first options_.listed waiting ones. Lock held.
  std::vector<QueuedRunState> state() const {
    std::vector<QueuedRunState> runs;
    for (const auto& worker : workers_) {
      if (!worker->current.run.run_id.empty()) runs.push_back(worker->current.run);
    }
    for (const Entry* entry : scheduler_.order(options_.listed)) runs.push_back(stateOf(*entry, hooks_.facts(entry->job)));
    return runs;
  }

  void noticeLoop() {
    std::unique_lock<std::mutex> guard(mutex_);
    for (;;) {
      notice_wake_.wait(guard, [this] { return changed_ || notices_stop_; });
      if (!changed_) return;
      changed_ = false;
      const std::vector<QueuedRunState> runs = state();
      guard.unlock();
      if (hooks_.changed) hooks_.changed(runs);
      guard.lock();
      notice_wake_.wait_for(guard, std::chrono::duration<double>(options_.notice_period_s),
                            [this] { return notices_stop_; });
    }
  }

  const Options options_;
  Hooks hooks_;
  std::mutex mutex_;
  std::condition_variable wake_;           ///< a run waits, or stopping_ (the workers)
  std::condition_variable watchdog_wake_;  ///< stopping_
  Scheduler scheduler_;
  std::vector<std::unique_ptr<Worker>> workers_;
  bool stopping_ = false;
  bool changed_ = false;       ///< the queue's state is not noticed yet
  bool notices_stop_ = false;  ///< the notice thread ends once the state is out
  std::condition_variable notice_wake_;
  std::thread watchdog_;
  std::thread notices_;
};

}  // namespace collision_lab::service
