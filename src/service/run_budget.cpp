#include "collision_lab/service/run_budget.h"

#include <cmath>
#include <sstream>

namespace collision_lab::service {

RunLimits limitsOf(const Budget& lab, const Budget& input) {
  RunLimits limits;
  if (input.max_collisions == 0) {
    limits.max_collisions = lab.max_collisions;
  } else if (lab.max_collisions == 0 || input.max_collisions <= lab.max_collisions) {
    limits.max_collisions = input.max_collisions;
  } else {
    limits.max_collisions = lab.max_collisions;
    limits.collision_ceiling = true;
  }
  limits.max_run_seconds = lab.max_run_seconds;
  if (std::isfinite(input.max_run_seconds) && input.max_run_seconds > 0 &&
      (limits.max_run_seconds == 0 || input.max_run_seconds < limits.max_run_seconds)) {
    limits.max_run_seconds = input.max_run_seconds;
    limits.time_from_input = true;
  }
  limits.max_bag_bytes = lab.max_bag_bytes;
  if (input.max_bag_bytes > 0 && (limits.max_bag_bytes == 0 || input.max_bag_bytes < limits.max_bag_bytes)) {
    limits.max_bag_bytes = input.max_bag_bytes;
    limits.bag_from_input = true;
  }
  return limits;
}

std::optional<ServiceStop> serviceStop(StopCause cause, const RunLimits& limits, const RunEnd& end,
                                       const StopContext& context) {
  const bool stopped = end.stop_reason == "CANCELLED";
  ServiceStop stop;
  std::ostringstream why;
  if (stopped && cause == StopCause::kTimeLimit) {
    stop.stop_reason = "SERVICE_TIME_LIMIT";
    why << "stopped by the time limit of " << limits.max_run_seconds << " s ("
        << (limits.time_from_input ? "the input's max_run_seconds" : "the node's ~max_run_seconds") << ") after "
        << end.collisions << " collisions, at its last certified impact";
  } else if (stopped && cause == StopCause::kBagLimit) {
    stop.stop_reason = "SERVICE_BAG_LIMIT";
    why << "stopped when its recorded messages passed the bag limit of " << limits.max_bag_bytes << " bytes ("
        << (limits.bag_from_input ? "the input's max_bag_bytes" : "the node's ~max_bag_bytes") << ") after "
        << end.collisions << " collisions, at its last certified impact";
  } else if (stopped && cause == StopCause::kDiskSpace) {
    stop.stop_reason = "SERVICE_DISK_SPACE";
    why << "stopped when the bag folder's free space fell under the node's ~min_free_space_mb = "
        << context.min_free_space_mb << " MB after " << end.collisions
        << " collisions, at its last certified impact; its bag holds the run to there";
  } else if (stopped && cause == StopCause::kStudentQuota) {
    stop.stop_reason = "SERVICE_STUDENT_QUOTA";
    why << "stopped when student '" << context.student << "''s bags passed the node's ~max_student_bag_mb = "
        << context.max_student_bag_mb << " MB after " << end.collisions
        << " collisions, at its last certified impact; its bag holds the run to there";
  } else if (stopped && cause == StopCause::kCancel) {
    stop.stop_reason = end.stop_reason;
    why << end.truncation_reason << " (cancelled by " << context.stopped_by << ")";
  } else if (end.stop_reason == "CAP" && limits.collision_ceiling) {
    stop.stop_reason = "SERVICE_COLLISION_LIMIT";
    why << "stopped at the node's ~max_collisions = " << limits.max_collisions << ", which lowered the input's "
        << "max_collisions = " << context.asked_max_collisions;
  } else {
    return std::nullopt;
  }
  stop.cancelled = cause == StopCause::kCancel;
  stop.truncation_reason = why.str();
  return stop;
}

}  // namespace collision_lab::service
