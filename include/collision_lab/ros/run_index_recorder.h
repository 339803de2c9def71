// The lab node's side of the run index (service/run_index.h, docs/ros.md "The run index"):
// converts the served InitialConditions, RunSummary and Rejected to the index's rows and
// JSON, answers ~list_runs from it, and recovers the runs of dead nodes at start.
//
// The index is a record, never a reason to lose a run: every RunIndexError is caught and
// logged (ROS_ERROR), and the run goes on. Thread-safe (RunIndex is).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ServedRun.h"
#include "collision_lab/service/run_index.h"

namespace collision_lab_ros {

/// The one JSON of a served input (InitialConditions), which the run index stores
/// (IndexedRun::scene_json) and the web serves as a run's "scene": InitialConditions' field
/// names, masses with "inf" for a wall, restitution_model by its name ("constant", "tc",
/// "viscoelastic", "threshold"; a number no model has, as that number); a value that is not
/// finite is null.
nlohmann::json inputFields(const collision_lab::InitialConditions& input);
/// inputFields as text.
std::string inputJson(const collision_lab::InitialConditions& input);
/// The served input back from inputFields (a run to serve again). restitution_model reads
/// as a name or a number (as the index stored it before 0.8). A scalar stored as null (not
/// finite: tc, elastic_below, viscoelastic_speed, ring, max_run_seconds, which the node
/// ignores unless in use) reads back as 0. Throws std::invalid_argument when it is not such
/// JSON, or a per-body value is null.
collision_lab::InitialConditions inputFromFields(const nlohmann::json& fields);
/// inputFromFields of inputJson's text.
collision_lab::InitialConditions inputFromJson(const std::string& text);
/// The one JSON of a RunSummary, which the run index stores (IndexedRun::summary_json) and
/// the web serves: the fields the class pages show, under RunSummary's field names but
/// "model" (model_name), "paper_collision_count" (paper_predicted_collision_count; null
/// when not defined, as predicted_collision_count), "recorded" (recording_ok with a bag);
/// a value that is not finite is null.
nlohmann::json summaryFields(const collision_lab::RunSummary& summary);
/// summaryFields as text.
std::string summaryJson(const collision_lab::RunSummary& summary);
/// The summary back from summaryFields: each field it holds (a null number as NaN), the
/// others at their defaults; a key it lacks keeps its default too. Throws
/// nlohmann::json::exception on a value of the wrong type.
collision_lab::RunSummary summaryFromFields(const nlohmann::json& fields);
/// How the summary's run ended, as the index's columns (IndexedRun::ending).
collision_lab::service::RunEnding endingOf(const collision_lab::RunSummary& summary);

/// What a bag holds, read with rosbag::View.
struct BagContents {
  std::uint64_t events = 0;       ///< [1] CollisionEvent messages
  double last_event_time = 0.0;   ///< [s] simulated time of the last one (CollisionEvent.time); 0 without events
  std::optional<collision_lab::InitialConditions> input;
  std::optional<collision_lab::RunSummary> summary;  ///< the run's summary, when it was written
};
/// Reads the bag at path (indexed: closed, or reindexed). Throws rosbag::BagException.
BagContents readBagContents(const std::string& path);

/// A bag of a dead owner that recoverActiveBags took.
struct RecoveredBag {
  std::string run_id;
  std::string bag_path;  ///< <run_id>.bag once recovered; empty when the file held no bag (an empty claim, removed)
  BagContents contents;
  std::string error;     ///< empty when recovered; else why not (the .active file is left as it was)
};

/// Recovers every <run_id>.bag.active in directory whose owner is dead, i.e. whose
/// flock(LOCK_EX|LOCK_NB) this call gets (claimBag: a live owner holds it, so a live
/// node's bag is never touched, whichever node shares the directory). Each is reindexed
/// (`rosbag reindex --output-dir`, python3-rosbag: rosbag's C++ API has no reindex) into a
/// private folder of directory, renamed to <run_id>.bag (never replacing a file) and read;
/// the .active file is then removed. An empty .active file (a claim whose bag was never
/// opened) is removed. Claim files of claimers that died before renaming them are removed.
/// kEmptyClaims: only the empty .active files (and the stale claim files), which cost no
/// reading.
enum class ActiveBags { kEmptyClaims, kAll };
std::vector<RecoveredBag> recoverActiveBags(const std::string& directory, ActiveBags which = ActiveBags::kAll);

/// Whether a live process holds <run_id>.bag.active (its flock cannot be taken).
bool activeBagOwned(const std::string& active_path);

/// How long a deferrable write of the index (a run's start) may wait for a commit.
constexpr std::chrono::milliseconds kDeferredWritesDelay{500};
/// How long the lab's writes wait for another connection's write lock before they are
/// put back and tried again later: short, so that a locked index holds up nothing.
constexpr std::chrono::milliseconds kIndexWriterLockWait{200};
/// The longest pause between two tries of writes that a locked or failing index refused.
constexpr std::chrono::milliseconds kIndexRetryMaxPause{5000};
/// How long a run's end (finished()) and ~list_runs wait for the index's commit.
constexpr std::chrono::milliseconds kIndexCommitWait{2000};
/// Recovery waits for the index in slices of this, so that stopRecovery() ends it.
constexpr std::chrono::milliseconds kRecoveryWaitSlice{100};

/// The lab node's writer of the index.
class RunIndexRecorder {
 public:
  /// Opens <bag_directory>/runs.sqlite (creating it and the directory). A failure is
  /// logged and the recorder records nothing (ok() false): the node serves on.
  explicit RunIndexRecorder(const std::string& bag_directory);
  ~RunIndexRecorder();

