#include "collision_lab/ros/lab_node.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>
#include <thread>
#include <utility>

#include <malloc.h>

#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_index_recorder.h"
#include "collision_lab/ros/run_recorder.h"
#include "collision_lab/ros/run_timeline.h"
#include "node_text.h"
#include "run_writer.h"

namespace collision_lab_ros {
namespace {

/// Message stamps double as bag times, which must be >= ros::TIME_MIN: under
/// use_sim_time without a clock, ROS time is 0, so fall back to wall time.
ros::Time stampNow() {
  const ros::Time now = ros::Time::now();
  if (now >= ros::TIME_MIN) return now;
  const ros::WallTime wall = ros::WallTime::now();
  return ros::Time(wall.sec, wall.nsec);
}

/// The reason to refuse input before simulating it (its envelope, service::checkEnvelope,
/// then the scene), if any. The scene's plan (core::planScene: its one validation, model and
/// prediction) goes to `plan` when the envelope holds.
std::optional<collision_lab::Rejected> checkInput(const collision_lab::InitialConditions& input,
                                                  std::size_t max_bodies,
                                                  std::optional<collision_lab::core::ScenePlan>& plan) {
  const std::size_t bodies = std::max({input.masses.size(), input.positions.size(), input.velocities.size()});
  if (const auto refusal = collision_lab::service::checkEnvelope({input.student, input.run_id, input.mode, bodies},
                                                                 max_bodies)) {
    return toRejectedMsg(*refusal);
  }
  plan = collision_lab::core::planScene(toScene(input));
  if (const auto& error = plan->error) return toRejectedMsg(*error);
  return std::nullopt;
}

/// run_id's row in the run index; none when the index does not list it or cannot be read.
std::optional<collision_lab::service::IndexedRun> indexedRun(const RunIndexRecorder& run_index,
                                                             const std::string& run_id) {
  if (!run_index.ok()) return std::nullopt;
  try {
    return run_index.committed()->find(run_id);  // this node's own runs are in run_ids_ too
  } catch (const collision_lab::service::RunIndexError& e) {
    ROS_WARN_STREAM("the run index cannot tell whether run_id '" << run_id << "' was served: " << e.what());
    return std::nullopt;
  }
}

/// At INFO for a lab, at DEBUG with ~log_runs false: at thousands of runs per second an
/// INFO line per run (console, log file and /rosout, another process) costs more than the
/// run itself. Every result is on run_summaries either way, and failures and warnings are
/// still logged as such.
void logRun(const collision_lab::RunSummary& summary, bool at_info) {
  const auto level = at_info ? ::ros::console::levels::Info : ::ros::console::levels::Debug;
  ROS_LOG_STREAM(level, ROSCONSOLE_DEFAULT_NAME,
                 "run " << summary.run_id << ": " << summary.collision_count << " collisions"
                        << (summary.truncated ? " (truncated)" : "") << ", " << predictedText(summary) << ", "
                        << summary.compute_time << " s"
                        << (summary.bag_path.empty() ? std::string() : ", bag " + summary.bag_path));
}

/// The recorded topics the node latches (node_constants.h): written with latching=1.
std::vector<std::string> latchedRecordedTopics(const RunTopics& topics, const std::string& parameters_topic) {
  std::vector<std::string> latched;
  if (kLatchPredictions) latched.push_back(topics.predictions.getTopic());
  if (kLatchRunSummaries) latched.push_back(topics.summaries.getTopic());
  if (kLatchRunParameters) latched.push_back(parameters_topic);
  return latched;
}

/// The core's options of a run in `mode`: what the lane chosen at intake (core::plannedImpacts)
/// and the worker's run both follow. Events are streamed to the visitors, never kept; asking
/// for them makes a closed-form scene simulated too (its events are published), as the CLI
/// does when it shows events. Without simulate_to_cap the model answers over the cap.
collision_lab::core::SceneRunOptions sceneRunOptions(collision_lab::core::RunMode mode, std::uint64_t max_collisions,
                                                     bool simulate_to_cap) {
  namespace core = collision_lab::core;
  core::SceneRunOptions options;
  options.lab.max_collisions = max_collisions;
  options.lab.events = mode == core::RunMode::kFull ? core::EventPolicy::all() : core::EventPolicy::none();
  options.lab.mode = mode;
  options.simulate_to_cap = simulate_to_cap;
  options.keep_events = false;
  return options;
}

/// The settings a run is served with (run_id and stamp are the RunWriter's).
collision_lab::RunParameters runParameters(const LabNodeParams& params, std::uint64_t max_collisions) {
  collision_lab::RunParameters msg;
  msg.package_version = COLLISION_LAB_VERSION;
  msg.node_name = ros::this_node::getName();
  msg.max_collisions = max_collisions;
  msg.max_published_events = params.max_published_events;
  msg.max_bodies = params.max_bodies;
  return msg;
}

}  // namespace

LabNode::LabNode(ros::NodeHandle nh, ros::NodeHandle private_nh, const RunObserverFactory& make_observer)
    : nh_(nh),
      params_(LabNodeParams::load(private_nh)),
      diagnostics_(nh, private_nh),
      service_spinner_(kServiceThreads, &service_queue_),
      cancel_spinner_(1, &cancel_queue_) {
  topics_.predictions = nh_.advertise<collision_lab::Prediction>(
      kPredictionsTopic, kOutputQueueSize, kLatchPredictions);
  topics_.events =
      nh_.advertise<collision_lab::CollisionEvent>(kCollisionEventsTopic, kOutputQueueSize);
  topics_.velocities =
      nh_.advertise<collision_lab::Velocities>(kVelocitiesTopic, kOutputQueueSize);
  topics_.energies =
      nh_.advertise<collision_lab::EnergyTransfer>(kEnergyTransfersTopic, kOutputQueueSize);
  topics_.progress = nh_.advertise<collision_lab::RunProgress>(kRunProgressTopic, kOutputQueueSize);
  topics_.summaries = nh_.advertise<collision_lab::RunSummary>(
      kRunSummariesTopic, kOutputQueueSize, kLatchRunSummaries);
  rejected_pub_ =
      nh_.advertise<collision_lab::Rejected>(kRejectedTopic, kOutputQueueSize, kLatchRejected);
  accepted_pub_ = nh_.advertise<collision_lab::AcceptedRun>(kAcceptedRunsTopic, kOutputQueueSize, kLatchAcceptedRuns);
  served_inputs_pub_ = nh_.advertise<collision_lab::InitialConditions>(kServedInputsTopic, kOutputQueueSize);
  run_queue_pub_ = nh_.advertise<collision_lab::RunQueue>(kRunQueueTopic, kMarkerQueueSize, kLatchRunQueue);
  if (params_.publish_markers && make_observer) marker_view_ = make_observer(nh_, private_nh);

  run_index_ = std::make_unique<RunIndexRecorder>(params_.bag_directory);
  collision_lab::service::RunIdClaims::Ledger ledger;
  ledger.served_before = [this](const std::string& run_id) { return indexedRun(*run_index_, run_id).has_value(); };
  ledger.held = [this](const std::string& run_id) { return heldInIndex(run_id); };
  ledger.take_bag = [this](const std::string& run_id, std::string& error) {
    return !params_.record || claimBag(params_.bag_directory, run_id, error) != BagClaim::kTaken;
  };
  run_ids_ = std::make_unique<collision_lab::service::RunIdClaims>(
      std::string("run_") + utcStamp("%Y%m%d_%H%M%S") + "_", kRunIdsRemembered, std::move(ledger));
  student_quota_ = std::make_unique<collision_lab::service::StudentQuota>(
      static_cast<std::uint64_t>(std::max(0.0, params_.max_student_bag_mb) * 1e6),
      [this](const std::string& student) { return studentBagBytes(student); });
  admission_ = std::make_unique<collision_lab::service::Admission>(
      collision_lab::service::Admission::Options{params_.record, params_.bag_directory, params_.min_free_space_mb,
                                                 params_.max_student_bag_mb},
      student_quota_.get());
  const std::string parameters_topic = nh_.resolveName(kRunParametersTopic);
  const RunBagWriter::Topics bag_topics{nh_.resolveName(kInitialConditionsTopic), topics_.predictions.getTopic(),
                                        topics_.events.getTopic(), topics_.summaries.getTopic(), parameters_topic,
                                        ros::this_node::getName(), latchedRecordedTopics(topics_, parameters_topic)};
  if (params_.record) dropped_bags_ = std::make_unique<RunBagWriter>(params_.bag_directory, bag_topics, kRecordQueueMessages);
  for (std::uint64_t i = 0; i < params_.workers; ++i) {
    auto worker = std::make_unique<Worker>();
    worker->short_only = i < params_.short_lane_workers;
    if (params_.record) worker->bags = std::make_unique<RunBagWriter>(params_.bag_directory, bag_topics, kRecordQueueMessages);
    workers_.push_back(std::move(worker));
  }
  queue_msg_.workers = static_cast<std::uint32_t>(params_.workers);
  queue_msg_.short_lane_workers = static_cast<std::uint32_t>(params_.short_lane_workers);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    publishQueue();  // latched: the empty queue, until the first run
  }

