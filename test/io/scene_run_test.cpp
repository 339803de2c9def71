// core::runScene, the entry point for scenes of any size: which path answers, when the
// engine runs, cancellation. Counts are derived by hand in the comments.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

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
  ASSERT_FALSE(core::planScene(scene).error);
  const core::SceneRunResult result = core::runScene(core::planScene(scene), withEvents(core::EventPolicy::all()));
  EXPECT_EQ(result.model.kind, core::ModelKind::kThreeBodyRotation);
  EXPECT_EQ(result.simulation.impact_count, 3u);  // shared/physics.md
  ASSERT_EQ(result.simulation.impacts.size(), 3u);
  // Every impact carries the rotation model's block, its velocities the record's.
  for (const core::ImpactRecord& impact : result.simulation.impacts) {
    ASSERT_TRUE(impact.model.has_value());
    EXPECT_EQ(impact.model->velocities_after[impact.pair_index], impact.velocities_after[0]);
    EXPECT_EQ(impact.model->velocities_after[impact.pair_index + 1], impact.velocities_after[1]);
  }
}

// Plan once (issue 20): planScene validates, chooses the model and predicts; runScene takes
// the plan and neither chooses nor predicts again: a model and a prediction changed in the
// plan are the ones the run reports (predict-only: the prediction is the answer).
TEST(SceneRun, TheRunTakesTheModelAndPredictionOfItsPlan) {
  core::ScenePlan ghosts = core::planScene(cradle());
  ASSERT_FALSE(ghosts.error);
  ASSERT_EQ(ghosts.model.kind, core::ModelKind::kGhosts);
  ASSERT_TRUE(ghosts.prediction && ghosts.prediction->impact_count);
  EXPECT_EQ(*ghosts.prediction->impact_count, 4u);  // shared/physics.md
  ghosts.model.reason = "the plan's reason";
  ghosts.prediction->impact_count = 7;
  core::SceneRunOptions predict_only = withEvents(core::EventPolicy::none());
  predict_only.lab.mode = core::RunMode::kPredictOnly;
  const core::SceneRunResult answered = core::runScene(ghosts, predict_only);
  EXPECT_EQ(answered.model.reason, "the plan's reason");
  EXPECT_EQ(answered.simulation.impact_count, 7u);

  core::ScenePlan triple = core::planScene({{1, 1, 1}, {2, 1, -1}, {-1, 0, 1}, {}});
  ASSERT_TRUE(triple.prediction && triple.prediction->impact_count);
  EXPECT_EQ(*triple.prediction->impact_count, 3u);  // shared/physics.md
  triple.prediction->impact_count = 5;
  const core::SceneRunResult run = core::runScene(triple, predict_only);
  EXPECT_EQ(run.model.kind, core::ModelKind::kThreeBodyRotation);
  EXPECT_EQ(run.simulation.impact_count, 5u);

  const core::ScenePlan rejected = core::planScene({{1, 1}, {0, 1}, {1, 0}, {}});
  ASSERT_TRUE(rejected.error);
  EXPECT_EQ(rejected.error->reason, core::Reason::kPositionsNotOrdered);
  EXPECT_FALSE(rejected.prediction);
}

