// rviz markers for one run, built from the run's messages alone (so a live node and a
// bag replay draw the same picture). Three views in one frame, side by side:
//   1. the scene: bodies sized by mass, walls as walls, animated along the exact
//      trajectory, with velocity labels;
//   2. the wedge in velocity space s-perp (the paper's Figure 1): lines L_AB and L_BC, the
//      escape cone, u_perp after each collision (simulated path) and as predicted;
//   3. plots: v_A, v_B, v_C against collision index (simulated lines, predicted points),
//      and kinetic energy per particle as bars, with axis labels.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <visualization_msgs/MarkerArray.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"

namespace collision_lab_ros {

/// What the marker view keeps of one run: everything up to the first N collisions.
struct RunRecord {
  collision_lab::InitialConditions input;
  std::optional<collision_lab::Prediction> prediction;
  std::vector<collision_lab::CollisionEvent> events;
  std::vector<collision_lab::Velocities> velocities;
  std::vector<collision_lab::EnergyTransfer> energies;
  std::optional<collision_lab::RunSummary> summary;
};

/// Positions [m] and velocities [m/s] at simulated time t [s], and how many of the kept
/// collisions have happened by then.
struct SceneState {
  std::array<double, 3> positions{};
  std::array<double, 3> velocities{};
  std::size_t collisions = 0;
};
SceneState stateAt(const RunRecord& run, double t);

/// One loop of the animation in simulated time [s]: past the last kept collision by a
/// quarter, so the bodies are seen flying apart.
double loopDuration(const RunRecord& run);

/// The parts that change only when a message arrives (axes, lines, paths, titles).
visualization_msgs::MarkerArray buildStaticMarkers(const RunRecord& run,
                                                   const std::string& frame_id);
/// The parts that move with simulated time t [s] (bodies, labels, cursors, bars).
visualization_msgs::MarkerArray buildAnimatedMarkers(const RunRecord& run, double t,
                                                     const std::string& frame_id);
/// Clears every marker of earlier runs.
visualization_msgs::MarkerArray deleteAllMarkers(const std::string& frame_id);

}  // namespace collision_lab_ros