  diagnostics_.setHardwareID("collision_lab");
  diagnostics_.add("lab runs", this, &LabNode::diagnose);
  diagnostics_timer_ = nh_.createWallTimer(ros::WallDuration(kDiagnosticsPeriod),
                                           [this](const ros::WallTimerEvent&) { diagnostics_.force_update(); });

  queue_publisher_ = std::thread(&LabNode::queuePublisherLoop, this);
  for (auto& worker : workers_) worker->thread = std::thread(&LabNode::workerLoop, this, std::ref(*worker));
  watchdog_ = std::thread(&LabNode::watchdogLoop, this);
  input_sub_ = nh_.subscribe(kInitialConditionsTopic, kInputQueueSize,
                             &LabNode::onInitialConditions, this);
  // The services' own queue: a waiting call never holds up the global queue.
  ros::NodeHandle service_nh(private_nh);
  service_nh.setCallbackQueue(&service_queue_);
  run_scene_srv_ = service_nh.advertiseService(kRunSceneService, &LabNode::onRunScene, this);
  run_preset_srv_ = service_nh.advertiseService(kRunPresetService, &LabNode::onRunPreset, this);
  service_spinner_.start();
  // ~cancel has a queue and thread of its own: it is answered even while every service
  // thread waits for a run.
  ros::NodeHandle cancel_nh(private_nh);
  cancel_nh.setCallbackQueue(&cancel_queue_);
  cancel_srv_ = cancel_nh.advertiseService(kCancelService, &LabNode::onCancel, this);
  list_runs_srv_ = cancel_nh.advertiseService(kListRunsService, &LabNode::onListRuns, this);
  cancel_spinner_.start();
  // The runs of dead nodes are ended, or served again, while the node serves (docs/ros.md,
  // "The run index"): reindexing a big bag takes seconds.
  recovery_ = std::thread([this] {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t ended =
        run_index_->recover([this](const RunIndexRecorder::QueuedRun& run) { return intake(run.input, Reply(), run.requested_run_id); });
    if (ended > 0) {
      ROS_INFO_STREAM("recovery: " << ended << " runs of dead nodes ended in "
                      << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
                      << " s, while the node served");
    }
  });
  ROS_INFO_STREAM("collision_lab_node: recording " << (params_.record ? "on" : "off")
                  << ", bags in " << params_.bag_directory << ", max_collisions "
                  << params_.max_collisions << ", max_published_events "
                  << params_.max_published_events << ", max_bodies " << params_.max_bodies
                  << ", presets from " << params_.scenario_file << "; " << params_.workers << " workers ("
                  << params_.short_lane_workers << " for short runs only), max_run_seconds "
                  << params_.max_run_seconds << ", max_bag_bytes " << params_.max_bag_bytes);
}