  bool ok() const { return index_ != nullptr; }
  const std::string& bagDirectory() const { return bag_directory_; }
  /// The index, with every write handed over so far committed.
  collision_lab::service::RunIndex* index() {
    flush();
    return index_.get();
  }
  /// The index as committed so far, at once (writes still queued are not in it yet).
  const collision_lab::service::RunIndex* committed() const { return index_.get(); }
  /// Waits until every write handed over so far is committed, at most max_wait (and not
  /// at all, unless_locked, while the index is locked); false when they are not committed yet.
  bool flush(std::chrono::milliseconds max_wait = std::chrono::milliseconds::max(), bool unless_locked = false) const;

  // The writes go to a writer thread, in order, which commits whatever has queued up in
  // one transaction (a group commit: under load one commit serves many runs). accepted(),
  // finished() and rejected() are committed at once; started() (queued -> running, which
  // recovery treats alike) waits for the next of them, at most kDeferredWritesDelay, so
  // that a short run's start and end share a commit. finished() returns once its write is
  // committed, so that whoever sees the summary finds the run finished; list() first waits
  // for every write handed over. Both wait at most kIndexCommitWait, and not at all while
  // the index is locked: writes that a locked index refuses (another program holds its
  // write lock) are kept, in order, and tried again (pauses doubling up to
  // kIndexRetryMaxPause) until they commit; none is dropped while the node runs. Writes
  // that fail otherwise (a full disk, a broken file) are logged and dropped.

  /// A run accepted and queued, before any worker can take it; input as served (its
  /// run_id assigned). requested_run_id: InitialConditions.run_id as sent.
  void accepted(const std::string& run_id, const std::string& student, const std::string& requested_run_id,
                const collision_lab::InitialConditions& input);
  /// The run left the queue: a worker computes it.
  void started(const std::string& run_id);
  /// Its summary is out (its bag closed).
  void finished(const collision_lab::RunSummary& summary);
  void rejected(const collision_lab::Rejected& rejected);

  /// run_id's row as committed; none when the index does not list it or cannot be read
  /// (logged).
  std::optional<collision_lab::service::IndexedRun> find(const std::string& run_id) const;
  /// True when a run of the index holds run_id: it has not ended (a dead node's queued run,
  /// which recovery serves again under its id, or a live node's), or its bag is on disk
  /// (recorded by any node: a lab that records no bags must not take it over). An ended
  /// run without a bag holds nothing: the index then keeps the newest run under it.
  bool holds(const std::string& run_id) const;
  /// [bytes] of the student's bags on disk, as the index lists them (0 when it cannot be read).
  std::uint64_t studentBagBytes(const std::string& student) const;

  /// ~list_runs: every run of the index (every node process that wrote bag_directory),
  /// oldest first, student's only when student is not empty; in ServedRun's format. Empty
  /// (and logged) when the index cannot be read.
  std::vector<collision_lab::ServedRun> list(const std::string& student) const;

