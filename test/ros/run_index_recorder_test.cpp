// The lab node's side of the run index, no master: the bag claim's lock (claimBag) held
// while a bag is written and dropped when it closes; recovery of the .active bag of a
// writer killed mid-run (reindexed, renamed, counted, indexed as interrupted), never of a
// live owner's; stale rows ended; ~list_runs' rows from the index; a write-locked index
// holds up nothing and loses no row; a full disk holds the index's writes until space is
// freed, and a finished run whose bag was left .active stays finished.
#include <sqlite3.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/io/scenario_file.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/run_index_recorder.h"
#include "collision_lab/ros/run_recorder.h"

namespace fs = std::filesystem;
using collision_lab::service::RunIndex;
using collision_lab::service::RunState;
using namespace collision_lab_ros;

namespace {

/// Whether another open file description can take path's flock now.
bool lockable(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool got = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
  ::close(fd);
  return got;
}

collision_lab::InitialConditions input(const std::string& run_id, const std::string& student) {
  collision_lab::InitialConditions in;
  in.header.stamp = ros::Time(1000);
  in.run_id = run_id;
  in.student = student;
  in.masses = {100, 1, std::numeric_limits<double>::infinity()};
  in.positions = {2, 1, 0};
  in.velocities = {-1, 0, 0};
  return in;
}

collision_lab::CollisionEvent event(const std::string& run_id, std::uint64_t k) {
  collision_lab::CollisionEvent e;
  e.run_id = run_id;
  e.index = k;
  e.time = 0.5 * static_cast<double>(k + 1);
  e.header.stamp = ros::Time(1000) + ros::Duration(e.time);
  return e;
}

/// Mounts a tmpfs of `megabytes` on dir; false where this process may not (not root).
bool mountTmpfs(const std::string& dir, int megabytes) {
  const std::string command =
      "mount -t tmpfs -o size=" + std::to_string(megabytes) + "m tmpfs '" + dir + "' 2>/dev/null";
  return std::system(command.c_str()) == 0;
}

/// Writes path until its file system has no byte left.
void fillDisk(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  const std::string chunk(1 << 20, 'x');
  for (std::size_t size : {chunk.size(), std::size_t{4096}, std::size_t{1}}) {
    while (::write(fd, chunk.data(), size) > 0) {
    }
  }
  ::close(fd);
}

class RunIndexRecorderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/run_index_recorder_test_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// A writer process killed mid-run: it claims run_id's bag, writes the input and
  /// `events` events, and ends without closing the bag (as kill -9 would).
  void killedWriter(const std::string& run_id, std::uint64_t events) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      RunRecorder* recorder = new RunRecorder(dir_, run_id);  // never destroyed: no close
      recorder->write("/initial_conditions", ros::Time(1000), input(run_id, "ana"));
      for (std::uint64_t k = 0; k < events; ++k) {
        const auto e = event(run_id, k);
        recorder->write("/collision_events", e.header.stamp, e);
      }
      ::_exit(recorder->ok() ? 0 : 1);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    ASSERT_TRUE(fs::exists(bagPath(dir_, run_id) + ".active"));
    ASSERT_FALSE(fs::exists(bagPath(dir_, run_id)));
  }

  std::string dir_;
};

/// Every field of InitialConditions, compared exactly (an infinite mass equals itself).
void expectSameInput(const collision_lab::InitialConditions& a, const collision_lab::InitialConditions& b,
                     const std::string& name) {
  EXPECT_EQ(a.run_id, b.run_id) << name;
  EXPECT_EQ(a.student, b.student) << name;
  EXPECT_EQ(a.mode, b.mode) << name;
  EXPECT_EQ(a.masses, b.masses) << name;
  EXPECT_EQ(a.positions, b.positions) << name;
  EXPECT_EQ(a.velocities, b.velocities) << name;
  EXPECT_EQ(a.restitution, b.restitution) << name;
  EXPECT_EQ(a.restitution_model, b.restitution_model) << name;
  EXPECT_EQ(a.tc, b.tc) << name;
  EXPECT_EQ(a.elastic_below, b.elastic_below) << name;
  EXPECT_EQ(a.viscoelastic_speed, b.viscoelastic_speed) << name;
  EXPECT_EQ(a.ring, b.ring) << name;
  EXPECT_EQ(a.max_collisions, b.max_collisions) << name;
  EXPECT_EQ(a.max_run_seconds, b.max_run_seconds) << name;
  EXPECT_EQ(a.max_bag_bytes, b.max_bag_bytes) << name;
}