LabNode::~LabNode() {
  run_index_->stopRecovery();
  recovery_.join();  // the runs it served again are in the queue, and dropped below
  // Cancel first: shutting a service down waits for its calls in progress, and a call
  // waits for its run.
  std::vector<Scheduler::Entry> waiting;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    waiting = scheduler_.drain();
    for (auto& worker : workers_) {
      if (!worker->current.run_id.empty()) stopRun(*worker, StopCause::kShutdown, "the node's shutdown");
    }
    publishQueue();
  }
  wake_.notify_all();
  watchdog_wake_.notify_all();
  for (Scheduler::Entry& entry : waiting) dropWaiting(std::move(entry.job), "the node's shutdown");
  for (auto& worker : workers_) worker->thread.join();
  watchdog_.join();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_publisher_stops_ = true;
  }
  queue_wake_.notify_one();
  queue_publisher_.join();  // the last queue state is out
  // Calls still in progress end once their run's bag is closed (the writers run on).
  input_sub_.shutdown();
  run_scene_srv_.shutdown();
  run_preset_srv_.shutdown();
  for (auto& worker : workers_) worker->bags.reset();  // writes and closes every bag handed over
  dropped_bags_.reset();
  cancel_srv_.shutdown();
  list_runs_srv_.shutdown();
  cancel_spinner_.stop();
  service_spinner_.stop();
}

