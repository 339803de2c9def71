// A minimal implementation of the run index (service/run_index.h) so that the web node's
// reader builds and is tested on this branch; the index's own implementation replaces it.
#include "collision_lab/service/run_index.h"

#include <sqlite3.h>

#include <filesystem>

namespace collision_lab::service {

namespace {

/// A prepared statement, finalized at the end of its scope.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) != SQLITE_OK) fail("prepare");
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& text) {
    sqlite3_bind_text(stmt_, i, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Statement& bind(int i, double x) {
    sqlite3_bind_double(stmt_, i, x);
    return *this;
  }
  Statement& bind(int i, std::int64_t x) {
    sqlite3_bind_int64(stmt_, i, x);
    return *this;
  }
  /// True while a row is available.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) fail("step");
    return false;
  }
  std::string text(int i) const {
    const auto* p = sqlite3_column_text(stmt_, i);
    return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(stmt_, i)))
             : std::string();
  }
  double real(int i) const { return sqlite3_column_double(stmt_, i); }
  std::int64_t integer(int i) const { return sqlite3_column_int64(stmt_, i); }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw RunIndexError(std::string("run index: ") + what + ": " + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

void exec(sqlite3* db, const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string text = message ? message : "unknown error";
    sqlite3_free(message);
    throw RunIndexError("run index: " + text);
  }
}

constexpr const char* kRunColumns =
    "run_id, student, requested_run_id, state, accepted_at, started_at, finished_at, scene_json, summary_json, "
    "stop_reason, collision_count, bag_path, csv_path";

IndexedRun rowOf(const Statement& s) {
  IndexedRun run;
  run.run_id = s.text(0);
  run.student = s.text(1);
  run.requested_run_id = s.text(2);
  run.state = runStateFromName(s.text(3)).value_or(RunState::kQueued);
  run.accepted_at = s.real(4);
  run.started_at = s.real(5);
  run.finished_at = s.real(6);
  run.scene_json = s.text(7);
  run.summary_json = s.text(8);
  run.stop_reason = s.text(9);
  run.collision_count = static_cast<std::uint64_t>(s.integer(10));
  run.bag_path = s.text(11);
  run.csv_path = s.text(12);
  return run;
}

}  // namespace

const char* runStateName(RunState state) {
  switch (state) {
    case RunState::kQueued: return "queued";
    case RunState::kRunning: return "running";
    case RunState::kFinished: return "finished";
    case RunState::kInterrupted: return "interrupted";
  }
  return "queued";
}

std::optional<RunState> runStateFromName(const std::string& name) {
  for (RunState s : {RunState::kQueued, RunState::kRunning, RunState::kFinished, RunState::kInterrupted}) {
    if (name == runStateName(s)) return s;
  }
  return std::nullopt;
}

RunIndex::RunIndex(const std::string& path) {
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                      nullptr) != SQLITE_OK) {
    const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw RunIndexError("run index " + path + ": " + message);
  }
  sqlite3_busy_timeout(db_, 5000);
  try {
    exec(db_, "PRAGMA journal_mode=WAL");
    exec(db_,
         "CREATE TABLE IF NOT EXISTS runs (run_id TEXT PRIMARY KEY, student TEXT, requested_run_id TEXT, "
         "state TEXT, accepted_at REAL, started_at REAL, finished_at REAL, scene_json TEXT, summary_json TEXT, "
         "stop_reason TEXT, collision_count INTEGER, bag_path TEXT, csv_path TEXT);"
         "CREATE TABLE IF NOT EXISTS rejections (id INTEGER PRIMARY KEY AUTOINCREMENT, at REAL, student TEXT, "
         "run_id TEXT, reason_name TEXT, field TEXT, message TEXT);");
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

RunIndex::~RunIndex() { sqlite3_close(db_); }

std::string RunIndex::defaultPath(const std::string& bag_directory) {
  return (std::filesystem::path(bag_directory) / "runs.sqlite").string();
}

void RunIndex::accepted(const IndexedRun& run) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_,
              "INSERT OR REPLACE INTO runs (run_id, student, requested_run_id, state, accepted_at, started_at, "
              "finished_at, scene_json, summary_json, stop_reason, collision_count, bag_path, csv_path) "
              "VALUES (?, ?, ?, ?, ?, 0, 0, ?, '', '', 0, ?, '')");
  s.bind(1, run.run_id).bind(2, run.student).bind(3, run.requested_run_id).bind(4, std::string(runStateName(run.state)));
  s.bind(5, run.accepted_at).bind(6, run.scene_json).bind(7, run.bag_path);
  s.step();
}