TEST(InputJson, EverySceneKindReadsBackAsServed) {
  // The one input JSON, which the index stores and the web serves as a run's scene: every
  // preset (walls, a ring, per-pair e, the TC model, gases), and the other restitution
  // models, come back field for field, bit for bit.
  using Model = collision_lab::core::RestitutionModelKind;
  std::vector<collision_lab::InitialConditions> inputs;
  for (const auto& entry : collision_lab::io::loadScenes(COLLISION_LAB_SOURCE_DIR "/config/scenarios.yaml")) {
    collision_lab::InitialConditions in =
        toInitialConditions(entry.scene, collision_lab::core::RunMode::kFull, entry.max_collisions);
    in.run_id = entry.name;
    in.student = "ana";
    in.max_run_seconds = 2.5;
    in.max_bag_bytes = 1'000'000;
    inputs.push_back(in);
  }
  collision_lab::InitialConditions threshold = inputs.front();
  threshold.restitution_model = static_cast<std::uint8_t>(Model::kThreshold);
  threshold.elastic_below = 0.1;
  threshold.mode = collision_lab::InitialConditions::MODE_SUMMARY_ONLY;
  collision_lab::InitialConditions viscoelastic = inputs.front();
  viscoelastic.restitution_model = static_cast<std::uint8_t>(Model::kViscoelastic);
  viscoelastic.viscoelastic_speed = 1.0 / 3.0;
  inputs.push_back(threshold);
  inputs.push_back(viscoelastic);
  std::set<std::string> kinds;
  for (const auto& in : inputs) {
    const nlohmann::json fields = inputFields(in);
    kinds.insert(fields["restitution_model"].get<std::string>());
    if (in.ring > 0) kinds.insert("ring");
    if (std::isinf(in.masses.front()) || std::isinf(in.masses.back())) kinds.insert("wall");
    if (in.masses.size() > 100) kinds.insert("gas");
    expectSameInput(inputFromJson(inputJson(in)), in, in.run_id);
  }
  EXPECT_EQ(kinds, (std::set<std::string>{"constant", "tc", "threshold", "viscoelastic", "ring", "wall", "gas"}));
}

TEST(InputJson, RowsOfEarlierVersionsStillReadAndBadOnesAreRefused) {
  // Before 0.8 the index stored restitution_model as its number.
  const collision_lab::InitialConditions in = inputFromJson(
      R"({"mode":0,"masses":[1,"inf"],"positions":[1,0],"velocities":[-1,0],"restitution":[],)"
      R"("restitution_model":1,"tc":0.5,"elastic_below":0,"viscoelastic_speed":0,"ring":null,)"
      R"("max_collisions":10,"max_run_seconds":0,"max_bag_bytes":0})");
  EXPECT_EQ(in.restitution_model, static_cast<std::uint8_t>(collision_lab::core::RestitutionModelKind::kTc));
  EXPECT_EQ(in.tc, 0.5);
  EXPECT_EQ(in.ring, 0.0);
  EXPECT_TRUE(std::isinf(in.masses[1]));
  EXPECT_EQ(inputFields(in)["restitution_model"], "tc");
  EXPECT_THROW(inputFromJson("not json"), std::invalid_argument);
  EXPECT_THROW(inputFromJson(R"({"mode":0,"masses":[1],"positions":[0],"velocities":[0],"restitution":[],)"
                             R"("restitution_model":"sticky","tc":0,"elastic_below":0,"viscoelastic_speed":0,)"
                             R"("ring":0,"max_collisions":1,"max_run_seconds":0,"max_bag_bytes":0})"),
               std::invalid_argument);
}

