// RunBook (the web server's view of the lab's runs) when the lab node's topics arrive out
// of order: they are separate connections, so a run's summary may come before its served
// input. Bags read on many threads at once. Bounded memory: runs evicted under a budget and
// read back from their bags; the run index (a fake RunSource) for old runs, the list, and
// the reconciliation of runs whose summary or events were missed. A live run past the lab's
// published-event cap, from its RunProgress samples. No master needed.
#include <stdlib.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <rosbag/bag.h>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/draw.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/run_view.h"
#include "collision_lab/web/run_book.h"
#include "collision_lab/ros/run_index_recorder.h"

namespace {

using nlohmann::json;

json runJson(collision_lab_web::RunBook& book, const std::string& run_id) {
  auto text = book.json(run_id);
  return text ? json::parse(text->first) : json();
}

TEST(RunBook, SummaryBeforeServedInputWaitsForTheScene) {
  collision_lab_web::RunBook book;
  collision_lab::AcceptedRun accepted;
  accepted.header.stamp.fromSec(1.0e9);
  accepted.run_id = "ana.run1";
  accepted.student = "ana";
  book.onAccepted(accepted);

  // An unrecorded run with no collisions: its summary comes first.
  collision_lab::RunSummary summary;
  summary.run_id = "ana.run1";
  summary.student = "ana";
  summary.recording_ok = false;
  summary.recording_error = "no space left on device";
  book.onSummary(summary);
  EXPECT_NE(runJson(book, "ana.run1").at("state"), "finished") << "finished without its scene";

  collision_lab::InitialConditions input;
  input.run_id = "ana.run1";
  input.student = "ana";
  input.masses = {1.0, 1.0};
  input.positions = {1.0, 0.0};
  input.velocities = {1.0, -1.0};  // moving apart: no collision
  book.onServedInput(input);
  const json run = runJson(book, "ana.run1");
  EXPECT_EQ(run.at("state"), "finished");
  EXPECT_EQ(run.at("scene").at("positions"), json({1.0, 0.0}));
  EXPECT_TRUE(run.contains("plots"));
  // Not recorded, and said so: on its page and in the list.
  EXPECT_EQ(run.at("summary").at("recorded"), false);
  EXPECT_EQ(run.at("summary").at("recording_error"), "no space left on device");
  const json listed = json::parse(book.list(std::nullopt));
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].at("recorded"), false);
}

TEST(RunBook, RunJoinedMidwayEndsWithItsSummary) {
  collision_lab_web::RunBook book;  // no AcceptedRun seen: the web node started later
  collision_lab::RunSummary summary;
  summary.run_id = "old";
  summary.collision_count = 3;
  book.onSummary(summary);
  const json run = runJson(book, "old");
  EXPECT_EQ(run.at("state"), "finished");
  EXPECT_EQ(run.at("summary").at("collision_count"), 3);
}

// The web node rebuilds runs from their bags on threads of their own while HTTP threads
// export events CSVs. rosbag::Bag loads its encryptor plugin through pluginlib, which is not
// thread-safe: thirty students at once crashed the web node (SIGSEGV in class_loader).
TEST(RunBook, BagsReadOnManyThreadsAtOnce) {
  char dir_template[] = "/tmp/run_book_test_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::filesystem::path dir(dir_template);
  const std::string bag_path = (dir / "ana.run1.bag").string();
  {
    rosbag::Bag bag;
    bag.open(bag_path, rosbag::bagmode::Write);
    collision_lab::InitialConditions input;
    input.run_id = "ana.run1";
    input.masses = {1.0, 1.0};
    input.positions = {1.0, 0.0};
    input.velocities = {-1.0, 0.0};
    bag.write("/collision_lab/served_inputs", ros::Time(1.0), input);
    bag.close();
  }
  constexpr int kThreads = 8;
  constexpr int kReadsEach = 40;
  std::atomic<int> read_with_scene{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      for (int k = 0; k < kReadsEach; ++k) {
        const collision_lab_web::BagRun run = collision_lab_web::readRunFromBag(bag_path, 64);
        if (run.record) ++read_with_scene;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(read_with_scene.load(), kThreads * kReadsEach);
  std::filesystem::remove_all(dir);
}


// ---- Bounded memory and the run index ----

using collision_lab::service::IndexedRun;
using collision_lab::service::RunState;

/// A RunSource of rows set by the test (the run index the lab node writes).
class FakeSource : public collision_lab_web::RunSource {
 public:
  void put(const IndexedRun& row) {
    std::lock_guard<std::mutex> lock(mutex_);
    rows_[row.run_id] = row;
    order_.push_back(row.run_id);
  }
  void setState(const std::string& run_id, RunState state) {
    std::lock_guard<std::mutex> lock(mutex_);
    rows_.at(run_id).state = state;
  }
  std::optional<IndexedRun> find(const std::string& run_id) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    ++finds;
    auto it = rows_.find(run_id);
    if (it == rows_.end()) return std::nullopt;
    return it->second;
  }
  std::vector<IndexedRun> list(const std::optional<std::string>& student) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<IndexedRun> out;
    for (const auto& id : order_) {
      const IndexedRun& row = rows_.at(id);
      if (!student || row.student == *student) out.push_back(row);
    }
    return out;
  }
  std::vector<collision_lab::service::IndexedRejection> rejections(const std::optional<std::string>& student,
                                                                  std::size_t limit) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    asked_limit = limit;
    std::vector<collision_lab::service::IndexedRejection> out;
    for (const auto& r : rejections_) {
      if (!student || r.student == *student) out.push_back(r);
    }
    return out;
  }
  void reject(const collision_lab::service::IndexedRejection& r) {
    std::lock_guard<std::mutex> lock(mutex_);
    rejections_.push_back(r);
  }
  mutable int finds = 0;
  mutable std::size_t asked_limit = 0;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, IndexedRun> rows_;
  std::vector<std::string> order_;
  std::vector<collision_lab::service::IndexedRejection> rejections_;
};

