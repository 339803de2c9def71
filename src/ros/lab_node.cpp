#include "collision_lab/ros/lab_node.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>
#include <utility>

#include <malloc.h>

#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_index_recorder.h"
#include "collision_lab/ros/run_recorder.h"
#include "lab_node_shared.h"

namespace collision_lab_ros {
namespace {

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

/// The recorded topics the node latches (node_constants.h): written with latching=1.
std::vector<std::string> latchedRecordedTopics(const RunTopics& topics, const std::string& parameters_topic) {
  std::vector<std::string> latched;
  if (kLatchPredictions) latched.push_back(topics.predictions.getTopic());
  if (kLatchRunSummaries) latched.push_back(topics.summaries.getTopic());
  if (kLatchRunParameters) latched.push_back(parameters_topic);
  return latched;
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
  ledger.served_before = [this](const std::string& run_id) { return run_index_->find(run_id).has_value(); };
  ledger.held = [this](const std::string& run_id) { return run_index_->holds(run_id); };
  ledger.take_bag = [this](const std::string& run_id, std::string& error) {
    return !params_.record || claimBag(params_.bag_directory, run_id, error) != BagClaim::kTaken;
  };
  run_ids_ = std::make_unique<collision_lab::service::RunIdClaims>(
      std::string("run_") + utcStamp("%Y%m%d_%H%M%S") + "_", kRunIdsRemembered, std::move(ledger));
  student_quota_ = std::make_unique<collision_lab::service::StudentQuota>(
      static_cast<std::uint64_t>(std::max(0.0, params_.max_student_bag_mb) * 1e6),
      [this](const std::string& student) { return run_index_->studentBagBytes(student); });
  admission_ = std::make_unique<collision_lab::service::Admission>(
      collision_lab::service::Admission::Options{params_.record, params_.bag_directory, params_.min_free_space_mb,
                                                 params_.max_student_bag_mb},
      student_quota_.get());
  const std::string parameters_topic = nh_.resolveName(kRunParametersTopic);
  const RunBagWriter::Topics bag_topics{nh_.resolveName(kInitialConditionsTopic), topics_.predictions.getTopic(),
                                        topics_.events.getTopic(), topics_.summaries.getTopic(), parameters_topic,
                                        ros::this_node::getName(), latchedRecordedTopics(topics_, parameters_topic)};
  if (params_.record) dropped_bags_ = std::make_unique<RunBagWriter>(params_.bag_directory, bag_topics, kRecordQueueMessages);
  pool_ = std::make_unique<Pool>(Pool::Options{params_.workers, params_.short_lane_workers, kWatchdogPeriod,
                                                kRunQueuePeriod, kRunQueueListed});
  if (params_.record) {
    for (auto& worker : pool_->workers()) {
      worker->slot.bags = std::make_unique<RunBagWriter>(params_.bag_directory, bag_topics, kRecordQueueMessages);
    }
  }
  queue_msg_.workers = static_cast<std::uint32_t>(params_.workers);
  queue_msg_.short_lane_workers = static_cast<std::uint32_t>(params_.short_lane_workers);

  diagnostics_.setHardwareID("collision_lab");
  diagnostics_.add("lab runs", this, &LabNode::diagnose);
  diagnostics_timer_ = nh_.createWallTimer(ros::WallDuration(kDiagnosticsPeriod),
                                           [this](const ros::WallTimerEvent&) { diagnostics_.force_update(); });

  Pool::Hooks hooks;
  hooks.facts = [](const Job& job) {
    return collision_lab::service::RunFacts{job.predicted_collisions, static_cast<std::uint32_t>(job.plan.scene.size()),
                                            job.limits.max_run_seconds};
  };
  hooks.serve = [this](Worker& worker, Pool::Entry& entry) { serve(worker, entry.job); };
  hooks.taken = [this](Worker& worker, const Pool::Entry& entry) {
    worker.slot.draws = marker_view_ && !view_busy_ && marker_view_->follows(entry.run_id);
    if (worker.slot.draws) view_busy_ = true;
  };
  hooks.ended = [this](Worker& worker) {
    if (worker.slot.draws) view_busy_ = false;
    worker.slot.draws = false;
  };
  // An idle lab gives the memory its runs freed back to the system (glibc keeps it
  // otherwise), so that its resident memory is what it holds, not its busiest moment.
  hooks.idle = [] { malloc_trim(0); };
  hooks.changed = [this](const std::vector<collision_lab::service::QueuedRunState>& runs) { publishQueue(runs); };
  pool_->start(std::move(hooks));  // latched on run_queue: the empty queue, until the first run
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
  for (Pool::Entry& entry : pool_->stop("the node's shutdown")) dropWaiting(std::move(entry.job), "the node's shutdown");
  pool_->join();  // the runs have ended; the last queue state is out
  // Calls still in progress end once their run's bag is closed (the writers run on).
  input_sub_.shutdown();
  run_scene_srv_.shutdown();
  run_preset_srv_.shutdown();
  for (auto& worker : pool_->workers()) worker->slot.bags.reset();  // writes and closes every bag handed over
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
    const auto lock = pool_->lock();
    if (pool_->stopping()) return false;  // reply's promise breaks: the call answers "shutting down"
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
    const std::size_t position = pool_->push(Pool::Entry{run_id, student, lane, std::move(job)});
    if (!served_again) announce(run_id, student, requested, position, lane);
  }
  return true;
}

void LabNode::publishQueue(const std::vector<collision_lab::service::QueuedRunState>& runs) {
  collision_lab::RunQueue msg = queue_msg_;
  msg.header.stamp = stampNow();
  collision_lab::QueuedRun run;
  for (const auto& state : runs) {
    run.run_id = state.run_id;
    run.student = state.student;
    run.lane = collision_lab::service::laneName(state.lane);
    run.running = state.running;
    run.predicted_collisions = state.predicted_collisions;
    run.body_count = state.body_count;
    msg.runs.push_back(run);
  }
  run_queue_pub_.publish(msg);
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

}  // namespace collision_lab_ros