TEST(SummaryJson, EveryFieldItWritesReadsBack) {
  // The one summary JSON, which the index stores and the web serves and reads back: each
  // field summaryFields writes comes back as it was (a value that is not finite as NaN).
  collision_lab::RunSummary s;
  s.run_id = "ana.pi";
  s.student = "ana";
  s.requested_run_id = "pi";
  s.mode = collision_lab::InitialConditions::MODE_SUMMARY_ONLY;
  s.model_name = "three_body_rotation";
  s.model_reason = "three elastic bodies";
  s.body_count = 3;
  s.collision_count = 31;
  s.simulated = true;
  s.truncated = true;
  s.truncation_reason = "stopped by the teacher";
  s.cancelled = true;
  s.stop_reason = "CANCELLED";
  s.predicted_collision_count = 31;
  s.predicted_collision_count_defined = true;
  s.paper_predicted_collision_count = -2;
  s.paper_predicted_collision_count_defined = true;
  s.infinite_collisions = true;
  s.final_velocities = {0.1, -0.7, std::numeric_limits<double>::infinity()};
  s.energy_lost = 1.0 / 3.0;
  s.collapsed = true;
  s.max_prediction_error = std::numeric_limits<double>::quiet_NaN();
  s.energy_relative_drift = 1e-300;
  s.momentum_relative_drift = -2.5e-17;
  s.compute_time = 0.125;
  s.uncertified_values = {"final_velocities"};
  s.time_beyond_range = true;
  s.published_events = 29;
  s.bag_path = "/bags/ana.pi.bag";
  s.recording_ok = true;
  s.recording_error = "none";
  const collision_lab::RunSummary r = summaryFromFields(nlohmann::json::parse(summaryJson(s)));
  EXPECT_EQ(r.run_id, s.run_id);
  EXPECT_EQ(r.student, s.student);
  EXPECT_EQ(r.requested_run_id, s.requested_run_id);
  EXPECT_EQ(r.mode, s.mode);
  EXPECT_EQ(r.model_name, s.model_name);
  EXPECT_EQ(r.model_reason, s.model_reason);
  EXPECT_EQ(r.body_count, s.body_count);
  EXPECT_EQ(r.collision_count, s.collision_count);
  EXPECT_EQ(r.simulated, s.simulated);
  EXPECT_EQ(r.truncated, s.truncated);
  EXPECT_EQ(r.truncation_reason, s.truncation_reason);
  EXPECT_EQ(r.cancelled, s.cancelled);
  EXPECT_EQ(r.stop_reason, s.stop_reason);
  EXPECT_EQ(r.predicted_collision_count, 31u);
  EXPECT_TRUE(r.predicted_collision_count_defined);
  EXPECT_EQ(r.paper_predicted_collision_count, -2);
  EXPECT_TRUE(r.paper_predicted_collision_count_defined);
  EXPECT_EQ(r.infinite_collisions, s.infinite_collisions);
  ASSERT_EQ(r.final_velocities.size(), 3u);
  EXPECT_EQ(r.final_velocities[0], 0.1);
  EXPECT_EQ(r.final_velocities[1], -0.7);
  EXPECT_TRUE(std::isnan(r.final_velocities[2])) << "JSON has no inf: null, read as NaN";
  EXPECT_EQ(r.energy_lost, s.energy_lost);
  EXPECT_EQ(r.collapsed, s.collapsed);
  EXPECT_TRUE(std::isnan(r.max_prediction_error));
  EXPECT_EQ(r.energy_relative_drift, s.energy_relative_drift);
  EXPECT_EQ(r.momentum_relative_drift, s.momentum_relative_drift);
  EXPECT_EQ(r.compute_time, s.compute_time);
  EXPECT_EQ(r.uncertified_values, s.uncertified_values);
  EXPECT_EQ(r.time_beyond_range, s.time_beyond_range);
  EXPECT_EQ(r.published_events, s.published_events);
  EXPECT_EQ(r.bag_path, s.bag_path);
  EXPECT_EQ(r.recording_ok, s.recording_ok);
  EXPECT_EQ(r.recording_error, s.recording_error);

  // Counts not defined are null, and read back as not defined.
  collision_lab::RunSummary open;
  const collision_lab::RunSummary o = summaryFromFields(summaryFields(open));
  EXPECT_FALSE(o.predicted_collision_count_defined);
  EXPECT_FALSE(o.paper_predicted_collision_count_defined);
  EXPECT_FALSE(o.recording_ok) << "recorded needs a bag";
}