/// A folder removed at the end of the test.
struct TempDir {
  TempDir() {
    char dir_template[] = "/tmp/run_book_test_XXXXXX";
    EXPECT_NE(mkdtemp(dir_template), nullptr);
    path = dir_template;
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::filesystem::path path;
};

/// A three-body run: its messages as the lab node publishes (and records) them.
struct ScriptedRun {
  collision_lab::AcceptedRun accepted;
  collision_lab::InitialConditions input;
  std::vector<collision_lab::CollisionEvent> events;
  collision_lab::RunSummary summary;
};

collision_lab::CollisionEvent impact(const std::string& run_id, std::uint64_t index, std::uint32_t pair, double time,
                                     double va, double vb) {
  collision_lab::CollisionEvent e;
  e.run_id = run_id;
  e.kind = collision_lab::CollisionEvent::KIND_IMPACT;
  e.index = index;
  e.pair_index = pair;
  e.first_moved = pair;
  e.last_moved = pair + 1;
  e.time = time;
  e.restitution = 1.0;
  e.pair_velocities_after = {va, vb};
  return e;
}

/// bodies bodies, `collisions` impacts (velocities swapped pair by pair), recorded in
/// dir/<run_id>.bag when dir is given.
ScriptedRun scriptedRun(const std::string& student, const std::string& run_id, double stamp, std::size_t bodies,
                        std::uint64_t collisions, const std::filesystem::path& dir) {
  ScriptedRun run;
  run.accepted.header.stamp.fromSec(stamp);
  run.accepted.run_id = run_id;
  run.accepted.student = student;
  run.input.run_id = run_id;
  run.input.student = student;
  for (std::size_t i = 0; i < bodies; ++i) {
    run.input.masses.push_back(1.0 + static_cast<double>(i % 3));
    run.input.positions.push_back(static_cast<double>(bodies - i));
    run.input.velocities.push_back(i % 2 ? 1.0 : -1.0);
  }
  for (std::uint64_t k = 1; k <= collisions; ++k) {
    const auto pair = static_cast<std::uint32_t>((k * 7) % (bodies - 1));
    run.events.push_back(impact(run_id, k, pair, 0.01 * static_cast<double>(k), 0.5 / static_cast<double>(k),
                                -0.25 * static_cast<double>(k % 5)));
  }
  run.summary.run_id = run_id;
  run.summary.student = student;
  run.summary.collision_count = collisions;
  run.summary.published_events = collisions;
  run.summary.stop_reason = "NO_MORE_COLLISIONS";
  run.summary.model_name = "scripted";
  run.summary.uncertified_values = {"final_time"};  // a value the run could not certify, named
  if (!dir.empty()) {
    run.summary.recording_ok = true;
    run.summary.bag_path = (dir / (run_id + ".bag")).string();
    rosbag::Bag bag;
    bag.open(run.summary.bag_path, rosbag::bagmode::Write);
    bag.write("/collision_lab/served_inputs", ros::Time(1.0), run.input);
    for (const auto& e : run.events) bag.write("/collision_lab/collision_events", ros::Time(2.0), e);
    bag.write("/collision_lab/run_summaries", ros::Time(3.0), run.summary);
    bag.close();
  }
  return run;
}

/// Feeds the book a run's messages: all, or the first `events` events and no summary.
void feed(collision_lab_web::RunBook& book, const ScriptedRun& run, std::optional<std::size_t> events = std::nullopt,
          bool summary = true) {
  book.onAccepted(run.accepted);
  book.onServedInput(run.input);
  const std::size_t n = events ? std::min(*events, run.events.size()) : run.events.size();
  for (std::size_t k = 0; k < n; ++k) book.onEvent(run.events[k]);
  if (summary) book.onSummary(run.summary);
}

IndexedRun rowOf(const ScriptedRun& run, RunState state) {
  IndexedRun row;
  row.run_id = run.input.run_id;
  row.student = run.input.student;
  row.state = state;
  row.accepted_at = run.accepted.header.stamp.toSec();
  row.scene_json = json({{"masses", run.input.masses}}).dump();
  row.body_count = static_cast<std::uint32_t>(run.input.masses.size());
  if (state == RunState::kFinished) {  // as the lab node writes it
    row.stop_reason = run.summary.stop_reason;
    row.collision_count = run.summary.collision_count;
    row.summary_json = collision_lab_ros::summaryJson(run.summary);
    row.ending = collision_lab_ros::endingOf(run.summary);
  }
  if (state == RunState::kInterrupted) {
    row.stop_reason = "INTERRUPTED";
    row.ending.truncated = true;
  }
  row.bag_path = run.summary.bag_path;
  return row;
}

collision_lab_web::RunBookOptions smallBudget(std::size_t bytes) {
  collision_lab_web::RunBookOptions options;
  options.memory_budget_bytes = bytes;
  options.reconcile_period = std::chrono::milliseconds(0);  // the tests call reconcile()
  options.reconcile_after = std::chrono::milliseconds(0);
  return options;
}

/// A run's JSON without its version: what the page shows.
std::string served(collision_lab_web::RunBook& book, const std::string& run_id) {
  auto text = book.json(run_id);
  return text ? text->first : std::string();
}

/// Threads of this process now [1].
std::size_t threadCount() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Threads:", 0) == 0) return std::stoul(line.substr(8));
  }
  return 0;
}