// One run result (issue 20): the simulation summary is filled for three bodies too, with
// the engine's count and final state; the over-cap rule answers from the model there too.
TEST(SceneRun, ThreeBodiesFillTheSimulationSummaryLikeEveryScene) {
  // The node's round-trip scene; the summary is the engine's run of the same scene
  // (bit-identical, test_three_body_rounding.cpp).
  const core::Scene scene{{1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1}, {}};
  const core::ScenePlan plan = core::planScene(scene);
  ASSERT_FALSE(plan.error);
  const core::SceneRunResult result = core::runScene(plan, withEvents(core::EventPolicy::none()));
  ASSERT_EQ(result.model.kind, core::ModelKind::kThreeBodyRotation);
  const core::SceneSimulation engine = core::runEngine(scene);
  EXPECT_TRUE(result.simulation.simulated);
  EXPECT_FALSE(result.simulation.truncated);
  EXPECT_EQ(result.simulation.stop, core::StopReason::kFinished);
  EXPECT_EQ(result.simulation.impact_count, engine.impact_count);
  EXPECT_EQ(result.simulation.impact_count, *plan.prediction->impact_count);
  EXPECT_EQ(result.simulation.final_velocities, engine.final_velocities);
  ASSERT_TRUE(result.simulation.matches_prediction.has_value());
  EXPECT_TRUE(*result.simulation.matches_prediction);
  EXPECT_LE(result.simulation.max_prediction_error, 1e-15);
  EXPECT_EQ(result.simulation.energy_lost, 0.0);

  // (1e12, 1, 1e12): 2,221,441 impacts (physics.md), over a cap of 1000: not simulated.
  core::SceneRunOptions capped = withEvents(core::EventPolicy::none());
  capped.lab.max_collisions = 1000;
  const core::SceneRunResult over =
      core::runScene(core::planScene({{1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0}, {}}), capped);
  EXPECT_FALSE(over.simulation.simulated);
  EXPECT_FALSE(over.simulation.truncated);
  EXPECT_EQ(over.simulation.impact_count, 2221441u);
  ASSERT_TRUE(over.prediction);
  EXPECT_EQ(over.simulation.final_velocities, over.prediction->final_velocities);
}

// One validation for every N and e (issue 20): a wall in the middle was INFINITE_MIDDLE_MASS
// for three elastic bodies and WALL_NOT_AT_END otherwise (failed before).
TEST(SceneRun, OneValidationGivesOneReasonWhateverNAndE) {
  core::Scene middle_wall{{1, INFINITY, 1}, {2, 1, 0}, {-1, 0, 0}, {}};
  EXPECT_EQ(core::planScene(middle_wall).error->reason, core::Reason::kWallNotAtEnd);
  const std::string message = core::planScene(middle_wall).error->message;
  middle_wall.restitution = {0.5};
  EXPECT_EQ(core::planScene(middle_wall).error->reason, core::Reason::kWallNotAtEnd);
  EXPECT_EQ(core::planScene(middle_wall).error->message, message);
  const core::Scene five{{1, 1, INFINITY, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}, {}};
  EXPECT_EQ(core::planScene(five).error->reason, core::Reason::kWallNotAtEnd);
  const core::Scene two_walls{{INFINITY, 1, INFINITY}, {2, 1, 0}, {0, 1, 0}, {}};
  EXPECT_FALSE(core::planScene(two_walls).error);
  EXPECT_EQ(core::planScene(two_walls).model.kind, core::ModelKind::kTwoWallsInfinite);
}

// The cradle: 4 impacts (shared/physics.md). Without events the closed form answers alone.
TEST(SceneRun, GhostsRunTheEngineOnlyWhenEventsAreAsked) {
  const core::SceneRunResult closed = core::runScene(core::planScene(cradle()), withEvents(core::EventPolicy::none()));
  EXPECT_FALSE(closed.simulation.simulated);
  EXPECT_EQ(closed.simulation.impact_count, 4u);

  std::size_t visited = 0;
  core::SceneVisitors visitors;
  visitors.impact = [&](const core::ImpactRecord&) { ++visited; };
  const core::SceneRunResult simulated = core::runScene(core::planScene(cradle()), withEvents(core::EventPolicy::all()), visitors);
  EXPECT_TRUE(simulated.simulation.simulated);
  EXPECT_EQ(simulated.simulation.impact_count, 4u);
  EXPECT_EQ(visited, 4u);
  ASSERT_TRUE(simulated.simulation.matches_prediction.has_value());
  EXPECT_TRUE(*simulated.simulation.matches_prediction);
  EXPECT_EQ(simulated.simulation.max_prediction_error, 0.0);
}