namespace {
/// A refusal of the admission (the floor, a quota) as the node's Rejected.
collision_lab::Rejected rejectionOf(const collision_lab::service::Refusal& refusal) {
  using Reason = collision_lab::service::Refusal::Reason;
  collision_lab::Rejected rejection;
  const bool disk = refusal.reason == Reason::kDiskSpace;
  rejection.reason = disk ? collision_lab::Rejected::DISK_SPACE : collision_lab::Rejected::STUDENT_QUOTA;
  rejection.reason_name = disk ? "DISK_SPACE" : "STUDENT_QUOTA";
  rejection.field = refusal.field;
  rejection.message = refusal.message;
  return rejection;
}
}  // namespace

std::uint64_t LabNode::studentBagBytes(const std::string& student) const {
  if (!run_index_->ok()) return 0;
  std::uint64_t bytes = 0;
  try {
    for (const auto& row : run_index_->committed()->list(student)) {
      std::error_code ec;
      const auto size = row.bag_path.empty() ? 0 : std::filesystem::file_size(row.bag_path, ec);
      if (!ec) bytes += size;
    }
  } catch (const collision_lab::service::RunIndexError& e) {
    ROS_WARN_STREAM("student '" << student << "': their bags are not counted: " << e.what());
  }
  return bytes;
}

bool LabNode::intake(collision_lab::InitialConditions input, Reply reply, const std::optional<std::string>& served_again) {
  namespace core = collision_lab::core;
  const std::string requested = served_again ? *served_again : input.run_id;
  std::optional<core::ScenePlan> plan;
  if (auto rejection = checkInput(input, params_.max_bodies, plan)) {
    if (served_again) {  // accepted once: not rejected now, ended as interrupted by recovery
      ROS_WARN_STREAM("run " << input.run_id << ": queued when its lab node died, not served again: " << rejection->message);
      return false;
    }
    rejection->student = input.student;
    ServeOutcome outcome = reject(std::move(*rejection), requested);
    if (reply) reply->set_value(std::move(outcome));
    return false;
  }
  const auto refusal = served_again ? std::nullopt : admission_->check(input.student);
  if (refusal) {
    collision_lab::Rejected refused = rejectionOf(*refusal);
    refused.student = input.student;
    ServeOutcome outcome = reject(std::move(refused), requested);
    if (reply) reply->set_value(std::move(outcome));
    return false;
  }
  Job job;
  job.limits = collision_lab::service::limitsOf(
      {params_.max_collisions, params_.max_run_seconds, params_.max_bag_bytes},
      {input.max_collisions, input.max_run_seconds, input.max_bag_bytes});
  const collision_lab::service::Lane lane = collision_lab::service::chooseLane(
      *plan, sceneRunOptions(*toRunMode(input.mode), job.limits.max_collisions, params_.simulate_to_cap), params_.lanes);
  if (plan->prediction && plan->prediction->impact_count) job.predicted_collisions = *plan->prediction->impact_count;
  // The run_id the input asks for: <student>.<run_id> (a run served again: as it first asked).
  const std::string base = collision_lab::service::requestedRunId(input.student, requested);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return false;  // reply's promise breaks: the call answers "shutting down"
    // Claimed here, before the run_id goes out on any message: the run_id a run reports
    // names a bag file this node created.
    if (served_again) {
      if (!run_ids_->claim(input.run_id, job.claim_error)) return false;
      ROS_INFO_STREAM("run " << input.run_id << ": queued when its lab node died; served again");
    } else {
      input.run_id = base.empty() ? run_ids_->fresh(job.claim_error) : run_ids_->claimAsked(base, job.claim_error);
    }
    if (!served_again && !base.empty() && input.run_id != base) {
      ROS_WARN_STREAM("run_id '" << base << "' is taken (its bag exists, or this node served "
                      "it before); serving the run as '" << input.run_id << "'");
    }
    // Taken only when served under another name than the one asked for (<student>.<run_id>).
    job.requested_run_id = input.run_id != base ? requested : std::string();
    const std::string run_id = input.run_id;
    const std::string student = input.student;
    // A run served again keeps its row as it was (queued, its time of acceptance), and is
    // not announced again: an AcceptedRun would answer whoever now asks for that run_id.
    if (!served_again) run_index_->accepted(run_id, student, requested, input);
    job.input = std::move(input);
    job.plan = std::move(*plan);
    job.reply = std::move(reply);
    const std::size_t position = scheduler_.push(Scheduler::Entry{run_id, student, lane, std::move(job)});
    if (!served_again) announce(run_id, student, requested, position, lane);
    publishQueue();
  }
  wake_.notify_all();
  return true;
}

