// The run index (service/run_index.h) on a real SQLite file, no master: it persists across
// reopening, records every state change and rejection, lists by student, and two
// connections on one file (as the lab node and the web node, or two processes) see each
// other's rows.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <sqlite3.h>

#include "collision_lab/service/run_index.h"

namespace fs = std::filesystem;
using collision_lab::service::IndexedRejection;
using collision_lab::service::IndexedRun;
using collision_lab::service::RunIndex;
using collision_lab::service::RunIndexError;
using collision_lab::service::RunState;

namespace {

class RunIndexTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/run_index_test_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
    path_ = RunIndex::defaultPath(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static IndexedRun queued(const std::string& run_id, const std::string& student, double at) {
    IndexedRun run;
    run.run_id = run_id;
    run.student = student;
    run.requested_run_id = "asked";
    run.accepted_at = at;
    run.scene_json = R"({"masses":[100,1,"inf"]})";
    run.body_count = 3;
    return run;
  }
  /// The ending of the pi billiard's run as its summary gives it.
  static collision_lab::service::RunEnding pi() {
    collision_lab::service::RunEnding ending;
    ending.model_name = "three_body_rotation";
    ending.simulated = true;
    return ending;
  }

  std::string dir_, path_;
};

TEST_F(RunIndexTest, LivesInTheBagDirectoryInWalMode) {
  EXPECT_EQ(path_, dir_ + "/runs.sqlite");
  RunIndex index(path_);
  index.accepted(queued("r1", "ana", 1.0));
  EXPECT_TRUE(fs::exists(path_));
  EXPECT_TRUE(fs::exists(path_ + "-wal"));  // the write-ahead log of WAL mode
}

TEST_F(RunIndexTest, KeepsEveryRunAcrossReopening) {
  {
    RunIndex index(path_);
    index.accepted(queued("r1", "ana", 1.0));
    index.started("r1", 2.0);
    index.finished("r1", 3.0, R"({"collision_count":31})", "FINISHED", 31, dir_ + "/r1.bag", pi());
    index.accepted(queued("r2", "ben", 4.0));
  }
  RunIndex reopened(path_);
  ASSERT_EQ(reopened.runCount(), 2u);
  const auto r1 = reopened.find("r1");
  ASSERT_TRUE(r1);
  EXPECT_EQ(r1->student, "ana");
  EXPECT_EQ(r1->requested_run_id, "asked");
  EXPECT_EQ(r1->state, RunState::kFinished);
  EXPECT_EQ(r1->accepted_at, 1.0);
  EXPECT_EQ(r1->started_at, 2.0);
  EXPECT_EQ(r1->finished_at, 3.0);
  EXPECT_EQ(r1->scene_json, R"({"masses":[100,1,"inf"]})");
  EXPECT_EQ(r1->summary_json, R"({"collision_count":31})");
  EXPECT_EQ(r1->stop_reason, "FINISHED");
  EXPECT_EQ(r1->collision_count, 31u);
  EXPECT_EQ(r1->bag_path, dir_ + "/r1.bag");
  EXPECT_EQ(r1->body_count, 3u);
  EXPECT_EQ(r1->ending.model_name, "three_body_rotation");
  EXPECT_TRUE(r1->ending.simulated);
  EXPECT_FALSE(r1->ending.truncated);
  EXPECT_EQ(reopened.find("r2")->state, RunState::kQueued);
  EXPECT_FALSE(reopened.find("r3"));
}

TEST_F(RunIndexTest, RecordsEveryStateChange) {
  RunIndex index(path_);
  index.accepted(queued("r1", "ana", 1.0));
  EXPECT_EQ(index.find("r1")->state, RunState::kQueued);
  EXPECT_EQ(index.find("r1")->started_at, 0.0);
  index.started("r1", 2.0);
  EXPECT_EQ(index.find("r1")->state, RunState::kRunning);
  EXPECT_EQ(index.find("r1")->started_at, 2.0);
  index.interrupted("r1", 5.0, R"({"events_in_bag":7})", 7, dir_ + "/r1.bag");
  const auto r1 = index.find("r1");
  EXPECT_EQ(r1->state, RunState::kInterrupted);
  EXPECT_EQ(r1->stop_reason, "INTERRUPTED");
  EXPECT_EQ(r1->collision_count, 7u);
  EXPECT_EQ(r1->finished_at, 5.0);
  EXPECT_EQ(r1->summary_json, R"({"events_in_bag":7})");
  EXPECT_TRUE(r1->ending.truncated);
  EXPECT_FALSE(r1->ending.simulated);
  // A late start never takes a run back from its end.
  index.started("r1", 6.0);
  EXPECT_EQ(index.find("r1")->state, RunState::kInterrupted);
  EXPECT_EQ(index.find("r1")->started_at, 2.0);

  index.setCsvPath("r1", dir_ + "/r1.events.csv");
  EXPECT_EQ(index.find("r1")->csv_path, dir_ + "/r1.events.csv");

  EXPECT_EQ(index.inState(RunState::kInterrupted).size(), 1u);
  EXPECT_TRUE(index.inState(RunState::kRunning).empty());
}

TEST_F(RunIndexTest, TheListIsReadFromColumnsWithoutTheJsonTexts) {
  RunIndex index(path_);
  index.accepted(queued("r1", "ana", 1.0));
  collision_lab::service::RunEnding stopped;
  stopped.model_name = "engine";
  stopped.simulated = stopped.truncated = stopped.cancelled = true;
  stopped.cancel_reason = "cancelled by the teacher after 12 collisions";
  index.finished("r1", 2.0, R"({"model":"not read by the list"})", "CANCELLED", 12, dir_ + "/r1.bag", stopped);
  const auto listed = index.list();
  ASSERT_EQ(listed.size(), 1u);
  const IndexedRun& r1 = listed[0];
  EXPECT_TRUE(r1.scene_json.empty());
  EXPECT_TRUE(r1.summary_json.empty());
  EXPECT_EQ(r1.body_count, 3u);
  EXPECT_EQ(r1.ending.model_name, "engine");
  EXPECT_TRUE(r1.ending.simulated && r1.ending.truncated && r1.ending.cancelled);
  EXPECT_FALSE(r1.ending.collapsed);
  EXPECT_EQ(r1.ending.cancel_reason, "cancelled by the teacher after 12 collisions");
  EXPECT_EQ(index.find("r1")->summary_json, R"({"model":"not read by the list"})");
}

TEST_F(RunIndexTest, AVersionOneFileGetsItsColumnsFromItsJson) {
  // A run index as version 1 wrote it (main of 2026-12-02): the ending only in the JSON.
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
    const char* v1 = R"sql(
CREATE TABLE runs (run_id TEXT PRIMARY KEY NOT NULL, student TEXT NOT NULL DEFAULT '',
  requested_run_id TEXT NOT NULL DEFAULT '', state TEXT NOT NULL, accepted_at REAL NOT NULL DEFAULT 0,
  started_at REAL NOT NULL DEFAULT 0, finished_at REAL NOT NULL DEFAULT 0, scene_json TEXT NOT NULL DEFAULT '',
  summary_json TEXT NOT NULL DEFAULT '', stop_reason TEXT NOT NULL DEFAULT '',
  collision_count INTEGER NOT NULL DEFAULT 0, bag_path TEXT NOT NULL DEFAULT '', csv_path TEXT NOT NULL DEFAULT '');
CREATE INDEX runs_by_student ON runs(student, accepted_at);
CREATE INDEX runs_by_state ON runs(state);
CREATE TABLE rejections (id INTEGER PRIMARY KEY AUTOINCREMENT, at REAL NOT NULL, student TEXT NOT NULL DEFAULT '',
  run_id TEXT NOT NULL DEFAULT '', reason_name TEXT NOT NULL DEFAULT '', field TEXT NOT NULL DEFAULT '',
  message TEXT NOT NULL DEFAULT '');
CREATE INDEX rejections_by_student ON rejections(student, id);
INSERT INTO runs (run_id, student, state, scene_json, summary_json, stop_reason, collision_count) VALUES
  ('ana.pi', 'ana', 'finished', '{"masses":[100,1,"inf"]}',
   '{"model":"three_body_rotation","simulated":true,"truncated":false,"collapsed":false,"cancelled":false}',
   'NO_MORE_COLLISIONS', 31),
  ('ben.gas', 'ben', 'finished', '{"masses":[1,1,1,1,1]}',
   '{"model":"engine","simulated":true,"truncated":true,"cancelled":true,"collapsed":false,"truncation_reason":"cancelled by ben"}',
   'CANCELLED', 9),
  ('cy.lost', 'cy', 'interrupted', 'not json', '', 'INTERRUPTED', 0),
  ('dan.cut', 'dan', 'interrupted', '{"masses":[1,1]}', '{"events_in_bag":4}', 'INTERRUPTED', 4);
PRAGMA journal_mode=WAL;
PRAGMA user_version=1;
)sql";
    ASSERT_EQ(sqlite3_exec(db, v1, nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
    sqlite3_close(db);
  }
  RunIndex index(path_);
  const auto pi = index.find("ana.pi");
  ASSERT_TRUE(pi);
  EXPECT_EQ(pi->body_count, 3u);
  EXPECT_EQ(pi->ending.model_name, "three_body_rotation");
  EXPECT_EQ(pi->scene_json, R"({"masses":[100,1,"inf"]})");
  EXPECT_TRUE(pi->ending.simulated);
  EXPECT_FALSE(pi->ending.truncated || pi->ending.cancelled || pi->ending.collapsed);
  EXPECT_TRUE(pi->ending.cancel_reason.empty());
  const auto gas = index.find("ben.gas");
  EXPECT_EQ(gas->body_count, 5u);
  EXPECT_TRUE(gas->ending.truncated && gas->ending.cancelled);
  EXPECT_EQ(gas->ending.cancel_reason, "cancelled by ben");
  EXPECT_EQ(gas->summary_json.substr(0, 16), R"({"model":"engine)");
  const auto lost = index.find("cy.lost");
  EXPECT_EQ(lost->body_count, 0u);  // unknown: its scene text is no JSON
  EXPECT_EQ(lost->scene_json, "not json");  // the texts kept as they were
  EXPECT_EQ(lost->ending.model_name, "");
  EXPECT_TRUE(lost->ending.truncated);  // interrupted
  EXPECT_TRUE(index.find("dan.cut")->ending.truncated);  // interrupted, whatever its text says
  std::vector<std::string> order;
  for (const auto& run : index.list()) order.push_back(run.run_id);
  EXPECT_EQ(order, (std::vector<std::string>{"ana.pi", "ben.gas", "cy.lost", "dan.cut"}));
  EXPECT_EQ(index.list(std::string("ben")).size(), 1u);  // by student: its index made again
  // Written by this version from now on, and opened again without a second migration.
  index.accepted(queued("dan.new", "dan", 4.0));
  RunIndex again(path_);
  EXPECT_EQ(again.runCount(), 5u);
  EXPECT_EQ(again.find("dan.new")->body_count, 3u);
}

TEST_F(RunIndexTest, AnEndWithoutARowCreatesIt) {
  RunIndex index(path_);
  index.interrupted("lost", 5.0, "{}", 3, dir_ + "/lost.bag");
  const auto lost = index.find("lost");
  ASSERT_TRUE(lost);
  EXPECT_EQ(lost->state, RunState::kInterrupted);
  EXPECT_EQ(lost->collision_count, 3u);
}

TEST_F(RunIndexTest, KeepsCountsUpToTwoToTheSixtyFour) {
  RunIndex index(path_);
  index.accepted(queued("big", "", 1.0));
  const std::uint64_t max = ~std::uint64_t{0};
  index.finished("big", 2.0, "{}", "CAP", max, "", {});
  EXPECT_EQ(index.find("big")->collision_count, max);
}

TEST_F(RunIndexTest, ListsOldestFirstAndByStudent) {
  RunIndex index(path_);
  index.accepted(queued("b1", "ben", 2.0));
  index.accepted(queued("a1", "ana", 1.0));
  index.accepted(queued("a2", "ana", 3.0));
  index.accepted(queued("x1", "", 4.0));
  std::vector<std::string> ids;
  for (const auto& run : index.list()) ids.push_back(run.run_id);
  EXPECT_EQ(ids, (std::vector<std::string>{"a1", "b1", "a2", "x1"}));
  ids.clear();
  for (const auto& run : index.list(std::string("ana"))) ids.push_back(run.run_id);
  EXPECT_EQ(ids, (std::vector<std::string>{"a1", "a2"}));
  ids.clear();
  for (const auto& run : index.list(std::string())) ids.push_back(run.run_id);  // anonymous
  EXPECT_EQ(ids, (std::vector<std::string>{"x1"}));
  EXPECT_EQ(index.list(std::nullopt, 2).size(), 2u);
}

TEST_F(RunIndexTest, KeepsOnlyTheNewestRejections) {
  RunIndex index(path_);
  const std::size_t sent = RunIndex::kRejectionsKept + 2;
  for (std::size_t k = 0; k < sent; ++k) {
    IndexedRejection r;
    r.at = static_cast<double>(k);
    r.student = "loop";
    r.run_id = "r" + std::to_string(k);
    index.rejected(r);
  }
  const auto kept = index.rejections();
  ASSERT_EQ(kept.size(), RunIndex::kRejectionsKept);
  EXPECT_EQ(kept.front().run_id, "r" + std::to_string(sent - 1));
  EXPECT_EQ(kept.back().run_id, "r2") << "the two oldest are dropped";
}

TEST_F(RunIndexTest, KeepsRejectionsNewestFirst) {
  RunIndex index(path_);
  for (int k = 0; k < 3; ++k) {
    IndexedRejection r;
    r.at = k;
    r.student = k == 1 ? "ben" : "ana";
    r.run_id = "r" + std::to_string(k);
    r.reason_name = "NON_POSITIVE_MASS";
    r.field = "masses[0]";
    r.message = "masses[0] is -1";
    index.rejected(r);
  }
  const auto all = index.rejections();
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].run_id, "r2");
  EXPECT_EQ(all[2].run_id, "r0");
  EXPECT_EQ(all[0].reason_name, "NON_POSITIVE_MASS");
  EXPECT_EQ(all[0].field, "masses[0]");
  EXPECT_EQ(all[0].message, "masses[0] is -1");
  EXPECT_GT(all[0].id, all[1].id);
  const auto ana = index.rejections(std::string("ana"), 1);
  ASSERT_EQ(ana.size(), 1u);
  EXPECT_EQ(ana[0].run_id, "r2");
  EXPECT_EQ(index.rejections(std::string("ben")).size(), 1u);
}