// max_prediction_error has one meaning (docs/cli.md): for the rotation model, the largest
// energy-norm error over every impact, also for a run cut at the cap; the scene's summary
// and the model's own carry the same number (failed before: the scene's summary compared
// the end only, in another norm, and was NaN when cut).
TEST(SceneRun, ThePredictionErrorOfThreeBodiesIsTheModelsOverEveryImpact) {
  core::Scene pi;
  pi.masses = {1e4, 1, std::numeric_limits<double>::infinity()};
  pi.positions = {2, 1, 0};
  pi.velocities = {-1, 0, 0};
  for (const std::uint64_t cap : {std::uint64_t{1000}, std::uint64_t{100}}) {
    core::SceneRunOptions options = withEvents(core::EventPolicy::all());
    options.lab.max_collisions = cap;
    options.simulate_to_cap = true;
    const core::SceneRunResult run = core::runScene(core::planScene(pi), options);
    EXPECT_EQ(run.simulation.impact_count, std::min<std::uint64_t>(cap, 314));
    // The largest energy-norm error over the impacts' model blocks (S = diag(sqrt m), the
    // wall's weight 0, v0 in the wall's frame: |S v0| = sqrt(1e4)).
    ASSERT_EQ(run.simulation.impacts.size(), run.simulation.impact_count);
    double largest = 0.0;
    for (const core::ImpactRecord& impact : run.simulation.impacts) {
      const auto& m = *impact.model;
      double norm_sq = 0.0;
      for (int i = 0; i < 2; ++i) {
        const double d = m.velocities_after[i] - m.predicted_velocities_after[i];
        norm_sq += pi.masses[i] * d * d;
      }
      largest = std::max(largest, std::sqrt(norm_sq) / 100.0);
    }
    const double model = run.simulation.max_prediction_error;
    EXPECT_TRUE(std::isfinite(model));
    EXPECT_LT(model, 1e-12);
    EXPECT_NEAR(model, largest, 1e-18);
  }
}

// A ball between walls would collide forever; a set cancel flag stops the engine at once,
// truncated (the engine checks it every 1024 impacts).
TEST(SceneRun, TheCancelFlagStopsTheEngineWithAPartialSummary) {
  const core::Scene scene{{INFINITY, 1, INFINITY}, {1, 0.5, 0}, {0, 1, 0}, {}};
  std::atomic<bool> cancel{true};
  core::SceneRunOptions options = withEvents(core::EventPolicy::none());
  options.cancel = &cancel;
  const core::SceneRunResult result = core::runScene(core::planScene(scene), options);
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
  const core::SceneRunResult result = core::runScene(core::planScene(scene), options);
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
  const core::SceneRunResult answered = core::runScene(core::planScene(cradle()), options, visitors);
  EXPECT_FALSE(answered.simulation.simulated);
  EXPECT_FALSE(answered.simulation.truncated);
  EXPECT_EQ(answered.simulation.impact_count, 4u);
  EXPECT_EQ(answered.simulation.final_velocities, (std::vector<double>{0, 0, 0, 0, -1}));
  EXPECT_EQ(visited, 0u);

  options.simulate_to_cap = true;
  const core::SceneRunResult simulated = core::runScene(core::planScene(cradle()), options, visitors);
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
  const core::SceneRunResult result = core::runScene(core::planScene(scene), options);
  EXPECT_EQ(result.model.kind, core::ModelKind::kThreeBodyRotation);
  EXPECT_FALSE(result.simulation.simulated);
  EXPECT_FALSE(result.simulation.truncated);
  EXPECT_EQ(result.simulation.impact_count, 314u);
  EXPECT_TRUE(result.simulation.impacts.empty());
}

// A ball between walls 1 m apart: infinitely many impacts, 1,000 simulated for display
// (not the cap of 10^7) unless asked.
TEST(SceneRun, TwoWallsAreSimulatedForDisplayOnly) {
  const core::Scene scene{{INFINITY, 1, INFINITY}, {1, 0.5, 0}, {0, 1, 0}, {}};
  core::SceneRunOptions options = withEvents(core::EventPolicy::none());
  const core::SceneRunResult shown = core::runScene(core::planScene(scene), options);
  EXPECT_TRUE(shown.simulation.truncated);
  EXPECT_EQ(shown.simulation.impact_count, core::kInfiniteRunDisplayCap);
  options.simulate_to_cap = true;
  options.lab.max_collisions = 5000;
  EXPECT_EQ(core::runScene(core::planScene(scene), options).simulation.impact_count, 5000u);
}