void LabNode::workerLoop(Worker& worker) {
  for (;;) {
    std::optional<Scheduler::Entry> entry;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stopping_ || scheduler_.ready(worker.short_only); });
      if (stopping_) return;
      entry = scheduler_.pop(worker.short_only);
      const Job& job = entry->job;
      worker.cancel = false;
      worker.cause = static_cast<int>(StopCause::kNone);
      CurrentRun& current = worker.current;
      current.run_id = entry->run_id;
      current.student = entry->student;
      current.lane = entry->lane;
      current.predicted_collisions = job.predicted_collisions;
      current.body_count = static_cast<std::uint32_t>(job.plan.scene.size());
      current.stopped_by.clear();
      current.deadline.reset();
      if (job.limits.max_run_seconds > 0) {
        current.deadline = std::chrono::steady_clock::now() +
                           std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(job.limits.max_run_seconds));
      }
      worker.draws = marker_view_ && !view_busy_ && marker_view_->follows(entry->run_id);
      if (worker.draws) view_busy_ = true;
      publishQueue();
    }
    serve(worker, entry->job);
    bool idle = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      worker.current = CurrentRun();
      if (worker.draws) view_busy_ = false;
      worker.draws = false;
      publishQueue();
      idle = scheduler_.size() == 0 &&
             std::all_of(workers_.begin(), workers_.end(), [](const auto& w) { return w->current.run_id.empty(); });
    }
    // An idle lab gives the memory its runs freed back to the system (glibc keeps it
    // otherwise), so that its resident memory is what it holds, not its busiest moment.
    if (idle) malloc_trim(0);
  }
}

void LabNode::watchdogLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    watchdog_wake_.wait_for(lock, std::chrono::duration<double>(kWatchdogPeriod));
    const auto now = std::chrono::steady_clock::now();
    for (auto& worker : workers_) {
      const CurrentRun& current = worker->current;
      if (!current.run_id.empty() && current.deadline && now >= *current.deadline) {
        stopRun(*worker, StopCause::kTimeLimit, std::string());
      }
    }
  }
}

void LabNode::stopRun(Worker& worker, StopCause cause, const std::string& by) {
  int none = static_cast<int>(StopCause::kNone);
  if (worker.cause.compare_exchange_strong(none, static_cast<int>(cause))) worker.current.stopped_by = by;
  worker.cancel = true;  // the run stops within 1024 impacts, at its last certified one
}

void LabNode::publishQueue() {
  queue_changed_ = true;
  queue_wake_.notify_one();
}

void LabNode::queuePublisherLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    queue_wake_.wait(lock, [this] { return queue_changed_ || queue_publisher_stops_; });
    if (!queue_changed_) return;
    queue_changed_ = false;
    collision_lab::RunQueue msg = buildQueue();
    lock.unlock();
    run_queue_pub_.publish(msg);
    lock.lock();
    // At most kRunQueuePeriod apart: a burst of runs is one message, not one per change.
    queue_wake_.wait_for(lock, std::chrono::duration<double>(kRunQueuePeriod), [this] { return queue_publisher_stops_; });
  }
}

