// collision_lab_node: serves InitialConditions of any size with the core's runScene (the
// CLI's entry point, so both give the same answers), publishes every output, records one
// bag per run and feeds the marker view. Inputs come from the topic `initial_conditions`
// and from the services ~run_scene and ~run_preset; all three take the same path (served,
// published, recorded, drawn). ~cancel stops the run in progress. Each accepted input is
// announced on `accepted_runs` with the run_id it got; ~list_runs lists the runs of the
// run index (<bag_directory>/runs.sqlite: every node process's), which the node writes
// (RunIndexRecorder). At start the node ends the runs of dead nodes in it (recover()).
//
// Threading contract (the workers' own: service/worker_pool.h):
// - Intake at arrival: the thread that receives an input (the topic callback on the global
//   queue, spun by main, or a service thread) checks it (checkInput, planScene), claims its
//   run_id and bag, pushes it to the pool and publishes its AcceptedRun (with its
//   queue_position and lane) at once, all under the pool's lock, so AcceptedRuns go out in
//   the order of the queue. A rejection is answered on that thread too.
// - ~workers workers (service::WorkerPool) serve the runs, of which the first
//   ~short_lane_workers take only short runs. Each worker has its own message buffers and
//   bag writer thread (WorkerSlot; RunBagWriter: a run's batches stay contiguous), so
//   runs of different workers interleave on the topics (every message names its run_id);
//   a run's own messages keep the order predictions, (collision_events, velocities,
//   energy_transfers) per collision, run_summaries. ros::Publisher is thread-safe.
// - The pool's lock guards its queue and running runs, the run_id claims and the marker
//   view's owner. The marker view (a RunObserver) draws one run at a time: a run draws
//   when it starts while no other run is drawn and the view follows it; other runs are
//   not drawn live. Its summary and rejections reach it from other threads (it is
//   thread-safe). run_queue is published on the pool's notice thread.
// - The services run on their own callback queue, spun by kServiceThreads threads. A call
//   takes its input in like the topic does and blocks only its own service thread until
//   the worker hands back the outcome (a promise). Further concurrent calls wait in roscpp.
// - ~cancel and ~list_runs run on a callback queue and thread of their own. ~cancel takes
//   a waiting run out of the scheduler (it is answered with a CANCELLED summary and its
//   bag closed on that thread, through the node's own bag writer) or stops a running one:
//   the pool sets its worker's cancel flag, which the core polls, with a cause. The
//   pool's watchdog does the same with the cause kTimeLimit at a run's deadline, and a
//   run's RunWriter with kBagLimit when its recorded bytes pass its limit, kDiskSpace
//   when the bag directory's free space falls under ~min_free_space_mb, or kStudentQuota
//   when its student's bags pass ~max_student_bag_mb.
// - Each worker catches every exception around its run: the run ends WORKER_ERROR, its
//   summary published and its bag closed, and the worker serves the next run.
// - With recording on, the worker hands each run's recorded messages over to its bag
//   writer thread (blocking only while kRecordQueueMessages messages wait). The writer
//   closes the run's bag, then publishes its summary and answers its service call
//   (finishRun), so a run's summary may follow the next run's first messages; every
//   summary still follows its own run's messages and its bag is closed when it goes out.
// - The diagnostics timer (global queue) reads counters through atomics and mutexes.
// - Destruction: no input is taken in any more; every waiting run is cancelled (CANCELLED
//   summary, bag closed, its call answered) and every running one stopped (cause
//   kShutdown), the workers and the watchdog are joined, then the subscription and the
//   services stop, the bag writers write and close every bag handed over (publishing their
//   summaries), and the service threads are stopped. main destroys the node on SIGINT
//   before ros::shutdown(), which would otherwise first wait for every service call.
#pragma once

#include <atomic>
#include <cstdint>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
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
#include "collision_lab/RunProgress.h"
#include "collision_lab/RunScene.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/RunQueue.h"
#include "collision_lab/ros/lab_node_params.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/run_observer.h"
#include "collision_lab/ros/served_runs.h"
#include "collision_lab/service/admission.h"
#include "collision_lab/service/run_budget.h"
#include "collision_lab/service/run_ids.h"
#include "collision_lab/service/student_quota.h"
#include "collision_lab/service/worker_pool.h"

