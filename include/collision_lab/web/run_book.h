// What the class's web server knows of the lab node's runs (docs/web.md), built from the
// lab node's own topics only: served_inputs, predictions, collision_events, run_summaries,
// accepted_runs and rejected. Every run the node serves is here, whoever sent it (a
// browser, rostopic pub, a service call), keyed by its served run_id.
//
// Big runs stay light: each run keeps a view model's RunRecord (run_record.h) without
// the rviz keyframes, whose series are min/max envelopes per column, so the JSON of a run
// has at most a few thousand points whatever its count. Events beyond the node's
// ~max_published_events are not published; when a summary says so, the run is rebuilt from
// its bag (readRunFromBag).
//
// Bounded memory (RunBookOptions::memory_budget_bytes): the runs held stay within a byte
// budget; the least recently used finished runs with a bag are evicted and read back from
// their bag when asked for again. With a RunSource (the run index), an evicted or never
// seen run (an old link after a restart) is found there, the run list is the index's, and
// runs believed queued or running are reconciled against it: finished there -> completed
// from the bag; interrupted there -> shown "interrupted" with the events its bag holds.
// An evicted run the RunSource does not know (or with none) leaves a small stub (its
// summary) for the list and the reload.
//
// Thread-safe: the ROS callbacks (one spinner thread) and the HTTP threads share it.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunProgress.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/run_record.h"
#include "collision_lab/web/run_source.h"

namespace collision_lab_web {

/// One run as the web pages show it.
struct WebRun {
  std::string run_id, student, requested_run_id;
  std::unique_ptr<collision_lab_ros::RunRecord> record;  ///< null until served_inputs arrives
  /// Closed form after each collision, per plotted body (three-body rotation only).
  std::vector<collision_lab_ros::Envelope> predicted;
  /// Before served_inputs arrives (the topics are separate connections).
  std::vector<collision_lab::CollisionEvent> early_events;
  std::optional<collision_lab::Prediction> early_prediction;
  std::uint64_t events_received = 0;  ///< published CollisionEvents of this run [1]
  /// The summary arrived but published events are still on their way, or the run is being
  /// rebuilt from its bag.
  std::optional<collision_lab::RunSummary> pending_summary;
  std::optional<collision_lab::RunSummary> summary;  ///< once finished
  bool rebuilding = false;
  bool finished = false;
  /// Finished because its node died (the index says interrupted): summary describes what
  /// its bag holds, stop reason INTERRUPTED.
  bool interrupted = false;
  /// Running by the index, before (or without) its served input: after a restart.
  bool started = false;
  std::string bag_error;  ///< why the rebuild from the bag failed (the live record stays)
  std::uint64_t version = 0;  ///< bumped on every change (event streams wait on it)
  /// The run JSON's totals (exact sums: computed once per version, not per request), and
  /// the version they are of.
  mutable std::string totals_json;
  mutable std::uint64_t totals_version = ~std::uint64_t{0};
  double accepted_stamp = 0.0;  ///< [s] since the epoch
  std::uint64_t sequence = 0;   ///< arrival order in the book [1]
  std::uint64_t last_used = 0;  ///< the book's use clock at the last read or change [1]
  std::chrono::steady_clock::time_point touched;  ///< the last message or completion
  std::size_t footprint = 0;    ///< bytes counted against the budget [bytes]
};

/// What an evicted run leaves when the RunSource does not know it (or there is none):
/// enough for the list and to read it back from its bag (whose summary it shows again).
struct EvictedRun {
  std::string student, requested_run_id, bag_path;
  double accepted_stamp = 0.0;        ///< [s] since the epoch
  std::uint64_t collision_count = 0;  ///< [1]
  std::uint64_t sequence = 0;         ///< its place in the list [1]
  std::uint32_t bodies = 0;           ///< [1]
  bool interrupted = false;
  collision_lab::service::RunEnding ending;
};

struct RunBookOptions {
  /// Threads that rebuild runs from their bags (the runs whose events were not all
  /// published): at most this many bags are read at once for them [1].
  std::size_t rebuild_threads = 2;
  std::size_t envelope_vertices = 1024;  ///< points per plotted series at most (RecordLimits) [1]
  /// The runs held in memory stay within this (web node ~memory_budget_bytes) [bytes]. A
  /// run without a bag is never evicted (it could not be read back); a run alone larger
  /// than the budget is kept while it is the newest. The default holds about 200 small
  /// runs (a class's last few each, every run in progress), so that a class reaches it
  /// early and the node's memory stays flat after; older runs come back from their bags
  /// in milliseconds.
  std::size_t memory_budget_bytes = std::size_t{4} << 20;
  /// The reconciliation against the RunSource runs this often on a thread of its own; 0:
  /// only when reconcile() is called [ms].
  std::chrono::milliseconds reconcile_period{2000};
  /// A run is reconciled once no message of it arrived for this long [ms].
  std::chrono::milliseconds reconcile_after{2000};
};

/// A submitted input's answer: the run_id it was served under (with its place in the
/// queue and lane, AcceptedRun), or its rejection.
struct Submission {
  std::optional<std::string> run_id;
  std::uint32_t queue_position = 0;  ///< [1] runs ahead of it when accepted
  std::string lane;                  ///< "short" or "long"; empty from an older lab node
  std::optional<collision_lab::Rejected> rejected;
};

class RunBook {
 public:
  /// envelope_vertices: points per plotted series at most (RecordLimits).
  explicit RunBook(std::size_t envelope_vertices = 1024);
  /// source: where evicted and unknown runs are found (null: none).
  RunBook(const RunBookOptions& options, std::shared_ptr<const RunSource> source);
  /// Stops the reconciliation; waits for the rebuilds from bags in progress.
  ~RunBook();
  RunBook(const RunBook&) = delete;
  RunBook& operator=(const RunBook&) = delete;

