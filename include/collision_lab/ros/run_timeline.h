// A run's timeline in ROS time: every message of a run is stamped
//   stamp = start + scale * t,
// with start the stamp of the run's InitialConditions and t the simulated time [s] of what
// the message reports, live and in the bag, so that `rosbag play` (rate, pause, step)
// drives a replay. The rule for the scale and the saturation are documented in
// RunSummary.msg (timeline_scale, timeline_saturated).
#pragma once

#include <cstdint>
#include <optional>

#include <ros/time.h>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab_ros {

/// Time of the scene's first contact [s]: the least gap / closing speed over the pairs that
/// approach (inf when the quotient overflows); empty when none approaches.
/// Precondition: the scene is valid (core::planScene gave no error).
std::optional<double> firstContactTime(const collision_lab::core::Scene& scene);

/// [bag s per simulated s]: 1 when first_contact is empty or within [1e-3, 1e3] s,
/// otherwise 10^(-floor(log10 first_contact)) (exponent clamped to +-300).
double chooseTimelineScale(const std::optional<double>& first_contact);

class RunTimeline {
 public:
  /// Offsets beyond this are saturated [bag s]: start + offset stays below ros::TIME_MAX
  /// for any start before 2106 - 32 years, and every gap of a bag fits ros::Duration
  /// (int32 seconds), which rosbag play uses.
  static constexpr double kMaxOffset = 1e9;

  /// start must be >= ros::TIME_MIN (a bag time); scale > 0.
  RunTimeline(const ros::Time& start, double scale) : start_(start), scale_(scale) {}

  /// start + scale * t, rounded to the nanosecond; t >= 0 [s]. Saturates (and remembers
  /// it) beyond kMaxOffset or ros::TIME_MAX; NaN counts as beyond.
  ros::Time stamp(double t);

  const ros::Time& start() const { return start_; }
  double scale() const { return scale_; }
  bool saturated() const { return saturated_; }

 private:
  ros::Time start_;
  double scale_;
  bool saturated_ = false;
};

}  // namespace collision_lab_ros
