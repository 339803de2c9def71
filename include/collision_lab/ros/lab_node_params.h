// The lab node's parameters (~record, ~bag_directory, the caps, the workers, the lanes, the
// ceilings), read once at start, and the rule every count parameter follows.
#pragma once

#include <cstdint>
#include <string>

#include <ros/node_handle.h>

#include "collision_lab/service/fair_scheduler.h"

namespace collision_lab_ros {

struct LabNodeParams {
  bool record = true;
  std::string bag_directory;  ///< "~" expanded
  std::uint64_t max_collisions = 0;
  /// Simulate up to the cap even when the model predicts more impacts (else the model
  /// answers at once: core::SceneRunOptions::simulate_to_cap).
  bool simulate_to_cap = false;
  std::uint64_t max_published_events = 0;
  /// Past max_published_events, a RunProgress goes out on run_progress at most this often
  /// [s] of wall time (~progress_period), and, when progress_every_events > 0 (a test hook,
  /// ~progress_every_events), every that many unpublished collisions [1] instead.
  double progress_period = 0.0;
  std::uint64_t progress_every_events = 0;
  bool publish_markers = true;
  bool log_runs = true;            ///< one INFO line per served run (else DEBUG)
  std::uint64_t max_bodies = 0;    ///< larger scenes are rejected (TOO_MANY_BODIES)
  double min_free_space_mb = 0.0;  ///< [MB] the bag directory's floor (kDefaultMinFreeSpaceMb); 0: none
  double max_student_bag_mb = 0.0; ///< [MB] a named student's bags at most (StudentQuota); 0: none
  std::string scenario_file;       ///< the presets of ~run_preset
  /// Worker threads [1] (~workers; default max(2, hardware threads)), of which
  /// short_lane_workers [1] take only short runs (~short_lane_workers, default 1).
  std::uint64_t workers = 2;
  std::uint64_t short_lane_workers = 1;
  /// What makes a run short (~short_max_collisions, ~short_max_seconds).
  collision_lab::service::LaneLimits lanes;
  /// Service ceilings an input may lower, never raise: wall time per run [s]
  /// (~max_run_seconds; <= 0: none) and recorded bytes per bag [bytes] (~max_bag_bytes; 0: none).
  double max_run_seconds = 0.0;
  std::uint64_t max_bag_bytes = 0;
  /// Test hook (~fail_runs_of_student): a run of this student throws std::bad_alloc from
  /// its first collision, as a worker that runs out of memory. Empty: none.
  std::string fail_runs_of_student;

  /// Reads ~record, ~bag_directory, ~max_collisions, ~simulate_to_cap, ~max_published_events,
  /// ~progress_period, ~progress_every_events,
  /// ~publish_markers, ~log_runs, ~max_bodies, ~min_free_space_mb, ~scenario_file (default: the package's
  /// config/scenarios.yaml), ~workers, ~short_lane_workers, ~short_max_collisions,
  /// ~short_max_seconds, ~max_run_seconds, ~max_bag_bytes and ~fail_runs_of_student, with
  /// the defaults of node_constants.h. Throws
  /// std::invalid_argument, naming the parameter, its value and the accepted range, when a
  /// count (~max_collisions, ~max_published_events, ~max_bodies, ~workers, ...) is not a
  /// whole number in [0, 2^64 - 1], when ~workers is 0 or ~short_lane_workers is not below
  /// ~workers.
  static LabNodeParams load(const ros::NodeHandle& private_nh);
};

/// The accepted range of a count parameter, as the errors state it.
constexpr char kCountParameterRange[] = "expected a whole number from 0 to 18446744073709551615 (2^64 - 1)";

/// A count parameter's value read as a double (the parameter server gives large integers
/// as doubles): value when it is a whole number in [0, 2^64 - 1]; otherwise error says so,
/// naming ~name, the value and the range (NaN, infinities, negative, fractional and too
/// large values, whose conversion to std::uint64_t would be undefined behaviour).
struct CountParameter {
  std::uint64_t value = 0;
  std::string error;  ///< empty when value holds
};
CountParameter countParameter(const std::string& name, double value);

}  // namespace collision_lab_ros
