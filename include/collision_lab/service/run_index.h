// The class's run index (docs/web.md, "Runs survive restarts"): one SQLite database,
// <bag_directory>/runs.sqlite, in WAL mode. The lab node writes it (every run it accepts,
// starts, finishes or finds interrupted, and every input it rejects); the web node and
// ~list_runs read it, so a restart of either node lists every run of the day and old links
// keep working. ROS-free: SQLite and the standard library only; messages are stored as
// JSON text made by the layer above.
//
// Thread-safe: one connection per RunIndex, guarded by a mutex. Several processes may open
// the same file (WAL: one writer, many readers; a busy timeout absorbs short waits, and
// readers never wait for a writer).
// Every method throws RunIndexError when SQLite fails; the callers log it and go on (the
// index is a record, never a reason to lose a run).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace collision_lab::service {

class RunIndexError : public std::runtime_error {
 public:
  /// sqlite_code: SQLite's result code of the failure (0: not SQLite's).
  explicit RunIndexError(const std::string& what, int sqlite_code = 0)
      : std::runtime_error(what), sqlite_code_(sqlite_code) {}
  /// True when the disk was full (SQLITE_FULL): the same write may succeed once space is freed.
  bool diskFull() const;

 private:
  int sqlite_code_;
};

/// A run's state in the index. A run moves queued -> running -> finished, or to
/// interrupted when its node died before it finished (found at the next start, or by a
/// reader that sees its bag closed without a summary).
enum class RunState { kQueued, kRunning, kFinished, kInterrupted };
const char* runStateName(RunState state);  ///< "queued", "running", "finished", "interrupted"
std::optional<RunState> runStateFromName(const std::string& name);

/// How an ended run ended, as the run list shows it (columns, so that a list reads no JSON).
struct RunEnding {
  std::string model_name;  ///< the model that answered (RunSummary.model_name); empty when interrupted
  bool simulated = false;  ///< impact by impact (not the model's count alone)
  bool truncated = false;  ///< cut short (a cap, a limit, a Stop, the node's death)
  bool collapsed = false;  ///< inelastic collapse
  bool cancelled = false;  ///< stopped by a Stop
  std::string cancel_reason;  ///< who stopped it and when, when cancelled
};

/// One row of the index.
struct IndexedRun {
  std::string run_id;            ///< as served (unique)
  std::string student;           ///< empty: anonymous
  std::string requested_run_id;  ///< as the input asked for it; may be empty
  RunState state = RunState::kQueued;
  double accepted_at = 0.0;  ///< [s] since the epoch (wall time)
  double started_at = 0.0;   ///< [s] since the epoch; 0 until running
  double finished_at = 0.0;  ///< [s] since the epoch; 0 until finished or interrupted
  std::string scene_json;    ///< the served input (InitialConditions) as JSON
  std::string summary_json;  ///< the RunSummary as JSON once finished; else empty
  std::string stop_reason;   ///< RunSummary.stop_reason once finished ("INTERRUPTED" when interrupted)
  std::uint64_t collision_count = 0;  ///< [1] RunSummary.collision_count once finished
  std::string bag_path;      ///< the run's final bag (<run_id>.bag) once finished or recovered; empty until then, or when not recorded
  std::string csv_path;      ///< the events CSV made beside the bag once asked for; empty until then
  std::uint32_t body_count = 0;  ///< [1] bodies of the served input (walls included); 0: unknown
  RunEnding ending;              ///< once finished or interrupted
};

/// One rejected input.
struct IndexedRejection {
  std::int64_t id = 0;  ///< the index's own row number
  double at = 0.0;      ///< [s] since the epoch
  std::string student, run_id, reason_name, field, message;
};

