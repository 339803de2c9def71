// rviz markers from a run's messages (no master).
#include <cmath>
#include <limits>
#include <set>

#include <gtest/gtest.h>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/msg_conversion.h"

namespace {

using namespace collision_lab_ros;

/// The whole run of a scene, as the node would publish it.
RunRecord recordOf(const std::array<double, 3>& masses, const std::array<double, 3>& positions,
                   const std::array<double, 3>& velocities) {
  core::Scene scene;
  scene.masses = masses;
  scene.positions = positions;
  scene.velocities = velocities;
  RunRecord run;
  run.input = toInitialConditions(scene, core::RunMode::kFull, 0);
  run.input.run_id = "markers";
  core::RunOptions options;
  const core::RunResult result = collision_lab::runLab(scene, options);
  run.prediction = toPredictionMsg(result.prediction);
  for (const auto& e : result.events) {
    run.events.push_back(toCollisionEventMsg(e));
    run.velocities.push_back(toVelocitiesMsg(e));
    run.energies.push_back(toEnergyTransferMsg(e));
  }
  run.summary = toRunSummaryMsg(result.summary, result.prediction, core::RunMode::kFull);
  return run;
}

TEST(MarkerBuilder, StateFollowsTheExactTrajectory) {
  const RunRecord run = recordOf({1, 1, 1}, {2, 1, -1}, {-1, 0, 1});
  ASSERT_EQ(run.events.size(), 3u);
  const SceneState start = stateAt(run, 0.0);
  EXPECT_EQ(start.collisions, 0u);
  EXPECT_DOUBLE_EQ(start.positions[0], 2.0);
  const SceneState half = stateAt(run, 0.5);
  EXPECT_DOUBLE_EQ(half.positions[0], 1.5);
  EXPECT_DOUBLE_EQ(half.positions[2], -0.5);
  // At each collision the bodies are where the event says.
  for (std::size_t k = 0; k < run.events.size(); ++k) {
    const auto& e = run.events[k];
    const SceneState at = stateAt(run, e.time);
    EXPECT_EQ(at.collisions, k + 1);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(at.positions[i], e.positions[i], 1e-12);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(at.velocities[i], e.velocities_after[i]);
  }
  EXPECT_GT(loopDuration(run), run.events.back().time);
}

void expectWellFormed(const visualization_msgs::MarkerArray& array) {
  std::set<std::pair<std::string, int>> ids;
  for (const auto& m : array.markers) {
    EXPECT_EQ(m.header.frame_id, "f");
    EXPECT_TRUE(ids.insert({m.ns, m.id}).second) << "duplicate " << m.ns << "/" << m.id;
    for (const auto& p : m.points) {
      EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << m.ns;
    }
    EXPECT_TRUE(std::isfinite(m.pose.position.x) && std::isfinite(m.pose.position.y)) << m.ns;
    EXPECT_GT(m.scale.x, 0) << m.ns;
  }
}

TEST(MarkerBuilder, ThreeViewsWellFormedWithAndWithoutWalls) {
  const double inf = std::numeric_limits<double>::infinity();
  for (const RunRecord& run : {recordOf({1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1}),
                               recordOf({100, 1, inf}, {2, 1, 0}, {-1, 0, 0}),
                               recordOf({1, 1, 1}, {2, 1, 0}, {1, 0, -1})}) {
    SCOPED_TRACE(run.events.size());
    const auto fixed = buildStaticMarkers(run, "f");
    expectWellFormed(fixed);
    std::set<std::string> namespaces;
    for (const auto& m : fixed.markers) namespaces.insert(m.ns);
    EXPECT_TRUE(namespaces.count("scene") && namespaces.count("wedge") &&
                namespaces.count("plot") && namespaces.count("energy"));
    for (double t : {0.0, 0.5 * loopDuration(run), loopDuration(run)}) {
      const auto animated = buildAnimatedMarkers(run, t, "f");
      expectWellFormed(animated);
      EXPECT_GE(animated.markers.size(), 10u);
    }
  }
}

TEST(MarkerBuilder, WedgePathStaysOnItsCircle) {
  // |u_perp| is conserved by every collision, so every simulated point of the path lies
  // on one circle around the wedge's centre.
  const RunRecord run = recordOf({1e4, 1, std::numeric_limits<double>::infinity()}, {2, 1, 0},
                                 {-1, 0, 0});
  const auto fixed = buildStaticMarkers(run, "f");
  const visualization_msgs::Marker* path = nullptr;
  const visualization_msgs::Marker* circle = nullptr;
  for (const auto& m : fixed.markers) {
    if (m.ns == "wedge" && m.type == visualization_msgs::Marker::SPHERE_LIST && !path) path = &m;
    if (m.ns == "wedge" && m.type == visualization_msgs::Marker::LINE_STRIP && !circle) circle = &m;
  }
  ASSERT_TRUE(path && circle);
  ASSERT_EQ(path->points.size(), run.events.size() + 1);
  const double cx = (circle->points[0].x + circle->points[48].x) / 2;
  const double cy = (circle->points[0].y + circle->points[48].y) / 2;
  const double r = std::hypot(circle->points[0].x - cx, circle->points[0].y - cy);
  for (const auto& p : path->points) EXPECT_NEAR(std::hypot(p.x - cx, p.y - cy), r, 1e-6 * r);
}

}  // namespace