namespace collision_lab_ros {

/// The publishers of a run's outputs, in the order a run uses them.
struct RunTopics {
  ros::Publisher predictions, events, velocities, energies, summaries, progress;
};

/// The per-collision messages the worker refills for every collision (run_writer.h's
/// EventStream), kept by the node so that their storage is reused from run to run.
struct EventMessages {
  collision_lab::CollisionEvent event;
  collision_lab::Velocities velocities;
  collision_lab::EnergyTransfer energy;
  collision_lab::RunProgress progress;
};

/// What a run has computed so far, kept outside its EventStream (run_writer.h) so that a
/// run that throws can still report it.
struct RunSoFar {
  std::uint64_t collisions = 0;  ///< [1] events seen
  std::uint64_t published = 0;   ///< [1] events published
  double last_time = 0.0;        ///< simulated time of the last collision [s]
};

/// Stamps, publishes and records the messages of one run (src/ros/run_writer.h).
class RunWriter;
class RunBagWriter;
class RunIndexRecorder;

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
  /// Cancels the waiting runs and stops the running ones (closing their bags).
  ~LabNode();

 private:
  /// Where a service call waits for its outcome; null for topic inputs.
  using Reply = std::shared_ptr<std::promise<ServeOutcome>>;
  using StopCause = collision_lab::service::StopCause;
  using RunLimits = collision_lab::service::RunLimits;
  /// An accepted run, from intake to its worker.
  struct Job {
    collision_lab::InitialConditions input;  ///< run_id assigned
    collision_lab::core::ScenePlan plan;
    std::string requested_run_id;  ///< RunSummary.requested_run_id: the run_id asked for when not served as it
    std::string claim_error;       ///< RunBagBatch::claim_error
    RunLimits limits;
    std::uint64_t predicted_collisions = 0;  ///< the model's count; 0: none
    Reply reply;
  };
  /// A worker's own state: its bag writer and its messages, refilled for every run (their
  /// storage is reused).
  struct WorkerSlot {
    std::unique_ptr<RunBagWriter> bags;  ///< null when not recording
    collision_lab::Prediction prediction_msg;
    EventMessages event_messages;
    collision_lab::RunSummary summary_msg;
    bool draws = false;  ///< the current run feeds the marker view (the pool's lock)
  };
  using Pool = collision_lab::service::WorkerPool<Job, WorkerSlot>;
  using Worker = Pool::Worker;

  void onInitialConditions(const collision_lab::InitialConditions::ConstPtr& msg);
  bool onRunScene(collision_lab::RunScene::Request& request,
                  collision_lab::RunScene::Response& response);
  bool onRunPreset(collision_lab::RunPreset::Request& request,
                   collision_lab::RunPreset::Response& response);
  bool onCancel(collision_lab::Cancel::Request& request, collision_lab::Cancel::Response& response);
  bool onListRuns(collision_lab::ListRuns::Request& request, collision_lab::ListRuns::Response& response);
  /// Takes input in and waits for its outcome; empty when the node stops before serving it.
  std::optional<ServeOutcome> serveAndWait(const collision_lab::InitialConditions& input);
  /// Intake: checks input, then rejects it (reply answered) or claims its run_id, queues
  /// it and announces it. On the receiving thread. served_again: the input is a queued run
  /// of a dead node (RunIndexRecorder::recover), served under its own run_id (input.run_id)
  /// and the run_id it asked for (*served_again); false when that run_id cannot be claimed,
  /// or the input is rejected now.
  bool intake(collision_lab::InitialConditions input, Reply reply,
              const std::optional<std::string>& served_again = std::nullopt);
  /// Publishes run_queue (latched) with the queue's state (the pool's notice thread).
  void publishQueue(const std::vector<collision_lab::service::QueuedRunState>& runs);