// Thirty gases ending at once used to start thirty threads, each reading a bag: a few
// rebuild threads take them in turn, and every run is still completed from its bag.
TEST(RunBookMemory, RunsEndingTogetherAreRebuiltByAFewThreads) {
  TempDir dir;
  collision_lab_web::RunBook book(smallBudget(std::size_t{64} << 20), nullptr);
  std::vector<ScriptedRun> runs;
  for (int k = 0; k < 20; ++k) {
    runs.push_back(scriptedRun("s" + std::to_string(k), "run" + std::to_string(k), 1.0e9 + k, 3, 2000, dir.path));
    // The topics stopped at 10 events (~max_published_events): the rest is in the bag.
    runs.back().summary.published_events = 10;
    runs.back().summary.events_not_published = true;
  }
  const std::size_t threads_before = threadCount();
  std::size_t threads_most = threads_before;
  for (const ScriptedRun& run : runs) {
    feed(book, run, 10);
    threads_most = std::max(threads_most, threadCount());
  }
  EXPECT_LE(threads_most, threads_before) << "a thread per rebuild";
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  for (const ScriptedRun& run : runs) {
    while (!book.finished(run.input.run_id) && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_TRUE(book.finished(run.input.run_id)) << run.input.run_id;
    EXPECT_EQ(json::parse(served(book, run.input.run_id)).at("collisions"), 2000) << run.input.run_id;
  }
}

TEST(RunBookMemory, EvictedRunIsServedAgainFromItsBagWithTheSameContent) {
  TempDir dir;
  // Without a RunSource: a stub stays for the list and the reload.
  collision_lab_web::RunBook book(smallBudget(1), nullptr);
  const ScriptedRun first = scriptedRun("ana", "ana.run1", 1.0e9, 3, 40, dir.path);
  feed(book, first);
  const std::string before = served(book, "ana.run1");
  ASSERT_FALSE(before.empty());
  EXPECT_EQ(json::parse(before).at("state"), "finished");
  const std::string list_before = book.list(std::nullopt);
  for (int k = 2; k <= 6; ++k) {
    const std::string id = "bo.run" + std::to_string(k);
    feed(book, scriptedRun("bo", id, 1.0e9 + k, 3, 40, dir.path));
  }
  // A one-byte budget keeps only the newest run.
  EXPECT_EQ(book.residentRuns(), 1u);
  EXPECT_TRUE(book.has("ana.run1"));
  EXPECT_TRUE(book.finished("ana.run1"));
  EXPECT_EQ(book.bagPath("ana.run1"), first.summary.bag_path);
  const json list = json::parse(book.list(std::nullopt));
  ASSERT_EQ(list.size(), 6u);
  EXPECT_EQ(list[0], json::parse(list_before)[0]) << "an evicted run is listed as before";
  EXPECT_EQ(served(book, "ana.run1"), before) << "read back from its bag, the same JSON";
}

TEST(RunBookMemory, EvictedRunIsReadBackThroughTheIndex) {
  TempDir dir;
  auto source = std::make_shared<FakeSource>();
  collision_lab_web::RunBook book(smallBudget(1), source);
  const ScriptedRun first = scriptedRun("ana", "ana.run1", 1.0e9, 3, 40, dir.path);
  source->put(rowOf(first, RunState::kFinished));
  feed(book, first);
  const std::string before = served(book, "ana.run1");
  for (int k = 2; k <= 4; ++k) {
    const ScriptedRun run = scriptedRun("bo", "bo.run" + std::to_string(k), 1.0e9 + k, 3, 40, dir.path);
    source->put(rowOf(run, RunState::kFinished));
    feed(book, run);
  }
  EXPECT_EQ(book.residentRuns(), 1u);
  EXPECT_EQ(served(book, "ana.run1"), before);
}

TEST(RunBookMemory, ConcurrentReadsOfAnOldRunLoadItOnce) {
  TempDir dir;
  auto source = std::make_shared<FakeSource>();
  const ScriptedRun old = scriptedRun("ana", "ana.old", 1.0e9, 3, 200, dir.path);
  source->put(rowOf(old, RunState::kFinished));
  collision_lab_web::RunBook book(smallBudget(std::size_t{64} << 20), source);  // a web node just restarted
  std::vector<std::thread> readers;
  std::atomic<int> answered{0};
  for (int t = 0; t < 8; ++t) {
    readers.emplace_back([&] {
      if (!served(book, "ana.old").empty()) ++answered;
    });
  }
  for (auto& t : readers) t.join();
  EXPECT_EQ(answered.load(), 8);
  EXPECT_EQ(source->finds, 1) << "one load for eight readers";
  const json run = json::parse(served(book, "ana.old"));
  EXPECT_EQ(run.at("state"), "finished");
  EXPECT_EQ(run.at("collisions"), 200);
  EXPECT_EQ(run.at("summary").at("collision_count"), 200);
  EXPECT_TRUE(book.finished("ana.old"));
  EXPECT_EQ(book.bagPath("ana.old"), old.summary.bag_path);
  EXPECT_FALSE(book.has("nobody.run"));
}

TEST(RunBookMemory, ListComesFromTheIndexWithLiveState) {
  TempDir dir;
  auto source = std::make_shared<FakeSource>();
  const ScriptedRun old = scriptedRun("ana", "ana.old", 1.0e9, 3, 10, dir.path);
  const ScriptedRun live = scriptedRun("bo", "bo.live", 1.0e9 + 5, 3, 10, dir.path);
  const ScriptedRun fresh = scriptedRun("bo", "bo.fresh", 1.0e9 + 9, 3, 10, dir.path);
  source->put(rowOf(old, RunState::kFinished));  // from before the web node's restart
  source->put(rowOf(live, RunState::kRunning));
  collision_lab_web::RunBook book(smallBudget(std::size_t{64} << 20), source);
  feed(book, live, 4, false);  // in progress: the book knows more than the index
  feed(book, fresh, 2, false);  // not in the index yet
  const json all = json::parse(book.list(std::nullopt));
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].at("run_id"), "ana.old");
  EXPECT_EQ(all[0].at("state"), "finished");
  EXPECT_EQ(all[0].at("collisions"), 10);
  EXPECT_EQ(all[0].at("bodies"), 3);
  EXPECT_EQ(all[0].at("model"), "scripted");
  EXPECT_EQ(all[1].at("run_id"), "bo.live");
  EXPECT_EQ(all[1].at("state"), "running");
  EXPECT_EQ(all[1].at("collisions"), 4) << "live state, not the index's";
  EXPECT_EQ(all[2].at("run_id"), "bo.fresh");
  const json bo = json::parse(book.list(std::string("bo")));
  ASSERT_EQ(bo.size(), 2u);
  EXPECT_EQ(book.residentRuns(), 2u) << "listing reads no old run back";
  // A page of the list: the same items, and the whole list's length.
  std::size_t total = 0;
  const json page = json::parse(book.list(std::nullopt, {1, 1, &total}));
  EXPECT_EQ(total, 3u);
  ASSERT_EQ(page.size(), 1u);
  EXPECT_EQ(page[0], all[1]);
  EXPECT_EQ(json::parse(book.list(std::nullopt, {2, 10, nullptr})), json::array({all[2]}));
  EXPECT_EQ(json::parse(book.list(std::nullopt, {5, 10, nullptr})), json::array());
}

