// collision_lab_node: serves InitialConditions of any size with the core's runScene (the
// CLI's entry point, so both give the same answers), publishes every output, records one
// bag per run and feeds the marker view. Inputs come from the topic `initial_conditions`
// and from the services ~run_scene and ~run_preset; all three take the same path (served,
// published, recorded, drawn). ~cancel stops the run in progress. Each accepted input is
// announced on `accepted_runs` with the run_id it got; ~list_runs lists the runs of the
// run index (<bag_directory>/runs.sqlite: every node process's), which the node writes
// (RunIndexRecorder). At start the node ends the runs of dead nodes in it (recover()).
//
// Threading contract:
// - One worker thread serves every input, from the topic and the services alike, in
//   arrival order, and does all publishing and recording: a run's messages go out in the
//   order predictions, (collision_events, velocities, energy_transfers) per collision,
//   run_summaries, and runs never interleave.
// - The topic callback (global callback queue, spun by main) only queues the input.
// - The services run on their own callback queue, spun by kServiceThreads threads of an
//   AsyncSpinner. A call queues its input like the topic does and blocks only its own
//   service thread until the worker hands back the outcome (a promise): the worker, topic
//   inputs, diagnostics and the marker animation (global queue) go on meanwhile. Further
//   concurrent calls wait in roscpp for a free service thread.
// - ~cancel and ~list_runs run on a callback queue and thread of their own, so they are
//   answered while every service thread waits for a run. It sets cancel_, which the run in progress polls
//   (SceneRunOptions::cancel); running_mutex_ guards which run that is.
// - With recording on, the worker hands each run's recorded messages over to a bag writer
//   thread (RunBagWriter; it blocks only while kRecordQueueMessages messages wait). The
//   writer closes the run's bag, then publishes its summary and answers its service call
//   (finishRun), so a run's summary may follow the next run's first messages; every
//   summary still follows its own run's messages and its bag is closed when it goes out.
// - The worker claims each run's bag file (claimBag, exclusive among every process that
//   shares bag_directory) when it assigns the run_id, before any message names it; the
//   bag writer only opens, writes and renames files so claimed.
// - The diagnostics timer (global queue) reads the worker's counters through atomics and
//   recording_mutex_.
// - Destruction: queued inputs are dropped (a call waiting for one answers ok = false) and
//   the run in progress is cancelled first, then the worker is joined (the cancelled run
//   closes its bag, its summary says cancelled), then the subscription and the services
//   stop (waiting only for calls whose run is over), the bag writer writes and closes
//   every bag handed over (publishing their summaries), and the service threads are
//   stopped. main destroys the node on SIGINT before ros::shutdown(), which would
//   otherwise first wait for every service call in progress, and so for its whole run.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/Cancel.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/ListRuns.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunPreset.h"
#include "collision_lab/RunScene.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/run_observer.h"

namespace collision_lab_ros {

struct LabNodeParams {
  bool record = true;
  std::string bag_directory;  ///< "~" expanded
  std::uint64_t max_collisions = 0;
  /// Simulate up to the cap even when the model predicts more impacts (else the model
  /// answers at once: core::SceneRunOptions::simulate_to_cap).
  bool simulate_to_cap = false;
  std::uint64_t max_published_events = 0;
  bool publish_markers = true;
  bool log_runs = true;            ///< one INFO line per served run (else DEBUG)
  std::uint64_t max_bodies = 0;    ///< larger scenes are rejected (TOO_MANY_BODIES)
  double min_free_space_mb = 0.0;  ///< [MB] diagnostics warn below it
  std::string scenario_file;       ///< the presets of ~run_preset