TEST_F(RunIndexTest, AReaderSeesAWritersRowsAtOnce) {
  RunIndex writer(path_);
  RunIndex reader(path_);
  EXPECT_FALSE(reader.find("r1"));
  writer.accepted(queued("r1", "ana", 1.0));
  ASSERT_TRUE(reader.find("r1"));
  EXPECT_EQ(reader.find("r1")->state, RunState::kQueued);
  writer.started("r1", 2.0);
  EXPECT_EQ(reader.find("r1")->state, RunState::kRunning);
  writer.finished("r1", 3.0, "{}", "FINISHED", 31, "", {});
  EXPECT_EQ(reader.find("r1")->state, RunState::kFinished);
}

TEST_F(RunIndexTest, TwoWritersOnOneFileLoseNothing) {
  constexpr int kRuns = 200;
  {
    RunIndex first(path_);
    RunIndex second(path_);
    auto write = [&](RunIndex& index, const std::string& prefix) {
      for (int k = 0; k < kRuns; ++k) {
        const std::string id = prefix + std::to_string(k);
        index.accepted(queued(id, prefix, k));
        index.started(id, k);
        index.finished(id, k, "{}", "FINISHED", k, "", {});
      }
    };
    std::thread a([&] { write(first, "a"); });
    std::thread b([&] { write(second, "b"); });
    a.join();
    b.join();
  }
  RunIndex index(path_);
  EXPECT_EQ(index.runCount(), 2u * kRuns);
  EXPECT_EQ(index.inState(RunState::kFinished).size(), 2u * kRuns);
}