  // ROS callbacks.
  void onAccepted(const collision_lab::AcceptedRun& msg);
  void onRejected(const collision_lab::Rejected& msg);
  void onServedInput(const collision_lab::InitialConditions& msg);
  void onPrediction(const collision_lab::Prediction& msg);
  void onEvent(const collision_lab::CollisionEvent& msg);
  /// A run past ~max_published_events: its sampled state goes into the record
  /// (RunRecord::addSample), so the live counter and plots move on until the summary's
  /// rebuild from the bag replaces them. Ignored before the run's served input.
  void onProgress(const collision_lab::RunProgress& msg);
  void onSummary(const collision_lab::RunSummary& msg);

  /// Registers an input about to be published under `requested` run_id for `student`:
  /// `on_answer` is called once, on the ROS callback's thread and without the book's lock,
  /// when its AcceptedRun or Rejected arrives. No thread waits for it.
  using AnswerCallback = std::function<void(const Submission&)>;
  void expect(const std::string& student, const std::string& requested, AnswerCallback on_answer);
  /// Forgets an input still unanswered (its sender gave up): true when it was still
  /// waiting, and then its callback is never called.
  bool forget(const std::string& student, const std::string& requested);

  /// Known in memory, as an evicted stub or to the RunSource.
  bool has(const std::string& run_id) const;
  /// Held in memory now: json(run_id) answers without reading a bag or the index.
  bool resident(const std::string& run_id) const;
  /// The run as JSON text (docs/web.md), with its version; nullopt for an unknown run_id.
  /// A run not in memory is loaded into the book first (from its bag when finished or
  /// interrupted; its state as the index says otherwise); concurrent loads of one run read
  /// its bag once.
  std::optional<std::pair<std::string, std::uint64_t>> json(const std::string& run_id);
  /// Waits until the run's version differs from `seen` or `timeout` passes; returns the
  /// current version (0 for a run not in memory) and whether the run is finished (an
  /// interrupted run is finished too). A run not in memory is loaded first, as by json().
  std::pair<std::uint64_t, bool> waitForChange(const std::string& run_id, std::uint64_t seen,
                                               std::chrono::milliseconds timeout);
  /// A page of a list: entries offset .. offset + limit - 1; total (when given) gets the
  /// length of the whole list.
  struct ListPage {
    std::size_t offset = 0;
    std::size_t limit = static_cast<std::size_t>(-1);
    std::size_t* total = nullptr;
  };
  /// Every run (student empty: everyone's), oldest first, as a JSON array text, or the page
  /// of it asked for. With a RunSource: every run it lists, with the live state of the runs
  /// in memory; only the page's index rows are read back into items.
  std::string list(const std::optional<std::string>& student, const ListPage& page) const;
  std::string list(const std::optional<std::string>& student) const { return list(student, ListPage{}); }
  /// The lab node's rejected inputs (student empty: everyone's), newest first, at most
  /// kRejectionsListed, as a JSON array text of {at [s since the epoch], student, run_id,
  /// reason_name, field, message}. Empty without a RunSource (the index keeps them).
  std::string rejections(const std::optional<std::string>& student) const;
  static constexpr std::size_t kRejectionsListed = 1000;
  /// The run's bag (RunSummary.bag_path) once it is finished (or interrupted) and
  /// recorded; empty otherwise.
  std::string bagPath(const std::string& run_id) const;
  bool finished(const std::string& run_id) const;