// plannedImpacts (what the node's lanes follow) is the run's own decision: 0 where the model
// answers alone, else the impacts the run simulates, or empty where the plan cannot count them
// (then the run is simulated, to its end or the cap).
TEST(SceneRun, PlannedImpactsAreTheImpactsTheRunSimulates) {
  std::vector<core::Scene> scenes = {
      core::Scene{{100, 1, INFINITY}, {2, 1, 0}, {-1, 0, 0}, {}},     // 31 impacts, the rotation model
      core::Scene{{1e6, 1, INFINITY}, {2, 1, 0}, {-1, 0, 0}, {}},     // 3,141 impacts
      cradle(),                                                      // equal masses: counted inversions
      core::Scene{{INFINITY, 1, INFINITY}, {1, 0.5, 0}, {0, 1, 0}, {}},  // two walls: endless
      core::Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.05}},          // the spiral collapses
      core::Scene{{2, 1}, {1, 0}, {-1, 1}, {0.5}},                    // two bodies
      core::Scene{{1, 3, 2, 5}, {3, 2, 1, 0}, {-1, 0.5, 0, 1}, {0.9}},  // no closed form
  };
  int counted = 0, uncounted = 0, answered = 0;
  for (const core::Scene& scene : scenes) {
    const core::ScenePlan plan = core::planScene(scene);
    ASSERT_FALSE(plan.error) << plan.error->message;
    for (const core::RunMode mode : {core::RunMode::kFull, core::RunMode::kSummaryOnly, core::RunMode::kPredictOnly}) {
      for (const bool events : {true, false}) {
        for (const std::uint64_t cap : {std::uint64_t{20}, std::uint64_t{100'000}}) {
          for (const bool to_cap : {false, true}) {
            core::SceneRunOptions options = withEvents(events ? core::EventPolicy::all() : core::EventPolicy::none());
            options.lab.mode = mode;
            options.lab.max_collisions = cap;
            options.simulate_to_cap = to_cap;
            const std::optional<std::uint64_t> planned = core::plannedImpacts(plan, options);
            const core::SceneSimulation run = core::runScene(plan, options).simulation;
            const std::string what = "scene " + std::to_string(&scene - scenes.data()) + " mode " +
                                     std::to_string(static_cast<int>(mode)) + " events " + std::to_string(events) +
                                     " cap " + std::to_string(cap) + " to_cap " + std::to_string(to_cap);
            if (!planned) {
              ++uncounted;
              EXPECT_TRUE(run.simulated) << what;
              EXPECT_LE(run.impact_count, cap) << what;
            } else if (*planned == 0) {
              ++answered;
              EXPECT_FALSE(run.simulated) << what;
            } else {
              ++counted;
              EXPECT_TRUE(run.simulated) << what;
              EXPECT_EQ(run.impact_count, *planned) << what;
            }
          }
        }
      }
    }
  }
  // Every kind of answer was met.
  EXPECT_GT(counted, 0);
  EXPECT_GT(uncounted, 0);
  EXPECT_GT(answered, 0);
}

// The engine's run keeps the events asked for, as the three-body path does (failed before:
// none kept, so a batch lost them).
TEST(SceneRun, TheEngineKeepsTheEventsAskedFor) {
  core::SceneRunOptions options = withEvents(core::EventPolicy::firstN(2));
  const core::SceneRunResult result = core::runScene(core::planScene(cradle()), options);
  ASSERT_EQ(result.simulation.impacts.size(), 2u);
  EXPECT_EQ(result.simulation.impacts[1].pair_index, 1u);
  EXPECT_EQ(result.simulation.impacts[1].time, 2.0);
  options.keep_events = false;
  EXPECT_TRUE(core::runScene(core::planScene(cradle()), options).simulation.impacts.empty());
}

}  // namespace

