#include "collision_lab/ros/lab_node.h"

#include <sys/statvfs.h>

#include <cstdlib>
#include <ctime>
#include <optional>
#include <utility>

#include <diagnostic_msgs/DiagnosticArray.h>

#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/node_constants.h"
#include "collision_lab/ros/run_recorder.h"

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

std::string defaultBagDirectory() {
  const char* ros_home = std::getenv("ROS_HOME");
  const std::string base = ros_home && *ros_home ? ros_home : expandUser("~/.ros");
  return base + "/" + kDefaultBagSubdirectory;
}

std::uint64_t getUint64(const ros::NodeHandle& nh, const std::string& name,
                        std::uint64_t fallback) {
  // XmlRpc integers are 32-bit; large values may come as doubles.
  double value = static_cast<double>(fallback);
  int as_int = 0;
  if (nh.getParam(name, as_int)) {
    value = as_int;
  } else {
    nh.getParam(name, value);
  }
  if (!(value >= 0)) {
    ROS_WARN_STREAM("~" << name << " = " << value << " is negative; using " << fallback);
    return fallback;
  }
  return static_cast<std::uint64_t>(value);
}

}  // namespace

LabNodeParams LabNodeParams::load(const ros::NodeHandle& private_nh) {
  LabNodeParams params;
  private_nh.param("record", params.record, true);
  private_nh.param("bag_directory", params.bag_directory, defaultBagDirectory());
  params.bag_directory = expandUser(params.bag_directory);
  params.max_collisions = getUint64(private_nh, "max_collisions", kDefaultMaxCollisions);
  params.max_published_events =
      getUint64(private_nh, "max_published_events", kDefaultMaxPublishedEvents);
  private_nh.param("publish_markers", params.publish_markers, true);
  private_nh.param("min_free_space_mb", params.min_free_space_mb, kDefaultMinFreeSpaceMb);
  return params;
}

std::string runIdProblem(const std::string& run_id) {
  if (run_id.size() > 200) return "is longer than 200 characters";
  if (run_id.empty() || run_id[0] == '.') return "must not be empty or start with '.'";
  for (char c : run_id) {
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                      (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!safe) return "may contain only letters, digits, '_', '-' and '.'";
  }
  return {};
}

LabNode::LabNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), params_(LabNodeParams::load(private_nh)) {
  predictions_pub_ =
      nh_.advertise<collision_lab::Prediction>(kPredictionsTopic, kOutputQueueSize);
  events_pub_ =
      nh_.advertise<collision_lab::CollisionEvent>(kCollisionEventsTopic, kOutputQueueSize);
  velocities_pub_ = nh_.advertise<collision_lab::Velocities>(kVelocitiesTopic, kOutputQueueSize);
  energy_pub_ =
      nh_.advertise<collision_lab::EnergyTransfer>(kEnergyTransfersTopic, kOutputQueueSize);
  summaries_pub_ = nh_.advertise<collision_lab::RunSummary>(kRunSummariesTopic, kOutputQueueSize);
  rejected_pub_ = nh_.advertise<collision_lab::Rejected>(kRejectedTopic, kOutputQueueSize);
  if (params_.publish_markers) {
    marker_view_ = std::make_unique<MarkerView>(nh_, MarkerViewParams::load(private_nh));
  }

  char start[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(start, sizeof start, "%Y%m%d_%H%M%S", std::gmtime(&now));
  run_id_prefix_ = std::string("run_") + start + "_";

  diagnostics_pub_ = nh_.advertise<diagnostic_msgs::DiagnosticArray>(kDiagnosticsTopic, 10);
  diagnostics_timer_ = nh_.createWallTimer(ros::WallDuration(kDiagnosticsPeriod),
                                           [this](const ros::WallTimerEvent&) { publishDiagnostics(); });

  worker_ = std::thread(&LabNode::workerLoop, this);
  input_sub_ = nh_.subscribe(kInitialConditionsTopic, kInputQueueSize,
                             &LabNode::onInitialConditions, this);
  ROS_INFO_STREAM("collision_lab_node: recording " << (params_.record ? "on" : "off")
                  << ", bags in " << params_.bag_directory << ", max_collisions "
                  << params_.max_collisions << ", max_published_events "
                  << params_.max_published_events);
}

LabNode::~LabNode() {
  input_sub_.shutdown();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    inputs_.clear();
  }
  wake_.notify_one();
  worker_.join();
}