TEST(RunBookMemory, MissedSummaryIsCompletedFromTheIndexAndTheBag) {
  TempDir dir;
  auto source = std::make_shared<FakeSource>();
  collision_lab_web::RunBook book(smallBudget(std::size_t{64} << 20), source);
  const ScriptedRun run = scriptedRun("ana", "ana.run1", 1.0e9, 3, 30, dir.path);
  source->put(rowOf(run, RunState::kRunning));
  feed(book, run, 12, false);  // the rest of its events and its summary were dropped
  EXPECT_EQ(book.reconcile(), 0u) << "still running by the index";
  EXPECT_FALSE(book.finished("ana.run1"));
  source->setState("ana.run1", RunState::kFinished);
  EXPECT_EQ(book.reconcile(), 1u);
  EXPECT_TRUE(book.finished("ana.run1"));
  const json out = json::parse(served(book, "ana.run1"));
  EXPECT_EQ(out.at("state"), "finished");
  EXPECT_EQ(out.at("collisions"), 30) << "every event, from the bag";
  EXPECT_EQ(out.at("summary").at("stop_reason"), "NO_MORE_COLLISIONS");
  // A late event of the completed run changes nothing.
  book.onEvent(run.events[12]);
  EXPECT_EQ(json::parse(served(book, "ana.run1")).at("collisions"), 30);
}

TEST(RunBookMemory, MissedEventsAreCompletedFromTheIndexAndTheBag) {
  TempDir dir;
  auto source = std::make_shared<FakeSource>();
  collision_lab_web::RunBook book(smallBudget(std::size_t{64} << 20), source);
  const ScriptedRun run = scriptedRun("ana", "ana.run1", 1.0e9, 3, 30, dir.path);
  source->put(rowOf(run, RunState::kFinished));
  feed(book, run, 7, true);  // the summary came, 23 of its published events never will
  EXPECT_FALSE(book.finished("ana.run1")) << "waits for its published events";
  EXPECT_EQ(book.reconcile(), 1u);
  const json out = json::parse(served(book, "ana.run1"));
  EXPECT_EQ(out.at("state"), "finished");
  EXPECT_EQ(out.at("collisions"), 30);
}

