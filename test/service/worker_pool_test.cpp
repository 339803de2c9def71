// The run service's workers (service/worker_pool.h), no master: fair order, the short lane,
// the watchdog, cancel and shutdown, and the queue's notices. Every wait is on an event
// (a condition the workers signal), never on the clock.
#include "collision_lab/service/worker_pool.h"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <vector>

namespace collision_lab::service {
namespace {

/// How long a wait for the workers may take before the test fails (generous: no timing is
/// asserted, only that the event comes).
constexpr std::chrono::seconds kPatience{30};

/// A test's run: its name, whether it waits for the gate or for a stop.
struct TestJob {
  bool wait_for_gate = false;
  bool wait_for_stop = false;
  double max_run_seconds = 0.0;
};

struct Slot {
  int runs = 0;
};

using Pool = WorkerPool<TestJob, Slot>;

/// What the workers did, observed from the test's thread.
class Log {
 public:
  void served(const std::string& run_id, StopCause cause, const std::string& stopped_by) {
    std::lock_guard<std::mutex> lock(mutex_);
    order_.push_back(run_id);
    causes_.push_back(cause);
    stopped_by_.push_back(stopped_by);
    changed_.notify_all();
  }
  void started(const std::string& run_id) {
    std::lock_guard<std::mutex> lock(mutex_);
    started_.push_back(run_id);
    changed_.notify_all();
  }
  // A regression fails the test after kPatience instead of hanging it.
  void waitServed(std::size_t runs) {
    std::unique_lock<std::mutex> lock(mutex_);
    ASSERT_TRUE(changed_.wait_for(lock, kPatience, [&] { return order_.size() >= runs; })) << runs << " runs served";
  }
  void waitStarted(std::size_t runs) {
    std::unique_lock<std::mutex> lock(mutex_);
    ASSERT_TRUE(changed_.wait_for(lock, kPatience, [&] { return started_.size() >= runs; })) << runs << " runs started";
  }
  void open() {
    std::lock_guard<std::mutex> lock(mutex_);
    gate_open_ = true;
    changed_.notify_all();
  }
  void waitGate() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return gate_open_; });
  }
  std::vector<std::string> order() {
    std::lock_guard<std::mutex> lock(mutex_);
    return order_;
  }
  std::vector<StopCause> causes() {
    std::lock_guard<std::mutex> lock(mutex_);
    return causes_;
  }
  std::vector<std::string> stoppedBy() {
    std::lock_guard<std::mutex> lock(mutex_);
    return stopped_by_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::string> order_, started_, stopped_by_;
  std::vector<StopCause> causes_;
  bool gate_open_ = false;
};

Pool::Hooks hooksFor(Pool& pool, Log& log) {
  Pool::Hooks hooks;
  hooks.facts = [](const TestJob& job) { return RunFacts{7, 3, job.max_run_seconds}; };
  hooks.serve = [&pool, &log](Pool::Worker& worker, Pool::Entry& entry) {
    log.started(entry.run_id);
    if (entry.job.wait_for_gate) log.waitGate();
    while (entry.job.wait_for_stop && !worker.cancel) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ++worker.slot.runs;
    std::string stopped_by;
    {
      const auto lock = pool.lock();
      stopped_by = worker.current.stopped_by;
    }
    log.served(entry.run_id, worker.stopCause(), stopped_by);
  };
  return hooks;
}

Pool::Entry entry(const std::string& run_id, const std::string& student, Lane lane, TestJob job = {}) {
  return Pool::Entry{run_id, student, lane, job};
}

/// Queues the entries in order, under one lock, as the lab node's intake does.
void push(Pool& pool, std::initializer_list<Pool::Entry> entries) {
  const auto lock = pool.lock();
  for (const Pool::Entry& e : entries) pool.push(e);
}

