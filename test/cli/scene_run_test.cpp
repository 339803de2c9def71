// core::runScene, the entry point for scenes of any size: which path answers, when the
// engine runs, cancellation. Counts are derived by hand in the comments.
#include <gtest/gtest.h>

#include <atomic>

#include "collision_lab/core/scene_run.h"

namespace {

namespace core = collision_lab::core;

core::Scene cradle() { return core::Scene{{1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}, {}}; }

core::SceneRunOptions withEvents(core::EventPolicy events) {
  core::SceneRunOptions options;
  options.lab.events = events;
  return options;
}

TEST(SceneRun, ThreeElasticBodiesTakeTheThreeBodyPath) {
  const core::Scene scene{{1, 1, 1}, {2, 1, -1}, {-1, 0, 1}, {}};
  ASSERT_FALSE(core::validateForRun(scene));
  const core::SceneRunResult result = core::runScene(scene, withEvents(core::EventPolicy::all()));
  ASSERT_TRUE(result.three_body.has_value());
  EXPECT_EQ(result.model.kind, core::ModelKind::kThreeBodyRotation);
  EXPECT_EQ(result.three_body->summary.collision_count, 3u);  // shared/physics.md
  EXPECT_EQ(result.three_body->events.size(), 3u);
}

TEST(SceneRun, ThreeBodiesKeepTheirThreeBodyRejections) {
  const core::Scene middle_wall{{1, INFINITY, 1}, {2, 1, 0}, {-1, 0, 0}, {}};
  EXPECT_EQ(core::validateForRun(middle_wall)->reason, core::Reason::kInfiniteMiddleMass);
  const core::Scene five{{1, 1, INFINITY, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}, {}};
  EXPECT_EQ(core::validateForRun(five)->reason, core::Reason::kWallNotAtEnd);
  const core::Scene two_walls{{INFINITY, 1, INFINITY}, {2, 1, 0}, {0, 1, 0}, {}};
  EXPECT_FALSE(core::validateForRun(two_walls));
  EXPECT_FALSE(core::usesThreeBodyPath(two_walls));
}

// The cradle: 4 impacts (shared/physics.md). Without events the closed form answers alone.
TEST(SceneRun, GhostsRunTheEngineOnlyWhenEventsAreAsked) {
  const core::SceneRunResult closed = core::runScene(cradle(), withEvents(core::EventPolicy::none()));
  EXPECT_FALSE(closed.simulation.simulated);
  EXPECT_EQ(closed.simulation.impact_count, 4u);

  std::size_t visited = 0;
  core::SceneVisitors visitors;
  visitors.impact = [&](const core::ImpactRecord&) { ++visited; };
  const core::SceneRunResult simulated = core::runScene(cradle(), withEvents(core::EventPolicy::all()), visitors);
  EXPECT_TRUE(simulated.simulation.simulated);
  EXPECT_EQ(simulated.simulation.impact_count, 4u);
  EXPECT_EQ(visited, 4u);
  ASSERT_TRUE(simulated.simulation.matches_prediction.has_value());
  EXPECT_TRUE(*simulated.simulation.matches_prediction);
  EXPECT_EQ(simulated.simulation.max_prediction_error, 0.0);
}

// A ball between walls would collide forever; a set cancel flag stops the engine at once,
// truncated (the engine checks it every 1024 impacts).
TEST(SceneRun, TheCancelFlagStopsTheEngineWithAPartialSummary) {
  const core::Scene scene{{INFINITY, 1, INFINITY}, {1, 0.5, 0}, {0, 1, 0}, {}};
  std::atomic<bool> cancel{true};
  core::SceneRunOptions options = withEvents(core::EventPolicy::none());
  options.cancel = &cancel;
  const core::SceneRunResult result = core::runScene(scene, options);
  EXPECT_TRUE(result.simulation.simulated);
  EXPECT_TRUE(result.simulation.truncated);
  EXPECT_EQ(result.simulation.stop, core::StopReason::kCancelled);
  EXPECT_LE(result.simulation.impact_count, 1024u);
  ASSERT_TRUE(result.prediction.has_value());
  EXPECT_TRUE(result.prediction->infinite);
}

TEST(SceneRun, PredictOnlyWithoutAClosedFormSimulatesNothing) {
  const core::Scene scene{{1, 2, 3, 4}, {3, 2, 1, 0}, {-1, 0, 0, 1}, {}};
  core::SceneRunOptions options;
  options.lab.mode = core::RunMode::kPredictOnly;
  const core::SceneRunResult result = core::runScene(scene, options);
  EXPECT_EQ(result.model.kind, core::ModelKind::kEventEngine);
  EXPECT_FALSE(result.prediction.has_value());
  EXPECT_FALSE(result.simulation.simulated);
}

}  // namespace
