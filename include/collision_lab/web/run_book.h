// What the class's web server knows of the lab node's runs (docs/web.md), built from the
// lab node's own topics only: served_inputs, predictions, collision_events, run_summaries,
// accepted_runs and rejected. Every run the node serves is here, whoever sent it (a
// browser, rostopic pub, a service call), keyed by its served run_id.
//
// Big runs stay light: each run keeps a marker view's RunRecord (marker_builder.h), whose
// series are min/max envelopes per column, so the JSON of a run has at most a few thousand
// points whatever its count. Events beyond the node's ~max_published_events are not
// published; when a summary says so, the run is rebuilt from its bag (readRunFromBag).
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
#include <string>
#include <thread>
#include <vector>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/marker_builder.h"

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
  std::string bag_error;  ///< why the rebuild from the bag failed (the live record stays)
  std::uint64_t version = 0;  ///< bumped on every change (event streams wait on it)
  double accepted_stamp = 0.0;  ///< [s] since the epoch
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
  /// Waits for the rebuilds from bags in progress.
  ~RunBook();
  RunBook(const RunBook&) = delete;
  RunBook& operator=(const RunBook&) = delete;

  // ROS callbacks.
  void onAccepted(const collision_lab::AcceptedRun& msg);
  void onRejected(const collision_lab::Rejected& msg);
  void onServedInput(const collision_lab::InitialConditions& msg);
  void onPrediction(const collision_lab::Prediction& msg);
  void onEvent(const collision_lab::CollisionEvent& msg);
  void onSummary(const collision_lab::RunSummary& msg);

  /// Registers an input about to be published under `requested` run_id for `student`:
  /// `on_answer` is called once, on the ROS callback's thread and without the book's lock,
  /// when its AcceptedRun or Rejected arrives. No thread waits for it.
  using AnswerCallback = std::function<void(const Submission&)>;
  void expect(const std::string& student, const std::string& requested, AnswerCallback on_answer);
  /// Forgets an input still unanswered (its sender gave up): true when it was still
  /// waiting, and then its callback is never called.
  bool forget(const std::string& student, const std::string& requested);

  bool has(const std::string& run_id) const;
  /// The run as JSON text (docs/web.md), with its version; nullopt for an unknown run_id.
  std::optional<std::pair<std::string, std::uint64_t>> json(const std::string& run_id) const;
  /// Waits until the run's version differs from `seen` or `timeout` passes; returns the
  /// current version (0 for an unknown run) and whether the run is finished.
  std::pair<std::uint64_t, bool> waitForChange(const std::string& run_id, std::uint64_t seen,
                                               std::chrono::milliseconds timeout) const;
  /// Every run (student empty: everyone's), oldest first, as a JSON array text.
  std::string list(const std::optional<std::string>& student) const;
  /// The run's bag (RunSummary.bag_path) once it is finished and recorded; empty otherwise.
  std::string bagPath(const std::string& run_id) const;
  bool finished(const std::string& run_id) const;

 private:
  WebRun& runLocked(const std::string& run_id);
  void finishLocked(WebRun& run, const collision_lab::RunSummary& summary);
  void maybeFinishLocked(WebRun& run);
  void rebuildFromBag(const std::string& run_id, const std::string& bag_path);
  /// Removes and returns the callback waiting for this input's answer (null if none).
  AnswerCallback takeWaitingLocked(const std::string& student, const std::string& requested);

  std::size_t envelope_vertices_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::map<std::string, WebRun> runs_;
  std::vector<std::string> order_;  ///< run_ids, oldest first
  /// Inputs published and not yet answered: key student + '\n' + requested run_id.
  std::map<std::string, AnswerCallback> waiting_;
  std::vector<std::thread> rebuilds_;  ///< one per run rebuilt from its bag; joined at the end
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
