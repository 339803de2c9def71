#include "collision_lab/service/run_index.h"

#include <sqlite3.h>

#include <chrono>
#include <filesystem>
#include <thread>
#include <utility>

namespace collision_lab::service {

namespace {

/// The schema this code writes (PRAGMA user_version). A file of a newer version is refused.
constexpr int kSchemaVersion = 2;

/// [KiB] of pages each connection keeps in memory.
constexpr int kPageCacheKiB = 256;

/// The runs table of version 2, its columns.
constexpr const char* kRunsTable = R"sql((
  run_id TEXT PRIMARY KEY NOT NULL,
  student TEXT NOT NULL DEFAULT '',
  requested_run_id TEXT NOT NULL DEFAULT '',
  state TEXT NOT NULL,                      -- queued, running, finished, interrupted
  accepted_at REAL NOT NULL DEFAULT 0,      -- [s] since the epoch
  started_at REAL NOT NULL DEFAULT 0,       -- [s] since the epoch; 0 until running
  finished_at REAL NOT NULL DEFAULT 0,      -- [s] since the epoch; 0 until ended
  stop_reason TEXT NOT NULL DEFAULT '',
  collision_count INTEGER NOT NULL DEFAULT 0,  -- [1], a uint64 stored as its int64 bits
  bag_path TEXT NOT NULL DEFAULT '',
  csv_path TEXT NOT NULL DEFAULT '',
  body_count INTEGER NOT NULL DEFAULT 0,    -- [1] the served input's bodies; 0: unknown
  model_name TEXT NOT NULL DEFAULT '',      -- RunEnding: how the run ended, once ended
  simulated INTEGER NOT NULL DEFAULT 0,
  truncated INTEGER NOT NULL DEFAULT 0,
  collapsed INTEGER NOT NULL DEFAULT 0,
  cancelled INTEGER NOT NULL DEFAULT 0,
  cancel_reason TEXT NOT NULL DEFAULT ''))sql";

/// Version 2. A run's JSON texts are a table apart, so that listing runs (their columns)
/// never reads them: a 10,000-body scene's text is 600 KB.
std::string schemaSql() {
  return std::string("CREATE TABLE IF NOT EXISTS runs ") + kRunsTable + ";" + R"sql(
CREATE INDEX IF NOT EXISTS runs_by_student ON runs(student, accepted_at);
CREATE INDEX IF NOT EXISTS runs_by_state ON runs(state);
CREATE TABLE IF NOT EXISTS run_texts (
  run_id TEXT PRIMARY KEY NOT NULL,
  scene_json TEXT NOT NULL DEFAULT '',      -- the served InitialConditions as JSON
  summary_json TEXT NOT NULL DEFAULT '');   -- the RunSummary as JSON once ended
CREATE TABLE IF NOT EXISTS rejections (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  at REAL NOT NULL,                         -- [s] since the epoch
  student TEXT NOT NULL DEFAULT '',
  run_id TEXT NOT NULL DEFAULT '',
  reason_name TEXT NOT NULL DEFAULT '',
  field TEXT NOT NULL DEFAULT '',
  message TEXT NOT NULL DEFAULT '');
CREATE INDEX IF NOT EXISTS rejections_by_student ON rejections(student, id);
)sql";
}