TEST(RunBookMemory, InterruptedRunShowsTheEventsItsBagHolds) {
  TempDir dir;
  auto source = std::make_shared<FakeSource>();
  collision_lab_web::RunBook book(smallBudget(std::size_t{64} << 20), source);
  ScriptedRun run = scriptedRun("ana", "ana.run1", 1.0e9, 3, 30, std::filesystem::path());
  // Its node died after 18 events: the bag has those and no summary.
  run.summary.bag_path = (dir.path / "ana.run1.bag").string();
  {
    rosbag::Bag bag;
    bag.open(run.summary.bag_path, rosbag::bagmode::Write);
    bag.write("/collision_lab/served_inputs", ros::Time(1.0), run.input);
    for (std::size_t k = 0; k < 18; ++k) bag.write("/collision_lab/collision_events", ros::Time(2.0), run.events[k]);
    bag.close();
  }
  source->put(rowOf(run, RunState::kRunning));
  feed(book, run, 5, false);
  source->setState("ana.run1", RunState::kInterrupted);
  std::thread stream([&] {  // a page's live stream of the run gets its final state
    const auto [version, finished] = book.waitForChange("ana.run1", 0, std::chrono::milliseconds(0));
    std::pair<std::uint64_t, bool> now{version, finished};
    while (!now.second) now = book.waitForChange("ana.run1", now.first, std::chrono::seconds(30));
    EXPECT_TRUE(book.finished("ana.run1"));
  });
  EXPECT_EQ(book.reconcile(), 1u);
  stream.join();
  const json out = json::parse(served(book, "ana.run1"));
  EXPECT_EQ(out.at("state"), "interrupted");
  EXPECT_EQ(out.at("collisions"), 18);
  EXPECT_EQ(out.at("summary").at("stop_reason"), "INTERRUPTED");
  EXPECT_EQ(out.at("summary").at("collision_count"), 18);
  EXPECT_EQ(book.bagPath("ana.run1"), run.summary.bag_path);
  EXPECT_EQ(json::parse(book.list(std::nullopt))[0].at("state"), "interrupted");
}

TEST(RunBookMemory, PeriodicReconciliationEndsARunWithoutBeingAsked) {
  TempDir dir;
  auto source = std::make_shared<FakeSource>();
  collision_lab_web::RunBookOptions options;
  options.reconcile_period = std::chrono::milliseconds(20);
  options.reconcile_after = std::chrono::milliseconds(0);
  collision_lab_web::RunBook book(options, source);
  const ScriptedRun run = scriptedRun("ana", "ana.run1", 1.0e9, 3, 30, dir.path);
  source->put(rowOf(run, RunState::kFinished));
  feed(book, run, 3, false);
  std::pair<std::uint64_t, bool> now{0, false};
  for (int k = 0; k < 100 && !now.second; ++k) now = book.waitForChange("ana.run1", now.first, std::chrono::seconds(1));
  EXPECT_TRUE(now.second) << "the periodic check completed it";
  EXPECT_EQ(json::parse(served(book, "ana.run1")).at("collisions"), 30);
}

TEST(RunBookMemory, WebRecordsKeepNoKeyframes) {
  // A 1,000-body gas: the marker view's record keeps about a thousand full states; the
  // web's keeps none, and its footprint is a small fraction.
  const ScriptedRun gas = scriptedRun("ana", "ana.gas", 1.0e9, 1000, 20000, std::filesystem::path());
  collision_lab_ros::RecordLimits rviz_limits;
  rviz_limits.envelope_vertices = 1024;
  collision_lab_ros::RunRecord rviz(gas.input, rviz_limits);
  collision_lab_ros::RecordLimits web_limits = rviz_limits;
  web_limits.keep_keyframes = false;
  collision_lab_ros::RunRecord web(gas.input, web_limits);
  for (const auto& e : gas.events) {
    rviz.add(e);
    web.add(e);
  }
  std::cout << "1,000-body gas, 20,000 impacts: rviz record " << rviz.memoryBytes() << " bytes, web record "
            << web.memoryBytes() << " bytes\n";
  EXPECT_GT(rviz.memoryBytes(), std::size_t{10} << 20);
  EXPECT_LT(web.memoryBytes(), std::size_t{1} << 20);
  EXPECT_EQ(web.collisions(), 20000u);
  const auto web_energy = web.energy().polyline(), rviz_energy = rviz.energy().polyline();
  ASSERT_EQ(web_energy.size(), rviz_energy.size()) << "the same plots";
  for (std::size_t k = 0; k < web_energy.size(); ++k) EXPECT_EQ(web_energy[k].y, rviz_energy[k].y);

  collision_lab_web::RunBook book(smallBudget(std::size_t{64} << 20), nullptr);
  feed(book, gas);
  EXPECT_LT(book.residentBytes(), std::size_t{1} << 20);
  EXPECT_EQ(json::parse(served(book, "ana.gas")).at("collisions"), 20000);
}


TEST(RunBookMemory, EvictedRunTheIndexDoesNotKnowKeepsAStub) {
  TempDir dir;
  auto source = std::make_shared<FakeSource>();  // the index missed this run
  collision_lab_web::RunBook book(smallBudget(1), source);
  const ScriptedRun first = scriptedRun("ana", "ana.run1", 1.0e9, 3, 40, dir.path);
  feed(book, first);
  const std::string before = served(book, "ana.run1");
  feed(book, scriptedRun("bo", "bo.run2", 1.0e9 + 1, 3, 40, dir.path));
  EXPECT_EQ(book.residentRuns(), 1u);
  const json list = json::parse(book.list(std::nullopt));
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].at("run_id"), "ana.run1");
  EXPECT_EQ(served(book, "ana.run1"), before);
}