TEST_F(RunIndexTest, TwoProcessesShareTheFile) {
  RunIndex parent(path_);
  parent.accepted(queued("parent_run", "ana", 1.0));
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // Another process: its own connection; it sees the parent's row and adds its own.
    int status = 1;
    try {
      RunIndex own(path_);
      if (own.find("parent_run")) {
        for (int k = 0; k < 50; ++k) own.accepted(queued("child_" + std::to_string(k), "ben", 2.0 + k));
        status = 0;
      }
    } catch (...) {
    }
    ::_exit(status);
  }
  for (int k = 0; k < 50; ++k) parent.accepted(queued("parent_" + std::to_string(k), "ana", 2.0 + k));
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the child did not see the parent's row";
  EXPECT_EQ(parent.list(std::string("ben")).size(), 50u);
  EXPECT_EQ(parent.runCount(), 101u);
}

TEST_F(RunIndexTest, ProcessesOpeningANewFileTogetherAllSucceed) {
  // Labs sharing a folder start together: each creates the tables and switches to WAL.
  constexpr int kProcesses = 8;
  std::vector<pid_t> children;
  for (int p = 0; p < kProcesses; ++p) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      int status = 1;
      try {
        RunIndex own(path_);
        own.accepted(queued("p" + std::to_string(p), "ana", p));
        status = 0;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "process %d: %s\n", p, e.what());
      }
      ::_exit(status);
    }
    children.push_back(child);
  }
  for (const pid_t child : children) {
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  EXPECT_EQ(RunIndex(path_).runCount(), static_cast<std::size_t>(kProcesses));
}

TEST_F(RunIndexTest, AFileThatIsNoDatabaseIsAnError) {
  fs::create_directories(dir_);
  {
    std::FILE* f = std::fopen(path_.c_str(), "w");
    std::fputs("this is not an SQLite database, it is long enough to be read as a header ......", f);
    std::fclose(f);
  }
  try {
    RunIndex index(path_);
    FAIL() << "opened a file that is no database";
  } catch (const RunIndexError& e) {
    EXPECT_NE(std::string(e.what()).find(path_), std::string::npos) << e.what();
  }
  EXPECT_THROW(RunIndex(dir_ + "/missing/dir/runs.sqlite"), RunIndexError);
}

}  // namespace
