// collision_lab_node as a class service (service_test.test, issue 30): the node's
// ~max_collisions is a ceiling, ~max_run_seconds and max_bag_bytes budget a run (each with
// its own stop reason, the bag complete), the queue is fair across students, short runs
// have a lane of their own, ~cancel drops a waiting run and stops a running one, and a
// worker's exception ends only its run.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/Cancel.h"
#include "collision_lab/RunQueue.h"
#include "collision_lab/RunScene.h"
#include "collision_lab/RunParameters.h"
#include "run_collector.h"

namespace {

using collision_lab_test::callService;
using collision_lab_test::makeInput;
using collision_lab_test::RunCollector;
using collision_lab_test::waitUntil;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint64_t kAll = std::numeric_limits<std::uint64_t>::max();

/// The pi billiard: masses (m, 1, inf), positions (2, 1, 0), velocities (-1, 0, 0).
collision_lab::RunScene piScene(const std::string& run_id, double m, std::uint64_t max_collisions,
                                std::uint8_t mode = collision_lab::InitialConditions::MODE_FULL) {
  collision_lab::RunScene call;
  call.request.run_id = run_id;
  call.request.masses = {m, 1, kInf};
  call.request.positions = {2, 1, 0};
  call.request.velocities = {-1, 0, 0};
  call.request.max_collisions = max_collisions;
  call.request.mode = mode;
  return call;
}

collision_lab::InitialConditions piInput(const std::string& run_id, const std::string& student, double m,
                                         std::uint8_t mode = collision_lab::InitialConditions::MODE_SUMMARY_ONLY) {
  collision_lab::InitialConditions input = makeInput(run_id, {m, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  input.student = student;
  input.mode = mode;
  input.max_collisions = kAll;
  return input;
}

/// The bag of a run: its events and the summary written last (checks it is complete).
struct BagContents {
  std::uint64_t events = 0;
  std::vector<collision_lab::RunSummary> summaries;
  std::vector<collision_lab::RunParameters> parameters;
};
BagContents readBag(const std::string& path) {
  BagContents contents;
  rosbag::Bag bag;
  bag.open(path, rosbag::bagmode::Read);  // throws when the bag is not complete
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (m.isType<collision_lab::CollisionEvent>()) ++contents.events;
    if (const auto s = m.instantiate<collision_lab::RunSummary>()) contents.summaries.push_back(*s);
    if (const auto p = m.instantiate<collision_lab::RunParameters>()) contents.parameters.push_back(*p);
  }
  return contents;
}

// ---- The collision ceiling (node ~max_collisions 1000, simulate_to_cap) ----

TEST(Service, TheNodesMaxCollisionsIsACeilingAClientMayOnlyLower) {
  // 31,415 impacts. A client asking 2^64 - 1 stops at the node's 1000.
  auto greedy = piScene("greedy", 1e8, kAll);
  ASSERT_TRUE(callService("/ceiling/collision_lab_node/run_scene", greedy));
  ASSERT_TRUE(greedy.response.ok) << greedy.response.message;
  const auto& s = greedy.response.summary;
  EXPECT_EQ(s.collision_count, 1000u);
  EXPECT_EQ(s.stop_reason, "SERVICE_COLLISION_LIMIT");
  EXPECT_TRUE(s.truncated);
  EXPECT_FALSE(s.cancelled);
  EXPECT_NE(s.truncation_reason.find("~max_collisions"), std::string::npos) << s.truncation_reason;
  const BagContents bag = readBag(s.bag_path);
  EXPECT_EQ(bag.events, 1000u);
  ASSERT_EQ(bag.parameters.size(), 1u);
  EXPECT_EQ(bag.parameters[0].max_collisions, 1000u);

  // A client asking less gets its own cap (CAP, not a service limit); 0 means the node's.
  auto modest = piScene("modest", 1e8, 500);
  ASSERT_TRUE(callService("/ceiling/collision_lab_node/run_scene", modest));
  EXPECT_EQ(modest.response.summary.collision_count, 500u);
  EXPECT_EQ(modest.response.summary.stop_reason, "CAP");
  auto fallback = piScene("fallback", 1e8, 0);
  ASSERT_TRUE(callService("/ceiling/collision_lab_node/run_scene", fallback));
  EXPECT_EQ(fallback.response.summary.collision_count, 1000u);
  EXPECT_EQ(fallback.response.summary.stop_reason, "CAP");
  // Under the ceiling, a run ends by itself: pi's 31.
  auto pi = piScene("pi31", 100, kAll);
  ASSERT_TRUE(callService("/ceiling/collision_lab_node/run_scene", pi));
  EXPECT_EQ(pi.response.summary.collision_count, 31u);
  EXPECT_EQ(pi.response.summary.stop_reason, "FINISHED");
}

TEST(Service, AStudentsRunIdIsTakenOnlyWhenItWasServedBefore) {
  // A student's run_id is served as <student>.<run_id>: that prefix is no sign of a taken id.
  auto first = piScene("pi_rviz", 100, kAll);
  first.request.student = "ben";
  ASSERT_TRUE(callService("/ceiling/collision_lab_node/run_scene", first));
  ASSERT_TRUE(first.response.ok) << first.response.message;
  EXPECT_EQ(first.response.summary.run_id, "ben.pi_rviz");
  EXPECT_EQ(first.response.summary.requested_run_id, "");
  EXPECT_EQ(first.response.message.find("was taken"), std::string::npos) << first.response.message;
  // The same id again is taken: served under the next free name, and said so.
  auto again = piScene("pi_rviz", 100, kAll);
  again.request.student = "ben";
  ASSERT_TRUE(callService("/ceiling/collision_lab_node/run_scene", again));
  ASSERT_TRUE(again.response.ok) << again.response.message;
  EXPECT_EQ(again.response.summary.run_id, "ben.pi_rviz.2");
  EXPECT_EQ(again.response.summary.requested_run_id, "pi_rviz");
  EXPECT_NE(again.response.message.find("run_id 'pi_rviz' was taken"), std::string::npos) << again.response.message;
}

// ---- The time and bag budgets (node ~max_run_seconds 1, ~max_collisions 1e15) ----

TEST(Service, ARunPastItsTimeBudgetStopsWithItsBagComplete) {
  // 3.14e8 impacts: far more than 1 s of work.
  auto endless = piScene("endless", 1e16, kAll, collision_lab::InitialConditions::MODE_SUMMARY_ONLY);
  ASSERT_TRUE(callService("/limits/collision_lab_node/run_scene", endless));
  ASSERT_TRUE(endless.response.ok) << endless.response.message;
  const auto& s = endless.response.summary;
  EXPECT_EQ(s.stop_reason, "SERVICE_TIME_LIMIT");
  EXPECT_TRUE(s.truncated);
  EXPECT_FALSE(s.cancelled);
  EXPECT_GT(s.collision_count, 0u);
  EXPECT_LT(s.collision_count, 314159265u);
  EXPECT_NE(s.truncation_reason.find("~max_run_seconds"), std::string::npos) << s.truncation_reason;
  EXPECT_TRUE(s.recording_ok) << s.recording_error;
  const BagContents bag = readBag(s.bag_path);
  ASSERT_EQ(bag.summaries.size(), 1u);
  EXPECT_EQ(bag.summaries[0].stop_reason, "SERVICE_TIME_LIMIT");
  EXPECT_EQ(bag.summaries[0].collision_count, s.collision_count);
  ASSERT_EQ(bag.parameters.size(), 1u);
  EXPECT_EQ(bag.parameters[0].max_run_seconds, 1.0);
  std::printf("time budget 1 s: stopped after %llu collisions, compute time %.3f s\n",
              static_cast<unsigned long long>(s.collision_count), s.compute_time);

  // An input may lower the budget, never raise it.
  auto raise = piScene("raise", 1e16, kAll, collision_lab::InitialConditions::MODE_SUMMARY_ONLY);
  raise.request.max_run_seconds = 1e6;
  ASSERT_TRUE(callService("/limits/collision_lab_node/run_scene", raise));
  EXPECT_EQ(raise.response.summary.stop_reason, "SERVICE_TIME_LIMIT");
  EXPECT_NE(raise.response.summary.truncation_reason.find("~max_run_seconds"), std::string::npos);
  auto lower = piScene("lower", 1e16, kAll, collision_lab::InitialConditions::MODE_SUMMARY_ONLY);
  lower.request.max_run_seconds = 0.2;
  ASSERT_TRUE(callService("/limits/collision_lab_node/run_scene", lower));
  EXPECT_EQ(lower.response.summary.stop_reason, "SERVICE_TIME_LIMIT");
  EXPECT_NE(lower.response.summary.truncation_reason.find("the input's max_run_seconds"), std::string::npos)
      << lower.response.summary.truncation_reason;
}

TEST(Service, ARunPastItsBagBudgetStopsWithItsBagComplete) {
  // 31,415 impacts, each recorded: far more than 20,000 bytes.
  auto big = piScene("big_bag", 1e8, kAll);
  big.request.max_bag_bytes = 20000;
  ASSERT_TRUE(callService("/limits/collision_lab_node/run_scene", big));
  ASSERT_TRUE(big.response.ok) << big.response.message;
  const auto& s = big.response.summary;
  EXPECT_EQ(s.stop_reason, "SERVICE_BAG_LIMIT");
  EXPECT_TRUE(s.truncated);
  EXPECT_LT(s.collision_count, 31415u);
  EXPECT_NE(s.truncation_reason.find("max_bag_bytes"), std::string::npos) << s.truncation_reason;
  const BagContents bag = readBag(s.bag_path);
  EXPECT_EQ(bag.events, s.collision_count);
  ASSERT_EQ(bag.summaries.size(), 1u);
  EXPECT_EQ(bag.summaries[0].stop_reason, "SERVICE_BAG_LIMIT");
  ASSERT_EQ(bag.parameters.size(), 1u);
  EXPECT_EQ(bag.parameters[0].max_bag_bytes, 20000u);
}

// ---- Scheduling (two workers, one for short runs only) ----

/// Watches the fair node's run starts (served_inputs) and acceptances.
class FairWatch {
 public:
  FairWatch() : runs_("fair") {
    ros::NodeHandle nh("fair");
    served_ = nh.subscribe<collision_lab::InitialConditions>(
        collision_lab_ros::kServedInputsTopic, 1000,
        [this](const collision_lab::InitialConditions::ConstPtr& msg) { started.push_back(msg->run_id); });
    accepted_ = nh.subscribe<collision_lab::AcceptedRun>(
        collision_lab_ros::kAcceptedRunsTopic, 1000,
        [this](const collision_lab::AcceptedRun::ConstPtr& msg) { accepted.push_back(*msg); });
    queue_ = nh.subscribe<collision_lab::RunQueue>(
        collision_lab_ros::kRunQueueTopic, 1000,
        [this](const collision_lab::RunQueue::ConstPtr& msg) { queues.push_back(*msg); });
    runs_.waitForConnection();
    waitUntil([this] { return served_.getNumPublishers() > 0 && accepted_.getNumPublishers() > 0; },
              "the fair node's served_inputs and accepted_runs");
  }
  RunCollector& runs() { return runs_; }
  /// Index of run_id among the runs started; -1 when not started.
  long startIndex(const std::string& run_id) const {
    for (std::size_t i = 0; i < started.size(); ++i) {
      if (started[i] == run_id) return static_cast<long>(i);
    }
    return -1;
  }
  const collision_lab::AcceptedRun* acceptance(const std::string& run_id) const {
    for (const auto& a : accepted) {
      if (a.run_id == run_id) return &a;
    }
    return nullptr;
  }

  std::vector<std::string> started;
  std::vector<collision_lab::AcceptedRun> accepted;
  std::vector<collision_lab::RunQueue> queues;

 private:
  RunCollector runs_;
  ros::Subscriber served_, accepted_, queue_;
};

FairWatch& fair() {
  static FairWatch watch;
  return watch;
}

/// A run of the fair node's long lane that no machine ends by itself: the pi billiard at
/// 10^20 (3.1 x 10^10 impacts), with a time budget of an hour. ~cancel ends it.
collision_lab::InitialConditions endlessInput(const std::string& run_id, const std::string& student) {
  collision_lab::InitialConditions input = piInput(run_id, student, 1e20);
  input.max_run_seconds = 3600;
  return input;
}

/// Stops run_id (running or waiting) with ~cancel and waits for its summary.
void stopAndAwait(FairWatch& w, const std::string& run_id) {
  collision_lab::Cancel cancel;
  cancel.request.run_id = run_id;
  cancel.request.requested_by = "service_test";
  ASSERT_TRUE(callService("/fair/collision_lab_node/cancel", cancel));
  EXPECT_TRUE(cancel.response.ok) << run_id << ": " << cancel.response.message;
  w.runs().waitFor(run_id);
}

/// Stops every run it names when it goes out of scope (a test that failed part-way, too), so
/// that no endless run is left on the fair node's one long-lane worker for the tests after.
struct StopsAtExit {
  std::vector<std::string> run_ids;
  ~StopsAtExit() {
    for (const std::string& run_id : run_ids) {
      collision_lab::Cancel cancel;
      cancel.request.run_id = run_id;
      cancel.request.requested_by = "service_test's clean-up";
      callService("/fair/collision_lab_node/cancel", cancel);  // not ok for a run already ended
    }
  }
};

TEST(Service, AStudentsTenthRunWaitsBehindAClassmatesFirst) {
  FairWatch& w = fair();
  // Ten runs of ana, then one of ben, each running until it is stopped: the order in which
  // they start is the scheduler's alone, however fast the machine (no time budget decides).
  const std::size_t before = w.started.size();
  StopsAtExit stops;
  std::vector<std::string>& ids = stops.run_ids;
  for (int i = 1; i <= 10; ++i) {
    w.runs().publish(endlessInput("r" + std::to_string(i), "ana"));
    ids.push_back("ana.r" + std::to_string(i));
  }
  w.runs().publish(endlessInput("r1", "ben"));
  ids.push_back("ben.r1");
  ASSERT_TRUE(waitUntil(
      [&] { return std::all_of(ids.begin(), ids.end(), [&](const std::string& id) { return w.acceptance(id); }); },
      "all eleven runs to be accepted"));
  // The fair node's one long-lane worker runs them one at a time: each is stopped once it
  // has started, and the next starts.
  for (std::size_t k = 0; k < ids.size(); ++k) {
    ASSERT_TRUE(waitUntil([&] { return w.started.size() > before + k; }, "the next run to start"));
    const std::string run_id = w.started[before + k];  // a copy: waiting spins callbacks that grow started
    stopAndAwait(w, run_id);
  }
  const auto startOf = [&](const std::string& id) { return w.startIndex(id) - static_cast<long>(before); };
  const long ben_start = startOf("ben.r1");
  ASSERT_GE(ben_start, 0);
  // ben's run starts right after ana's second (ana.r1 was running when the rest arrived).
  EXPECT_LT(ben_start, startOf("ana.r3"));
  EXPECT_LE(ben_start, 2);
  const auto* accepted = w.acceptance("ben.r1");
  ASSERT_NE(accepted, nullptr);
  EXPECT_EQ(accepted->lane, "long");
  EXPECT_LE(accepted->queue_position, 1u);  // at most ana.r2 ahead of it
  const auto* last = w.acceptance("ana.r10");
  ASSERT_NE(last, nullptr);
  EXPECT_GE(last->queue_position, 8u);
  // The queue was published with the workers and a waiting run.
  ASSERT_FALSE(w.queues.empty());
  EXPECT_EQ(w.queues.back().workers, 2u);
  EXPECT_EQ(w.queues.back().short_lane_workers, 1u);
  bool saw_waiting = false;
  for (const auto& q : w.queues) {
    for (const auto& r : q.runs) saw_waiting = saw_waiting || !r.running;
  }
  EXPECT_TRUE(saw_waiting);
  EXPECT_TRUE(waitUntil([&] { return w.queues.back().runs.empty(); }, "an empty run_queue"));
}

TEST(Service, AShortRunNeverWaitsBehindLongOnes) {
  FairWatch& w = fair();
  // Three long runs occupy the long lane until they are stopped.
  const StopsAtExit stops{{"carl.long1", "carl.long2", "carl.long3"}};
  for (int i = 1; i <= 3; ++i) w.runs().publish(endlessInput("long" + std::to_string(i), "carl"));
  ASSERT_TRUE(waitUntil([&] { return w.startIndex("carl.long1") >= 0; }, "carl.long1 to start"));
  const auto sent = std::chrono::steady_clock::now();
  w.runs().publish(piInput("quick", "dora", 100, collision_lab::InitialConditions::MODE_FULL));
  const auto& quick = w.runs().waitFor("dora.quick");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  ASSERT_EQ(quick.summaries.size(), 1u);
  EXPECT_EQ(quick.summaries[0].collision_count, 31u);
  // It finished while the first long run still ran.
  EXPECT_TRUE(w.runs().runs().at("carl.long1").summaries.empty());
  const auto* accepted = w.acceptance("dora.quick");
  ASSERT_NE(accepted, nullptr);
  EXPECT_EQ(accepted->lane, "short");
  std::printf("short run with the long lane busy: summary %.3f s after it was sent\n", seconds);
  for (int i = 1; i <= 3; ++i) stopAndAwait(w, "carl.long" + std::to_string(i));
}

TEST(Service, CancelDropsAWaitingRunAndStopsARunningOne) {
  FairWatch& w = fair();
  for (const char* id : {"first", "second"}) {
    auto input = piInput(id, "eve", 1e16);
    input.max_run_seconds = 60;
    w.runs().publish(input);
  }
  ASSERT_TRUE(waitUntil([&] { return w.startIndex("eve.first") >= 0 && w.acceptance("eve.second"); },
                        "eve.first to start and eve.second to be accepted"));
  collision_lab::Cancel waiting;
  waiting.request.run_id = "eve.second";
  waiting.request.requested_by = "the teacher";
  ASSERT_TRUE(callService("/fair/collision_lab_node/cancel", waiting));
  EXPECT_TRUE(waiting.response.ok) << waiting.response.message;
  const auto& second = w.runs().waitFor("eve.second");
  ASSERT_EQ(second.summaries.size(), 1u);
  EXPECT_EQ(second.summaries[0].stop_reason, "CANCELLED");
  EXPECT_TRUE(second.summaries[0].cancelled);
  EXPECT_FALSE(second.summaries[0].simulated);
  EXPECT_NE(second.summaries[0].truncation_reason.find("the teacher"), std::string::npos);
  EXPECT_EQ(readBag(second.summaries[0].bag_path).summaries.size(), 1u);
  EXPECT_EQ(w.startIndex("eve.second"), -1);  // never started

  collision_lab::Cancel running;
  running.request.run_id = "eve.first";
  running.request.requested_by = "its student";
  ASSERT_TRUE(callService("/fair/collision_lab_node/cancel", running));
  EXPECT_TRUE(running.response.ok) << running.response.message;
  const auto& first = w.runs().waitFor("eve.first");
  ASSERT_EQ(first.summaries.size(), 1u);
  EXPECT_EQ(first.summaries[0].stop_reason, "CANCELLED");
  EXPECT_TRUE(first.summaries[0].truncated);
  EXPECT_NE(first.summaries[0].truncation_reason.find("its student"), std::string::npos);
  EXPECT_EQ(readBag(first.summaries[0].bag_path).summaries.size(), 1u);

  collision_lab::Cancel nothing;
  nothing.request.run_id = "eve.nope";
  ASSERT_TRUE(callService("/fair/collision_lab_node/cancel", nothing));
  EXPECT_FALSE(nothing.response.ok);
}

TEST(Service, AWorkersExceptionEndsOnlyItsRun) {
  FairWatch& w = fair();
  w.runs().publish(piInput("boom", "crasher", 100, collision_lab::InitialConditions::MODE_FULL));
  const auto& boom = w.runs().waitFor("crasher.boom");
  ASSERT_EQ(boom.summaries.size(), 1u);
  const auto& s = boom.summaries[0];
  EXPECT_EQ(s.stop_reason, "WORKER_ERROR");
  EXPECT_TRUE(s.truncated);
  EXPECT_NE(s.truncation_reason.find("bad_alloc"), std::string::npos) << s.truncation_reason;
  EXPECT_EQ(readBag(s.bag_path).summaries.size(), 1u);
  // The node goes on: the next runs are served.
  w.runs().publish(piInput("after", "fred", 100, collision_lab::InitialConditions::MODE_FULL));
  const auto& after = w.runs().waitFor("fred.after");
  ASSERT_EQ(after.summaries.size(), 1u);
  EXPECT_EQ(after.summaries[0].stop_reason, "FINISHED");
  EXPECT_EQ(after.summaries[0].collision_count, 31u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "service_test");
  ros::NodeHandle nh;
  ros::Time::init();
  // The nodes start with the test: wait (generously) until each serves.
  for (const char* ns : {"ceiling", "limits", "fair"}) {
    const std::string service = std::string("/") + ns + "/collision_lab_node/run_scene";
    if (!ros::service::waitForService(service, ros::Duration(60.0))) {
      std::fprintf(stderr, "%s did not come up\n", service.c_str());
      return 1;
    }
  }
  return RUN_ALL_TESTS();
}