TEST_F(RunIndexRecorderTest, AClaimIsLockedUntilItsBagIsClosed) {
  std::string error;
  ASSERT_EQ(claimBag(dir_, "r1", error), BagClaim::kClaimed) << error;
  const std::string active = bagPath(dir_, "r1") + ".active";
  EXPECT_TRUE(bagClaimHeld(active));
  EXPECT_FALSE(lockable(active));
  EXPECT_TRUE(activeBagOwned(active));
  {
    rosbag::Bag reused;
    RunRecorder recorder(dir_, "r1", reused, "");
    recorder.write("/initial_conditions", ros::Time(1000), input("r1", "ana"));
    EXPECT_FALSE(lockable(active));  // held while written
    ASSERT_TRUE(recorder.close()) << recorder.error();
  }
  EXPECT_FALSE(bagClaimHeld(active));
  EXPECT_TRUE(lockable(bagPath(dir_, "r1")));  // the renamed file's lock is gone too
  // A claim given back (cancelled while queued) drops its lock.
  ASSERT_EQ(claimBag(dir_, "r2", error), BagClaim::kClaimed) << error;
  releaseBagClaim(bagPath(dir_, "r2") + ".active");
  EXPECT_TRUE(lockable(bagPath(dir_, "r2") + ".active"));
}

TEST_F(RunIndexRecorderTest, ALiveOwnersBagIsNeverTaken) {
  std::string error;
  ASSERT_EQ(claimBag(dir_, "live", error), BagClaim::kClaimed) << error;
  rosbag::Bag reused;
  RunRecorder recorder(dir_, "live", reused, "");
  recorder.write("/initial_conditions", ros::Time(1000), input("live", "ana"));
  EXPECT_TRUE(recoverActiveBags(dir_).empty());
  EXPECT_TRUE(fs::exists(bagPath(dir_, "live") + ".active"));
  EXPECT_TRUE(recorder.close()) << recorder.error();
  EXPECT_TRUE(fs::exists(bagPath(dir_, "live")));
}

TEST_F(RunIndexRecorderTest, AKilledWritersBagIsReindexedRenamedAndCounted) {
  constexpr std::uint64_t kWritten = 30000;  // several chunks: most reach the disk before the kill
  killedWriter("dead", kWritten);
  {  // unindexed: rosbag's C++ API refuses it
    rosbag::Bag raw;
    EXPECT_ANY_THROW(raw.open(bagPath(dir_, "dead") + ".active", rosbag::bagmode::Read));
  }
  const auto recovered = recoverActiveBags(dir_);
  ASSERT_EQ(recovered.size(), 1u);
  EXPECT_EQ(recovered[0].error, "");
  EXPECT_EQ(recovered[0].run_id, "dead");
  EXPECT_EQ(recovered[0].bag_path, bagPath(dir_, "dead"));
  EXPECT_FALSE(fs::exists(bagPath(dir_, "dead") + ".active"));
  ASSERT_TRUE(recovered[0].contents.input);
  EXPECT_EQ(recovered[0].contents.input->student, "ana");
  EXPECT_FALSE(recovered[0].contents.summary);
  const std::uint64_t events = recovered[0].contents.events;
  EXPECT_GT(events, 0u);
  EXPECT_LE(events, kWritten);
  EXPECT_EQ(recovered[0].contents.last_event_time, 0.5 * static_cast<double>(events));  // events are written in order

  // The bag reads with rosbag::View and holds that many events, in order.
  rosbag::Bag bag(bagPath(dir_, "dead"), rosbag::bagmode::Read);
  rosbag::View view(bag, rosbag::TopicQuery("/collision_events"));
  std::uint64_t k = 0;
  for (const auto& m : view) {
    const auto e = m.instantiate<collision_lab::CollisionEvent>();
    ASSERT_TRUE(e);
    ASSERT_EQ(e->index, k++);
  }
  EXPECT_EQ(k, events);
}