TEST(WorkerPool, ServesEveryStudentInTurn) {
  Log log;  // outlives the pool, whose runs report to it
  Pool pool({1, 0});
  pool.start(hooksFor(pool, log));
  {
    const auto lock = pool.lock();
    TestJob gate;
    gate.wait_for_gate = true;
    pool.push(entry("first", "zoe", Lane::kLong, gate));  // holds the one worker
  }
  log.waitStarted(1);
  {
    const auto lock = pool.lock();
    EXPECT_EQ(pool.push(entry("ana1", "ana", Lane::kLong)), 0u);
    EXPECT_EQ(pool.push(entry("ana2", "ana", Lane::kLong)), 1u);
    EXPECT_EQ(pool.push(entry("ana3", "ana", Lane::kLong)), 2u);
    EXPECT_EQ(pool.push(entry("ben1", "ben", Lane::kLong)), 1u) << "ben's first run goes after ana's first";
    EXPECT_EQ(pool.waiting(), 4u);
    EXPECT_EQ(pool.running(), 1u);
  }
  log.open();
  log.waitServed(5);
  EXPECT_EQ(log.order(), (std::vector<std::string>{"first", "ana1", "ben1", "ana2", "ana3"}));
  pool.stop("the test");
  pool.join();
  EXPECT_EQ(pool.workers()[0]->slot.runs, 5);
}

TEST(WorkerPool, AShortLaneWorkerServesShortRunsWhileALongOneRuns) {
  Log log;  // outlives the pool, whose runs report to it
  Pool pool({2, 1});  // worker 0 takes short runs only
  pool.start(hooksFor(pool, log));
  TestJob gate;
  gate.wait_for_gate = true;
  push(pool, {entry("long", "ana", Lane::kLong, gate)});
  log.waitStarted(1);
  push(pool, {entry("short", "ben", Lane::kShort)});
  log.waitServed(1);  // while "long" still waits for the gate
  EXPECT_EQ(log.order(), std::vector<std::string>{"short"});
  log.open();
  log.waitServed(2);
  pool.stop("the test");
  pool.join();
  EXPECT_EQ(pool.workers()[0]->slot.runs, 1);
  EXPECT_EQ(pool.workers()[1]->slot.runs, 1);
}

TEST(WorkerPool, TheWatchdogStopsARunAtItsDeadline) {
  Log log;  // outlives the pool, whose runs report to it
  Pool pool({1, 0, 0.001});
  pool.start(hooksFor(pool, log));
  TestJob endless;
  endless.wait_for_stop = true;
  endless.max_run_seconds = 0.01;
  push(pool, {entry("endless", "ana", Lane::kLong, endless)});
  log.waitServed(1);
  EXPECT_EQ(log.causes(), std::vector<StopCause>{StopCause::kTimeLimit});
  pool.stop("the test");
  pool.join();
}