/// Version 1 (one runs table with the texts, no ending columns) to 2: the rows keep their
/// order, the texts move to run_texts, and the body count and ending are filled in from the
/// texts as version 1 wrote them (collision_lab_ros::inputJson and summaryJson's keys).
std::string migrationFrom1Sql() {
  return std::string("ALTER TABLE runs RENAME TO runs_v1; DROP INDEX IF EXISTS runs_by_student; "
                     "DROP INDEX IF EXISTS runs_by_state; CREATE TABLE runs ") + kRunsTable + ";" + R"sql(
CREATE INDEX runs_by_student ON runs(student, accepted_at);
CREATE INDEX runs_by_state ON runs(state);
CREATE TABLE run_texts (
  run_id TEXT PRIMARY KEY NOT NULL,
  scene_json TEXT NOT NULL DEFAULT '',
  summary_json TEXT NOT NULL DEFAULT '');
INSERT INTO runs (run_id, student, requested_run_id, state, accepted_at, started_at, finished_at, stop_reason,
                  collision_count, bag_path, csv_path, body_count, model_name, simulated, truncated, collapsed,
                  cancelled, cancel_reason)
  SELECT run_id, student, requested_run_id, state, accepted_at, started_at, finished_at, stop_reason,
         collision_count, bag_path, csv_path,
         CASE WHEN json_valid(scene_json) THEN coalesce(json_array_length(scene_json, '$.masses'), 0) ELSE 0 END,
         CASE WHEN json_valid(summary_json) THEN coalesce(json_extract(summary_json, '$.model'), '') ELSE '' END,
         CASE WHEN json_valid(summary_json) THEN coalesce(json_extract(summary_json, '$.simulated'), 0) ELSE 0 END,
         CASE WHEN state = 'interrupted' THEN 1
              WHEN json_valid(summary_json) THEN coalesce(json_extract(summary_json, '$.truncated'), 0) ELSE 0 END,
         CASE WHEN json_valid(summary_json) THEN coalesce(json_extract(summary_json, '$.collapsed'), 0) ELSE 0 END,
         CASE WHEN json_valid(summary_json) THEN coalesce(json_extract(summary_json, '$.cancelled'), 0) ELSE 0 END,
         CASE WHEN NOT json_valid(summary_json) THEN ''
              WHEN coalesce(json_extract(summary_json, '$.cancelled'), 0)
              THEN coalesce(json_extract(summary_json, '$.truncation_reason'), '') ELSE '' END
  FROM runs_v1 ORDER BY rowid;
INSERT INTO run_texts (run_id, scene_json, summary_json) SELECT run_id, scene_json, summary_json FROM runs_v1 ORDER BY rowid;
DROP TABLE runs_v1;
)sql";
}

/// A row's columns (the list), then with its texts (find, inState: runs r LEFT JOIN run_texts t).
constexpr const char* kRunHeadColumns =
    "run_id, student, requested_run_id, state, accepted_at, started_at, finished_at, stop_reason, collision_count, "
    "bag_path, csv_path, body_count, model_name, simulated, truncated, collapsed, cancelled, cancel_reason";
constexpr const char* kRunWithTexts =
    "SELECT r.run_id, student, requested_run_id, state, accepted_at, started_at, finished_at, stop_reason, "
    "collision_count, bag_path, csv_path, body_count, model_name, simulated, truncated, collapsed, cancelled, "
    "cancel_reason, t.scene_json, t.summary_json FROM runs r LEFT JOIN run_texts t ON t.run_id = r.run_id";
constexpr int kRunHeadColumnCount = 18;

using StatementCache = std::unordered_map<std::string, sqlite3_stmt*>;

