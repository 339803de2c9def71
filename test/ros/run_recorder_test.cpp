// Per-run bags without a master: final name only when closed, failures reported; a
// run's file is claimed exclusively and never overwritten, also by writers racing for the
// same run_ids; the writer thread (RunBagWriter) writes every message handed over, under
// backpressure, closes every bag before it is destroyed, and writes the latched topics'
// connection headers as `rosbag record` does.
#include <atomic>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <ros/time.h>
#include <rosbag/view.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/run_recorder.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_ros::BagClaim;
using collision_lab_ros::claimBag;
using collision_lab_ros::RunRecorder;

std::string contents(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// A fresh directory per test, removed afterwards.
class RunRecorderTest : public testing::Test {
 protected:
  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/collision_lab_recorder_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_;
};

TEST_F(RunRecorderTest, WritesUnderActiveNameAndRenamesOnClose) {
  const ros::Time stamp(1.5e9);
  collision_lab::RunSummary summary;
  summary.run_id = "r1";
  summary.collision_count = 7;
  {
    RunRecorder recorder(dir_ + "/nested", "r1");
    ASSERT_TRUE(recorder.ok()) << recorder.error();
    EXPECT_EQ(recorder.path(), dir_ + "/nested/r1.bag");
    recorder.write("/collision_lab/run_summaries", stamp, summary);
    EXPECT_TRUE(fs::exists(dir_ + "/nested/r1.bag.active"));
    EXPECT_FALSE(fs::exists(dir_ + "/nested/r1.bag"));
    EXPECT_TRUE(recorder.close());
  }
  EXPECT_FALSE(fs::exists(dir_ + "/nested/r1.bag.active"));
  ASSERT_TRUE(fs::exists(dir_ + "/nested/r1.bag"));

  rosbag::Bag bag(dir_ + "/nested/r1.bag", rosbag::bagmode::Read);
  rosbag::View view(bag);
  ASSERT_EQ(view.size(), 1u);
  const auto m = *view.begin();
  EXPECT_EQ(m.getTopic(), "/collision_lab/run_summaries");
  EXPECT_EQ(m.getTime(), stamp);
  EXPECT_EQ(m.instantiate<collision_lab::RunSummary>()->collision_count, 7u);
}

// The lab node records on one bag writer thread per worker: bags made, opened, closed and
// destroyed on several threads at once must not race in pluginlib's class loader (a fresh
// rosbag::Bag per run, unlocked, crashed the node with SIGSEGV).
TEST_F(RunRecorderTest, BagsRecordedOnManyThreadsAtOnceAreAllComplete) {
  constexpr int kThreads = 6;
  constexpr int kBagsEach = 40;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([this, t] {
      for (int k = 0; k < kBagsEach; ++k) {
        collision_lab::RunSummary summary;
        summary.run_id = "t" + std::to_string(t) + "_" + std::to_string(k);
        summary.collision_count = static_cast<std::uint64_t>(k);
        RunRecorder recorder(dir_, summary.run_id);
        recorder.write("/collision_lab/run_summaries", ros::Time(1.0 + k), summary);
        recorder.close();
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (int t = 0; t < kThreads; ++t) {
    for (int k = 0; k < kBagsEach; ++k) {
      const std::string path = dir_ + "/t" + std::to_string(t) + "_" + std::to_string(k) + ".bag";
      ASSERT_TRUE(fs::exists(path)) << path;
      rosbag::Bag bag(path, rosbag::bagmode::Read);
      rosbag::View view(bag);
      ASSERT_EQ(view.size(), 1u) << path;
      EXPECT_EQ(view.begin()->instantiate<collision_lab::RunSummary>()->collision_count, static_cast<std::uint64_t>(k));
    }
  }
}

TEST_F(RunRecorderTest, UncreatableDirectoryIsReportedNotThrown) {
  std::ofstream(dir_ + "/file") << "x";
  RunRecorder recorder(dir_ + "/file/bags", "r1");
  EXPECT_FALSE(recorder.ok());
  EXPECT_NE(recorder.error().find(dir_ + "/file/bags"), std::string::npos) << recorder.error();
  recorder.write("/t", ros::Time(1.5e9), collision_lab::RunSummary());
  EXPECT_FALSE(recorder.close());
}

TEST_F(RunRecorderTest, WriteAtTimeZeroFailsCleanly) {
  RunRecorder recorder(dir_, "r0");
  ASSERT_TRUE(recorder.ok());
  recorder.write("/t", ros::Time(0), collision_lab::RunSummary());
  EXPECT_FALSE(recorder.ok());
  EXPECT_FALSE(recorder.close());
  EXPECT_FALSE(fs::exists(dir_ + "/r0.bag"));
}

TEST_F(RunRecorderTest, AClaimIsExclusiveAndAFinishedBagKeepsItsName) {
  std::string error;
  EXPECT_EQ(claimBag(dir_ + "/new", "r1", error), BagClaim::kClaimed) << error;
  EXPECT_TRUE(fs::is_regular_file(dir_ + "/new/r1.bag.active"));
  EXPECT_EQ(claimBag(dir_ + "/new", "r1", error), BagClaim::kTaken);  // its .active exists
  std::ofstream(dir_ + "/r2.bag") << "finished";
  EXPECT_EQ(claimBag(dir_, "r2", error), BagClaim::kTaken);
  EXPECT_FALSE(fs::exists(dir_ + "/r2.bag.active"));  // the name was given up again
  EXPECT_EQ(contents(dir_ + "/r2.bag"), "finished");
  std::ofstream(dir_ + "/file") << "x";
  EXPECT_EQ(claimBag(dir_ + "/file/bags", "r3", error), BagClaim::kFailed);
  EXPECT_NE(error.find(dir_ + "/file/bags"), std::string::npos) << error;
}

TEST_F(RunRecorderTest, ARecorderNeverWritesOverAnotherRunsBag) {
  std::ofstream(dir_ + "/done.bag") << "another run";
  std::ofstream(dir_ + "/busy.bag.active") << "another run in progress";
  for (const char* run_id : {"done", "busy"}) {
    RunRecorder recorder(dir_, run_id);
    EXPECT_FALSE(recorder.ok()) << run_id;
    EXPECT_NE(recorder.error().find("not overwritten"), std::string::npos) << recorder.error();
    EXPECT_FALSE(recorder.close());
  }
  EXPECT_EQ(contents(dir_ + "/done.bag"), "another run");
  EXPECT_EQ(contents(dir_ + "/busy.bag.active"), "another run in progress");
  EXPECT_FALSE(fs::exists(dir_ + "/done.bag.active"));
  EXPECT_FALSE(fs::exists(dir_ + "/busy.bag"));
}

TEST_F(RunRecorderTest, CloseFailsLoudlyRatherThanReplaceAFile) {
  RunRecorder recorder(dir_, "r1");
  ASSERT_TRUE(recorder.ok()) << recorder.error();
  recorder.write("/t", ros::Time(1.5e9), collision_lab::RunSummary());
  std::ofstream(dir_ + "/r1.bag") << "written by a writer that does not claim";
  EXPECT_FALSE(recorder.close());
  EXPECT_NE(recorder.error().find("not overwritten"), std::string::npos) << recorder.error();
  EXPECT_EQ(contents(dir_ + "/r1.bag"), "written by a writer that does not claim");
  // This run's bag is kept, complete, under its .active name.
  rosbag::Bag bag(dir_ + "/r1.bag.active", rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(bag).size(), 1u);
}

TEST_F(RunRecorderTest, RacingClaimersGetEachRunIdOnce) {
  // Eight writers claim the same 300 run_ids at once; an owner finishes its bag at once
  // (renames it), so later claimers meet finished bags as well as .active files.
  constexpr int kWriters = 8;
  constexpr int kRunIds = 300;
  std::vector<std::atomic<int>> owners(kRunIds);
  std::atomic<int> failures{0};
  std::vector<std::thread> writers;
  for (int w = 0; w < kWriters; ++w) {
    writers.emplace_back([&, w] {
      for (int k = 0; k < kRunIds; ++k) {
        const std::string run_id = "r" + std::to_string(k);
        std::string error;
        const BagClaim claim = claimBag(dir_, run_id, error);
        if (claim == BagClaim::kFailed) ++failures;
        if (claim != BagClaim::kClaimed) continue;
        ++owners[k];
        const std::string path = dir_ + "/" + run_id + ".bag";
        std::ofstream(path + ".active") << w;
        fs::rename(path + ".active", path);
      }
    });
  }
  for (auto& writer : writers) writer.join();
  EXPECT_EQ(failures.load(), 0);
  for (int k = 0; k < kRunIds; ++k) EXPECT_EQ(owners[k].load(), 1) << "r" << k;
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().extension(), ".bag") << entry.path();
    ++files;
  }
  EXPECT_EQ(files, static_cast<std::size_t>(kRunIds));
}

/// One run for RunBagWriter, its bag claimed in dir: its parameters, input, prediction
/// and events (index k at 1 + k s), in batches of at most batch_events, the summary last.
std::vector<collision_lab_ros::RunBagBatch> runBatches(const std::string& dir, const std::string& run_id,
                                                       std::size_t events, std::size_t batch_events) {
  const ros::Time start(1.5e9);
  std::vector<collision_lab_ros::RunBagBatch> batches(1);
  batches[0].run_id = run_id;
  batches[0].opens = true;
  if (claimBag(dir, run_id, batches[0].claim_error) == BagClaim::kTaken) batches[0].claim_error = "taken";
  batches[0].parameters.emplace();
  batches[0].parameters->header.stamp = start;
  batches[0].parameters->run_id = run_id;
  batches[0].parameters->max_collisions = 1000 + events;
  batches[0].input.emplace();
  batches[0].input->header.stamp = start;
  batches[0].prediction.emplace();
  batches[0].prediction->header.stamp = start;
  for (std::size_t k = 0; k < events; ++k) {
    if (batches.back().events.size() == batch_events) {
      batches.emplace_back();
      batches.back().run_id = run_id;
    }
    collision_lab::CollisionEvent event;
    event.index = k;
    event.header.stamp = start + ros::Duration(1.0 + static_cast<double>(k));
    batches.back().events.push_back(event);
  }
  auto& last = batches.back();
  last.summary.emplace();
  last.summary->run_id = run_id;
  last.summary->collision_count = events;
  last.summary->header.stamp = start + ros::Duration(1.0 + static_cast<double>(events));
  return batches;
}

TEST_F(RunRecorderTest, BagWriterClosesEveryBagHandedOverWithEveryMessage) {
  constexpr int kRuns = 40;
  std::vector<collision_lab::RunSummary> closed;  // on_closed runs on the writer's thread, in order
  {
    // A bound of 100 queued messages: the runs below (up to 1,000 events) push against it.
    collision_lab_ros::RunBagWriter writer(dir_, {"/in", "/pred", "/events", "/sum", "", "", {}}, 100);
    for (int r = 0; r < kRuns; ++r) {
      for (auto& batch : runBatches(dir_, "run" + std::to_string(r), 25 * static_cast<std::size_t>(r), 64)) {
        if (batch.summary) batch.on_closed = [&closed](collision_lab::RunSummary& s) { closed.push_back(s); };
        writer.push(std::move(batch));
      }
    }
  }  // the destructor drains the queue
  ASSERT_EQ(closed.size(), static_cast<std::size_t>(kRuns));
  for (int r = 0; r < kRuns; ++r) {
    SCOPED_TRACE(r);
    const std::string run_id = "run" + std::to_string(r);
    const auto events = 25u * static_cast<unsigned>(r);
    EXPECT_EQ(closed[r].run_id, run_id);
    EXPECT_TRUE(closed[r].recording_ok) << closed[r].recording_error;
    EXPECT_EQ(closed[r].bag_path, dir_ + "/" + run_id + ".bag");
    EXPECT_FALSE(fs::exists(dir_ + "/" + run_id + ".bag.active"));
    rosbag::Bag bag(closed[r].bag_path, rosbag::bagmode::Read);
    EXPECT_EQ(rosbag::View(bag).size(), 3 + events);  // no parameters topic given: not written
    EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/in")).size(), 1u);
    EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/pred")).size(), 1u);
    std::uint64_t index = 0;
    for (const auto& m : rosbag::View(bag, rosbag::TopicQuery("/events"))) {
      EXPECT_EQ(m.instantiate<collision_lab::CollisionEvent>()->index, index++);
    }
    EXPECT_EQ(index, events);
    rosbag::View summaries(bag, rosbag::TopicQuery("/sum"));
    ASSERT_EQ(summaries.size(), 1u);
    EXPECT_EQ(summaries.begin()->instantiate<collision_lab::RunSummary>()->collision_count, events);
  }
}

TEST_F(RunRecorderTest, BagWriterReportsAFailedBagAndGoesOn) {
  std::ofstream(dir_ + "/file") << "x";
  std::vector<collision_lab::RunSummary> closed;
  {
    collision_lab_ros::RunBagWriter writer(dir_ + "/file/bags", {"/in", "/pred", "/events", "/sum", "", "", {}}, 10);
    for (const char* run_id : {"a", "b"}) {
      for (auto& batch : runBatches(dir_ + "/file/bags", run_id, 30, 8)) {
        if (batch.summary) batch.on_closed = [&closed](collision_lab::RunSummary& s) { closed.push_back(s); };
        writer.push(std::move(batch));
      }
    }
  }
  ASSERT_EQ(closed.size(), 2u);
  for (const auto& summary : closed) {
    EXPECT_FALSE(summary.recording_ok);
    EXPECT_NE(summary.recording_error.find(dir_ + "/file/bags"), std::string::npos) << summary.recording_error;
  }
}

TEST_F(RunRecorderTest, BagWriterSurvivesAnExceptionAndReportsTheRunItCost) {
  std::vector<collision_lab::RunSummary> closed;
  {
    collision_lab_ros::RunBagWriter writer(dir_, {"/in", "/pred", "/events", "/sum"}, 10);
    // Run a's on_closed throws (in the node: publishing its summary): before, the writer
    // thread ended the process.
    for (auto& batch : runBatches(dir_, "a", 30, 8)) {
      if (batch.summary) batch.on_closed = [](collision_lab::RunSummary&) { throw std::runtime_error("injected"); };
      writer.push(std::move(batch));
    }
    // Run x's batches come without the one that opens its bag: they cannot be written,
    // and its summary says so.
    auto lost = runBatches(dir_, "x", 30, 8);
    lost.erase(lost.begin());
    for (auto& batch : lost) {
      if (batch.summary) batch.on_closed = [&closed](collision_lab::RunSummary& s) { closed.push_back(s); };
      writer.push(std::move(batch));
    }
    for (auto& batch : runBatches(dir_, "b", 30, 8)) {
      if (batch.summary) batch.on_closed = [&closed](collision_lab::RunSummary& s) { closed.push_back(s); };
      writer.push(std::move(batch));
    }
  }
  // a: written and closed before its on_closed threw.
  EXPECT_EQ(rosbag::View(rosbag::Bag(dir_ + "/a.bag", rosbag::bagmode::Read)).size(), 3 + 30u);
  ASSERT_EQ(closed.size(), 2u);
  EXPECT_EQ(closed[0].run_id, "x");
  EXPECT_FALSE(closed[0].recording_ok);
  EXPECT_EQ(closed[0].recording_error, "the bag writer failed: no bag is open for this batch");
  EXPECT_FALSE(fs::exists(dir_ + "/x.bag"));
  // b: served as if nothing had happened.
  EXPECT_EQ(closed[1].run_id, "b");
  EXPECT_TRUE(closed[1].recording_ok) << closed[1].recording_error;
  rosbag::Bag bag(dir_ + "/b.bag", rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(bag).size(), 3 + 30u);
}

TEST_F(RunRecorderTest, LatchedTopicsAreWrittenAsRosbagRecordWritesThem) {
  const collision_lab_ros::RunBagWriter::Topics topics{
      "/lab2/in", "/lab2/pred", "/lab2/events", "/lab2/sum", "/lab2/params", "/lab2/lab_node",
      {"/lab2/pred", "/lab2/sum", "/lab2/params"}};
  {
    collision_lab_ros::RunBagWriter writer(dir_, topics, 100);
    for (const char* run_id : {"a", "b"}) {  // the second reuses the writer's Bag
      for (auto& batch : runBatches(dir_, run_id, 5, 2)) {
        if (batch.parameters) batch.parameters->package_version = "9.8.7";
        writer.push(std::move(batch));
      }
    }
  }
  for (const char* run_id : {"a", "b"}) {
    SCOPED_TRACE(run_id);
    rosbag::Bag bag(dir_ + "/" + run_id + ".bag", rosbag::bagmode::Read);
    rosbag::View view(bag);
    std::map<std::string, std::map<std::string, std::string>> headers;  // by topic
    for (const rosbag::ConnectionInfo* c : view.getConnections()) headers[c->topic] = *c->header;
    ASSERT_EQ(headers.size(), 5u);
    for (const char* latched : {"/lab2/pred", "/lab2/sum", "/lab2/params"}) {
      EXPECT_EQ(headers[latched]["latching"], "1") << latched;
      EXPECT_EQ(headers[latched]["callerid"], "/lab2/lab_node") << latched;
    }
    EXPECT_EQ(headers["/lab2/pred"]["type"], "collision_lab/Prediction");
    for (const char* live : {"/lab2/in", "/lab2/events"}) EXPECT_EQ(headers[live].count("latching"), 0u) << live;
    // The messages read back.
    rosbag::View parameters_view(bag, rosbag::TopicQuery("/lab2/params"));
    ASSERT_EQ(parameters_view.size(), 1u);
    const auto parameters = parameters_view.begin()->instantiate<collision_lab::RunParameters>();
    ASSERT_TRUE(parameters);
    EXPECT_EQ(parameters->run_id, run_id);
    EXPECT_EQ(parameters->package_version, "9.8.7");
    EXPECT_EQ(parameters->max_collisions, 1005u);
    rosbag::View summaries(bag, rosbag::TopicQuery("/lab2/sum"));
    ASSERT_EQ(summaries.size(), 1u);
    EXPECT_EQ(summaries.begin()->instantiate<collision_lab::RunSummary>()->collision_count, 5u);
  }
}

TEST(ExpandUser, ExpandsLeadingTildeOnly) {
  setenv("HOME", "/home/lab", 1);
  EXPECT_EQ(collision_lab_ros::expandUser("~/.ros/x"), "/home/lab/.ros/x");
  EXPECT_EQ(collision_lab_ros::expandUser("/a/~b"), "/a/~b");
}

}  // namespace