TEST_F(RunIndexRecorderTest, RecoveryIndexesTheRunAsInterruptedWithItsEvents) {
  // The rows of a node that died (its recorder's writes committed), then the node that
  // starts after it.
  auto died = std::make_unique<RunIndexRecorder>(dir_);
  ASSERT_TRUE(died->ok());
  died->accepted("dead", "ana", "", input("dead", "ana"));
  died->started("dead");
  killedWriter("dead", 30000);
  // Another dead run the index never saw: its row comes from the bag's input.
  killedWriter("unknown", 30000);
  // Queued rows of dead nodes: one without a bag, one whose final bag has its summary.
  died->accepted("queued", "ana", "", input("queued", "ana"));
  died->accepted("done", "ben", "", input("done", "ben"));
  died->started("done");
  {
    RunRecorder done(dir_, "done");
    collision_lab::RunSummary summary;
    summary.run_id = "done";
    summary.stop_reason = "FINISHED";
    summary.collision_count = 31;
    summary.header.stamp = ros::Time(1001);
    done.write("/run_summaries", summary.header.stamp, summary);
    ASSERT_TRUE(done.close());
  }

  died.reset();
  RunIndexRecorder recorder(dir_);
  EXPECT_EQ(recorder.recover(), 4u);
  RunIndex& index = *recorder.index();
  const auto dead = index.find("dead");
  ASSERT_TRUE(dead);
  EXPECT_EQ(dead->state, RunState::kInterrupted);
  EXPECT_EQ(dead->stop_reason, "INTERRUPTED");
  EXPECT_EQ(dead->bag_path, bagPath(dir_, "dead"));
  rosbag::Bag bag(dead->bag_path, rosbag::bagmode::Read);
  EXPECT_EQ(dead->collision_count, rosbag::View(bag, rosbag::TopicQuery("/collision_events")).size());
  EXPECT_GT(dead->collision_count, 0u);
  EXPECT_NE(dead->summary_json.find("\"events_in_bag\""), std::string::npos) << dead->summary_json;

  const auto unknown = index.find("unknown");
  ASSERT_TRUE(unknown);
  EXPECT_EQ(unknown->state, RunState::kInterrupted);
  EXPECT_EQ(unknown->student, "ana");
  EXPECT_GT(unknown->collision_count, 0u);

  EXPECT_EQ(index.find("queued")->state, RunState::kInterrupted);
  EXPECT_EQ(index.find("queued")->collision_count, 0u);
  EXPECT_EQ(index.find("done")->state, RunState::kFinished);
  EXPECT_EQ(index.find("done")->stop_reason, "FINISHED");
  EXPECT_EQ(index.find("done")->collision_count, 31u);

  EXPECT_TRUE(index.inState(RunState::kRunning).empty());
  EXPECT_TRUE(index.inState(RunState::kQueued).empty());

  // ~list_runs' format, from the index.
  const auto listed = recorder.list("ben");
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].accepted.run_id, "done");
  EXPECT_TRUE(listed[0].finished);
  EXPECT_EQ(listed[0].collision_count, 31u);
  EXPECT_EQ(recorder.list("").size(), 4u);
}