// A web node started after a day of runs, on the real SQLite index: every run listed, an old
// link served from its bag.
TEST(RunBookMemory, RestartedWebNodeServesTheIndexsRuns) {
  TempDir dir;
  const std::string index_path = collision_lab::service::RunIndex::defaultPath(dir.path.string());
  {
    collision_lab::service::RunIndex index(index_path);  // the lab node's writes
    for (int k = 1; k <= 30; ++k) {
      const ScriptedRun run = scriptedRun("s" + std::to_string(k % 5), "run" + std::to_string(k), 1.0e9 + k, 3, 25,
                                          dir.path);
      IndexedRun row = rowOf(run, RunState::kQueued);
      index.accepted(row);
      index.started(row.run_id, row.accepted_at + 0.5);
      if (k == 30) {
        index.interrupted(row.run_id, row.accepted_at + 1, "", 25, run.summary.bag_path);
      } else {
        index.finished(row.run_id, row.accepted_at + 1, collision_lab_ros::summaryJson(run.summary), "NO_MORE_COLLISIONS",
                       25, run.summary.bag_path, collision_lab_ros::endingOf(run.summary));
      }
    }
  }
  collision_lab_web::RunBook book(smallBudget(std::size_t{64} << 20), collision_lab_web::openIndexRunSource(index_path));
  const json list = json::parse(book.list(std::nullopt));
  ASSERT_EQ(list.size(), 30u);
  EXPECT_EQ(list[0].at("run_id"), "run1");
  EXPECT_EQ(list[0].at("state"), "finished");
  EXPECT_EQ(list[0].at("model"), "scripted");  // read back from the index as the node wrote it
  EXPECT_EQ(list[29].at("state"), "interrupted");
  EXPECT_EQ(json::parse(book.list(std::string("s1"))).size(), 6u);
  EXPECT_EQ(book.residentRuns(), 0u);
  ASSERT_TRUE(book.has("run7"));
  const json run = json::parse(served(book, "run7"));
  EXPECT_EQ(run.at("state"), "finished");
  EXPECT_EQ(run.at("collisions"), 25);
  EXPECT_EQ(run.at("student"), "s2");
  EXPECT_EQ(run.at("summary").at("uncertified_values"), json::array({"final_time"}));
  EXPECT_EQ(run.at("summary").at("time_beyond_range"), false);
  EXPECT_EQ(book.bagPath("run7"), (dir.path / "run7.bag").string());
  EXPECT_EQ(json::parse(served(book, "run30")).at("state"), "interrupted");
}

}  // namespace

TEST(RunBookRejections, ListsTheIndexsRejectionsAsJson) {
  auto source = std::make_shared<FakeSource>();
  collision_lab::service::IndexedRejection r;
  r.at = 1.8e9;
  r.student = "ben";
  r.run_id = "pi_rviz";
  r.reason_name = "NON_POSITIVE_MASS";
  r.field = "masses[0]";
  r.message = "m_A is -1 kg; a mass must be positive";
  source->reject(r);
  r.student = "ana";
  source->reject(r);
  collision_lab_web::RunBook book(smallBudget(1), source);
  const json bens = json::parse(book.rejections(std::string("ben")));
  ASSERT_EQ(bens.size(), 1u);
  EXPECT_EQ(bens[0].at("student"), "ben");
  EXPECT_EQ(bens[0].at("run_id"), "pi_rviz");
  EXPECT_EQ(bens[0].at("reason_name"), "NON_POSITIVE_MASS");
  EXPECT_EQ(bens[0].at("field"), "masses[0]");
  EXPECT_EQ(bens[0].at("message"), "m_A is -1 kg; a mass must be positive");
  EXPECT_DOUBLE_EQ(bens[0].at("at").get<double>(), 1.8e9);
  EXPECT_EQ(json::parse(book.rejections(std::nullopt)).size(), 2u);
  EXPECT_EQ(source->asked_limit, collision_lab_web::RunBook::kRejectionsListed);
  // Without a run index there is nothing to list.
  collision_lab_web::RunBook alone(smallBudget(1), nullptr);
  EXPECT_EQ(json::parse(alone.rejections(std::nullopt)).size(), 0u);
}