/// One use of a prepared statement, taken from the connection's cache (prepared on first
/// use), reset and cleared when it goes out of scope. Every value is bound, never spliced
/// into the SQL.
class Statement {
 public:
  Statement(StatementCache& cache, sqlite3* db, const std::string& path, const std::string& sql)
      : db_(db), path_(path) {
    sqlite3_stmt*& cached = cache[sql];
    if (!cached && sqlite3_prepare_v3(db, sql.c_str(), static_cast<int>(sql.size()), SQLITE_PREPARE_PERSISTENT,
                                      &cached, nullptr) != SQLITE_OK) {
      cache.erase(sql);
      fail("preparing '" + sql + "'");
    }
    stmt_ = cached;
  }
  ~Statement() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int index, const std::string& text) {
    check(sqlite3_bind_text(stmt_, index, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& bind(int index, double value) {
    check(sqlite3_bind_double(stmt_, index, value));
    return *this;
  }
  Statement& bind(int index, std::int64_t value) {
    check(sqlite3_bind_int64(stmt_, index, value));
    return *this;
  }
  /// True while a row is ready; false when done.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail("executing '" + std::string(sqlite3_sql(stmt_)) + "'");
  }
  void run() {
    while (step()) {
    }
  }
  /// Runs a savepoint's SQL (SAVEPOINT, RELEASE) on the statement's connection.
  void savepoint(const char* sql) const {
    if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) != SQLITE_OK) fail(std::string("executing '") + sql + "'");
  }
  /// Undoes the writes since the savepoint `name` and ends it; errors are ignored (the
  /// failure being handled is the one reported).
  void rollBackTo(const std::string& name) const {
    sqlite3_exec(db_, ("ROLLBACK TO " + name + "; RELEASE " + name).c_str(), nullptr, nullptr, nullptr);
  }
  std::string text(int column) const {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, column));
    return p ? std::string(p, static_cast<std::size_t>(sqlite3_column_bytes(stmt_, column))) : std::string();
  }
  double real(int column) const { return sqlite3_column_double(stmt_, column); }
  std::int64_t integer(int column) const { return sqlite3_column_int64(stmt_, column); }

 private:
  void check(int rc) const {
    if (rc != SQLITE_OK) fail("binding a value");
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw RunIndexError("run index " + path_ + ": " + what + ": " + sqlite3_errmsg(db_), sqlite3_errcode(db_));
  }

  sqlite3* db_;
  const std::string& path_;
  sqlite3_stmt* stmt_ = nullptr;
};

/// Runs a run's row and its texts' statements as one (a savepoint: inside a group's
/// transaction, or a transaction of its own); neither is written when one fails.
void runTogether(Statement& row, Statement& texts) {
  row.savepoint("SAVEPOINT run_row");
  try {
    row.run();
    texts.run();
  } catch (...) {
    row.rollBackTo("run_row");
    throw;
  }
  row.savepoint("RELEASE run_row");
}

std::int64_t asStored(std::uint64_t count) { return static_cast<std::int64_t>(count); }
std::uint64_t asCount(std::int64_t stored) { return static_cast<std::uint64_t>(stored); }
std::int64_t flag(bool value) { return value ? 1 : 0; }

/// A row of kRunHeadColumns, or of kRunWithTexts when with_json.
IndexedRun readRun(const Statement& s, bool with_json) {
  IndexedRun run;
  run.run_id = s.text(0);
  run.student = s.text(1);
  run.requested_run_id = s.text(2);
  // A state this version does not know (a newer writer) reads as interrupted: not live.
  run.state = runStateFromName(s.text(3)).value_or(RunState::kInterrupted);
  run.accepted_at = s.real(4);
  run.started_at = s.real(5);
  run.finished_at = s.real(6);
  run.stop_reason = s.text(7);
  run.collision_count = asCount(s.integer(8));
  run.bag_path = s.text(9);
  run.csv_path = s.text(10);
  run.body_count = static_cast<std::uint32_t>(s.integer(11));
  run.ending.model_name = s.text(12);
  run.ending.simulated = s.integer(13) != 0;
  run.ending.truncated = s.integer(14) != 0;
  run.ending.collapsed = s.integer(15) != 0;
  run.ending.cancelled = s.integer(16) != 0;
  run.ending.cancel_reason = s.text(17);
  if (with_json) {
    run.scene_json = s.text(kRunHeadColumnCount);
    run.summary_json = s.text(kRunHeadColumnCount + 1);
  }
  return run;
}

std::string limitClause(std::size_t limit) {
  return limit == 0 ? std::string() : " LIMIT " + std::to_string(limit);
}

}  // namespace

const char* runStateName(RunState state) {
  switch (state) {
    case RunState::kQueued:
      return "queued";
    case RunState::kRunning:
      return "running";
    case RunState::kFinished:
      return "finished";
    case RunState::kInterrupted:
      return "interrupted";
  }
  return "interrupted";
}