TEST_F(RunIndexRecorderTest, ALiveNodesQueuedRunIsLeftAlone) {
  RunIndexRecorder(dir_).accepted("waiting", "", "", input("waiting", ""));  // another node's
  RunIndexRecorder recorder(dir_);
  std::string error;
  ASSERT_EQ(claimBag(dir_, "waiting", error), BagClaim::kClaimed) << error;  // its live owner
  EXPECT_EQ(recorder.recover(), 0u);
  EXPECT_EQ(recorder.index()->find("waiting")->state, RunState::kQueued);
  releaseBagClaim(bagPath(dir_, "waiting") + ".active");
  // Its owner gone (lock dropped) and the claim empty: interrupted, the empty claim removed.
  EXPECT_EQ(recorder.recover(), 1u);
  EXPECT_EQ(recorder.index()->find("waiting")->state, RunState::kInterrupted);
  EXPECT_FALSE(fs::exists(bagPath(dir_, "waiting") + ".active"));
}

TEST_F(RunIndexRecorderTest, WritesAreCommittedInOrderAndAFinishedRunIsSeenAtOnce) {
  RunIndexRecorder recorder(dir_);
  RunIndex reader(RunIndex::defaultPath(dir_));  // another connection, as the web node's
  constexpr int kRuns = 200;
  for (int k = 0; k < kRuns; ++k) {
    const std::string run_id = "r" + std::to_string(k);
    recorder.accepted(run_id, "ana", "", input(run_id, "ana"));
    recorder.started(run_id);
    if (k % 2 != 0) continue;
    collision_lab::RunSummary summary;
    summary.run_id = run_id;
    summary.student = "ana";
    summary.stop_reason = "FINISHED";
    summary.collision_count = 31;
    recorder.finished(summary);
    // finished() returns once its row is committed: whoever saw the summary finds it.
    const auto row = reader.find(run_id);
    ASSERT_TRUE(row.has_value()) << run_id;
    EXPECT_EQ(row->state, RunState::kFinished) << run_id;
    EXPECT_EQ(row->collision_count, 31u) << run_id;
    EXPECT_GT(row->started_at, 0.0) << run_id;  // its start went in before its end
  }
  // list() first waits for every write handed over: the odd runs running (their start
  // waited for a commit), the even ones finished, all in the order accepted.
  const auto runs = recorder.list("ana");
  ASSERT_EQ(runs.size(), static_cast<std::size_t>(kRuns));
  for (int k = 0; k < kRuns; ++k) {
    EXPECT_EQ(runs[k].accepted.run_id, "r" + std::to_string(k));
    EXPECT_EQ(runs[k].finished, k % 2 == 0) << k;
  }
  const auto odd = reader.find("r1");
  ASSERT_TRUE(odd.has_value());
  EXPECT_EQ(odd->state, RunState::kRunning);
}

TEST_F(RunIndexRecorderTest, JsonOfInputAndSummary) {
  const std::string in = inputJson(input("r", "ana"));
  EXPECT_NE(in.find("\"masses\":[100.0,1.0,\"inf\"]"), std::string::npos) << in;
  EXPECT_NE(in.find("\"student\":\"ana\""), std::string::npos) << in;
  collision_lab::RunSummary s;
  s.collision_count = 31;
  s.stop_reason = "FINISHED";
  s.energy_lost = std::nan("");
  const std::string sum = summaryJson(s);
  EXPECT_NE(sum.find("\"collision_count\":31"), std::string::npos) << sum;
  EXPECT_NE(sum.find("\"energy_lost\":null"), std::string::npos) << sum;
}

