// A run's budget in the class service (ROS-free): the lab's ceilings lowered, never raised,
// by what the input asks (RunLimits), and how a run stopped by the service ends: its stop
// reason and the sentence that says why, with the limit and whose it was (serviceStop).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace collision_lab::service {

/// Limits of the lab, or asked by one input: 0 is none.
struct Budget {
  std::uint64_t max_collisions = 0;  ///< [1]
  double max_run_seconds = 0.0;      ///< [s]
  std::uint64_t max_bag_bytes = 0;   ///< [bytes]
};

/// A run's limits: the lab's, each lowered by the input's own where it asks less.
struct RunLimits {
  std::uint64_t max_collisions = 0;  ///< [1]; 0: none
  bool collision_ceiling = false;    ///< the lab's max_collisions lowered the input's cap
  double max_run_seconds = 0.0;      ///< [s]; 0: none
  bool time_from_input = false;      ///< the input's max_run_seconds is the binding one
  std::uint64_t max_bag_bytes = 0;   ///< [bytes]; 0: none
  bool bag_from_input = false;       ///< the input's max_bag_bytes is the binding one
};

/// The limits of a run that asks `input` of a lab with ceilings `lab`. An input's 0 (and a
/// time that is not a positive finite number) asks nothing; a cap of 0 takes the lab's.
RunLimits limitsOf(const Budget& lab, const Budget& input);

/// Why the service stopped a run (the first cause wins).
enum class StopCause : int { kNone, kCancel, kTimeLimit, kBagLimit, kDiskSpace, kStudentQuota, kShutdown };

/// How a run ended, as the engine reported it.
struct RunEnd {
  std::string stop_reason;        ///< the engine's: "CANCELLED" when its cancel flag stopped it, "CAP", ...
  std::string truncation_reason;  ///< the engine's sentence
  std::uint64_t collisions = 0;   ///< [1]
};

/// What the service says of a run it stopped or capped.
struct ServiceStop {
  std::string stop_reason;        ///< SERVICE_TIME_LIMIT, SERVICE_BAG_LIMIT, SERVICE_DISK_SPACE,
                                  ///< SERVICE_STUDENT_QUOTA, SERVICE_COLLISION_LIMIT, or CANCELLED
  std::string truncation_reason;  ///< the limit, whose it was, and where the run stopped
  bool cancelled = false;         ///< ~cancel stopped it
};

/// The context of the sentence: who stopped it, and the lab's disk limits.
struct StopContext {
  std::string stopped_by;          ///< ~cancel's requested_by
  std::string student;
  std::uint64_t asked_max_collisions = 0;  ///< [1] the input's
  double min_free_space_mb = 0.0;          ///< [MB] the lab's floor
  double max_student_bag_mb = 0.0;         ///< [MB] the lab's quota
};

/// The service's ending of a run that `cause` stopped (the engine ended it CANCELLED) or
/// the lab's collision ceiling capped; empty when the run ended on its own terms.
std::optional<ServiceStop> serviceStop(StopCause cause, const RunLimits& limits, const RunEnd& end,
                                       const StopContext& context);

}  // namespace collision_lab::service