class RunIndex {
 public:
  /// [ms] how long a statement waits for another connection's write lock by default.
  static constexpr int kDefaultBusyTimeoutMs = 10000;
  /// Opens (creating when missing) the database at path, in WAL mode, with its tables.
  /// busy_timeout_ms: how long a write waits for another connection's write lock before
  /// it fails (opening the file waits up to kDefaultBusyTimeoutMs whatever it is).
  explicit RunIndex(const std::string& path, int busy_timeout_ms = kDefaultBusyTimeoutMs);
  ~RunIndex();
  RunIndex(const RunIndex&) = delete;
  RunIndex& operator=(const RunIndex&) = delete;

  /// <bag_directory>/runs.sqlite
  static std::string defaultPath(const std::string& bag_directory);

  // ---- Writer (the lab node) ----
  /// A run accepted and queued (its row is created; a row of that run_id is replaced).
  /// Only the run's own fields are used: state and times as given (normally kQueued).
  void accepted(const IndexedRun& run);
  /// A queued run starts (a run in another state is left as it is).
  void started(const std::string& run_id, double at);
  /// The run's summary is out and its bag closed.
  void finished(const std::string& run_id, double at, const std::string& summary_json,
                const std::string& stop_reason, std::uint64_t collision_count, const std::string& bag_path,
                const RunEnding& ending);
  /// The run will never finish (its node died); summary_json may describe what its bag holds.
  /// Its ending: truncated, not simulated.
  /// finished() and interrupted() create the run's row when it has none.
  void interrupted(const std::string& run_id, double at, const std::string& summary_json,
                   std::uint64_t collision_count, const std::string& bag_path);
  /// A rejected input; only the newest kRejectionsKept are kept.
  void rejected(const IndexedRejection& rejection);
  /// Calls `writes` (calls of the write methods above) inside one transaction: one commit
  /// for all of them (group commit). Waits at most lock_wait for the write lock; returns
  /// false, having called nothing, when another connection held it longer (SQLITE_BUSY):
  /// the caller tries again later. Throws RunIndexError when the transaction cannot begin
  /// for another reason, or its commit fails (nothing of the group is then written).
  bool writeTogether(const std::function<void()>& writes, std::chrono::milliseconds lock_wait);
  static constexpr std::size_t kRejectionsKept = 100000;
  /// The events CSV made beside the run's bag (the web node, once, on the first download).
  void setCsvPath(const std::string& run_id, const std::string& csv_path);

  // ---- Readers ----
  std::optional<IndexedRun> find(const std::string& run_id) const;
  /// Oldest accepted first; only student's when student is given (empty string: anonymous).
  /// limit 0: all. The rows come without their JSON texts (scene_json and summary_json
  /// empty): find() gives them.
  std::vector<IndexedRun> list(const std::optional<std::string>& student = std::nullopt, std::size_t limit = 0) const;
  /// Runs in a state, oldest first (a lab node's start: queued and running ones are interrupted).
  std::vector<IndexedRun> inState(RunState state) const;
  /// Newest first, at most limit (0: all); only student's when given.
  std::vector<IndexedRejection> rejections(const std::optional<std::string>& student = std::nullopt,
                                           std::size_t limit = 0) const;
  std::size_t runCount() const;

 private:
  /// WAL mode and the tables (created when the file has none). Throws RunIndexError.
  void initialize();
  /// Runs sql (no values: schema and pragmas only).
  void execute(const std::string& sql);
  /// finished() and interrupted(): the run's end, its row created when missing.
  void end(const std::string& run_id, RunState state, double at, const std::string& summary_json,
           const std::string& stop_reason, std::uint64_t collision_count, const std::string& bag_path,
           const RunEnding& ending);

  /// Finalizes the prepared statements (before the connection closes).
  void finalizeStatements();

  const std::string path_;  ///< for the errors
  const int busy_timeout_ms_;
  mutable std::mutex mutex_;
  sqlite3* db_ = nullptr;
  /// Each SQL text prepared once, on first use, and reused (under mutex_): preparing cost
  /// more than a row's write.
  mutable std::unordered_map<std::string, sqlite3_stmt*> statements_;
};

}  // namespace collision_lab::service