  // ---- A worker's (each on its own Worker) ----
  /// Runs job, catching every exception (WORKER_ERROR).
  void serve(Worker& worker, Job& job);
  /// Publishes, records and draws one accepted run.
  void run(Worker& worker, Job& job, RunWriter& out, RunSoFar& progress);
  /// Ends a run that threw `what` before its summary was handed over: WORKER_ERROR.
  void failRun(Worker& worker, Job& job, RunWriter& out, const RunSoFar& progress, const std::string& what);
  /// The stop reason of a service limit or of ~cancel (service::serviceStop), put into summary.
  void applyStopCause(Worker& worker, const Job& job, collision_lab::RunSummary& summary);
  /// Ends a run that never started (cancelled while waiting, or at shutdown): a CANCELLED,
  /// not simulated summary, its bag written with its input and closed. Any thread.
  void dropWaiting(Job job, const std::string& by);
  /// Records the input (stamped at the run's start) and publishes the prediction.
  void publishStart(Worker& worker, RunWriter& out, const collision_lab::InitialConditions& input,
                    const collision_lab::core::ScenePlan& plan);
  /// Stamps the summary and finishes the run: at once when not recording, else on the
  /// bag writer's thread once the bag is closed.
  void publishEnd(RunWriter& out, collision_lab::RunSummary& summary, double last_event_time, Reply reply,
                  bool draws);
  /// Publishes the summary last, counts, draws and logs the run, answers reply. Runs on
  /// the worker (not recording) or on the bag writer's thread.
  void finishRun(const collision_lab::RunSummary& summary, const Reply& reply, bool draws);
  ServeOutcome reject(collision_lab::Rejected msg, const std::string& run_id);
  /// Tells the sender which run_id input got, its place in the queue and lane
  /// (`accepted_runs`, the log) and records the run for ~list_runs. The pool's lock held.
  void announce(const std::string& run_id, const std::string& student, const std::string& requested,
                std::size_t queue_position, collision_lab::service::Lane lane);

  /// The status "<node>: lab runs" of /diagnostics: runs accepted and rejected, the queue,
  /// the last run's compute time, the recording state and the free space in bag_directory.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// Adds the last recording error and the free space in bag_directory to status.
  void addRecordingStatus(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_;
  LabNodeParams params_;
  ros::Subscriber input_sub_;
  RunTopics topics_;
  ros::Publisher rejected_pub_;
  ros::Publisher accepted_pub_, served_inputs_pub_, run_queue_pub_;
  ServedRuns served_runs_;
  /// Writes the run index (<bag_directory>/runs.sqlite) and answers ~list_runs from it.
  std::unique_ptr<RunIndexRecorder> run_index_;
  /// Each named student's bytes of bags (~max_student_bag_mb); made before recovery serves runs.
  std::unique_ptr<collision_lab::service::StudentQuota> student_quota_;
  /// Whether a new run is taken now, whether a recording run goes on: the bag folder's
  /// floor (~min_free_space_mb) and student_quota_ (DISK_SPACE, STUDENT_QUOTA).
  std::unique_ptr<collision_lab::service::Admission> admission_;
  /// Publishes /diagnostics; the wall timer forces an update every kDiagnosticsPeriod (the
  /// updater's own rate follows ROS time, which stands still on a replay before its clock).
  diagnostic_updater::Updater diagnostics_;
  ros::WallTimer diagnostics_timer_;
  std::unique_ptr<RunObserver> marker_view_;

  // Counters, read by the diagnostics timer.
  std::atomic<std::uint64_t> runs_accepted_{0};
  std::atomic<std::uint64_t> runs_rejected_{0};
  std::atomic<double> last_compute_time_{0.0};
  std::mutex recording_mutex_;
  std::string last_recording_error_;  ///< empty while recording works
  RecentDurations recording_times_;   ///< the workers' hand-over time per run [s]
  /// Writes the bags of runs that never started (dropWaiting); null when not recording.
  std::unique_ptr<RunBagWriter> dropped_bags_;

  /// The run_ids this node serves under: remembered, and held in the index and the bag
  /// folder (its Ledger); recording, a claimed run_id's .bag.active file is this node's.
  std::unique_ptr<collision_lab::service::RunIdClaims> run_ids_;
  bool view_busy_ = false;  ///< a running run feeds the marker view
  collision_lab::RunQueue queue_msg_;  ///< run_queue's constant fields (its workers)
  std::thread recovery_;  ///< RunIndexRecorder::recover, at the start

  ros::CallbackQueue service_queue_;
  ros::AsyncSpinner service_spinner_;
  ros::ServiceServer run_scene_srv_, run_preset_srv_;
  ros::CallbackQueue cancel_queue_;
  ros::AsyncSpinner cancel_spinner_;
  ros::ServiceServer cancel_srv_, list_runs_srv_;

  /// The scheduler, the workers, the watchdog and the queue's notices. Its lock guards
  /// run_ids_ and view_busy_ too. Last: its threads use the members above, so it goes first.
  std::unique_ptr<Pool> pool_;
};

}  // namespace collision_lab_ros