// One prediction type (issue 32): the rotation model's prediction is a core::Prediction like
// every model's, with the paper's count, the bound ceil(pi / alpha), the angles and the first
// pair. Pi billiard (100, 1, inf): 31 impacts (shared/physics.md); alpha = atan(1/10) since
// m_B / m_A = 1/100 with the wall C; at most ceil(pi / alpha) = 32; A meets B first.
TEST(SceneRun, TheRotationModelPredictsInTheOnePredictionType) {
  const double inf = std::numeric_limits<double>::infinity();
  const core::ScenePlan plan = core::planScene({{100, 1, inf}, {2, 1, 0}, {-1, 0, 0}, {}});
  ASSERT_FALSE(plan.error);
  ASSERT_EQ(plan.model.kind, core::ModelKind::kThreeBodyRotation);
  ASSERT_TRUE(plan.prediction);
  const core::Prediction& p = *plan.prediction;
  EXPECT_EQ(p.kind, core::ModelKind::kThreeBodyRotation);
  ASSERT_TRUE(p.impact_count);
  EXPECT_EQ(*p.impact_count, 31u);
  ASSERT_TRUE(p.max_possible_impact_count && p.alpha && p.theta && p.omega && p.first_pair_index);
  EXPECT_EQ(*p.max_possible_impact_count, 32u);
  EXPECT_NEAR(*p.alpha, std::atan(0.1), 1e-15);
  EXPECT_NEAR(*p.theta, 2 * std::atan(0.1), 1e-15);
  EXPECT_NEAR(*p.omega, M_PI - std::atan(0.1), 1e-15);
  EXPECT_EQ(*p.first_pair_index, 0u);
  EXPECT_EQ(p.energy_lost, 0.0);
  ASSERT_EQ(p.final_velocities.size(), 3u);
  const core::SceneRunResult run = core::runScene(plan, withEvents(core::EventPolicy::none()));
  EXPECT_EQ(run.simulation.impact_count, 31u);
  ASSERT_TRUE(run.prediction && run.prediction->impact_count);
  EXPECT_EQ(*run.prediction->impact_count, 31u);
}

// One answer to "which model?" (issue 32): three elastic bodies whose momentum in the wall's
// frame overflows a double are beyond the rotation model's range. validate(Scene) accepts
// them (every value in the lab frame is a double), and the plan's model says what runs them:
// the engine, not the rotation model. B (1 kg at 1e154 m/s) meets the wall C at -1e154 m/s:
// m (v_B - v_C)^2 = 4e308 overflows. A (0.5 kg) moves with the wall.
TEST(SceneRun, ThreeElasticBodiesBeyondTheRotationRangeAreTheEnginesInThePlan) {
  const double inf = std::numeric_limits<double>::infinity();
  const core::Scene scene{{0.5, 1, inf}, {2, 1, 0}, {-1e154, 1e154, -1e154}, {}};
  const core::ScenePlan plan = core::planScene(scene);
  ASSERT_FALSE(plan.error) << plan.error->message;
  EXPECT_EQ(plan.model.kind, core::ModelKind::kEventEngine);
  EXPECT_EQ(core::chooseModel(scene).kind, core::ModelKind::kEventEngine);
  EXPECT_FALSE(plan.prediction);
  const core::SceneRunResult run = core::runScene(plan, withEvents(core::EventPolicy::none()));
  EXPECT_TRUE(run.simulation.simulated);
  EXPECT_TRUE(run.simulation.impacts.empty());
}

// Three elastic bodies that never meet keep the rotation model's values beside the model's
// answer (the CLI and the node print them): count 0, the bound and the angles.
TEST(SceneRun, ThreeElasticBodiesThatNeverMeetKeepTheRotationValues) {
  const core::ScenePlan plan = core::planScene({{1, 1, 1}, {3, 2, 1}, {1, 0, -1}, {}});
  ASSERT_FALSE(plan.error);
  EXPECT_EQ(plan.model.kind, core::ModelKind::kNoCollisions);
  ASSERT_TRUE(plan.prediction && plan.prediction->impact_count && plan.prediction->max_possible_impact_count);
  EXPECT_EQ(*plan.prediction->impact_count, 0u);
  EXPECT_EQ(*plan.prediction->max_possible_impact_count, 3u);  // equal masses: alpha = pi/3
  EXPECT_FALSE(plan.prediction->first_pair_index);
}