  /// Reads ~record, ~bag_directory, ~max_collisions, ~simulate_to_cap, ~max_published_events,
  /// ~publish_markers, ~log_runs, ~max_bodies, ~min_free_space_mb and ~scenario_file (default: the package's
  /// config/scenarios.yaml), with the defaults of node_constants.h. Throws
  /// std::invalid_argument, naming the parameter, its value and the accepted range, when a
  /// count (~max_collisions, ~max_published_events, ~max_bodies) is not a whole number in
  /// [0, 2^64 - 1].
  static LabNodeParams load(const ros::NodeHandle& private_nh);
};

/// The accepted range of a count parameter, as the errors state it.
constexpr char kCountParameterRange[] = "expected a whole number from 0 to 18446744073709551615 (2^64 - 1)";

/// A count parameter's value read as a double (the parameter server gives large integers
/// as doubles): value when it is a whole number in [0, 2^64 - 1]; otherwise error says so,
/// naming ~name, the value and the range (NaN, infinities, negative, fractional and too
/// large values, whose conversion to std::uint64_t would be undefined behaviour).
struct CountParameter {
  std::uint64_t value = 0;
  std::string error;  ///< empty when value holds
};
CountParameter countParameter(const std::string& name, double value);

/// Empty when run_id is safe as a bag file name; otherwise why not.
std::string runIdProblem(const std::string& run_id);
/// Empty when student is a valid InitialConditions.student (empty is: anonymous);
/// otherwise why not.
std::string studentProblem(const std::string& student);
/// The run_id an input asks for: <student>.<run_id>, <student> when it names no run_id,
/// or run_id when it names no student (empty: the node assigns one). A taken one is then
/// served as <that>.N.
std::string requestedRunId(const collision_lab::InitialConditions& input);

/// The runs a node accepted, the newest kServedRunsKept of them, for ~list_runs.
/// Thread-safe: the worker adds each run as it accepts it, and whichever thread publishes
/// a run's summary completes it.
class ServedRuns {
 public:
  void accepted(const collision_lab::AcceptedRun& run);
  void finished(const collision_lab::RunSummary& summary);
  /// Oldest first; those of student, or every run when student is empty.
  std::vector<collision_lab::ServedRun> list(const std::string& student) const;

 private:
  mutable std::mutex mutex_;
  std::deque<collision_lab::ServedRun> runs_;
};

/// The publishers of a run's outputs, in the order a run uses them.
struct RunTopics {
  ros::Publisher predictions, events, velocities, energies, summaries;
};

/// The per-collision messages the worker refills for every collision (lab_node.cpp's
/// EventStream), kept by the node so that their storage is reused from run to run.
struct EventMessages {
  collision_lab::CollisionEvent event;
  collision_lab::Velocities velocities;
  collision_lab::EnergyTransfer energy;
};

/// Stamps, publishes and records the messages of one run (lab_node.cpp).
class RunWriter;
class RunBagWriter;
class RunIndexRecorder;

/// The newest kRecordingTimeWindow samples of a duration [s], thread-safe.
class RecentDurations {
 public:
  void add(double seconds);
  /// The q-quantile (q in [0, 1]) of the kept samples [s]; 0 when there are none.
  double quantile(double q) const;
  std::size_t size() const;

 private:
  mutable std::mutex mutex_;
  std::vector<double> samples_;
  std::size_t next_ = 0;
};

/// The answer to one input: its summary when served, else its rejection.
struct ServeOutcome {
  std::optional<collision_lab::RunSummary> summary;
  collision_lab::Rejected rejected;
};

class LabNode {
 public:
  /// make_observer (may be empty) makes the in-process viewer fed when ~publish_markers
  /// is true: collision_lab_node passes the marker view's.
  LabNode(ros::NodeHandle nh, ros::NodeHandle private_nh, const RunObserverFactory& make_observer = {});
  /// Finishes the run in progress (closing its bag), drops queued inputs.
  ~LabNode();

 private:
  /// Where a service call waits for its outcome; null for topic inputs.
  using Reply = std::shared_ptr<std::promise<ServeOutcome>>;
  struct Job {
    collision_lab::InitialConditions::ConstPtr input;
    Reply reply;
  };

  void onInitialConditions(const collision_lab::InitialConditions::ConstPtr& msg);
  bool onRunScene(collision_lab::RunScene::Request& request,
                  collision_lab::RunScene::Response& response);
  bool onRunPreset(collision_lab::RunPreset::Request& request,
                   collision_lab::RunPreset::Response& response);
  bool onCancel(collision_lab::Cancel::Request& request, collision_lab::Cancel::Response& response);
  bool onListRuns(collision_lab::ListRuns::Request& request, collision_lab::ListRuns::Response& response);
  /// Queues input for the worker and waits for its outcome; empty when the node stops
  /// before serving it.
  std::optional<ServeOutcome> serveAndWait(const collision_lab::InitialConditions& input);
  void enqueue(Job job);
  void workerLoop();