namespace {

// The page and rviz get the same view description for the same run: the web JSON's view
// texts equal rviz's title and note (marker builder) for the same messages.
TEST(RunBookView, PageAndRvizGetTheSameViewDescription) {
  collision_lab::InitialConditions input;
  input.run_id = "ana.run1";
  input.student = "ana";
  input.masses = {1.0, 1.0, 1.0};
  input.positions = {2.0, 1.0, 0.0};
  input.velocities = {-1.0, 0.0, 1.0};
  input.restitution = {0.05, 0.05};
  input.max_collisions = 1000;
  collision_lab::Prediction prediction;
  prediction.run_id = "ana.run1";
  prediction.model_name = "three_body_spiral";
  prediction.model = collision_lab::Prediction::MODEL_THREE_BODY_SPIRAL;
  prediction.collapsed = true;
  prediction.collapse_time = 3.5;
  prediction.infinite_collisions = true;
  collision_lab::CollisionEvent collapse;
  collapse.run_id = "ana.run1";
  collapse.kind = collision_lab::CollisionEvent::KIND_COLLAPSE;
  collapse.first_moved = 0;
  collapse.last_moved = 2;
  collapse.time = 3.5;
  collapse.position = 1.0;
  collapse.pair_velocities_after = {0.0, 0.0};
  collision_lab::RunSummary summary;
  summary.run_id = "ana.run1";
  summary.student = "ana";
  summary.simulated = true;
  summary.collapsed = true;
  summary.collapse_count = 1;
  summary.recording_ok = false;

  collision_lab_web::RunBook book;
  book.onServedInput(input);
  book.onPrediction(prediction);
  book.onEvent(collapse);
  book.onSummary(summary);
  const json view = runJson(book, "ana.run1").at("view");

  collision_lab_ros::RunRecord rviz(input);
  rviz.prediction = prediction;
  rviz.add(collapse);
  rviz.summary = summary;
  EXPECT_EQ(view.at("title"), collision_lab_ros::markers::runTitle(rviz));
  EXPECT_EQ(view.at("note"), collision_lab_ros::markers::runNote(rviz));
  EXPECT_EQ(view.at("collapse"), "collapse at t = 3.5 s, x = 1 m, bodies A..C");
  EXPECT_EQ(view.at("worldline_bodies").at(0).at("colour"), collision_lab_ros::bodyColourHex(0));
}

// One colour per body (issue 31): the run JSON's view gives, for a scene of more bodies
// than rviz's palette has colours, the hex of exactly what rviz draws for each body (its
// start velocity's colour), for the page to draw. (Failed before: the JSON said the palette
// by index, rviz drew the start velocity's colour.)
TEST(RunBookView, PageAndRvizGetTheSameBodyColours) {
  collision_lab::InitialConditions input;
  input.run_id = "ana.run2";
  input.student = "ana";
  for (int i = 0; i < 12; ++i) {
    input.masses.push_back(1.0);
    input.positions.push_back(12.0 - i);
    input.velocities.push_back(i % 3 == 0 ? -1.0 : i % 3 == 1 ? 0.5 : 0.0);
  }
  input.restitution = {1.0};
  input.max_collisions = 1000;
  collision_lab_web::RunBook book;
  book.onServedInput(input);
  const json view = runJson(book, "ana.run2").at("view");
  collision_lab_ros::RunRecord rviz(input);
  const auto drawn = collision_lab_ros::buildAnimatedMarkers(rviz, collision_lab_ros::FrameClock{0.0, ""}, "f");
  const auto hex = [](const std_msgs::ColorRGBA& c) {
    char out[8];
    std::snprintf(out, sizeof out, "#%02x%02x%02x", static_cast<unsigned>(std::lround(c.r * 255)),
                  static_cast<unsigned>(std::lround(c.g * 255)), static_cast<unsigned>(std::lround(c.b * 255)));
    return std::string(out);
  };
  ASSERT_EQ(view.at("body_colours").size(), 12u);
  EXPECT_TRUE(view.at("colour_by_start_velocity").get<bool>());
  EXPECT_NE(view.at("colour_legend").get<std::string>().find("blue: moving left"), std::string::npos);
  // The worldlines and velocity series the view names are in the bodies' colours.
  for (const char* list : {"worldline_bodies", "velocity_bodies"}) {
    ASSERT_FALSE(view.at(list).empty()) << list;
    for (const auto& body : view.at(list)) {
      EXPECT_EQ(body.at("colour"), view.at("body_colours").at(body.at("index").get<std::size_t>())) << list;
    }
  }
  // rviz's scene at the start: all bodies of 1 kg in one list, in body order, each in the
  // colour the page gets.
  std::vector<std::string> scene;
  for (const auto& m : drawn.markers) {
    if (m.ns == collision_lab_ros::markers::ns::kBodies && m.action == visualization_msgs::Marker::ADD) {
      for (const auto& c : m.colors) scene.push_back(hex(c));
    }
  }
  EXPECT_EQ(scene, view.at("body_colours").get<std::vector<std::string>>());
  // Bodies at rest are purple (layout::kRestPurple: 0.62, 0.42, 0.72), moving left blue,
  // moving right red: three colours, not twelve.
  EXPECT_EQ(view.at("body_colours").at(2), "#9e6bb8");
  EXPECT_NE(view.at("body_colours").at(0), view.at("body_colours").at(1));
}

}  // namespace

// ---- A live run past the lab's published-event cap (RunProgress) ----

