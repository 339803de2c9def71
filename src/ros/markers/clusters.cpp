// Clusters: neighbours moving together (stuck by e = 0, or one after an inelastic collapse;
// the cluster rule, core/nbody/engine.h). The messages put a cluster's bodies at one point
// with one velocity, so equal positions and velocities (exactly) are what joins them. Drawn
// joined in the scene (an amber ring around the bodies; their names in the note row) and as one thick amber
// worldline in the x-t diagram (worldlines.cpp).
#include <algorithm>
#include <cmath>

#include "collision_lab/ros/markers/draw.h"

namespace collision_lab_ros::markers {

using namespace layout;

bool mayCluster(const RunRecord& run) {
  const auto& e = run.input().restitution;
  return run.collapses() > 0 || std::any_of(e.begin(), e.end(), [](double value) { return value == 0.0; });
}

std::vector<std::pair<std::size_t, std::size_t>> clustersOf(const RunRecord& run, const std::vector<double>& x,
                                                            const std::vector<double>& v) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  const std::size_t n = std::min(x.size(), v.size());
  for (std::size_t first = 0; first < n;) {
    std::size_t last = first;
    while (last + 1 < n && !run.isWall(last) && !run.isWall(last + 1) && x[last + 1] == x[last] &&
           v[last + 1] == v[last]) {
      ++last;
    }
    if (last > first) out.emplace_back(first, last);
    first = last + 1;
  }
  return out;
}

void drawClusters(const Canvas& c, const SceneState& state) {
  std::vector<std::pair<std::size_t, std::size_t>> clusters;
  if (mayCluster(c.run)) clusters = clustersOf(c.run, state.positions, state.velocities);
  const SceneAxis axis = bodiesAxis(c.run, state);
  // Small scenes: around the largest body (kSmallestBody + kBodyGrowth); large: the largest class.
  const double radius = (largeScene(c.run) ? kManyBodySize + kManyBodyGrowth * (kMassClasses - 1)
                                           : kSmallestBody + kBodyGrowth) / 2 + kClusterRingMargin;
  Marker rings = c.lines(ns::kClusters, kClusterRings, Marker::LINE_LIST, kClusterRingWidth, color(kClusterAmber));
  std::string names;
  for (std::size_t k = 0; k < clusters.size(); ++k) {
    const auto [first, last] = clusters[k];
    const double x = axis.toX(state.positions[first]);
    for (int s = 0; s < kClusterRingSegments; ++s) {
      for (int end : {s, s + 1}) {
        const double angle = 2 * M_PI * end / kClusterRingSegments;
        rings.points.push_back(point(x + radius * std::cos(angle), kSceneY + radius * std::sin(angle), kDotZ));
      }
    }
    if (k < kMaxClusterNames) {
      names += (k ? ", " : "") + bodyName(first) + (last == first + 1 ? "+" : "..") + bodyName(last) +
               " (" + withSeparators(last - first + 1) + ")";
    }
  }
  if (clusters.size() > kMaxClusterNames) names += " and " + withSeparators(clusters.size() - kMaxClusterNames) + " more";
  if (clusters.empty()) {
    c.add(deleteMarker(ns::kClusters, kClusterRings, c.frame_id));
    c.add(deleteMarker(ns::kClusters, kClusterLabel, c.frame_id));
    return;
  }
  c.addLines(rings);
  // In the note row's right part: the bodies' own tags crowd around the ring.
  c.add(c.text(ns::kClusters, kClusterLabel, kClusterNamesX, kNoteY, "moving as one (amber rings): " + names,
               kSmallTextSize, color(kClusterAmber)));
}

}  // namespace collision_lab_ros::markers