std::optional<RunState> runStateFromName(const std::string& name) {
  for (RunState state : {RunState::kQueued, RunState::kRunning, RunState::kFinished, RunState::kInterrupted}) {
    if (name == runStateName(state)) return state;
  }
  return std::nullopt;
}

RunIndex::RunIndex(const std::string& path, int busy_timeout_ms) : path_(path), busy_timeout_ms_(busy_timeout_ms) {
  const int rc = sqlite3_open_v2(path.c_str(), &db_,
                                 SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    const std::string error = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw RunIndexError("run index " + path + ": cannot open: " + error);
  }
  sqlite3_busy_timeout(db_, busy_timeout_ms);
  // Nodes starting together (labs sharing a folder) meet here: switching to WAL and
  // creating the tables may answer SQLITE_BUSY at once, without the busy handler (e.g.
  // while another connection recovers the WAL), so the set-up is tried again until the
  // default busy timeout has passed.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::milliseconds(kDefaultBusyTimeoutMs);
  for (;;) {
    try {
      initialize();
      return;
    } catch (const RunIndexError&) {
      const int code = sqlite3_errcode(db_) & 0xff;
      if ((code == SQLITE_BUSY || code == SQLITE_LOCKED) && std::chrono::steady_clock::now() < give_up) {
        sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        continue;
      }
      finalizeStatements();
      sqlite3_close(db_);
      db_ = nullptr;
      throw;
    }
  }
}

void RunIndex::initialize() {
  execute("PRAGMA journal_mode=WAL");
  // WAL's own durability: a commit survives the process (a crash of the node); only a
  // power cut may lose the last commits.
  execute("PRAGMA synchronous=NORMAL");
  // A small page cache: the file's pages stay in the system's cache anyway, and a node's
  // memory then stays flat as a class's index grows (SQLite's default is 2 MB per connection).
  execute("PRAGMA cache_size=-" + std::to_string(kPageCacheKiB));
  std::int64_t found = 0;
  {  // finalized before the writes below: a finalize resets the connection's error code
    Statement version(statements_, db_, path_, "PRAGMA user_version");
    version.step();
    found = version.integer(0);
  }
  if (found == kSchemaVersion) return;
  if (found > kSchemaVersion) {
    throw RunIndexError("run index " + path_ + ": schema version " + std::to_string(found) +
                        " is newer than this program's " + std::to_string(kSchemaVersion));
  }
  execute("BEGIN IMMEDIATE");
  {  // again under the write lock: another process may have set the file up meanwhile
    Statement version(statements_, db_, path_, "PRAGMA user_version");
    version.step();
    found = version.integer(0);
  }
  if (found < kSchemaVersion) {
    execute(found == 1 ? migrationFrom1Sql() : schemaSql());
    execute("PRAGMA user_version=" + std::to_string(kSchemaVersion));
  }
  execute("COMMIT");
}

RunIndex::~RunIndex() {
  finalizeStatements();
  sqlite3_close(db_);
}

void RunIndex::finalizeStatements() {
  for (auto& entry : statements_) sqlite3_finalize(entry.second);
  statements_.clear();
}

bool RunIndexError::diskFull() const { return (sqlite_code_ & 0xff) == SQLITE_FULL; }

std::string RunIndex::defaultPath(const std::string& bag_directory) {
  return (std::filesystem::path(bag_directory) / "runs.sqlite").string();
}

void RunIndex::execute(const std::string& sql) {
  char* message = nullptr;
  const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &message);
  if (rc != SQLITE_OK) {
    const std::string error = message ? message : sqlite3_errmsg(db_);
    sqlite3_free(message);
    throw RunIndexError("run index " + path_ + ": executing '" + sql.substr(0, 60) + "': " + error, rc);
  }
}