void LabNode::onInitialConditions(const collision_lab::InitialConditions::ConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    inputs_.push_back(msg);
  }
  wake_.notify_one();
}

void LabNode::workerLoop() {
  for (;;) {
    collision_lab::InitialConditions::ConstPtr input;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !inputs_.empty(); });
      if (stopping_) return;
      input = inputs_.front();
      inputs_.pop_front();
    }
    serve(*input);
  }
}

std::string LabNode::newRunId() {
  std::string run_id;
  do {
    run_id = run_id_prefix_ + std::to_string(++run_counter_);
  } while (params_.record && bagExists(params_.bag_directory, run_id));
  return run_id;
}

void LabNode::reject(collision_lab::Rejected msg, const std::string& run_id) {
  msg.header.stamp = stampNow();
  msg.run_id = run_id;
  ++runs_rejected_;
  ROS_WARN_STREAM("rejected run '" << run_id << "': " << msg.reason_name << " in field "
                  << msg.field << ": " << msg.message);
  rejected_pub_.publish(msg);
  if (marker_view_) marker_view_->onRejected(msg);
}

void LabNode::serve(collision_lab::InitialConditions input) {
  if (input.run_id.empty()) input.run_id = newRunId();
  const std::string run_id = input.run_id;

  if (const std::string problem = runIdProblem(run_id); !problem.empty()) {
    reject(toRejectedMsg(NodeReason::kInvalidRunId, "run_id", "run_id '" + run_id + "' " + problem),
           run_id);
    return;
  }
  const std::optional<core::RunMode> mode = toRunMode(input.mode);
  if (!mode) {
    reject(toRejectedMsg(NodeReason::kInvalidMode, "mode",
                         "mode " + std::to_string(input.mode) + " is not one of MODE_FULL (0), "
                         "MODE_PREDICT_ONLY (1), MODE_SUMMARY_ONLY (2)"),
           run_id);
    return;
  }
  const core::Scene scene = toScene(input);
  if (const auto error = collision_lab::validate(scene)) {
    reject(toRejectedMsg(*error), run_id);
    return;
  }
  if (params_.record && bagExists(params_.bag_directory, run_id)) {
    reject(toRejectedMsg(NodeReason::kDuplicateRunId, "run_id",
                         "a bag for run_id '" + run_id + "' already exists in " +
                             params_.bag_directory + "; bags are never overwritten"),
           run_id);
    return;
  }

  std::optional<RunRecorder> recorder;
  if (params_.record) recorder.emplace(params_.bag_directory, run_id);
  const auto publishAndRecord = [&](const ros::Publisher& pub, auto& msg) {
    msg.header.stamp = stampNow();
    msg.run_id = run_id;
    pub.publish(msg);
    if (recorder) recorder->write(pub.getTopic(), msg.header.stamp, msg);
  };

  input.header.stamp = stampNow();
  if (recorder) recorder->write(nh_.resolveName(kInitialConditionsTopic), input.header.stamp, input);
  if (marker_view_) marker_view_->onInitialConditions(input);

  core::RunOptions options;
  options.max_collisions = input.max_collisions ? input.max_collisions : params_.max_collisions;
  options.events = collision_lab::EventPolicy::none();
  options.mode = *mode;
  options.skip_simulation_over_cap = true;

  // The prediction goes out before the simulation starts.
  const core::Prediction core_prediction = collision_lab::predict(scene);
  collision_lab::Prediction prediction = toPredictionMsg(core_prediction);
  publishAndRecord(predictions_pub_, prediction);
  if (marker_view_) marker_view_->onPrediction(prediction);

  std::uint64_t published_events = 0;
  bool events_not_published = false;
  const auto onEvent = [&](const core::LabEvent& event) {
    collision_lab::CollisionEvent event_msg = toCollisionEventMsg(event);
    collision_lab::Velocities velocities_msg = toVelocitiesMsg(event);
    collision_lab::EnergyTransfer energy_msg = toEnergyTransferMsg(event);
    event_msg.run_id = run_id;
    if (marker_view_) marker_view_->onCollisionEvent(event_msg);  // every event, published or not
    const bool publish = published_events < params_.max_published_events;
    if (publish) {
      publishAndRecord(events_pub_, event_msg);
      publishAndRecord(velocities_pub_, velocities_msg);
      publishAndRecord(energy_pub_, energy_msg);
      ++published_events;
    } else {
      events_not_published = true;
      if (!recorder) return;
      const ros::Time stamp = stampNow();
      for (auto* header : {&event_msg.header, &velocities_msg.header, &energy_msg.header}) {
        header->stamp = stamp;
      }
      event_msg.run_id = velocities_msg.run_id = energy_msg.run_id = run_id;
      recorder->write(events_pub_.getTopic(), stamp, event_msg);
      recorder->write(velocities_pub_.getTopic(), stamp, velocities_msg);
      recorder->write(energy_pub_.getTopic(), stamp, energy_msg);
    }
  };
  const core::RunResult result = collision_lab::runLab(scene, options, core_prediction, onEvent);

  collision_lab::RunSummary summary = toRunSummaryMsg(result.summary, result.prediction, *mode);
  summary.published_events = published_events;
  summary.events_not_published = events_not_published;
  if (recorder) {
    summary.bag_path = recorder->path();
    summary.recording_ok = recorder->ok();
    summary.recording_error = recorder->error();
  }
  summary.header.stamp = stampNow();
  summary.run_id = run_id;
  if (recorder) {
    recorder->write(summaries_pub_.getTopic(), summary.header.stamp, summary);
    if (!recorder->close()) {
      ROS_ERROR_STREAM("run " << run_id << ": recording failed: " << recorder->error());
    }
    // The published summary reports the bag's final state, closing included.
    summary.recording_ok = recorder->ok();
    summary.recording_error = recorder->error();
  }
  summaries_pub_.publish(summary);
  ++runs_accepted_;
  last_compute_time_ = summary.compute_time;
  if (recorder) {
    std::lock_guard<std::mutex> lock(recording_mutex_);
    last_recording_error_ = summary.recording_error;
  }
  if (marker_view_) marker_view_->onRunSummary(summary);
  ROS_INFO_STREAM("run " << run_id << ": " << summary.collision_count << " collisions"
                  << (summary.truncated ? " (truncated)" : "") << ", predicted "
                  << summary.predicted_collision_count << ", " << summary.compute_time
                  << " s" << (recorder ? ", bag " + summary.bag_path : std::string()));
}