void RunIndex::started(const std::string& run_id, double at) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, "UPDATE runs SET state = 'running', started_at = ? WHERE run_id = ?");
  s.bind(1, at).bind(2, run_id);
  s.step();
}

void RunIndex::finished(const std::string& run_id, double at, const std::string& summary_json,
                        const std::string& stop_reason, std::uint64_t collision_count, const std::string& bag_path) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_,
              "UPDATE runs SET state = 'finished', finished_at = ?, summary_json = ?, stop_reason = ?, "
              "collision_count = ?, bag_path = ? WHERE run_id = ?");
  s.bind(1, at).bind(2, summary_json).bind(3, stop_reason).bind(4, static_cast<std::int64_t>(collision_count));
  s.bind(5, bag_path).bind(6, run_id);
  s.step();
}

void RunIndex::interrupted(const std::string& run_id, double at, const std::string& summary_json,
                           std::uint64_t collision_count, const std::string& bag_path) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_,
              "UPDATE runs SET state = 'interrupted', finished_at = ?, summary_json = ?, stop_reason = 'INTERRUPTED', "
              "collision_count = ?, bag_path = ? WHERE run_id = ?");
  s.bind(1, at).bind(2, summary_json).bind(3, static_cast<std::int64_t>(collision_count)).bind(4, bag_path);
  s.bind(5, run_id);
  s.step();
}

void RunIndex::rejected(const IndexedRejection& r) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_,
              "INSERT INTO rejections (at, student, run_id, reason_name, field, message) VALUES (?, ?, ?, ?, ?, ?)");
  s.bind(1, r.at).bind(2, r.student).bind(3, r.run_id).bind(4, r.reason_name).bind(5, r.field).bind(6, r.message);
  s.step();
}

void RunIndex::setCsvPath(const std::string& run_id, const std::string& csv_path) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, "UPDATE runs SET csv_path = ? WHERE run_id = ?");
  s.bind(1, csv_path).bind(2, run_id);
  s.step();
}

std::optional<IndexedRun> RunIndex::find(const std::string& run_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, (std::string("SELECT ") + kRunColumns + " FROM runs WHERE run_id = ?").c_str());
  s.bind(1, run_id);
  if (!s.step()) return std::nullopt;
  return rowOf(s);
}

std::vector<IndexedRun> RunIndex::list(const std::optional<std::string>& student, std::size_t limit) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string sql = std::string("SELECT ") + kRunColumns + " FROM runs";
  if (student) sql += " WHERE student = ?";
  sql += " ORDER BY accepted_at, rowid";
  if (limit > 0) sql += " LIMIT " + std::to_string(limit);
  Statement s(db_, sql.c_str());
  if (student) s.bind(1, *student);
  std::vector<IndexedRun> out;
  while (s.step()) out.push_back(rowOf(s));
  return out;
}

std::vector<IndexedRun> RunIndex::inState(RunState state) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, (std::string("SELECT ") + kRunColumns + " FROM runs WHERE state = ? ORDER BY accepted_at, rowid").c_str());
  s.bind(1, std::string(runStateName(state)));
  std::vector<IndexedRun> out;
  while (s.step()) out.push_back(rowOf(s));
  return out;
}

std::vector<IndexedRejection> RunIndex::rejections(const std::optional<std::string>& student, std::size_t limit) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string sql = "SELECT id, at, student, run_id, reason_name, field, message FROM rejections";
  if (student) sql += " WHERE student = ?";
  sql += " ORDER BY id DESC";
  if (limit > 0) sql += " LIMIT " + std::to_string(limit);
  Statement s(db_, sql.c_str());
  if (student) s.bind(1, *student);
  std::vector<IndexedRejection> out;
  while (s.step()) {
    IndexedRejection r;
    r.id = s.integer(0);
    r.at = s.real(1);
    r.student = s.text(2);
    r.run_id = s.text(3);
    r.reason_name = s.text(4);
    r.field = s.text(5);
    r.message = s.text(6);
    out.push_back(std::move(r));
  }
  return out;
}

std::size_t RunIndex::runCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, "SELECT COUNT(*) FROM runs");
  return s.step() ? static_cast<std::size_t>(s.integer(0)) : 0;
}

}  // namespace collision_lab::service
