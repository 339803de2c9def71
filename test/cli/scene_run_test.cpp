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

// One validation for every N and e (issue 20): a wall in the middle was INFINITE_MIDDLE_MASS
// for three elastic bodies and WALL_NOT_AT_END otherwise (failed before).
TEST(SceneRun, OneValidationGivesOneReasonWhateverNAndE) {
  core::Scene middle_wall{{1, INFINITY, 1}, {2, 1, 0}, {-1, 0, 0}, {}};
  EXPECT_EQ(core::validateForRun(middle_wall)->reason, core::Reason::kWallNotAtEnd);
  const std::string message = core::validateForRun(middle_wall)->message;
  middle_wall.restitution = {0.5};
  EXPECT_EQ(core::validateForRun(middle_wall)->reason, core::Reason::kWallNotAtEnd);
  EXPECT_EQ(core::validateForRun(middle_wall)->message, message);
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

// ---- The over-cap rule (issue 20): the model answers when it predicts more than the cap ----

// The cradle's 4 impacts over a cap of 3, every event asked for: the ghosts model answers
// (failed before: the engine simulated up to the cap); asked to, the engine runs to the cap.
TEST(SceneRun, OverTheCapTheModelAnswersUnlessAskedToSimulate) {
  core::SceneRunOptions options = withEvents(core::EventPolicy::all());
  options.lab.max_collisions = 3;
  std::size_t visited = 0;
  core::SceneVisitors visitors;
  visitors.impact = [&](const core::ImpactRecord&) { ++visited; };
  const core::SceneRunResult answered = core::runScene(cradle(), options, visitors);
  EXPECT_FALSE(answered.simulation.simulated);
  EXPECT_FALSE(answered.simulation.truncated);
  EXPECT_EQ(answered.simulation.impact_count, 4u);
  EXPECT_EQ(answered.simulation.final_velocities, (std::vector<double>{0, 0, 0, 0, -1}));
  EXPECT_EQ(visited, 0u);

  options.simulate_to_cap = true;
  const core::SceneRunResult simulated = core::runScene(cradle(), options, visitors);
  EXPECT_TRUE(simulated.simulation.simulated);
  EXPECT_TRUE(simulated.simulation.truncated);
  EXPECT_EQ(simulated.simulation.impact_count, 3u);
  EXPECT_EQ(visited, 3u);
}

// Galperin's billiard with m_A / m_B = 1e4: 314 collisions (config/scenarios.yaml,
// pi_digits_3) over a cap of 100: the closed form answers, its count the run's.
TEST(SceneRun, OverTheCapTheThreeBodyModelAnswersWithItsCount) {
  const core::Scene scene{{1e4, 1, INFINITY}, {2, 1, 0}, {-1, 0, 0}, {}};
  core::SceneRunOptions options = withEvents(core::EventPolicy::all());
  options.lab.max_collisions = 100;
  const core::SceneRunResult result = core::runScene(scene, options);
  ASSERT_TRUE(result.three_body.has_value());
  EXPECT_FALSE(result.three_body->summary.simulated);
  EXPECT_FALSE(result.three_body->summary.truncated);
  EXPECT_EQ(result.three_body->summary.collision_count, 314u);
  EXPECT_TRUE(result.three_body->events.empty());
}

// A ball between walls 1 m apart: infinitely many impacts, 1,000 simulated for display
// (not the cap of 10^7) unless asked.
TEST(SceneRun, TwoWallsAreSimulatedForDisplayOnly) {
  const core::Scene scene{{INFINITY, 1, INFINITY}, {1, 0.5, 0}, {0, 1, 0}, {}};
  core::SceneRunOptions options = withEvents(core::EventPolicy::none());
  const core::SceneRunResult shown = core::runScene(scene, options);
  EXPECT_TRUE(shown.simulation.truncated);
  EXPECT_EQ(shown.simulation.impact_count, core::kInfiniteRunDisplayCap);
  options.simulate_to_cap = true;
  options.lab.max_collisions = 5000;
  EXPECT_EQ(core::runScene(scene, options).simulation.impact_count, 5000u);
}

// The engine's run keeps the events asked for, as the three-body path does (failed before:
// none kept, so a batch lost them).
TEST(SceneRun, TheEngineKeepsTheEventsAskedFor) {
  core::SceneRunOptions options = withEvents(core::EventPolicy::firstN(2));
  const core::SceneRunResult result = core::runScene(cradle(), options);
  ASSERT_EQ(result.simulation.impacts.size(), 2u);
  EXPECT_EQ(result.simulation.impacts[1].pair_index, 1u);
  EXPECT_EQ(result.simulation.impacts[1].time, 2.0);
  options.keep_events = false;
  EXPECT_TRUE(core::runScene(cradle(), options).simulation.impacts.empty());
}

}  // namespace