void LabNode::publishDiagnostics() {
  diagnostic_msgs::DiagnosticStatus status;
  status.name = ros::this_node::getName() + ": lab runs";
  status.hardware_id = "collision_lab";
  status.level = diagnostic_msgs::DiagnosticStatus::OK;
  status.message = "serving";
  const auto add = [&status](const std::string& key, const std::string& value) {
    diagnostic_msgs::KeyValue pair;
    pair.key = key;
    pair.value = value;
    status.values.push_back(pair);
  };
  add("runs accepted", std::to_string(runs_accepted_.load()));
  add("runs rejected", std::to_string(runs_rejected_.load()));
  add("last run compute time [s]", std::to_string(last_compute_time_.load()));
  add("recording", params_.record ? "on" : "off");
  add("bag directory", params_.bag_directory);
  if (params_.record) {
    std::string recording_error;
    {
      std::lock_guard<std::mutex> lock(recording_mutex_);
      recording_error = last_recording_error_;
    }
    add("last recording error", recording_error);
    if (!recording_error.empty()) {
      status.level = diagnostic_msgs::DiagnosticStatus::ERROR;
      status.message = "recording failed: " + recording_error;
    }
    struct statvfs space {};
    if (statvfs(params_.bag_directory.c_str(), &space) == 0) {
      const double free_mb = static_cast<double>(space.f_bavail) * space.f_frsize / 1e6;
      add("free space in bag directory [MB]", std::to_string(free_mb));
      if (free_mb < params_.min_free_space_mb && status.level == diagnostic_msgs::DiagnosticStatus::OK) {
        status.level = diagnostic_msgs::DiagnosticStatus::WARN;
        status.message = "low free space for bags: " + std::to_string(free_mb) + " MB";
      }
    } else {
      add("free space in bag directory [MB]", "unknown (directory not readable)");
    }
  }
  diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = stampNow();
  array.status.push_back(status);
  diagnostics_pub_.publish(array);
}

}  // namespace collision_lab_ros
