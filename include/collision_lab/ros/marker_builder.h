// rviz markers for one run of N bodies, built from the run's messages alone (so a live
// node and a bag replay draw the same picture). The views (docs/rviz.md):
//   - the scene: bodies sized by mass (log scale), walls as walls, animated along the exact
//     trajectory (never extrapolated), with the time and the collision counter; labelled
//     with their velocities up to kMaxPlottedBodies, coloured by velocity beyond;
//   - three bodies (at most one wall): the wedge in velocity space s-perp (the paper's
//     Figure 1): lines L_AB and L_BC, the escape cone, u_perp after the collisions
//     (simulated and by the closed form); with e < 1 the spiral, and for a collapse the
//     orbit's directions converging to the eigen-directions of the cycle, r_c in the legend;
//     other scenes in its place: the velocities now body by body (small N) or their
//     histogram against the Maxwell-like Gaussian (large N);
//   - velocities against collision index as steps (constant between impacts), with the
//     paper's printed eqs. (2.15)/(2.16) as a third series where they differ, and B on its
//     own scale when it dwarfs A and C (three bodies);
//   - the x-t diagram (worldlines; a sample for large N), with the ghosts' straight
//     worldlines for equal elastic masses;
//   - kinetic energy per body, the total and the heat so far against collision index;
//     momentum of the finite masses;
//   - kinetic energy per body now as bars (small N), or the totals now (large N).
// Each view is drawn by its own functions in src/ros/markers/<view>.cpp; their marker
// namespaces and ids are in markers/ids.h, their layout in markers/layout.h.
//
// They draw a RunRecord (run_record.h), and take the view description (run_view.h).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/run_record.h"

namespace collision_lab_ros {

/// The clock of a run replayed by `rosbag play --clock`: replayedTime while the bag plays, and
/// on from there to endTime(run), as the live view goes, once the run's RunSummary has come.
/// A bag's last message is its RunSummary, stamped at the last collision, and rosbag play's
/// clock stops with it: without this the replay would end frozen at the last impact, before
/// the bodies' final free flight. After the summary the replay goes on in wall time, at the
/// pace the bag played at so far (simulated s per wall s), or on the ROS clock where that is
/// ahead (a bag that goes on).
class ReplayClock {
 public:
  /// Simulated time [s] to show at ROS time `now`, `wall` seconds [s] after the run's
  /// InitialConditions arrived; never past endTime(run).
  double at(const RunRecord& run, const ros::Time& now, double wall);
  /// A new run (or the same bag played again): forget where the last one stopped.
  void reset() { summary_seen_.reset(); }

 private:
  struct Instant {
    double t;     ///< simulated [s]
    double wall;  ///< since the InitialConditions arrived [s]
  };
  std::optional<Instant> summary_seen_;  ///< the first frame after the RunSummary came
};

/// One frame's time line for the status text.
struct FrameClock {
  double t = 0.0;           ///< simulated time requested [s]
  std::string description;  ///< e.g. "slow motion: sim time x0.001", "bag clock"
};

/// The parts that change only when a message arrives (axes, plots, paths, titles).
visualization_msgs::MarkerArray buildStaticMarkers(const RunRecord& run, const std::string& frame_id);
/// The parts that move with simulated time (bodies, labels, cursors, bars).
visualization_msgs::MarkerArray buildAnimatedMarkers(const RunRecord& run, const FrameClock& clock,
                                                     const std::string& frame_id);
/// A banner for a rejected input: its run_id and student, reason, field and message
/// (markers/ids.h: ns kRejected, ids kFramedText, kFramedBox).
std::vector<visualization_msgs::Marker> rejectedBanner(const collision_lab::Rejected& rejected,
                                                       const std::string& frame_id);
/// Before the first run: how to send one, `command` (ns kHint, the same ids and
/// kFramedTextBold: the text is drawn bold, so that its underscores show).
std::vector<visualization_msgs::Marker> hintMarkers(const std::string& command, const std::string& frame_id);
/// Deletes the marker ns/id (when a banner or hint is no longer shown).
visualization_msgs::Marker deleteMarker(const std::string& ns, int id, const std::string& frame_id);
/// Clears every marker of earlier runs.
visualization_msgs::MarkerArray deleteAllMarkers(const std::string& frame_id);

/// rviz's limits (rviz 1.14, Debian 12), applied to every array the view publishes as a
/// last guard (the builders already stay within them): a LINE_STRIP or LINE_LIST longer
/// than kRvizMaxLinePoints is thinned, a list with too few points for its type, a
/// TRIANGLE_LIST not in threes, an odd LINE_LIST, a blank text or a non-finite value is
/// dropped (rviz rejects those with an error). Returns how many markers it changed.
std::size_t enforceRvizLimits(visualization_msgs::MarkerArray& array);

}  // namespace collision_lab_ros