  // ---- The worker's (not thread-safe) ----
  /// Validates input, assigns its run_id (in input), then runs it or rejects it; reply
  /// gets the outcome once the run is finished (its bag closed).
  void serve(collision_lab::InitialConditions& input, Reply reply);
  /// Publishes, records and draws one validated run (its run_id assigned).
  /// requested_run_id: RunSummary.requested_run_id.
  /// claim_error: RunBagBatch::claim_error.
  /// Runs the input's plan (core::planScene, made once when the input was checked).
  void run(collision_lab::InitialConditions& input, const collision_lab::core::ScenePlan& plan,
           const std::string& requested_run_id, const std::string& claim_error, Reply reply);
  /// runScene, as the run that ~cancel stops.
  collision_lab::core::SceneRunResult runCancellable(const std::string& run_id,
                                                     const collision_lab::core::ScenePlan& plan,
                                                     const collision_lab::core::SceneRunOptions& options,
                                                     const collision_lab::core::SceneVisitors& visitors);
  /// Records the input (stamped at the run's start) and publishes the prediction.
  void publishStart(RunWriter& out, const collision_lab::InitialConditions& input,
                    const collision_lab::core::ScenePlan& plan);
  /// Stamps the summary and finishes the run: at once when not recording, else on the
  /// bag writer's thread once the bag is closed.
  void publishEnd(RunWriter& out, collision_lab::RunSummary& summary, double last_event_time, Reply reply);
  /// Publishes the summary last, counts, draws and logs the run, answers reply. Runs on
  /// the worker (not recording) or on the bag writer's thread.
  void finishRun(const collision_lab::RunSummary& summary, const Reply& reply);
  ServeOutcome reject(collision_lab::Rejected msg, const std::string& run_id);
  /// Tells the sender which run_id input got (`accepted_runs`, the log) and records the
  /// run for ~list_runs. requested: the input's run_id as sent.
  void announce(const collision_lab::InitialConditions& input, const std::string& requested);
  /// <prefix><counter>, the first one claim() takes.
  std::string newRunId(std::string& claim_error);
  /// requested, or the first requested.N (N = 2, 3, ...) that claim() takes.
  std::string claimRunId(const std::string& requested, std::string& claim_error);
  /// Takes run_id for this node's next run. False when this node served it before or,
  /// recording, when claimBag finds its bag taken (by any process sharing bag_directory).
  /// True when taken: recording, its .bag.active file is this node's (claimBag), or, when
  /// claimBag failed for another reason, claim_error says why (the run is served
  /// unrecorded, recording_ok false).
  bool claim(const std::string& run_id, std::string& claim_error);

  /// The status "<node>: lab runs" of /diagnostics: runs accepted and rejected, the last
  /// run's compute time, the recording state and the free space in bag_directory.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// Adds the last recording error and the free space in bag_directory to status.
  void addRecordingStatus(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_;
  LabNodeParams params_;
  ros::Subscriber input_sub_;
  RunTopics topics_;
  ros::Publisher rejected_pub_;
  ros::Publisher accepted_pub_, served_inputs_pub_;
  ServedRuns served_runs_;
  /// Writes the run index (<bag_directory>/runs.sqlite) and answers ~list_runs from it.
  std::unique_ptr<RunIndexRecorder> run_index_;
  /// Publishes /diagnostics; the wall timer forces an update every kDiagnosticsPeriod (the
  /// updater's own rate follows ROS time, which stands still on a replay before its clock).
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer diagnostics_timer_;
  std::unique_ptr<RunObserver> marker_view_;
  std::string run_id_prefix_;
  std::uint64_t run_counter_ = 0;
  std::unordered_set<std::string> used_run_ids_;
  // The worker's messages of a run, refilled for every run: their storage is reused.
  collision_lab::InitialConditions served_input_;
  collision_lab::AcceptedRun accepted_msg_;
  collision_lab::Prediction prediction_msg_;
  EventMessages event_messages_;
  collision_lab::RunSummary summary_msg_;

  // Written by the worker, read by the diagnostics timer.
  std::atomic<std::uint64_t> runs_accepted_{0};
  std::atomic<std::uint64_t> runs_rejected_{0};
  std::atomic<double> last_compute_time_{0.0};
  std::mutex recording_mutex_;
  std::string last_recording_error_;  ///< empty while recording works
  RecentDurations recording_times_;   ///< the worker's hand-over time per run [s]
  /// Writes the bags (null when not recording); on_closed publishes each run's summary.
  std::unique_ptr<RunBagWriter> bags_;

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<Job> inputs_;
  bool stopping_ = false;
  std::thread worker_;

  std::mutex running_mutex_;
  std::string running_run_id_;  ///< empty when no run is in progress
  std::atomic<bool> cancel_{false};
  std::atomic<bool> stopping_run_{false};  ///< set by the destructor: cancel every run

  ros::CallbackQueue service_queue_;
  ros::AsyncSpinner service_spinner_;
  ros::ServiceServer run_scene_srv_, run_preset_srv_;
  ros::CallbackQueue cancel_queue_;
  ros::AsyncSpinner cancel_spinner_;
  ros::ServiceServer cancel_srv_, list_runs_srv_;
};

}  // namespace collision_lab_ros