TEST(WorkerPool, CancelStopsOnlyTheRunAskedForAndKeepsTheFirstCause) {
  Log log;  // outlives the pool, whose runs report to it
  Pool pool({2, 0});
  pool.start(hooksFor(pool, log));
  TestJob endless;
  endless.wait_for_stop = true;
  push(pool, {entry("a", "ana", Lane::kLong, endless), entry("b", "ben", Lane::kLong, endless)});
  log.waitStarted(2);
  {
    const auto lock = pool.lock();
    EXPECT_EQ(pool.stopRunning("a", StopCause::kCancel, "teacher"), std::vector<std::string>{"a"});
    EXPECT_EQ(pool.stopRunning("a", StopCause::kTimeLimit, ""), std::vector<std::string>{"a"});
    EXPECT_TRUE(pool.stopRunning("nobody", StopCause::kCancel, "teacher").empty());
  }
  log.waitServed(1);
  EXPECT_EQ(log.order(), std::vector<std::string>{"a"});
  EXPECT_EQ(log.causes(), std::vector<StopCause>{StopCause::kCancel});
  EXPECT_EQ(log.stoppedBy(), std::vector<std::string>{"teacher"});
  pool.stop("the shutdown");
  pool.join();
  EXPECT_EQ(log.order(), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(log.causes()[1], StopCause::kShutdown);
  EXPECT_EQ(log.stoppedBy()[1], "the shutdown");
}

TEST(WorkerPool, StopHandsBackTheWaitingRunsAndTakesNoMore) {
  Log log;  // outlives the pool, whose runs report to it
  Pool pool({1, 0});
  pool.start(hooksFor(pool, log));
  TestJob endless;
  endless.wait_for_stop = true;
  push(pool, {entry("running", "ana", Lane::kLong, endless)});
  log.waitStarted(1);
  {
    const auto lock = pool.lock();
    pool.push(entry("w1", "ana", Lane::kLong));
    pool.push(entry("w2", "ben", Lane::kShort));
    const auto taken_out = pool.remove("w1");
    ASSERT_TRUE(taken_out);
    EXPECT_EQ(taken_out->student, "ana");
    EXPECT_FALSE(pool.remove("w1"));
  }
  const std::vector<Pool::Entry> waiting = pool.stop("the shutdown");
  ASSERT_EQ(waiting.size(), 1u);
  EXPECT_EQ(waiting[0].run_id, "w2");
  EXPECT_TRUE(pool.stop("again").empty());
  {
    const auto lock = pool.lock();
    EXPECT_TRUE(pool.stopping());
  }
  pool.join();
  EXPECT_EQ(log.order(), std::vector<std::string>{"running"});
  EXPECT_EQ(log.causes(), std::vector<StopCause>{StopCause::kShutdown});
}

TEST(WorkerPool, TheLastNoticeIsTheNewestState) {
  Log log;  // with the notices, outlives the pool, whose threads report to them
  std::mutex notices_mutex;
  std::condition_variable noticed;
  std::vector<std::vector<QueuedRunState>> notices;
  int idle = 0;
  Pool pool({1, 0, 0.1, 0.0, 2});
  Pool::Hooks hooks = hooksFor(pool, log);
  hooks.changed = [&](const std::vector<QueuedRunState>& runs) {
    std::lock_guard<std::mutex> lock(notices_mutex);
    notices.push_back(runs);
    noticed.notify_all();
  };
  hooks.idle = [&] { ++idle; };
  pool.start(std::move(hooks));
  TestJob gate;
  gate.wait_for_gate = true;
  push(pool, {entry("r1", "ana", Lane::kLong, gate)});
  log.waitStarted(1);
  {
    const auto lock = pool.lock();
    for (const char* run_id : {"r2", "r3", "r4"}) pool.push(entry(run_id, "ana", Lane::kLong));
  }
  {
    // r1 holds the worker until the gate opens: the state after r4's push is noticed.
    std::unique_lock<std::mutex> lock(notices_mutex);
    ASSERT_TRUE(noticed.wait_for(lock, kPatience, [&] { return !notices.empty() && notices.back().size() == 3; }));
  }
  log.open();
  log.waitServed(4);
  pool.stop("the test");
  pool.join();
  std::lock_guard<std::mutex> lock(notices_mutex);
  ASSERT_FALSE(notices.empty());
  EXPECT_TRUE(notices.back().empty()) << "every run has ended";
  bool listed_running_and_waiting = false;
  for (const auto& runs : notices) {
    EXPECT_LE(runs.size(), 3u) << "the running run and at most 2 waiting ones";
    for (const auto& run : runs) {
      EXPECT_EQ(run.predicted_collisions, 7u);
      EXPECT_EQ(run.body_count, 3u);
    }
    if (runs.size() == 3 && runs[0].run_id == "r1" && runs[0].running && !runs[1].running) {
      listed_running_and_waiting = true;
    }
  }
  EXPECT_TRUE(listed_running_and_waiting) << "the notice after r4's push lists r1 running, r2 and r3 waiting";
  EXPECT_GE(idle, 1) << "the pool fell idle after r4";
}

}  // namespace
}  // namespace collision_lab::service