void RunIndex::accepted(const IndexedRun& run) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(statements_, db_, path_,
              std::string("INSERT OR REPLACE INTO runs (") + kRunHeadColumns +
                  ") VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18)");
  s.bind(1, run.run_id).bind(2, run.student).bind(3, run.requested_run_id).bind(4, std::string(runStateName(run.state)));
  s.bind(5, run.accepted_at).bind(6, run.started_at).bind(7, run.finished_at).bind(8, run.stop_reason);
  s.bind(9, asStored(run.collision_count)).bind(10, run.bag_path).bind(11, run.csv_path);
  s.bind(12, static_cast<std::int64_t>(run.body_count)).bind(13, run.ending.model_name);
  s.bind(14, flag(run.ending.simulated)).bind(15, flag(run.ending.truncated)).bind(16, flag(run.ending.collapsed));
  s.bind(17, flag(run.ending.cancelled)).bind(18, run.ending.cancel_reason);
  Statement texts(statements_, db_, path_,
                  "INSERT OR REPLACE INTO run_texts (run_id, scene_json, summary_json) VALUES (?1, ?2, ?3)");
  texts.bind(1, run.run_id).bind(2, run.scene_json).bind(3, run.summary_json);
  runTogether(s, texts);
}

bool RunIndex::writeTogether(const std::function<void()>& writes, std::chrono::milliseconds lock_wait) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sqlite3_busy_timeout(db_, static_cast<int>(lock_wait.count()));
    const int rc = sqlite3_exec(db_, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr);
    sqlite3_busy_timeout(db_, busy_timeout_ms_);
    if ((rc & 0xff) == SQLITE_BUSY || (rc & 0xff) == SQLITE_LOCKED) return false;
    if (rc != SQLITE_OK) {
      throw RunIndexError("run index " + path_ + ": beginning a group of writes: " + sqlite3_errmsg(db_), rc);
    }
  }
  try {
    writes();
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  const int rc = sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr);
  if (rc != SQLITE_OK) {
    const std::string error = sqlite3_errmsg(db_);
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw RunIndexError("run index " + path_ + ": committing a group of writes: " + error, rc);
  }
  return true;
}

void RunIndex::started(const std::string& run_id, double at) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Only a queued run starts: a late call never takes a run back from its end.
  Statement s(statements_, db_, path_, "UPDATE runs SET state = 'running', started_at = ?2 WHERE run_id = ?1 AND state = 'queued'");
  s.bind(1, run_id).bind(2, at).run();
}

void RunIndex::finished(const std::string& run_id, double at, const std::string& summary_json,
                        const std::string& stop_reason, std::uint64_t collision_count, const std::string& bag_path,
                        const RunEnding& ending) {
  end(run_id, RunState::kFinished, at, summary_json, stop_reason, collision_count, bag_path, ending);
}

void RunIndex::interrupted(const std::string& run_id, double at, const std::string& summary_json,
                           std::uint64_t collision_count, const std::string& bag_path) {
  RunEnding ending;
  ending.truncated = true;
  end(run_id, RunState::kInterrupted, at, summary_json, "INTERRUPTED", collision_count, bag_path, ending);
}

void RunIndex::end(const std::string& run_id, RunState state, double at, const std::string& summary_json,
                   const std::string& stop_reason, std::uint64_t collision_count, const std::string& bag_path,
                   const RunEnding& ending) {
  std::lock_guard<std::mutex> lock(mutex_);
  // A run without a row (accepted before its node had the index) gets one, so that no
  // run's end is lost.
  Statement s(statements_, db_, path_,
              "INSERT INTO runs (run_id, state, finished_at, stop_reason, collision_count, bag_path, "
              "model_name, simulated, truncated, collapsed, cancelled, cancel_reason) "
              "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12) ON CONFLICT(run_id) DO UPDATE SET "
              "state = excluded.state, finished_at = excluded.finished_at, "
              "stop_reason = excluded.stop_reason, collision_count = excluded.collision_count, "
              "bag_path = excluded.bag_path, model_name = excluded.model_name, simulated = excluded.simulated, "
              "truncated = excluded.truncated, collapsed = excluded.collapsed, cancelled = excluded.cancelled, "
              "cancel_reason = excluded.cancel_reason");
  s.bind(1, run_id).bind(2, std::string(runStateName(state))).bind(3, at).bind(4, stop_reason);
  s.bind(5, asStored(collision_count)).bind(6, bag_path).bind(7, ending.model_name);
  s.bind(8, flag(ending.simulated)).bind(9, flag(ending.truncated)).bind(10, flag(ending.collapsed));
  s.bind(11, flag(ending.cancelled)).bind(12, ending.cancelled ? ending.cancel_reason : std::string());
  Statement texts(statements_, db_, path_,
                  "INSERT INTO run_texts (run_id, summary_json) VALUES (?1, ?2) "
                  "ON CONFLICT(run_id) DO UPDATE SET summary_json = excluded.summary_json");
  texts.bind(1, run_id).bind(2, summary_json);
  runTogether(s, texts);
}

