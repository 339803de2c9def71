#include "collision_lab/ros/marker_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "collision_lab/ros/markers/ids.h"
#include "collision_lab/ros/node_constants.h"

namespace collision_lab_ros {

namespace {
/// Collisions of a run held while its InitialConditions has not arrived (a replay's topics
/// are not ordered against each other). Beyond, they count as missed.
constexpr std::size_t kMaxPendingEvents = 100000;
}  // namespace

bool MarkerViewParams::follows(const std::string& run_id) const {
  // prefix, or prefix followed by '.' and what follows (any text, or digits only)
  const auto named = [&](const std::string& prefix, bool digits_only) {
    if (run_id.compare(0, prefix.size(), prefix) != 0) return false;
    if (run_id.size() == prefix.size()) return true;
    if (run_id[prefix.size()] != '.' || run_id.size() == prefix.size() + 1) return false;
    return !digits_only || std::all_of(run_id.begin() + prefix.size() + 1, run_id.end(),
                                       [](char c) { return c >= '0' && c <= '9'; });
  };
  return (follow_run_id.empty() || named(follow_run_id, true)) &&
         (follow_student.empty() || named(follow_student, false));
}

bool MarkerViewParams::follows(const collision_lab::Rejected& rejected) const {
  return (follow_run_id.empty() || rejected.run_id == follow_run_id) &&
         (follow_student.empty() || rejected.student == follow_student);
}

MarkerViewParams MarkerViewParams::load(const ros::NodeHandle& private_nh) {
  MarkerViewParams params;
  private_nh.param("follow_run_id", params.follow_run_id, std::string());
  private_nh.param("follow_student", params.follow_student, std::string());
  private_nh.param("time_scale", params.time_scale, kDefaultTimeScale);
  private_nh.param("marker_rate", params.marker_rate, kDefaultMarkerRate);
  private_nh.param("frame_id", params.frame_id, std::string(kMarkerFrame));
  if (!(params.marker_rate > 0)) {
    ROS_WARN_STREAM("~marker_rate = " << params.marker_rate << " Hz is not positive; using "
                    << kDefaultMarkerRate << " Hz");
    params.marker_rate = kDefaultMarkerRate;
  }
  const std::string fallback = ros::Time::isSimTime() ? "ros" : "wall";
  std::string clock;
  private_nh.param("clock", clock, fallback);
  if (clock != "wall" && clock != "ros") {
    ROS_WARN_STREAM("~clock = '" << clock << "' is neither 'wall' nor 'ros'; using '" << fallback << "'");
    clock = fallback;
  }
  params.clock = clock == "ros" ? Clock::kRos : Clock::kWall;
  return params;
}

MarkerView::MarkerView(ros::NodeHandle nh, const MarkerViewParams& params) : nh_(nh), params_(params) {
  markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>(kMarkersTopic, kMarkerQueueSize, true);
  animated_pub_ = nh_.advertise<visualization_msgs::MarkerArray>(kAnimatedMarkersTopic, kMarkerQueueSize, true);
  timer_ = nh_.createWallTimer(ros::WallDuration(1.0 / params_.marker_rate), &MarkerView::onTimer, this);
}

void MarkerView::subscribe(const std::string& inputs_topic) {
  replay_ = inputs_topic == kInitialConditionsTopic;
  // Queues as deep as the node's, so a replayed burst is not thinned out.
  subscribers_.push_back(nh_.subscribe<collision_lab::InitialConditions>(
      inputs_topic, kOutputQueueSize,
      [this](const collision_lab::InitialConditions::ConstPtr& m) { onInitialConditions(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::Prediction>(
      kPredictionsTopic, kOutputQueueSize, [this](const collision_lab::Prediction::ConstPtr& m) { onPrediction(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::CollisionEvent>(
      kCollisionEventsTopic, kOutputQueueSize,
      [this](const collision_lab::CollisionEvent::ConstPtr& m) { onCollisionEvent(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::RunSummary>(
      kRunSummariesTopic, kOutputQueueSize, [this](const collision_lab::RunSummary::ConstPtr& m) { onRunSummary(*m); }));
  subscribers_.push_back(nh_.subscribe<collision_lab::Rejected>(
      kRejectedTopic, kOutputQueueSize, [this](const collision_lab::Rejected::ConstPtr& m) { onRejected(*m); }));
}

void MarkerView::select(const std::string& run_id) {
  if (has_run_id_ && run_id == run_id_) return;
  if (has_run_id_) left_run_id_ = run_id_;
  run_id_ = run_id;
  has_run_id_ = true;
  run_.reset();
  pending_ = Pending{};
  run_changed_ = true;
}

void MarkerView::onInitialConditions(const collision_lab::InitialConditions& msg) {
  if (!params_.follows(msg.run_id)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (run_ && msg.run_id == run_id_) has_run_id_ = false;  // the same run again: start afresh
  select(msg.run_id);
  rejected_.reset();  // a rejection stays on screen until the next run
  run_.emplace(msg);
  run_->prediction = pending_.prediction;
  run_->summary = pending_.summary;
  for (const auto& event : pending_.events) run_->add(event);
  pending_ = Pending{};
  run_start_ = ros::WallTime::now();
  static_dirty_ = true;
}

template <typename Msg>
void MarkerView::keep(const Msg& msg, std::optional<Msg> RunRecord::*in_run, std::optional<Msg> Pending::*pending) {
  if (!params_.follows(msg.run_id)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (stale(msg.run_id)) return;
  select(msg.run_id);
  (run_ ? (*run_).*in_run : pending_.*pending) = msg;
  static_dirty_ = true;
}

void MarkerView::onPrediction(const collision_lab::Prediction& msg) {
  keep(msg, &RunRecord::prediction, &Pending::prediction);
}

void MarkerView::onCollisionEvent(const collision_lab::CollisionEvent& msg) {
  if (!params_.follows(msg.run_id)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (stale(msg.run_id)) return;
  select(msg.run_id);
  if (run_) {
    run_->add(msg);
  } else if (pending_.events.size() < kMaxPendingEvents) {
    pending_.events.push_back(msg);
  }
  static_dirty_ = true;
}

void MarkerView::onRunSummary(const collision_lab::RunSummary& msg) {
  keep(msg, &RunRecord::summary, &Pending::summary);
}

void MarkerView::onRejected(const collision_lab::Rejected& msg) {
  if (!params_.follows(msg)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  rejected_ = msg;
}

FrameClock MarkerView::frameClock(const RunRecord& run, const ros::WallTime& run_start, const ros::WallTime& now) {
  FrameClock clock;
  if (params_.clock == MarkerViewParams::Clock::kRos) {
    const double scale = run.prediction ? run.prediction->timeline_scale : 0.0;
    const double t = replay_ && ros::Time::isSimTime()
                         ? replay_clock_.at(run, ros::Time::now(), (now - run_start).toSec())
                         : simulatedTimeOnTimeline(ros::Time::now(), run.input().header.stamp, scale);
    clock.t = std::min(t, endTime(run));
    clock.description = "ROS clock" + std::string(ros::Time::isSimTime() ? " (bag)" : "");
    return clock;
  }
  const double elapsed = (now - run_start).toSec();
  if (params_.time_scale > 0) {
    const double end = endTime(run);
    const double into = std::fmod(elapsed, end / params_.time_scale + kMarkerEndHold);
    clock.t = std::min(into * params_.time_scale, end);
    clock.description = "sim time x" + std::to_string(params_.time_scale);
    return clock;
  }
  const TimeWarp warp(run);
  const double loop = autoLoopDuration(run.collisions());
  const double into = std::fmod(elapsed, loop + kMarkerEndHold);
  const double phase = std::min(into / loop, 1.0);
  clock.t = warp.timeAt(phase);
  if (into >= loop) {
    clock.description = "held at the end";  // not "sim time x0"
    return clock;
  }
  char rate[64];
  std::snprintf(rate, sizeof rate, "sim time x%.2g", warp.rateAt(phase) / loop);
  clock.description = rate;
  return clock;
}

std::string MarkerView::hintText() const {
  std::string following;
  if (!params_.follow_student.empty()) following += " student '" + params_.follow_student + "'";
  if (!params_.follow_run_id.empty()) following += " run '" + params_.follow_run_id + "'";
  if (!following.empty()) following = "Following" + following + ". ";
  if (replay_) {
    return following + "Waiting for a run. Replay one:\nroslaunch collision_lab replay.launch bag:=<run>.bag";
  }
  const std::string student = params_.follow_student.empty() ? "" : "student: " + params_.follow_student + ", ";
  return following + "No run yet. Send one, e.g.:\nrostopic pub -1 " + nh_.resolveName(kInitialConditionsTopic) +
         " collision_lab/InitialConditions\n'{" + student +
         "masses: [100.0, 1.0, .inf], positions: [2.0, 1.0, 0.0], "
         "velocities: [-1.0, 0.0, 0.0]}'\n(numbers as 1.0e+8, not 1e8; .inf is a wall)";
}

void MarkerView::addOverlays(visualization_msgs::MarkerArray& animated) {
  auto& out = animated.markers;
  const auto show = [&](bool shown, bool& was_shown, const std::string& ns,
                        const std::vector<visualization_msgs::Marker>& markers) {
    if (shown) out.insert(out.end(), markers.begin(), markers.end());
    if (was_shown && !shown) {
      for (int id : {markers::kFramedText, markers::kFramedBox, markers::kFramedTextBold}) {
        out.push_back(deleteMarker(ns, id, params_.frame_id));
      }
    }
    was_shown = shown;
  };
  const bool banner = rejected_.has_value();
  show(banner, banner_shown_, markers::ns::kRejected,
       banner ? rejectedBanner(*rejected_, params_.frame_id) : std::vector<visualization_msgs::Marker>{});
  const bool hint = !has_run_id_;
  show(hint, hint_shown_, markers::ns::kHint, hint ? hintMarkers(hintText(), params_.frame_id) : std::vector<visualization_msgs::Marker>{});
}

void MarkerView::onTimer(const ros::WallTimerEvent&) {
  // The node's worker takes mutex_ on every collision: hold it only to copy the run when
  // it changed (a RunRecord is bounded by its RecordLimits), and build the markers without it.
  visualization_msgs::MarkerArray static_markers, animated, overlays;
  bool rebuild_static = false;
  ros::WallTime run_start;
  const ros::WallTime now = ros::WallTime::now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // A deletion goes in the same message as the new picture, so rviz never shows the
    // two together, and every static message (the latched one too) is a whole picture.
    if (run_changed_) {
      animated = deleteAllMarkers(params_.frame_id);
      replay_clock_.reset();
      banner_shown_ = hint_shown_ = false;
    }
    rebuild_static = run_changed_ || (run_ && static_dirty_);
    if (rebuild_static && run_) static_dirty_ = false;
    run_changed_ = false;
    if (rebuild_static) drawn_run_ = run_;  // every change of run_ sets run_changed_ or static_dirty_
    run_start = run_start_;
    addOverlays(overlays);
  }
  if (rebuild_static) {
    static_markers = deleteAllMarkers(params_.frame_id);
    if (drawn_run_) {
      const auto built = buildStaticMarkers(*drawn_run_, params_.frame_id);
      static_markers.markers.insert(static_markers.markers.end(), built.markers.begin(), built.markers.end());
    }
  }
  if (drawn_run_) {
    const auto built = buildAnimatedMarkers(*drawn_run_, frameClock(*drawn_run_, run_start, now), params_.frame_id);
    animated.markers.insert(animated.markers.end(), built.markers.begin(), built.markers.end());
  }
  animated.markers.insert(animated.markers.end(), overlays.markers.begin(), overlays.markers.end());
  for (auto* array : {&static_markers, &animated}) {
    if (const std::size_t changed = enforceRvizLimits(*array)) {
      ROS_WARN_STREAM_THROTTLE(10, changed << " markers did not fit rviz's limits and were thinned or dropped");
    }
  }
  if (!static_markers.markers.empty()) markers_pub_.publish(static_markers);
  if (!animated.markers.empty()) animated_pub_.publish(animated);
}

}  // namespace collision_lab_ros