collision_lab::RunQueue LabNode::buildQueue() const {
  collision_lab::RunQueue msg = queue_msg_;
  msg.header.stamp = stampNow();
  msg.runs.clear();
  collision_lab::QueuedRun run;
  for (const auto& worker : workers_) {
    const CurrentRun& current = worker->current;
    if (current.run_id.empty()) continue;
    run.run_id = current.run_id;
    run.student = current.student;
    run.lane = collision_lab::service::laneName(current.lane);
    run.running = true;
    run.predicted_collisions = current.predicted_collisions;
    run.body_count = current.body_count;
    msg.runs.push_back(run);
  }
  for (const Scheduler::Entry* entry : scheduler_.order(kRunQueueListed)) {
    run.run_id = entry->run_id;
    run.student = entry->student;
    run.lane = collision_lab::service::laneName(entry->lane);
    run.running = false;
    run.predicted_collisions = entry->job.predicted_collisions;
    run.body_count = static_cast<std::uint32_t>(entry->job.plan.scene.size());
    msg.runs.push_back(run);
  }
  return msg;
}

bool LabNode::heldInIndex(const std::string& run_id) {
  using collision_lab::service::RunState;
  const auto run = indexedRun(*run_index_, run_id);
  if (!run) return false;
  if (run->state == RunState::kQueued || run->state == RunState::kRunning) return true;
  std::error_code ec;
  return !run->bag_path.empty() && std::filesystem::exists(run->bag_path, ec);
}

void LabNode::announce(const std::string& run_id, const std::string& student, const std::string& requested,
                       std::size_t queue_position, collision_lab::service::Lane lane) {
  collision_lab::AcceptedRun accepted;
  accepted.header.stamp = stampNow();
  accepted.run_id = run_id;
  accepted.requested_run_id = requested;
  accepted.student = student;
  accepted.queue_position = static_cast<std::uint32_t>(queue_position);
  accepted.lane = collision_lab::service::laneName(lane);
  accepted_pub_.publish(accepted);
  served_runs_.accepted(accepted);
  // As logRun: at INFO for a lab, at DEBUG with ~log_runs false.
  const auto level = params_.log_runs ? ::ros::console::levels::Info : ::ros::console::levels::Debug;
  ROS_LOG_STREAM(level, ROSCONSOLE_DEFAULT_NAME,
                 "accepted run " << run_id << (student.empty() ? std::string() : " of student '" + student + "'")
                                 << (requested.empty() || requested == run_id ? std::string() : " (asked for '" + requested + "')")
                                 << ", " << accepted.lane << " lane, " << queue_position << " runs ahead");
}

ServeOutcome LabNode::reject(collision_lab::Rejected msg, const std::string& run_id) {
  msg.header.stamp = stampNow();
  msg.run_id = run_id;
  ++runs_rejected_;
  ROS_WARN_STREAM("rejected run '" << run_id << "'"
                  << (msg.student.empty() ? std::string() : " of student '" + msg.student + "'") << ": "
                  << msg.reason_name << " in field " << msg.field << ": " << msg.message);
  rejected_pub_.publish(msg);
  run_index_->rejected(msg);
  if (marker_view_) marker_view_->onRejected(msg);
  return ServeOutcome{std::nullopt, msg};
}

void LabNode::serve(Worker& worker, Job& job) {
  const ros::Time start = stampNow();
  RunWriter out(job.input.run_id, RunTimeline(start, chooseTimelineScale(firstContactTime(job.plan.scene))),
                worker.bags.get(), job.claim_error,
                RunWriter::RecordLimits{job.limits.max_bag_bytes, admission_.get(), student_quota_.get(),
                                        job.input.student},
                [this, &worker](RunWriter::Limit limit) {
                  const StopCause cause = limit == RunWriter::Limit::kBagBytes    ? StopCause::kBagLimit
                                          : limit == RunWriter::Limit::kFreeSpace ? StopCause::kDiskSpace
                                                                                  : StopCause::kStudentQuota;
                  std::lock_guard<std::mutex> lock(mutex_);
                  stopRun(worker, cause, std::string());
                });
  job.input.header.stamp = start;
  RunSoFar progress;
  std::string what;
  try {
    run(worker, job, out, progress);
    return;
  } catch (const std::exception& e) {
    what = e.what();
  } catch (...) {
    what = "an exception of unknown type";
  }
  if (out.finished()) {
    ROS_ERROR_STREAM("run " << job.input.run_id << ": failed after its summary was handed over: " << what);
    return;
  }
  try {
    failRun(worker, job, out, progress, what);
  } catch (...) {
    ROS_ERROR_STREAM("run " << job.input.run_id << ": the worker failed (" << what
                     << ") and could not report it; the node goes on");
  }
}