namespace {

/// The pi billiard (masses 1e4, 1, inf: 314 impacts) as the lab node sends it: its served
/// input, prediction and every CollisionEvent, from the core (not from the code under test).
struct PiRun {
  collision_lab::InitialConditions input;
  collision_lab::Prediction prediction;
  std::vector<collision_lab::CollisionEvent> events;
};

PiRun piRun(const std::string& run_id) {
  collision_lab::core::Scene scene = collision_lab::core::threeBodies();
  scene.masses = {1e4, 1.0, std::numeric_limits<double>::infinity()};
  scene.positions = {2.0, 1.0, 0.0};
  scene.velocities = {-1.0, 0.0, 0.0};
  PiRun run;
  run.input = collision_lab_ros::toInitialConditions(scene, collision_lab::core::RunMode::kFull, 10'000);
  run.input.run_id = run_id;
  const collision_lab::core::ScenePlan plan = collision_lab::core::planScene(collision_lab_ros::toScene(run.input));
  run.prediction = collision_lab_ros::toPredictionMsg(plan);
  run.prediction.run_id = run_id;
  collision_lab::core::SceneRunOptions options;
  options.lab.mode = collision_lab::core::RunMode::kFull;
  options.lab.max_collisions = 10'000;
  collision_lab::core::SceneVisitors visitors;
  collision_lab_ros::SceneEventConverter converter(plan.scene);
  visitors.impact = [&](const collision_lab::core::ImpactRecord& e) {
    run.events.push_back(converter.impact(e));
    run.events.back().run_id = run_id;
  };
  collision_lab::core::runScene(plan, options, visitors);
  return run;
}

/// What the lab node publishes on run_progress at event e (elastic: no heat).
collision_lab::RunProgress progressAt(const collision_lab::CollisionEvent& e, std::uint64_t published) {
  collision_lab::RunProgress p;
  p.run_id = e.run_id;
  p.collisions = e.index;
  p.time = e.time;
  p.published = published;
  p.latest_event = e;
  return p;
}

// The web node sees the first 100 events (the lab's ~max_published_events), then samples
// at 200 and 300: the counter, the note and the plots follow the samples, and nothing
// counts as missing (issue 31: the counter froze at the cap until the summary).
TEST(RunBookProgress, SamplesPastTheCapMoveTheCounterAndThePlots) {
  const PiRun pi = piRun("ana.run1");
  ASSERT_EQ(pi.events.size(), 314u) << "pi's digits: 314 impacts";
  collision_lab_web::RunBook book;
  book.onServedInput(pi.input);
  book.onPrediction(pi.prediction);
  for (std::size_t k = 0; k < 100; ++k) book.onEvent(pi.events[k]);
  EXPECT_EQ(runJson(book, "ana.run1").at("collisions"), 100);

  book.onProgress(progressAt(pi.events[199], 100));
  book.onProgress(progressAt(pi.events[299], 100));
  const json run = runJson(book, "ana.run1");
  EXPECT_EQ(run.at("state"), "running");
  EXPECT_EQ(run.at("collisions"), 300) << "the progress message's count, not the published events'";
  EXPECT_DOUBLE_EQ(run.at("newest_time").get<double>(), pi.events[299].time);
  const json& view = run.at("view");
  EXPECT_EQ(view.at("collisions_so_far"), 300);
  EXPECT_EQ(view.at("counter"), "300 of 314 collisions predicted, running");
  const std::string note = view.at("note");
  EXPECT_NE(note.find("sampled past the first 100 collisions published"), std::string::npos) << note;
  EXPECT_EQ(note.find("missing"), std::string::npos) << "samples are no lost messages: " << note;
  // Each plot ends at the sample, with its values (the JSON's six significant digits).
  for (const json& series : run.at("plots").at("velocity")) {
    const std::size_t body = series.at("body");
    const json& last = series.at("points").back();
    EXPECT_EQ(last[0], 300) << "body " << body;
    EXPECT_NEAR(last[1].get<double>(), pi.events[299].velocities_after[body], 1e-5) << "body " << body;
  }
  EXPECT_NEAR(run.at("plots").at("energy").back()[1].get<double>(), pi.events[299].total_energy,
              1e-5 * pi.events[299].total_energy);
  for (const json& line : run.at("plots").at("worldlines")) {
    const std::size_t body = line.at("body");
    const json& last = line.at("points").back();
    EXPECT_NEAR(last[0].get<double>(), pi.events[299].time, 1e-5 * pi.events[299].time) << "body " << body;
    EXPECT_NEAR(last[1].get<double>(), pi.events[299].positions[body], 1e-5) << "body " << body;
  }
}

// A sample past a gap restarts the record's replay from its state: published events after
// it continue from the exact state, as if every collision had been received.
TEST(RunRecordSample, ReplayGoesOnFromTheSampledState) {
  const PiRun pi = piRun("ana.run1");
  ASSERT_EQ(pi.events.size(), 314u);
  collision_lab_ros::RunRecord whole(pi.input), sampled(pi.input);
  for (const auto& e : pi.events) whole.add(e);
  for (std::size_t k = 0; k < 10; ++k) sampled.add(pi.events[k]);
  sampled.addSample(pi.events[149], 0.0);
  EXPECT_TRUE(sampled.sampled());
  EXPECT_EQ(sampled.sampledAfter(), 10u);
  EXPECT_EQ(sampled.sampledCollisions(), 139u) << "collisions 11..149, known by count";
  EXPECT_EQ(sampled.missedCollisions(), 0u);
  EXPECT_EQ(sampled.collisions(), 150u);
  sampled.addSample(pi.events[149], 0.0);  // the same sample again: ignored
  EXPECT_EQ(sampled.collisions(), 150u);
  for (std::size_t k = 150; k < pi.events.size(); ++k) sampled.add(pi.events[k]);
  EXPECT_EQ(sampled.collisions(), 314u);
  EXPECT_EQ(sampled.missedCollisions(), 0u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(sampled.velocity(i).last().y, whole.velocity(i).last().y, 1e-9) << "body " << i;
    EXPECT_NEAR(sampled.worldline(i).last().y, whole.worldline(i).last().y, 1e-9) << "body " << i;
  }
  EXPECT_NEAR(sampled.energy().last().y, whole.energy().last().y, 1e-9);

  // A sample without every body's state cannot move the plots: counted as malformed.
  collision_lab::CollisionEvent bare = pi.events[313];
  bare.positions.clear();
  collision_lab_ros::RunRecord record(pi.input);
  record.addSample(bare, 0.0);
  EXPECT_EQ(record.malformedEvents(), 1u);
  EXPECT_EQ(record.collisions(), 0u);
}

}  // namespace