TEST_F(RunIndexRecorderTest, AWriteLockedIndexHoldsUpNothingAndLosesNoRow) {
  RunIndexRecorder recorder(dir_);
  ASSERT_TRUE(recorder.ok());
  // Another program holds the write lock, far longer than the writer's busy timeout.
  sqlite3* locker = nullptr;
  ASSERT_EQ(sqlite3_open(RunIndex::defaultPath(dir_).c_str(), &locker), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(locker, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr), SQLITE_OK);

  recorder.accepted("locked", "ana", "", input("locked", "ana"));
  recorder.started("locked");
  collision_lab::RunSummary summary;
  summary.run_id = "locked";
  summary.student = "ana";
  summary.stop_reason = "FINISHED";
  summary.collision_count = 31;
  recorder.finished(summary);  // returns: the run's end does not wait for the lock
  collision_lab::Rejected rejected;
  rejected.student = "ben";
  rejected.reason_name = "INVALID_MASS";
  rejected.message = "masses must be > 0";
  recorder.rejected(rejected);
  // Readers are not held up, and see nothing uncommitted.
  EXPECT_FALSE(recorder.committed()->find("locked"));
  EXPECT_FALSE(recorder.flush(10 * kIndexWriterLockWait));

  ASSERT_EQ(sqlite3_exec(locker, "COMMIT", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(locker);
  ASSERT_TRUE(recorder.flush(std::chrono::minutes(1)));  // the kept writes, tried again, commit
  const auto row = recorder.committed()->find("locked");
  ASSERT_TRUE(row);
  EXPECT_EQ(row->state, RunState::kFinished);
  EXPECT_EQ(row->collision_count, 31u);
  EXPECT_EQ(row->student, "ana");
  const auto rejections = recorder.committed()->rejections(std::string("ben"));
  ASSERT_EQ(rejections.size(), 1u);
  EXPECT_EQ(rejections[0].reason_name, "INVALID_MASS");
}

TEST_F(RunIndexRecorderTest, AQueuedRunOfADeadNodeIsOfferedToBeServedAgain) {
  auto served = input("fay.long", "fay");
  served.restitution = {0.5, 1.0};
  served.restitution_model = collision_lab::InitialConditions::RESTITUTION_THRESHOLD;
  served.elastic_below = 0.25;
  served.max_collisions = 1000;
  served.max_run_seconds = 2.5;
  {
    RunIndexRecorder dead(dir_);
    dead.accepted("fay.long", "fay", "long", served);
    std::string error;
    ASSERT_EQ(claimBag(dir_, "fay.long", error), BagClaim::kClaimed) << error;
    releaseBagClaim(bagPath(dir_, "fay.long") + ".active");  // its node died: the claim is left empty
  }
  RunIndexRecorder recorder(dir_);
  std::vector<RunIndexRecorder::QueuedRun> offered;
  EXPECT_EQ(recorder.recover([&](const RunIndexRecorder::QueuedRun& run) {
              offered.push_back(run);
              return true;
            }),
            0u);
  ASSERT_EQ(offered.size(), 1u);
  const collision_lab::InitialConditions& again = offered[0].input;
  EXPECT_EQ(offered[0].requested_run_id, "long");
  EXPECT_EQ(again.run_id, "fay.long");
  EXPECT_EQ(again.student, "fay");
  EXPECT_EQ(again.masses, served.masses);  // the wall's inf included
  EXPECT_EQ(again.positions, served.positions);
  EXPECT_EQ(again.velocities, served.velocities);
  EXPECT_EQ(again.restitution, served.restitution);
  EXPECT_EQ(again.restitution_model, served.restitution_model);
  EXPECT_EQ(again.elastic_below, served.elastic_below);
  EXPECT_EQ(again.max_collisions, served.max_collisions);
  EXPECT_EQ(again.max_run_seconds, served.max_run_seconds);
  EXPECT_EQ(recorder.index()->find("fay.long")->state, RunState::kQueued);  // taken: left queued
  // Not taken: ended as interrupted, as before.
  EXPECT_EQ(recorder.recover([](const RunIndexRecorder::QueuedRun&) { return false; }), 1u);
  EXPECT_EQ(recorder.index()->find("fay.long")->state, RunState::kInterrupted);
  EXPECT_THROW(inputFromJson("{\"masses\": [1, null]}"), std::invalid_argument);
}

// A run this process accepted is its own, never a dead node's: recovery leaves it as it is,
// with or without a bag claim (a node that does not record has none).
TEST_F(RunIndexRecorderTest, RecoveryLeavesThisProcesssOwnRunsAlone) {
  RunIndexRecorder recorder(dir_);
  recorder.accepted("mine", "ana", "", input("mine", "ana"));
  recorder.started("mine");
  recorder.accepted("mine_queued", "ana", "", input("mine_queued", "ana"));
  int offered = 0;
  EXPECT_EQ(recorder.recover([&](const RunIndexRecorder::QueuedRun&) { return ++offered > 0; }), 0u);
  EXPECT_EQ(offered, 0);
  EXPECT_EQ(recorder.index()->find("mine")->state, RunState::kRunning);
  EXPECT_EQ(recorder.index()->find("mine_queued")->state, RunState::kQueued);
}

TEST_F(RunIndexRecorderTest, AFinishedRunWhoseBagWasLeftActiveStaysFinished) {
  // A bag that failed on a full disk keeps its .active name, while the run's summary
  // reaches the index: the next start recovers the bag and keeps the run finished.
  RunIndexRecorder recorder(dir_);
  recorder.accepted("full", "ana", "", input("full", "ana"));
  recorder.started("full");
  killedWriter("full", 100);
  collision_lab::RunSummary summary;
  summary.run_id = "full";
  summary.student = "ana";
  summary.stop_reason = "FINISHED";
  summary.collision_count = 245308;
  summary.bag_path = bagPath(dir_, "full");
  summary.recording_ok = false;
  summary.recording_error = "writing /collision_events failed: Problem writing data to disk";
  recorder.finished(summary);
  ASSERT_TRUE(recorder.flush(std::chrono::minutes(1)));

  EXPECT_EQ(recorder.recover(), 0u);
  const auto row = recorder.index()->find("full");
  ASSERT_TRUE(row);
  EXPECT_EQ(row->state, RunState::kFinished);
  EXPECT_EQ(row->stop_reason, "FINISHED");
  EXPECT_EQ(row->collision_count, 245308u);
  EXPECT_NE(row->summary_json.find("\"recorded\":false"), std::string::npos) << row->summary_json;
  EXPECT_NE(row->summary_json.find("Problem writing data to disk"), std::string::npos) << row->summary_json;
}

TEST_F(RunIndexRecorderTest, AFullDiskHoldsTheIndexWritesUntilSpaceIsFreed) {
  const std::string small = dir_ + "/small";
  fs::create_directories(small);
  if (!mountTmpfs(small, 2)) GTEST_SKIP() << "no tmpfs can be mounted here (it takes root)";
  struct Unmount {
    std::string dir;
    ~Unmount() { std::system(("umount -l '" + dir + "'").c_str()); }
  } unmount{small};
  RunIndexRecorder recorder(small);
  ASSERT_TRUE(recorder.ok());
  recorder.accepted("early", "ana", "", input("early", "ana"));
  ASSERT_TRUE(recorder.flush(std::chrono::minutes(1)));
  fillDisk(small + "/filler");

  recorder.accepted("late", "ben", "", input("late", "ben"));
  collision_lab::RunSummary summary;
  summary.run_id = "late";
  summary.student = "ben";
  summary.stop_reason = "FINISHED";
  summary.collision_count = 31;
  recorder.finished(summary);  // returns: the run's end does not wait for space
  EXPECT_FALSE(recorder.flush(std::chrono::seconds(2)));
  EXPECT_FALSE(recorder.committed()->find("late"));

  fs::remove(small + "/filler");
  ASSERT_TRUE(recorder.flush(std::chrono::minutes(1)));  // the kept writes, tried again, commit
  const auto row = recorder.committed()->find("late");
  ASSERT_TRUE(row);
  EXPECT_EQ(row->state, RunState::kFinished);
  EXPECT_EQ(row->collision_count, 31u);
  EXPECT_EQ(row->student, "ben");
}

}  // namespace