void LabNode::run(Worker& worker, Job& job, RunWriter& out, RunSoFar& progress) {
  namespace core = collision_lab::core;
  collision_lab::InitialConditions& input = job.input;
  const core::ScenePlan& plan = job.plan;
  const core::RunMode mode = *toRunMode(input.mode);
  run_index_->started(input.run_id);
  publishStart(worker, out, input, plan);  // the prediction goes out before the simulation starts

  core::SceneRunOptions options = sceneRunOptions(mode, job.limits.max_collisions, params_.simulate_to_cap);
  collision_lab::RunParameters parameters = runParameters(params_, options.lab.max_collisions);
  parameters.max_run_seconds = job.limits.max_run_seconds;
  parameters.max_bag_bytes = job.limits.max_bag_bytes;
  out.record(std::move(parameters));
  options.cancel = &worker.cancel;
  const bool fail = !params_.fail_runs_of_student.empty() && input.student == params_.fail_runs_of_student;
  const PublishLimits limits{params_.max_published_events, params_.progress_period, params_.progress_every_events};
  EventStream events(topics_, out, worker.draws ? marker_view_.get() : nullptr, limits, plan.scene,
                     worker.event_messages, progress, fail);
  core::SceneVisitors visitors;
  visitors.impact = [&events](const core::ImpactRecord& r) { events(r); };
  visitors.collapse = [&events](const core::Collapse& c) { events(c); };  // in order, between the impacts
  const core::SceneRunResult result = core::runScene(plan, options, visitors);

  collision_lab::RunSummary& summary = worker.summary_msg;
  fillRunSummaryMsg(result, plan.scene.size(), mode, summary);
  summary.published_events = progress.published;
  summary.events_not_published = events.cut();
  summary.requested_run_id = job.requested_run_id;
  summary.student = input.student;
  applyStopCause(worker, job, summary);
  publishEnd(out, summary, progress.last_time, std::move(job.reply), worker.draws);
}

void LabNode::applyStopCause(Worker& worker, const Job& job, collision_lab::RunSummary& summary) {
  const auto cause = static_cast<StopCause>(worker.cause.load());
  collision_lab::service::StopContext context;
  if (cause == StopCause::kCancel) {  // the node's mutex only for a cancelled run
    std::lock_guard<std::mutex> lock(mutex_);
    context.stopped_by = worker.current.stopped_by;
  }
  context.student = job.input.student;
  context.asked_max_collisions = job.input.max_collisions;
  context.min_free_space_mb = params_.min_free_space_mb;
  context.max_student_bag_mb = params_.max_student_bag_mb;
  const auto stop =
      collision_lab::service::serviceStop(cause, job.limits,
                                          {summary.stop_reason, summary.truncation_reason, summary.collision_count},
                                          context);
  if (!stop) return;
  summary.stop_reason = stop->stop_reason;
  summary.cancelled = stop->cancelled;
  summary.truncated = true;
  summary.truncation_reason = stop->truncation_reason;
}

namespace {

/// The summary of a run that has not computed (its plan's model and prediction only).
void unsimulatedSummary(const collision_lab::core::ScenePlan& plan, const collision_lab::InitialConditions& input,
                        collision_lab::RunSummary& summary) {
  collision_lab::core::SceneRunResult result;
  result.model = plan.model;
  result.prediction = plan.prediction;
  fillRunSummaryMsg(result, plan.scene.size(), *toRunMode(input.mode), summary);
  summary.student = input.student;
}

}  // namespace

void LabNode::failRun(Worker& worker, Job& job, RunWriter& out, const RunSoFar& progress, const std::string& what) {
  ROS_ERROR_STREAM("run " << job.input.run_id << ": the worker failed after " << progress.collisions
                   << " collisions: " << what << "; the run ends WORKER_ERROR and the node goes on");
  collision_lab::RunSummary& summary = worker.summary_msg;
  unsimulatedSummary(job.plan, job.input, summary);
  summary.simulated = true;
  summary.collision_count = progress.collisions;
  summary.published_events = progress.published;
  summary.events_not_published = progress.published < progress.collisions;
  summary.truncated = true;
  summary.stop_reason = "WORKER_ERROR";
  summary.truncation_reason = "the worker failed after " + std::to_string(progress.collisions) +
                              " collisions: " + what + "; the bag holds the collisions before";
  summary.requested_run_id = job.requested_run_id;
  publishEnd(out, summary, progress.last_time, std::move(job.reply), worker.draws);
}