  /// One reconciliation pass (what the periodic thread does): every run in memory not
  /// finished, with no message for reconcile_after, that the RunSource says finished or
  /// interrupted is completed from its bag. Returns how many runs it completed [1].
  std::size_t reconcile();
  /// Bytes the runs in memory hold, as counted against the budget [bytes].
  std::size_t residentBytes() const;
  /// Runs held in memory [1].
  std::size_t residentRuns() const;

 private:
  /// How a run is to be completed from its bag when no summary came by the topics.
  struct Completion {
    bool interrupted = false;
    collision_lab::RunSummary fallback;  ///< when the bag has no summary
  };

  WebRun& runLocked(const std::string& run_id);
  void finishLocked(WebRun& run, const collision_lab::RunSummary& summary);
  void maybeFinishLocked(WebRun& run);
  /// Queues the run's rebuild from its bag for the rebuild threads.
  void startRebuildLocked(WebRun& run, const std::string& bag_path);
  /// A rebuild thread: takes the queued rebuilds one by one until the book stops (the
  /// queued ones left are dropped then; each ends its current one).
  void rebuildLoop();
  /// Reads the bag and completes the run (its pending summary, else the bag's, else the
  /// completion's fallback).
  void completeFromBag(const std::string& run_id, const std::string& bag_path, const std::optional<Completion>& how);
  /// Makes the run resident (from a stub or the RunSource); false when unknown.
  bool load(const std::string& run_id);
  /// A loaded run's fields from its stub (evicted: it ended), which is then dropped.
  void fillFromStubLocked(WebRun& run, const EvictedRun& stub);
  /// A loaded run's fields from its index row: waiting, running or ended.
  void fillFromRowLocked(WebRun& run, const collision_lab::service::IndexedRun& row);
  void touchLocked(WebRun& run);
  void countLocked(WebRun& run);
  /// The RunSource has the run, finished or interrupted (so an evicted run needs no stub).
  bool sourceKnows(const std::string& run_id) const;
  /// Evicts least recently used finished runs until within the budget; `keep` stays.
  void enforceBudgetLocked(const std::string& keep);
  void reconcileLoop();
  /// Removes and returns the callback waiting for this input's answer (null if none).
  AnswerCallback takeWaitingLocked(const std::string& student, const std::string& requested);

  RunBookOptions options_;
  std::shared_ptr<const RunSource> source_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::map<std::string, WebRun> runs_;
  std::map<std::uint64_t, std::string> order_;  ///< sequence -> run_id, oldest first
  std::uint64_t next_sequence_ = 1;
  std::uint64_t use_clock_ = 0;
  std::size_t resident_bytes_ = 0;  ///< sum of runs_' footprints [bytes]
  std::map<std::string, EvictedRun> evicted_;  ///< evicted runs the RunSource does not know
  std::set<std::string> loading_;  ///< runs being read back (one load each)
  /// Inputs published and not yet answered: key student + '\n' + requested run_id.
  std::map<std::string, AnswerCallback> waiting_;
  /// Rebuilds from bags waiting for a rebuild thread (run_id, bag path), oldest first. A
  /// few threads read bags, however many runs end at once: memory and threads are bounded.
  std::deque<std::pair<std::string, std::string>> rebuild_queue_;
  std::condition_variable rebuild_wanted_;  ///< rebuild_queue_ grew, or stopping_
  std::vector<std::thread> rebuilders_;
  bool stopping_ = false;
  std::condition_variable stop_;
  std::thread reconciler_;
};

/// A run rebuilt from a bag: its served InitialConditions, Prediction, every
/// CollisionEvent (into the record) and RunSummary. Throws std::runtime_error.
struct BagRun {
  std::unique_ptr<collision_lab_ros::RunRecord> record;
  std::vector<collision_lab_ros::Envelope> predicted;
};
BagRun readRunFromBag(const std::string& bag_path, std::size_t envelope_vertices);

/// Text safe inside HTML element content and attribute values (& < > " ').
std::string htmlEscape(const std::string& text);

}  // namespace collision_lab_web