void RunIndex::rejected(const IndexedRejection& rejection) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(statements_, db_, path_,
              "INSERT INTO rejections (at, student, run_id, reason_name, field, message) VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
  s.bind(1, rejection.at).bind(2, rejection.student).bind(3, rejection.run_id).bind(4, rejection.reason_name);
  s.bind(5, rejection.field).bind(6, rejection.message);
  s.run();
  // Bounded: a student's loop of bad sends cannot grow the file without end.
  Statement trim(statements_, db_, path_, "DELETE FROM rejections WHERE id <= last_insert_rowid() - ?1");
  trim.bind(1, static_cast<std::int64_t>(kRejectionsKept)).run();
}

void RunIndex::setCsvPath(const std::string& run_id, const std::string& csv_path) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(statements_, db_, path_, "UPDATE runs SET csv_path = ?2 WHERE run_id = ?1");
  s.bind(1, run_id).bind(2, csv_path).run();
}

std::optional<IndexedRun> RunIndex::find(const std::string& run_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(statements_, db_, path_, std::string(kRunWithTexts) + " WHERE r.run_id = ?1");
  s.bind(1, run_id);
  if (!s.step()) return std::nullopt;
  return readRun(s, /*with_json=*/true);
}

std::vector<IndexedRun> RunIndex::list(const std::optional<std::string>& student, std::size_t limit) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(statements_, db_, path_,
              std::string("SELECT ") + kRunHeadColumns + " FROM runs" + (student ? " WHERE student = ?1" : "") +
                  " ORDER BY accepted_at, rowid" + limitClause(limit));
  if (student) s.bind(1, *student);
  std::vector<IndexedRun> runs;
  while (s.step()) runs.push_back(readRun(s, /*with_json=*/false));
  return runs;
}

std::vector<IndexedRun> RunIndex::inState(RunState state) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(statements_, db_, path_,
              std::string(kRunWithTexts) + " WHERE state = ?1 ORDER BY accepted_at, r.rowid");
  s.bind(1, std::string(runStateName(state)));
  std::vector<IndexedRun> runs;
  while (s.step()) runs.push_back(readRun(s, /*with_json=*/true));
  return runs;
}

std::vector<IndexedRejection> RunIndex::rejections(const std::optional<std::string>& student, std::size_t limit) const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(statements_, db_, path_,
              std::string("SELECT id, at, student, run_id, reason_name, field, message FROM rejections") +
                  (student ? " WHERE student = ?1" : "") + " ORDER BY id DESC" + limitClause(limit));
  if (student) s.bind(1, *student);
  std::vector<IndexedRejection> found;
  while (s.step()) {
    IndexedRejection r;
    r.id = s.integer(0);
    r.at = s.real(1);
    r.student = s.text(2);
    r.run_id = s.text(3);
    r.reason_name = s.text(4);
    r.field = s.text(5);
    r.message = s.text(6);
    found.push_back(std::move(r));
  }
  return found;
}

std::size_t RunIndex::runCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(statements_, db_, path_, "SELECT count(*) FROM runs");
  s.step();
  return static_cast<std::size_t>(s.integer(0));
}

}  // namespace collision_lab::service
