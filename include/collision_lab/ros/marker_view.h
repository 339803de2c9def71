// Publishes the newest run's picture on `markers` (static: axes, plots, titles) and its
// animation on `markers_animated`, both latched, so an rviz opened late shows the last run
// and its last frame. Fed either directly by collision_lab_node (every collision, whether
// published or not), or from the node's topics (collision_lab_markers, on bag replay):
// markers are not recorded in bags, replay regenerates them.
//
// The animation's clock (~clock):
//   "wall": loops over the run in wall time, at ~time_scale simulated s per wall s, or
//           (time_scale <= 0) auto-timed with dense bursts in slow motion (TimeWarp);
//   "ros":  follows ROS time on the run's timeline, simulated t =
//           (ros::Time::now() - InitialConditions stamp) / Prediction.timeline_scale, so
//           that rosbag play --clock drives it: rate (-r), pause (space) and step (s);
//           a replay never shows a time before the newest collision received (replayedTime),
//           and goes on to the run's end like the live view once the bag's clock has stopped
//           at its RunSummary (ReplayClock).
// The default is "ros" under use_sim_time, "wall" otherwise.
//
// Which runs it shows (~follow_run_id, ~follow_student): by default whichever run is
// newest; a view that follows shows only the runs, and rejections, of one run_id or one
// student (MarkerViewParams::follows), so that a student's rviz keeps their own run while
// the class sends theirs.
#pragma once

#include <cstddef>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <ros/ros.h>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/run_observer.h"

namespace collision_lab_ros {

struct MarkerViewParams {
  enum class Clock { kWall, kRos };

  double time_scale = 0.0;   ///< simulated s per wall s; <= 0: auto (wall clock only)
  double marker_rate = 0.0;  ///< [Hz]
  std::string frame_id;
  Clock clock = Clock::kWall;
  /// Empty: every run. Otherwise the run_id to show, also as served when taken
  /// (<follow_run_id>.N).
  std::string follow_run_id;
  /// Empty: every run. Otherwise the student whose runs to show: the run_ids <student>
  /// and <student>.*, which the node gives every input that names that student
  /// (InitialConditions.run_id), and the rejections that name them.
  std::string follow_student;

  /// True when a message of run_id is to be shown.
  bool follows(const std::string& run_id) const;
  /// True when a rejection is to be shown.
  bool follows(const collision_lab::Rejected& rejected) const;

  /// Reads ~time_scale, ~marker_rate, ~frame_id, ~clock ("wall" or "ros"),
  /// ~follow_run_id and ~follow_student, with the defaults of node_constants.h.
  static MarkerViewParams load(const ros::NodeHandle& private_nh);
};

class MarkerView : public RunObserver {
 public:
  MarkerView(ros::NodeHandle nh, const MarkerViewParams& params);

  /// Subscribes to the run topics and `rejected` in nh's namespace: the inputs from
  /// inputs_topic (kInitialConditionsTopic on replay, kServedInputsTopic beside a live node).
  void subscribe(const std::string& inputs_topic);

  /// A message of a new run_id starts a new picture; so does a second InitialConditions
  /// of the current run (a bag played again). A run's other messages may arrive before
  /// its InitialConditions: they wait for it. Thread-safe.
  void onInitialConditions(const collision_lab::InitialConditions& msg) override;
  /// MarkerViewParams::follows.
  bool follows(const std::string& run_id) const override { return params_.follows(run_id); }
  void onPrediction(const collision_lab::Prediction& msg) override;
  void onCollisionEvent(const collision_lab::CollisionEvent& msg) override;
  void onRunSummary(const collision_lab::RunSummary& msg) override;
  /// Shown over whatever run is on screen until the next run starts. Messages of runs
  /// (and rejections) the params do not follow are ignored.
  void onRejected(const collision_lab::Rejected& msg) override;

 private:
  /// Messages of the current run that came before its InitialConditions.
  struct Pending {
    std::optional<collision_lab::Prediction> prediction;
    std::optional<collision_lab::RunSummary> summary;
    std::vector<collision_lab::CollisionEvent> events;
  };

  /// Keeps a run's Prediction or RunSummary: in the run, or pending until its
  /// InitialConditions comes.
  template <typename Msg>
  void keep(const Msg& msg, std::optional<Msg> RunRecord::*in_run, std::optional<Msg> Pending::*pending);
  void onTimer(const ros::WallTimerEvent& event);
  /// Switches to run_id when it is not the current run. Call with mutex_ held.
  void select(const std::string& run_id);
  /// A message of the run shown before the current one: with recording on, a run's summary
  /// goes out only once its bag is closed, which can be after the next run has started.
  /// Such a message must not switch the view back. Call with mutex_ held.
  bool stale(const std::string& run_id) const { return has_run_id_ && run_id != run_id_ && run_id == left_run_id_; }
  /// The animation's clock for run, started (wall clock) at run_start. Needs no lock (the
  /// timer's alone: it moves replay_clock_ on).
  FrameClock frameClock(const RunRecord& run, const ros::WallTime& run_start, const ros::WallTime& now);
  std::string hintText() const;
  /// The banner and hint markers of this frame (adds, or deletes of ones shown before).
  void addOverlays(visualization_msgs::MarkerArray& animated);

  ros::NodeHandle nh_;
  MarkerViewParams params_;
  ros::Publisher markers_pub_, animated_pub_;
  ros::WallTimer timer_;
  std::vector<ros::Subscriber> subscribers_;
  bool replay_ = false;  ///< fed by subscriptions rather than by the node

  std::mutex mutex_;
  std::string run_id_;
  std::string left_run_id_;  ///< the run shown before run_id_
  bool has_run_id_ = false;
  std::optional<RunRecord> run_;
  Pending pending_;
  bool run_changed_ = false;   // the previous run's markers must be deleted
  bool static_dirty_ = false;  // the static markers must be rebuilt
  ros::WallTime run_start_;
  std::optional<collision_lab::Rejected> rejected_;  ///< since the current run started
  bool banner_shown_ = false, hint_shown_ = false;

  /// The timer's copy of run_, taken under mutex_ when run_ changed and drawn without it.
  std::optional<RunRecord> drawn_run_;
  /// A replay's clock past the bag's end (the timer's alone).
  ReplayClock replay_clock_;
};

}  // namespace collision_lab_ros