void LabNode::dropWaiting(Job job, const std::string& by) {
  const ros::Time start = stampNow();
  RunWriter out(job.input.run_id, RunTimeline(start, chooseTimelineScale(firstContactTime(job.plan.scene))),
                dropped_bags_.get(), job.claim_error, RunWriter::RecordLimits{}, {});
  job.input.header.stamp = start;
  out.record(job.input);
  collision_lab::RunParameters parameters = runParameters(params_, job.limits.max_collisions);
  parameters.max_run_seconds = job.limits.max_run_seconds;
  parameters.max_bag_bytes = job.limits.max_bag_bytes;
  out.record(std::move(parameters));
  // As every run: its prediction, then its summary; every bag holds parameters, input,
  // prediction and summary.
  collision_lab::Prediction prediction;
  fillPredictionMsg(job.plan, prediction);
  prediction.timeline_scale = out.timeline().scale();
  out.publish(topics_.predictions, prediction, 0.0);
  out.record(prediction);
  collision_lab::RunSummary summary;
  unsimulatedSummary(job.plan, job.input, summary);
  summary.collision_count = 0;
  summary.cancelled = true;
  summary.truncated = true;
  summary.stop_reason = "CANCELLED";
  summary.truncation_reason = "cancelled by " + by + " before it started";
  summary.requested_run_id = job.requested_run_id;
  publishEnd(out, summary, 0.0, std::move(job.reply), false);
}

void LabNode::publishStart(Worker& worker, RunWriter& out, const collision_lab::InitialConditions& input,
                           const collision_lab::core::ScenePlan& plan) {
  out.record(input);
  served_inputs_pub_.publish(input);
  RunObserver* view = worker.draws ? marker_view_.get() : nullptr;
  if (view) view->onInitialConditions(input);
  collision_lab::Prediction& prediction = worker.prediction_msg;
  fillPredictionMsg(plan, prediction);
  prediction.timeline_scale = out.timeline().scale();
  out.publish(topics_.predictions, prediction, 0.0);
  out.record(prediction);
  if (view) view->onPrediction(prediction);
}

void LabNode::publishEnd(RunWriter& out, collision_lab::RunSummary& summary, double last_event_time, Reply reply,
                         bool draws) {
  summary.timeline_scale = out.timeline().scale();
  out.stamp(summary, last_event_time);
  summary.timeline_saturated = out.timeline().saturated();
  if (summary.timeline_saturated) {
    ROS_WARN_STREAM("run " << summary.run_id << ": collisions after " << RunTimeline::kMaxOffset
                    << " bag s are stamped at that limit (timeline_scale "
                    << summary.timeline_scale << ")");
  }
  if (!out.recording()) {
    out.markFinished();
    finishRun(summary, reply, draws);
    return;
  }
  out.finish(summary, [this, reply, draws, counted = out.quotaBytes()](collision_lab::RunSummary& closed) {
    std::error_code ec;
    const auto bag_bytes = std::filesystem::file_size(closed.recording_ok ? closed.bag_path : closed.bag_path + ".active", ec);
    student_quota_->ended(closed.student, counted, ec ? 0 : bag_bytes);
    finishRun(closed, reply, draws);
  });
  recording_times_.add(out.recordingSeconds());
}

void LabNode::finishRun(const collision_lab::RunSummary& summary, const Reply& reply, bool draws) {
  if (params_.record) {
    std::lock_guard<std::mutex> lock(recording_mutex_);
    last_recording_error_ = summary.recording_error;
    if (!summary.recording_ok) ROS_ERROR_STREAM("run " << summary.run_id << ": recording failed: " << summary.recording_error);
  }
  // The summary goes out last, after everything it counts (and its bag is closed).
  served_runs_.finished(summary);  // before the summary: whoever saw it finds the run finished
  run_index_->finished(summary);
  topics_.summaries.publish(summary);
  ++runs_accepted_;
  last_compute_time_ = summary.compute_time;
  if (draws && marker_view_) marker_view_->onRunSummary(summary);
  logRun(summary, params_.log_runs);
  if (reply) reply->set_value(ServeOutcome{summary, {}});
}

}  // namespace collision_lab_ros
