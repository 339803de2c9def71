#include "collision_lab/ros/marker_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_lab/ros/markers/draw.h"
#include "collision_lab/ros/msg_conversion.h"

namespace collision_lab_ros {

double ReplayClock::at(const RunRecord& run, const ros::Time& now, double wall) {
  const double end = endTime(run);
  const double on_bag_clock = std::min(replayedTime(run, now), end);
  if (!run.summary) {
    summary_seen_.reset();
    return on_bag_clock;
  }
  if (!summary_seen_) summary_seen_ = Instant{on_bag_clock, wall};
  const Instant& seen = *summary_seen_;
  // The pace so far, or the timeline's (rate 1) when nothing has been played yet.
  const double scale = run.prediction && std::isfinite(run.prediction->timeline_scale) &&
                               run.prediction->timeline_scale > 0
                           ? run.prediction->timeline_scale
                           : 1.0;
  const double pace = seen.t > 0 && seen.wall > 0 ? seen.t / seen.wall : 1.0 / scale;
  return std::min(std::max(on_bag_clock, seen.t + std::max(wall - seen.wall, 0.0) * pace), end);
}

// ---- the pictures: one function per view (src/ros/markers/) ----

visualization_msgs::MarkerArray buildStaticMarkers(const RunRecord& run, const std::string& frame_id) {
  visualization_msgs::MarkerArray array;
  const RunView view = makeRunView(run);
  const markers::Canvas canvas{run, view, frame_id, array.markers};
  markers::drawTitle(canvas);
  markers::drawSceneAxis(canvas);
  markers::drawWedge(canvas);
  markers::drawSideViewAxes(canvas);
  markers::drawVelocitySteps(canvas);
  markers::drawConservedSteps(canvas);
  markers::drawWorldlines(canvas);
  markers::drawEnergyBarsAxis(canvas);
  markers::drawTemperature(canvas);
  return array;
}

visualization_msgs::MarkerArray buildAnimatedMarkers(const RunRecord& run, const FrameClock& clock,
                                                     const std::string& frame_id) {
  visualization_msgs::MarkerArray array;
  const RunView view = makeRunView(run);
  const markers::Canvas canvas{run, view, frame_id, array.markers};
  const SceneState state = stateAt(run, clock.t);
  markers::drawBodies(canvas, state);
  markers::drawMagnifier(canvas, state);
  markers::drawStatus(canvas, state, clock);
  markers::drawWedgeCursor(canvas, state);
  markers::drawSideViewNow(canvas, state);
  markers::drawStepsCursor(canvas, state);
  markers::drawWorldlinesCursor(canvas, state);
  markers::drawEnergyBars(canvas, state);
  markers::drawTemperatureNow(canvas, state);
  markers::drawClusters(canvas, state);
  return array;
}

}  // namespace collision_lab_ros