  /// A run that was queued, never started, when its node died: to be served again.
  struct QueuedRun {
    collision_lab::InitialConditions input;  ///< as served: its run_id, student and scene
    std::string requested_run_id;            ///< as the input asked for it
  };
  /// Serves a queued run of a dead node again; true when it is taken (queued anew).
  using ServeAgain = std::function<bool(const QueuedRun&)>;

  /// At the node's start, on a thread of its own while the node serves: recovers the .active bags of dead owners
  /// (recoverActiveBags) and records their runs as interrupted (stop reason INTERRUPTED,
  /// the events the bag holds; finished from its summary when the bag has one; a run the
  /// index has as finished keeps its row, e.g. one whose bag failed on a full disk), then ends
  /// every run the index still has running, or queued, with no live owner: completed as
  /// finished from its final bag's summary, else interrupted with the events its bag holds
  /// (none without a bag). A queued run with no bag whose stored input reads back is first
  /// offered to serve_again (oldest first), and left queued when it takes it. What needs no
  /// bag read comes first (empty claims, then the queued runs), so that a big bag's
  /// reindexing (seconds) holds up no queued run. Nothing stays "running". Its index writes
  /// go through the writer thread, as every write. Returns the runs it ended.
  /// Runs accepted since this recorder was made are this process's and never ended here.
  /// stopRecovery() ends it early (between two bags or runs; a reindex in progress ends
  /// first), and its waits for the index give up then.
  std::size_t recover(const ServeAgain& serve_again = {});
  void stopRecovery();

 private:
  /// Ends run_id from what its bag holds (finished with a summary, else interrupted); false,
  /// and the row kept, when the index has it as finished already.
  bool endFromBag(const std::string& run_id, const std::string& bag_path, const BagContents& contents,
                  const std::string& note);
  /// recover(): ends the runs of recovered bags (ended counts them).
  void takeRecoveredBags(const std::vector<RecoveredBag>& bags, std::size_t& ended);
  /// recover(): the open runs (queued_only: only the queued ones whose .active is gone)
  /// with no live owner, each served again (when queued, not offered before; offered says
  /// whether serve_again took it) or ended (not when taken).
  void endOpenRuns(const ServeAgain& serve_again, bool queued_only, std::map<std::string, bool>& offered,
                   std::size_t& ended);

  /// Hands `write` to the writer thread; returns its ticket (its place in the order of
  /// writes). An urgent write is committed at once (with whatever has queued up); a
  /// deferrable one waits for the next urgent write, or kDeferredWritesDelay.
  std::uint64_t enqueue(std::function<void()> write, bool urgent);
  /// Waits until every write up to `ticket` is committed (they become urgent), at most
  /// max_wait (and not at all, unless_locked, while the index is locked); false when they
  /// are not committed yet.
  bool waitWritten(std::uint64_t ticket, std::chrono::milliseconds max_wait = std::chrono::milliseconds::max(),
                   bool unless_locked = false) const;
  /// The writer thread: takes every write queued so far and commits them together
  /// (RunIndex::writeTogether), until the recorder is destroyed and nothing is left.
  /// Refused groups go back to the front of the queue and are tried again after a pause;
  /// at the recorder's end they get one last try.
  void writerLoop();
  /// One try at committing group; false when the index was locked (logged). A group that
  /// fails otherwise is logged and counts as done.
  bool commit(const std::vector<std::function<void()>>& group);

  std::string bag_directory_;
  const double started_at_;  ///< [s] since the epoch, wall time: this process's runs are newer
  std::atomic<bool> recovery_stops_{false};
  std::unique_ptr<collision_lab::service::RunIndex> index_;
  // The writer thread's queue: writes in order, committed in groups.
  mutable std::mutex writes_mutex_;
  mutable std::condition_variable writes_queued_;     ///< pending_ grew, or writer_stops_
  mutable std::condition_variable writes_committed_;  ///< written_ grew
  std::vector<std::function<void()>> pending_;
  std::chrono::steady_clock::time_point oldest_pending_;  ///< when pending_ last became non-empty
  mutable std::uint64_t urgent_ = 0;  ///< urgent writes and waiters since the last commit
  std::uint64_t queued_ = 0;   ///< writes ever queued
  std::uint64_t written_ = 0;  ///< writes ever committed (or, at the end, given up and logged)
  bool writer_stops_ = false;
  bool locked_out_ = false;  ///< the last try found the index locked: waiters do not wait
  std::thread writer_;
};

}  // namespace collision_lab_ros
