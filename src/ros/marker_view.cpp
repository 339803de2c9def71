#include "collision_lab/ros/marker_view.h"

#include <cmath>

#include "collision_lab/ros/node_constants.h"

namespace collision_lab_ros {

namespace {
constexpr double kStaticRepublishPeriod = 1.0;  ///< [s], for rviz instances that join late
}

MarkerViewParams MarkerViewParams::load(const ros::NodeHandle& private_nh) {
  MarkerViewParams params;
  private_nh.param("time_scale", params.time_scale, kDefaultTimeScale);
  private_nh.param("marker_rate", params.marker_rate, kDefaultMarkerRate);
  int max_plotted = static_cast<int>(kDefaultMaxPlottedEvents);
  private_nh.param("max_plotted_events", max_plotted, max_plotted);
  params.max_plotted_events = static_cast<std::size_t>(std::max(max_plotted, 0));
  private_nh.param("frame_id", params.frame_id, std::string(kMarkerFrame));
  if (!(params.marker_rate > 0)) {
    ROS_WARN_STREAM("~marker_rate = " << params.marker_rate << " Hz is not positive; using "
                    << kDefaultMarkerRate << " Hz");
    params.marker_rate = kDefaultMarkerRate;
  }
  return params;
}

MarkerView::MarkerView(ros::NodeHandle nh, const MarkerViewParams& params)
    : nh_(nh), params_(params) {
  markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>(kMarkersTopic, kMarkerQueueSize);
  timer_ = nh_.createWallTimer(ros::WallDuration(1.0 / params_.marker_rate), &MarkerView::onTimer,
                               this);
}

void MarkerView::subscribe() {
  // Queues as deep as the node's, so a replayed burst is not thinned out.
  subscribers_.push_back(nh_.subscribe<collision_lab::InitialConditions>(
      kInitialConditionsTopic, kOutputQueueSize,
      [this](const collision_lab::InitialConditions::ConstPtr& m) { onInitialConditions(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::Prediction>(
      kPredictionsTopic, kOutputQueueSize,
      [this](const collision_lab::Prediction::ConstPtr& m) { onPrediction(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::CollisionEvent>(
      kCollisionEventsTopic, kOutputQueueSize,
      [this](const collision_lab::CollisionEvent::ConstPtr& m) { onCollisionEvent(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::Velocities>(
      kVelocitiesTopic, kOutputQueueSize,
      [this](const collision_lab::Velocities::ConstPtr& m) { onVelocities(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::EnergyTransfer>(
      kEnergyTransfersTopic, kOutputQueueSize,
      [this](const collision_lab::EnergyTransfer::ConstPtr& m) { onEnergyTransfer(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::RunSummary>(
      kRunSummariesTopic, kOutputQueueSize,
      [this](const collision_lab::RunSummary::ConstPtr& m) { onRunSummary(*m); }));
}

RunRecord& MarkerView::select(const std::string& run_id) {
  if (!has_run_ || run_id != current_run_id_) {
    run_ = RunRecord{};
    current_run_id_ = run_id;
    has_run_ = true;
    run_changed_ = true;
    run_start_ = ros::WallTime::now();
  }
  static_dirty_ = true;
  return run_;
}

void MarkerView::onInitialConditions(const collision_lab::InitialConditions& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  select(msg.run_id).input = msg;
  run_start_ = ros::WallTime::now();
}

void MarkerView::onPrediction(const collision_lab::Prediction& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  select(msg.run_id).prediction = msg;
}

void MarkerView::onCollisionEvent(const collision_lab::CollisionEvent& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& events = select(msg.run_id).events;
  if (events.size() < params_.max_plotted_events) events.push_back(msg);
}

void MarkerView::onVelocities(const collision_lab::Velocities& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& velocities = select(msg.run_id).velocities;
  if (velocities.size() < params_.max_plotted_events) velocities.push_back(msg);
}

void MarkerView::onEnergyTransfer(const collision_lab::EnergyTransfer& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& energies = select(msg.run_id).energies;
  if (energies.size() < params_.max_plotted_events) energies.push_back(msg);
}

void MarkerView::onRunSummary(const collision_lab::RunSummary& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  select(msg.run_id).summary = msg;
}

void MarkerView::onTimer(const ros::WallTimerEvent&) {
  visualization_msgs::MarkerArray static_markers, animated;
  bool clear = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // Nothing to draw before the run's masses and start are known.
    if (!has_run_ || run_.input.run_id != current_run_id_) return;
    const ros::WallTime now = ros::WallTime::now();
    clear = run_changed_;
    run_changed_ = false;
    if (static_dirty_ || (now - last_static_publish_).toSec() >= kStaticRepublishPeriod) {
      static_markers = buildStaticMarkers(run_, params_.frame_id);
      static_dirty_ = false;
      last_static_publish_ = now;
    }
    const double loop = loopDuration(run_);
    const double time_scale =
        params_.time_scale > 0 ? params_.time_scale : loop / kAutoLoopDuration;
    const double t = std::fmod((now - run_start_).toSec() * time_scale, loop);
    animated = buildAnimatedMarkers(run_, t, params_.frame_id);
  }
  if (clear) {
    // In the same message, so rviz never sees the new run drawn over the old one.
    auto& markers = static_markers.markers;
    markers.insert(markers.begin(), deleteAllMarkers(params_.frame_id).markers.front());
  }
  if (!static_markers.markers.empty()) markers_pub_.publish(static_markers);
  markers_pub_.publish(animated);
}

}  // namespace collision_lab_ros
