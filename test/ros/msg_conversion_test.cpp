// Message <-> core conversions (no master).
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "collision_lab/io/scene_report.h"
#include "collision_lab/ros/lab_node.h"
#include "collision_lab/ros/marker_view.h"
#include "collision_lab/ros/msg_conversion.h"
#include "collision_lab/ros/node_constants.h"

namespace {

using namespace collision_lab_ros;
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(MsgConversion, SceneRoundTripKeepsWallsAndValues) {
  collision_lab::core::Scene scene = collision_lab::core::threeBodies();
  scene.masses = {kInf, 2.5, 1e-300};
  scene.positions = {3, 1, -0.1};
  scene.velocities = {-0.5, 0, 1e150};
  const auto msg = toInitialConditions(scene, collision_lab::core::RunMode::kSummaryOnly, 77);
  EXPECT_EQ(msg.mode, collision_lab::InitialConditions::MODE_SUMMARY_ONLY);
  EXPECT_EQ(msg.max_collisions, 77u);
  const collision_lab::core::Scene back = toScene(msg);
  EXPECT_EQ(back.masses, std::vector<double>(scene.masses.begin(), scene.masses.end()));
  EXPECT_EQ(back.positions, std::vector<double>(scene.positions.begin(), scene.positions.end()));
  EXPECT_EQ(back.velocities, std::vector<double>(scene.velocities.begin(), scene.velocities.end()));
  EXPECT_TRUE(back.restitution.empty());
}

TEST(MsgConversion, AnySceneRoundTripKeepsItsListsAsGiven) {
  // Invalid on purpose (unequal lengths): the conversion copies, validation judges.
  const collision_lab::core::Scene scene{{1, 2, kInf, 4}, {5, 4, 3}, {-1, 0}, {0.5, 0.25, 1, 7}};
  const auto msg = toInitialConditions(scene, collision_lab::core::RunMode::kFull, 0);
  const collision_lab::core::Scene back = toScene(msg);
  EXPECT_EQ(back.masses, scene.masses);
  EXPECT_EQ(back.positions, scene.positions);
  EXPECT_EQ(back.velocities, scene.velocities);
  EXPECT_EQ(back.restitution, scene.restitution);
}

// Issue 21 (failed before: no such fields).
TEST(MsgConversion, RestitutionModelAndRingRoundTrip) {
  collision_lab::core::Scene scene{{1, 1}, {9, 1}, {1, -1}, {0.5}};
  scene.restitution_model.kind = collision_lab::core::RestitutionModelKind::kTc;
  scene.restitution_model.tc = 1e-3;
  scene.ring = 10;
  const auto msg = toInitialConditions(scene, collision_lab::core::RunMode::kFull, 0);
  EXPECT_EQ(msg.restitution_model, collision_lab::InitialConditions::RESTITUTION_TC);
  EXPECT_EQ(msg.tc, 1e-3);
  EXPECT_EQ(msg.ring, 10.0);
  const collision_lab::core::Scene back = toScene(msg);
  EXPECT_EQ(back.restitution_model.kind, collision_lab::core::RestitutionModelKind::kTc);
  EXPECT_EQ(back.restitution_model.tc, 1e-3);
  EXPECT_EQ(back.ring, 10.0);
  collision_lab::InitialConditions threshold;
  threshold.restitution_model = collision_lab::InitialConditions::RESTITUTION_THRESHOLD;
  threshold.elastic_below = 0.01;
  EXPECT_EQ(toScene(threshold).restitution_model.elastic_below, 0.01);
  collision_lab::InitialConditions soft;
  soft.restitution_model = collision_lab::InitialConditions::RESTITUTION_VISCOELASTIC;
  soft.viscoelastic_speed = 2;
  EXPECT_EQ(toScene(soft).restitution_model.viscoelastic_speed, 2.0);
  EXPECT_EQ(toScene(collision_lab::InitialConditions{}).restitution_model.kind,
            collision_lab::core::RestitutionModelKind::kConstant);  // the default
}

/// The engine's record of an impact of pair `pair` that moved bodies first..last (the
/// pair alone unless given).
collision_lab::core::ImpactRecord record(std::uint64_t index, std::size_t pair, double t, double x,
                                         std::array<double, 2> before, std::array<double, 2> after,
                                         std::array<double, 2> gained, double lost,
                                         std::optional<std::size_t> first = {}, std::optional<std::size_t> last = {}) {
  collision_lab::core::ImpactRecord r;
  r.index = index, r.pair_index = pair, r.time = t, r.position = x;
  r.velocities_before = before, r.velocities_after = after, r.energy_gained = gained, r.energy_lost = lost;
  r.first_moved = first.value_or(pair), r.last_moved = last.value_or(pair + 1);
  return r;
}

// Masses 1, 1, 2 at x = 2, 1, 0, v = -1, 0, 0; AB sticks (e = 0), BC is elastic. By hand:
// AB meet at t = 1 s, x = 1 m and both move at -1/2 m/s (0.25 J of heat); the 2 kg cluster
// AB reaches C at t = 3 s, x = 0 m, and (equal masses, e = 1) stops while C takes -1/2 m/s.
TEST(SceneEventConverter, RebuildsEveryBodyThroughAStickingImpactAndAClusterImpact) {
  SceneEventConverter converter({{1, 1, 2}, {2, 1, 0}, {-1, 0, 0}, {0, 1}});
  const auto first = converter.impact(record(1, 0, 1.0, 1.0, {-1, 0}, {-0.5, -0.5}, {-0.375, 0.125}, 0.25));
  EXPECT_EQ(first.kind, collision_lab::CollisionEvent::KIND_IMPACT);
  EXPECT_EQ(first.restitution, 0.0);
  EXPECT_EQ(first.first_moved, 0u);
  EXPECT_EQ(first.last_moved, 1u);
  EXPECT_FALSE(first.cluster_impact);
  EXPECT_EQ(first.positions, (std::vector<double>{1, 1, 0}));
  EXPECT_EQ(first.velocities_before, (std::vector<double>{-1, 0, 0}));
  EXPECT_EQ(first.velocities_after, (std::vector<double>{-0.5, -0.5, 0}));
  EXPECT_EQ(first.energy_transfer, (std::vector<double>{-0.375, 0.125, 0}));
  EXPECT_EQ(first.kinetic_energy_after, (std::vector<double>{0.125, 0.125, 0}));
  EXPECT_EQ(first.total_energy, 0.25);
  EXPECT_EQ(first.total_momentum, -1.0);
  EXPECT_EQ(converter.energyTransferMsg(first).cumulative_energy_lost, 0.25);

  // The engine's record says the cluster AB moved (bodies 0..2).
  const auto second = converter.impact(record(2, 1, 3.0, 0.0, {-0.5, 0}, {0, -0.5}, {-0.25, 0.25}, 0, 0, 2));
  EXPECT_EQ(second.first_moved, 0u);  // the cluster AB moved as one
  EXPECT_EQ(second.last_moved, 2u);
  EXPECT_TRUE(second.cluster_impact);
  EXPECT_EQ(second.positions, (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(second.velocities_after, (std::vector<double>{0, 0, -0.5}));
  EXPECT_EQ(second.energy_transfer, (std::vector<double>{-0.125, -0.125, 0.25}));
  EXPECT_EQ(second.total_energy, 0.25);
  EXPECT_EQ(second.total_momentum, -1.0);
  const auto v = converter.velocitiesMsg(second);
  EXPECT_EQ(v.v, (std::vector<double>{0, 0, -0.5}));
  EXPECT_EQ(v.v_c, -0.5);
  const auto t = converter.energyTransferMsg(second);
  EXPECT_EQ(t.delta, (std::vector<double>{-0.125, -0.125, 0.25}));
  EXPECT_EQ(t.kinetic, (std::vector<double>{0, 0, 0.25}));
  EXPECT_EQ(t.energy_lost, 0.0);
  EXPECT_EQ(t.cumulative_energy_lost, 0.25);
}

// The node's events and the CLI's are one record (io::SceneEventState): every impact of an
// inelastic run carries the same values in both. The energy a single body gains in an
// impact is the engine's own (pair_energy_transfer), not a difference of the replay's
// kinetic energies, which rounds otherwise (it did before: the node's differed).
TEST(SceneEventConverter, EveryEventCarriesTheCliRecordsValues) {
  const collision_lab::core::Scene scene{{1, 2.7, 0.3, 1.9, 5}, {4, 3.1, 2.2, 1.3, 0}, {-0.7, 0.1, 0.3, -0.2, 0.9},
                                         {0.9, 0.7, 1, 0.55}};
  SceneEventConverter converter(scene);
  collision_lab::io::SceneEventJson cli(scene);
  std::size_t single_pair_impacts = 0;
  const auto result = collision_lab::core::runEngine(scene, {}, [&](const collision_lab::core::ImpactRecord& r) {
    const auto msg = converter.impact(r);
    const collision_lab::io::Json json = cli.impact(r);
    ASSERT_EQ(msg.energy_transfer.size(), 5u);
    for (std::size_t i = 0; i < 5; ++i) {
      EXPECT_EQ(msg.energy_transfer[i], json.at("energy_transfer")[i].get<double>()) << "impact " << r.index;
      EXPECT_EQ(msg.velocities_after[i], json.at("velocities_after")[i].get<double>());
      EXPECT_EQ(msg.positions[i], json.at("positions")[i].get<double>());
    }
    EXPECT_EQ(msg.total_energy, json.at("total_energy").get<double>());
    if (!msg.cluster_impact) {
      ++single_pair_impacts;
      EXPECT_EQ(msg.energy_transfer[msg.pair_index], msg.pair_energy_transfer[0]) << "impact " << r.index;
      EXPECT_EQ(msg.energy_transfer[msg.pair_index + 1], msg.pair_energy_transfer[1]) << "impact " << r.index;
    }
  });
  EXPECT_GT(result.impact_count, 3u);
  EXPECT_GT(single_pair_impacts, 0u);
}

// A ring's seam impact (issue 21; wrote past the bodies before): L = 10 m, A (1 kg, 9 m,
// +1 m/s) meets B (3 kg, 1 m, -1 m/s) across the seam at t = 1 s, x = 0; by hand B stops and
// A leaves at -2 m/s: B gains -1.5 J, A +1.5 J. The record is pair 1 (B right, A left).
TEST(SceneEventConverter, ARingSeamImpactMovesBodyNMinus1AndBody0) {
  collision_lab::core::Scene scene{{1, 3}, {9, 1}, {1, -1}, {}};
  scene.ring = 10;
  SceneEventConverter converter(scene);
  const auto event = converter.impact(record(1, 1, 1.0, 0.0, {-1, 1}, {0, -2}, {-1.5, 1.5}, 0, 1, 0));
  EXPECT_FALSE(event.cluster_impact);
  EXPECT_EQ(event.first_moved, 1u);
  EXPECT_EQ(event.last_moved, 0u);
  EXPECT_EQ(event.velocities_after, (std::vector<double>{-2, 0}));
  EXPECT_EQ(event.energy_transfer, (std::vector<double>{1.5, -1.5}));
  EXPECT_EQ(event.pair_energy_transfer[0], -1.5);
  EXPECT_EQ(event.pair_energy_transfer[1], 1.5);
  EXPECT_EQ(converter.energyTransferMsg(event).delta, (std::vector<double>{1.5, -1.5}));
}

// Three equal masses that collapse: afterwards all move at the centre-of-mass velocity.
TEST(SceneEventConverter, ACollapseMovesItsBodiesOnAsOneAtTheirCentreOfMass) {
  SceneEventConverter converter({{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.05}});
  collision_lab::core::Collapse collapse;
  collapse.first_body = 0, collapse.last_body = 2, collapse.time = 2.5, collapse.position = -0.5;
  collapse.impacts_before = 40;
  collapse.velocity = -1.0 / 3;  // the centre of mass: momentum -1 kg m/s, 3 kg
  const auto msg = converter.collapse(collapse);
  EXPECT_EQ(msg.kind, collision_lab::CollisionEvent::KIND_COLLAPSE);
  EXPECT_EQ(msg.index, 40u);
  EXPECT_EQ(msg.first_moved, 0u);
  EXPECT_EQ(msg.last_moved, 2u);
  for (double v : msg.velocities_after) EXPECT_DOUBLE_EQ(v, -1.0 / 3);
  EXPECT_EQ(msg.positions, (std::vector<double>{-0.5, -0.5, -0.5}));
  EXPECT_DOUBLE_EQ(msg.energy_lost, 0.5 - 1.0 / 6);  // 1/2 J before, 3 (1/2)(1/9) J after
  EXPECT_DOUBLE_EQ(converter.energyTransferMsg(msg).cumulative_energy_lost, 1.0 / 3);
}

// The collapse above with a fourth body D (1 kg at x = -10 m, 0.5 m/s, e = 0.5 with C) that
// meets the cluster afterwards. By hand: the cluster's centre of mass is at 2 - t/3 m, so D
// meets it at t = 14.4 s, x = -2.8 m; one body of 3 kg at -1/3 m/s against 1 kg at 1/2 m/s
// (momentum -1/2, approach 5/6 m/s) leaves the cluster at -1/48 m/s and D at -7/16 m/s, and
// turns (1 - e^2) mu A^2 / 2 = (3/4)(3/4)(25/36)/2 = 25/128 J into heat.
TEST(SceneEventConverter, AnImpactAfterACollapseMovesTheWholeClusterAsItsRecordSays) {
  SceneEventConverter converter({{1, 1, 1, 1}, {3, 2, 1, -10}, {-1, 0, 0, 0.5}, {0.05, 0.05, 0.5}});
  collision_lab::core::Collapse collapse;
  collapse.first_body = 0, collapse.last_body = 2, collapse.time = 3.5, collapse.position = 2 - 3.5 / 3;
  collapse.velocity = -1.0 / 3;
  converter.collapse(collapse);
  const auto msg = converter.impact(
      record(41, 2, 14.4, -2.8, {-1.0 / 3, 0.5}, {-1.0 / 48, -7.0 / 16}, {0, 0}, 25.0 / 128, 0, 3));
  EXPECT_TRUE(msg.cluster_impact);
  EXPECT_EQ(msg.first_moved, 0u);
  EXPECT_EQ(msg.last_moved, 3u);
  ASSERT_EQ(msg.velocities_before.size(), 4u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(msg.velocities_before[i], -1.0 / 3);
  EXPECT_EQ(msg.velocities_before[3], 0.5);
  EXPECT_EQ(msg.velocities_after, (std::vector<double>{-1.0 / 48, -1.0 / 48, -1.0 / 48, -7.0 / 16}));
  EXPECT_EQ(msg.positions, (std::vector<double>{-2.8, -2.8, -2.8, -2.8}));
  EXPECT_DOUBLE_EQ(msg.total_momentum, -0.5);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(msg.energy_transfer[i], 0.5 / 2304 - 1.0 / 18);
  EXPECT_DOUBLE_EQ(msg.energy_transfer[3], 49.0 / 512 - 0.125);
  EXPECT_DOUBLE_EQ(converter.energyTransferMsg(msg).cumulative_energy_lost, 1.0 / 3 + 25.0 / 128);
}

TEST(SceneEventConverter, AboveTheFullStateLimitOnlyThePairFieldsAndThePlotScalarsCarryTheBodies) {
  const std::size_t n = collision_lab::CollisionEvent::FULL_STATE_MAX_BODIES + 1;
  collision_lab::core::Scene scene{std::vector<double>(n, 1.0), {}, std::vector<double>(n, 0.0), {}};
  for (std::size_t i = 0; i < n; ++i) scene.positions.push_back(static_cast<double>(n - i));
  scene.velocities[1] = -1;
  SceneEventConverter converter(scene);
  // Equal masses: bodies 1 and 2 swap velocities, body 1 gives its 0.5 J to body 2.
  const auto msg = converter.impact(record(1, 1, 1.0, static_cast<double>(n - 2), {-1, 0}, {0, -1}, {-0.5, 0.5}, 0));
  EXPECT_TRUE(msg.positions.empty());
  EXPECT_TRUE(msg.velocities_after.empty());
  EXPECT_TRUE(std::isnan(msg.total_energy));
  EXPECT_TRUE(std::isnan(msg.total_momentum));
  EXPECT_EQ(msg.pair_velocities_after[1], -1.0);
  // The plot topics follow the same rule: no length-N arrays (240 KB an impact at
  // N = 10,000), the scalar fields of bodies 0, 1, 2 still there.
  const auto v = converter.velocitiesMsg(msg);
  EXPECT_TRUE(v.v.empty());
  EXPECT_EQ(v.v_a, 0.0);
  EXPECT_EQ(v.v_b, 0.0);
  EXPECT_EQ(v.v_c, -1.0);
  const auto t = converter.energyTransferMsg(msg);
  EXPECT_TRUE(t.delta.empty());
  EXPECT_TRUE(t.kinetic.empty());
  EXPECT_EQ(t.delta_a, 0.0);
  EXPECT_EQ(t.delta_b, -0.5);
  EXPECT_EQ(t.delta_c, 0.5);
  EXPECT_EQ(t.kinetic_b, 0.0);
  EXPECT_EQ(t.kinetic_c, 0.5);
  EXPECT_EQ(t.cumulative_energy_lost, 0.0);
}

TEST(SceneEventConverter, AtTheFullStateLimitThePlotsCarryEveryBody) {
  const std::size_t n = collision_lab::CollisionEvent::FULL_STATE_MAX_BODIES;
  collision_lab::core::Scene scene{std::vector<double>(n, 1.0), {}, std::vector<double>(n, 0.0), {}};
  for (std::size_t i = 0; i < n; ++i) scene.positions.push_back(static_cast<double>(n - i));
  scene.velocities[10] = -1;
  SceneEventConverter converter(scene);
  const auto msg = converter.impact(record(1, 10, 1.0, static_cast<double>(n - 11), {-1, 0}, {0, -1}, {-0.5, 0.5}, 0));
  const auto v = converter.velocitiesMsg(msg);
  ASSERT_EQ(v.v.size(), n);
  EXPECT_EQ(v.v[10], 0.0);
  EXPECT_EQ(v.v[11], -1.0);
  const auto t = converter.energyTransferMsg(msg);
  ASSERT_EQ(t.delta.size(), n);
  ASSERT_EQ(t.kinetic.size(), n);
  EXPECT_EQ(t.delta[10], -0.5);
  EXPECT_EQ(t.delta[11], 0.5);
  EXPECT_EQ(t.kinetic[11], 0.5);
}

TEST(MsgConversion, AScenePredictedByNoFormulaFlagsEveryFieldAsNotGiven) {
  collision_lab::core::ScenePlan p;
  p.model = {collision_lab::core::ModelKind::kEventEngine, "no formula"};
  p.scene.masses.assign(7, 1.0);
  const auto msg = toPredictionMsg(p);
  EXPECT_EQ(msg.model, collision_lab::Prediction::MODEL_EVENT_ENGINE);
  EXPECT_EQ(msg.model_name, "event_engine");
  EXPECT_EQ(msg.model_reason, "no formula");
  EXPECT_EQ(msg.body_count, 7u);
  EXPECT_FALSE(msg.collision_count_defined);
  EXPECT_EQ(msg.first_pair_index, collision_lab::Prediction::PAIR_NONE);
  EXPECT_TRUE(msg.final_velocities.empty());
  for (double x : {msg.alpha, msg.theta, msg.energy_lost, msg.collapse_time, msg.collapse_position,
                   msg.critical_restitution, msg.spiral_angle}) {
    EXPECT_TRUE(std::isnan(x));
  }
}

TEST(MsgConversion, ANotSimulatedSceneSaysSoAndLeavesNoZeros) {
  collision_lab::core::SceneRunResult result;
  result.model = {collision_lab::core::ModelKind::kEventEngine, "no formula"};
  result.simulation.energy_lost = std::nan("");
  result.simulation.energy_relative_drift = result.simulation.momentum_relative_drift = std::nan("");
  const auto msg = toRunSummaryMsg(result, 5, collision_lab::core::RunMode::kPredictOnly);
  EXPECT_EQ(msg.stop_reason, "NOT_SIMULATED");
  EXPECT_FALSE(msg.simulated);
  EXPECT_EQ(msg.body_count, 5u);
  EXPECT_FALSE(msg.predicted_collision_count_defined);
  EXPECT_TRUE(std::isnan(msg.energy_lost));
  EXPECT_TRUE(std::isnan(msg.collapse_time));
  EXPECT_TRUE(std::isnan(msg.critical_restitution));
}

TEST(MsgConversion, RunModes) {
  EXPECT_EQ(toRunMode(0), collision_lab::core::RunMode::kFull);
  EXPECT_EQ(toRunMode(1), collision_lab::core::RunMode::kPredictOnly);
  EXPECT_EQ(toRunMode(2), collision_lab::core::RunMode::kSummaryOnly);
  EXPECT_FALSE(toRunMode(3));
  EXPECT_FALSE(toRunMode(255));
}

TEST(MsgConversion, PairCodes) {
  EXPECT_EQ(toPairCode(collision_lab::core::Pair::AB), collision_lab::Prediction::PAIR_AB);
  EXPECT_EQ(toPairCode(collision_lab::core::Pair::BC), collision_lab::Prediction::PAIR_BC);
  EXPECT_EQ(toPairCode(std::nullopt), collision_lab::Prediction::PAIR_NONE);
  EXPECT_EQ(toPair(collision_lab::Prediction::PAIR_BC), collision_lab::core::Pair::BC);
  EXPECT_FALSE(toPair(collision_lab::Prediction::PAIR_NONE));
}

// Every field a prediction gives reaches the message as it is, whichever model gave it; a
// field it does not give says so (NaN, PAIR_NONE, not defined).
TEST(MsgConversion, EveryPredictionFieldReachesTheMessage) {
  collision_lab::core::ScenePlan plan;
  plan.model = {collision_lab::core::ModelKind::kThreeBodyRotation, "rotation"};
  plan.scene.masses.assign(3, 1.0);
  collision_lab::core::Prediction p;
  p.kind = collision_lab::core::ModelKind::kThreeBodyRotation;
  p.impact_count = 2221441;
  p.paper_impact_count = -3;
  p.max_possible_impact_count = 2221442;
  p.alpha = 0.1;
  p.theta = p.spiral_angle = 0.2;
  p.omega = M_PI - 0.1;
  p.phi_bc = 0.3;
  p.psi = 4.5;
  p.critical_restitution = 0.8;
  p.first_pair_index = 1;
  p.final_velocities = {1, -2, 3};
  plan.prediction = p;
  auto msg = toPredictionMsg(plan);
  EXPECT_EQ(msg.collision_count, 2221441u);
  EXPECT_TRUE(msg.collision_count_defined);
  EXPECT_TRUE(msg.paper_collision_count_defined);
  EXPECT_EQ(msg.paper_collision_count, -3);
  EXPECT_EQ(msg.max_possible_collision_count, 2221442u);
  EXPECT_EQ(msg.alpha, 0.1);
  EXPECT_EQ(msg.theta, 0.2);
  EXPECT_EQ(msg.omega, M_PI - 0.1);
  EXPECT_EQ(msg.phi_bc, 0.3);
  EXPECT_EQ(msg.psi, 4.5);
  EXPECT_EQ(msg.critical_restitution, 0.8);
  EXPECT_EQ(msg.spiral_angle, 0.2);
  EXPECT_EQ(msg.first_pair_index, collision_lab::Prediction::PAIR_BC);
  EXPECT_EQ(msg.final_velocities, (std::vector<double>{1, -2, 3}));
  EXPECT_EQ(msg.energy_lost, 0.0);

  plan.prediction->paper_impact_count.reset();
  plan.prediction->first_pair_index.reset();
  plan.prediction->phi_bc.reset();
  msg = toPredictionMsg(plan);
  EXPECT_FALSE(msg.paper_collision_count_defined);
  EXPECT_EQ(msg.first_pair_index, collision_lab::Prediction::PAIR_NONE);
  EXPECT_TRUE(std::isnan(msg.phi_bc));
}

/// Three bodies and an impact of theirs with its model block (every value distinct).
const collision_lab::core::Scene kThreeBodies{{1, 1, 1}, {2, 1, 0}, {-1, 0.5, 1}, {}};

collision_lab::core::ImpactRecord sampleEvent() {
  collision_lab::core::ImpactRecord e;
  e.index = 42;
  e.pair_index = 1;
  e.time = 1.5;
  e.position = -0.25;
  e.velocities_before = {0.5, 1};
  e.velocities_after = {0.9, 0.2};
  e.energy_gained = {0.1, -0.1};
  e.first_moved = 1;
  e.last_moved = 2;
  collision_lab::core::ImpactModelValues& m = e.model.emplace();
  m.positions = {1, -0.25, -0.25};
  m.velocities_before = {-1, 0.5, 1};
  m.velocities_after = {-1, 0.9, 0.2};
  m.energy_transfer = {0, 0.1, -0.1};
  m.total_energy = 3.25;
  m.total_momentum = -0.5;
  m.predicted_velocities_after = {-1, 0.9000001, 0.2};
  m.paper_velocities_after = {7, 8, 9};
  m.predicted_energy_transfer = {0, 0.11, -0.11};
  m.paper_energy_transfer = {0, 0.2, -0.2};
  m.kinetic_energy_after = {0.5, 0.81, 0.06};
  return e;
}

/// The message of sampleEvent(), converted as the node converts it.
collision_lab::CollisionEvent sampleMsg() { return SceneEventConverter(kThreeBodies).impact(sampleEvent()); }

std::vector<double> vectorOf(const std::array<double, 3>& values) { return {values.begin(), values.end()}; }

TEST(MsgConversion, AnImpactsModelBlockIsCopiedAsItIs) {
  const collision_lab::core::ImpactRecord e = sampleEvent();
  const collision_lab::core::ImpactModelValues& m = *e.model;
  const auto msg = sampleMsg();
  EXPECT_EQ(msg.kind, collision_lab::CollisionEvent::KIND_IMPACT);
  EXPECT_EQ(msg.pair_index, collision_lab::CollisionEvent::PAIR_BC);
  EXPECT_EQ(msg.index, e.index);
  EXPECT_EQ(msg.time, e.time);
  EXPECT_EQ(msg.position, e.position);
  EXPECT_EQ(msg.pair_velocities_after[0], 0.9);
  EXPECT_EQ(msg.pair_energy_transfer[1], -0.1);
  EXPECT_EQ(msg.positions, vectorOf(m.positions));
  EXPECT_EQ(msg.velocities_before, vectorOf(m.velocities_before));
  EXPECT_EQ(msg.velocities_after, vectorOf(m.velocities_after));
  EXPECT_EQ(msg.energy_transfer, vectorOf(m.energy_transfer));
  EXPECT_EQ(msg.total_energy, m.total_energy);
  EXPECT_EQ(msg.total_momentum, m.total_momentum);
  EXPECT_EQ(msg.predicted_velocities_after, vectorOf(m.predicted_velocities_after));
  EXPECT_EQ(msg.paper_velocities_after, vectorOf(m.paper_velocities_after));
  EXPECT_EQ(msg.predicted_energy_transfer, vectorOf(m.predicted_energy_transfer));
  EXPECT_EQ(msg.paper_energy_transfer, vectorOf(m.paper_energy_transfer));
  EXPECT_EQ(msg.kinetic_energy_after, vectorOf(m.kinetic_energy_after));
  // Without the block, the same impact's model arrays are empty.
  collision_lab::core::ImpactRecord plain = e;
  plain.model.reset();
  const auto engine_msg = SceneEventConverter(kThreeBodies).impact(plain);
  EXPECT_TRUE(engine_msg.predicted_velocities_after.empty());
  EXPECT_TRUE(engine_msg.paper_energy_transfer.empty());
  EXPECT_EQ(engine_msg.velocities_after.size(), 3u);
}

TEST(MsgConversion, PlotTopicsAreTheEventsSimulatedValues) {
  collision_lab::CollisionEvent event = sampleMsg();
  event.header.stamp = ros::Time(1700000000, 5);
  event.run_id = "plotted";
  const auto v = toVelocitiesMsg(event);
  EXPECT_EQ(v.header.stamp, event.header.stamp);
  EXPECT_EQ(v.run_id, "plotted");
  EXPECT_EQ(v.index, 42u);
  EXPECT_EQ(v.time, 1.5);
  EXPECT_EQ(v.v_a, -1.0);
  EXPECT_EQ(v.v_b, 0.9);
  EXPECT_EQ(v.v_c, 0.2);
  const auto t = toEnergyTransferMsg(event, 0.0);
  EXPECT_EQ(t.header.stamp, event.header.stamp);
  EXPECT_EQ(t.run_id, "plotted");
  EXPECT_EQ(t.index, 42u);
  EXPECT_EQ(t.time, 1.5);
  EXPECT_EQ(t.delta_a, 0.0);
  EXPECT_EQ(t.delta_b, 0.1);
  EXPECT_EQ(t.delta_c, -0.1);
  EXPECT_EQ(t.kinetic_a, 0.5);
  EXPECT_EQ(t.kinetic_b, 0.81);
  EXPECT_EQ(t.kinetic_c, 0.06);
}

/// msg as it goes out on a topic (NaN fields compare equal here, unlike operator==).
template <class Message>
std::vector<std::uint8_t> wireBytes(const Message& msg) {
  std::vector<std::uint8_t> bytes(ros::serialization::serializationLength(msg));
  ros::serialization::OStream stream(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  ros::serialization::serialize(stream, msg);
  return bytes;
}

// The node refills one message of each kind for every event (src/ros/run_writer.h's EventStream):
// a message that carried another event, of the other path or another size, must go out
// as a fresh conversion of the new one, with nothing left over.
TEST(MsgConversion, AReusedMessageCarriesItsNewEventAlone) {
  const std::size_t n = collision_lab::CollisionEvent::FULL_STATE_MAX_BODIES + 1;
  collision_lab::core::Scene large{std::vector<double>(n, 1.0), {}, std::vector<double>(n, 0.0), {}};
  for (std::size_t i = 0; i < n; ++i) large.positions.push_back(static_cast<double>(n - i));
  large.velocities[1] = -1;
  const collision_lab::core::ImpactRecord impact = record(1, 1, 1.0, static_cast<double>(n - 2), {-1, 0}, {0, -1},
                                                          {-0.5, 0.5}, 0);
  SceneEventConverter fresh_converter(large), reused_converter(large);
  const collision_lab::CollisionEvent fresh = fresh_converter.impact(impact);

  // A three-body event (every array filled, the model's too), then the large scene's
  // impact (no arrays): the same message as converted fresh.
  collision_lab::CollisionEvent reused = sampleMsg();
  reused_converter.impact(impact, reused);
  EXPECT_EQ(wireBytes(reused), wireBytes(fresh));
  EXPECT_TRUE(reused.predicted_velocities_after.empty());
  EXPECT_TRUE(reused.positions.empty());

  collision_lab::Velocities velocities = toVelocitiesMsg(sampleMsg());
  reused_converter.velocitiesMsg(reused, velocities);
  EXPECT_EQ(wireBytes(velocities), wireBytes(fresh_converter.velocitiesMsg(fresh)));
  collision_lab::EnergyTransfer energy = toEnergyTransferMsg(sampleMsg(), 2.0);
  reused_converter.energyTransferMsg(reused, energy);
  EXPECT_EQ(wireBytes(energy), wireBytes(fresh_converter.energyTransferMsg(fresh)));

  // And back: the three-body event into the message of the large scene's.
  collision_lab::CollisionEvent three_body = fresh;
  three_body.header.stamp = ros::Time(1700000000, 5);
  three_body.run_id = "plotted";
  SceneEventConverter(kThreeBodies).impact(sampleEvent(), three_body);
  collision_lab::CollisionEvent expected = sampleMsg();
  expected.header = three_body.header;
  expected.run_id = three_body.run_id;
  EXPECT_EQ(wireBytes(three_body), wireBytes(expected));
  fillVelocitiesMsg(three_body, velocities);
  EXPECT_EQ(wireBytes(velocities), wireBytes(toVelocitiesMsg(three_body)));
  fillEnergyTransferMsg(three_body, 0.0, energy);
  EXPECT_EQ(wireBytes(energy), wireBytes(toEnergyTransferMsg(three_body, 0.0)));
}

TEST(MsgConversion, RunSummaryPhysicsFields) {
  // A three-body result: the summary comes from the one simulation, the rotation model's
  // block (its counts, its error at every impact) from three_body.
  collision_lab::core::SceneRunResult result;
  result.model = collision_lab::core::ModelChoice{collision_lab::core::ModelKind::kThreeBodyRotation, "rotation"};
  collision_lab::core::SceneSimulation& s = result.simulation;
  s.simulated = true;
  s.impact_count = 10;
  s.truncated = true;
  s.stop = collision_lab::core::StopReason::kCap;
  s.stop_message = "cap";
  s.final_velocities = {1, 2, 3};
  s.max_prediction_error = 1e-15;  // the rotation model's, over every impact (runScene)
  s.energy_relative_drift = 2e-16;
  s.momentum_relative_drift = std::nan("");
  result.compute_time_s = 0.5;
  collision_lab::core::Prediction rotation;
  rotation.kind = collision_lab::core::ModelKind::kThreeBodyRotation;
  rotation.impact_count = 11;
  rotation.alpha = M_PI / 3;
  rotation.theta = rotation.spiral_angle = 0.5;
  rotation.omega = M_PI - M_PI / 3;
  rotation.max_possible_impact_count = 12;
  result.prediction = rotation;
  const auto msg = toRunSummaryMsg(result, 3, collision_lab::core::RunMode::kFull);
  EXPECT_EQ(msg.collision_count, 10u);
  EXPECT_TRUE(msg.truncated);
  EXPECT_EQ(msg.truncation_reason, "cap");
  EXPECT_EQ(msg.stop_reason, "CAP");
  EXPECT_EQ(msg.predicted_collision_count, 11u);
  EXPECT_TRUE(msg.predicted_collision_count_defined);
  EXPECT_FALSE(msg.paper_predicted_collision_count_defined);
  EXPECT_EQ(msg.spiral_angle, 0.5);
  EXPECT_EQ(msg.max_prediction_error, 1e-15);
  EXPECT_EQ(msg.final_velocities[2], 3.0);
  EXPECT_EQ(msg.energy_lost, 0.0);
  EXPECT_TRUE(std::isnan(msg.momentum_relative_drift));
  EXPECT_EQ(msg.compute_time, 0.5);
  EXPECT_EQ(msg.mode, collision_lab::InitialConditions::MODE_FULL);
}

// The spiral's opening angle is its prediction's (the core's), copied like every field
// (failed before: the prediction had none and the conversion computed it for that model).
TEST(MsgConversion, TheSpiralsOpeningAngleComesFromItsPrediction) {
  const collision_lab::core::ScenePlan plan = collision_lab::core::planScene({{1, 1, 1}, {2, 1, 0}, {-1, 0, 0.5}, {0.5}});
  ASSERT_FALSE(plan.error);
  ASSERT_EQ(plan.model.kind, collision_lab::core::ModelKind::kThreeBodySpiral);
  ASSERT_TRUE(plan.prediction && plan.prediction->alpha);
  EXPECT_NEAR(*plan.prediction->alpha, M_PI / 3, 1e-15);  // equal masses: alpha = pi/3
  EXPECT_EQ(toPredictionMsg(plan).alpha, *plan.prediction->alpha);
}

TEST(MsgConversion, ThreeEqualMassesTakeTheOnePathToThreeImpacts) {
  // Three equal masses, the outer ones approaching the middle one: 3 impacts (shared/physics.md),
  // the outer velocities exchanged; the rotation model answers, and its block rides along.
  const collision_lab::core::Scene scene{{1, 1, 1}, {2, 1, -1}, {-1, 0, 1}, {}};
  const collision_lab::core::ScenePlan plan = collision_lab::core::planScene(scene);
  ASSERT_FALSE(plan.error);
  const auto prediction = toPredictionMsg(plan);
  EXPECT_EQ(prediction.model_name, "three_body_rotation");
  EXPECT_EQ(prediction.collision_count, 3u);
  EXPECT_TRUE(prediction.collision_count_defined);
  EXPECT_NEAR(prediction.alpha, M_PI / 3, 1e-15);  // equal masses: alpha = pi/3
  for (const auto mode : {collision_lab::core::RunMode::kFull, collision_lab::core::RunMode::kPredictOnly}) {
    collision_lab::core::SceneRunOptions options;
    options.lab.mode = mode;
    const auto msg = toRunSummaryMsg(collision_lab::core::runScene(plan, options), 3, mode);
    const bool simulated = mode == collision_lab::core::RunMode::kFull;
    EXPECT_EQ(msg.simulated, simulated);
    EXPECT_EQ(msg.stop_reason, simulated ? "FINISHED" : "NOT_SIMULATED");
    EXPECT_EQ(msg.collision_count, 3u);
    EXPECT_EQ(msg.predicted_collision_count, 3u);
    EXPECT_TRUE(msg.predicted_collision_count_defined);
    EXPECT_FALSE(msg.truncated);
    ASSERT_EQ(msg.final_velocities.size(), 3u);
    EXPECT_NEAR(msg.final_velocities[0], 1.0, 1e-15);
    EXPECT_NEAR(msg.final_velocities[1], 0.0, 1e-15);
    EXPECT_NEAR(msg.final_velocities[2], -1.0, 1e-15);
    EXPECT_EQ(msg.energy_lost, 0.0);
    EXPECT_EQ(std::isnan(msg.max_prediction_error), !simulated);
  }
}

TEST(MsgConversion, Rejections) {
  collision_lab::core::ValidationError error{collision_lab::core::Reason::kTripleCollision, "positions", "a triple collision"};
  const auto msg = toRejectedMsg(error);
  EXPECT_EQ(msg.reason, collision_lab::Rejected::TRIPLE_COLLISION);
  EXPECT_EQ(msg.reason_name, "TRIPLE_COLLISION");
  EXPECT_EQ(msg.field, "positions");
  const auto dup = toRejectedMsg(NodeReason::kDuplicateRunId, "run_id", "exists");
  EXPECT_EQ(dup.reason, collision_lab::Rejected::DUPLICATE_RUN_ID);
  EXPECT_EQ(dup.reason_name, "DUPLICATE_RUN_ID");
}

TEST(MsgConversion, InvalidStudentHasItsOwnCode) {
  const auto msg = toRejectedMsg(NodeReason::kInvalidStudent, "student", "bad");
  EXPECT_EQ(msg.reason, 204);
  EXPECT_EQ(msg.reason_name, "INVALID_STUDENT");
}

TEST(MsgConversion, EachEnvelopeRefusalHasItsNodeCode) {
  using Reason = collision_lab::service::EnvelopeRefusal::Reason;
  const std::pair<Reason, std::uint8_t> codes[] = {{Reason::kInvalidStudent, collision_lab::Rejected::INVALID_STUDENT},
                                                   {Reason::kInvalidRunId, collision_lab::Rejected::INVALID_RUN_ID},
                                                   {Reason::kInvalidMode, collision_lab::Rejected::INVALID_MODE},
                                                   {Reason::kTooManyBodies, collision_lab::Rejected::TOO_MANY_BODIES}};
  for (const auto& [reason, code] : codes) {
    const auto msg = toRejectedMsg(collision_lab::service::EnvelopeRefusal{reason, "field", "why"});
    EXPECT_EQ(msg.reason, code);
    EXPECT_EQ(msg.field, "field");
    EXPECT_EQ(msg.message, "why");
  }
}

collision_lab::AcceptedRun accepted(const std::string& run_id, const std::string& student) {
  collision_lab::AcceptedRun run;
  run.run_id = run_id;
  run.student = student;
  return run;
}

TEST(ServedRuns, ListsOneStudentsRunsOldestFirstAndCompletesThemWithTheirSummary) {
  ServedRuns runs;
  runs.accepted(accepted("ana", "ana"));
  runs.accepted(accepted("ben.x", "ben"));
  runs.accepted(accepted("ana.2", "ana"));
  runs.accepted(accepted("run_1", ""));
  collision_lab::RunSummary summary;
  summary.run_id = "ana";
  summary.collision_count = 31;
  summary.bag_path = "/bags/ana.bag";
  summary.recording_ok = true;
  summary.stop_reason = "FINISHED";
  runs.finished(summary);

  const auto ana = runs.list("ana");
  ASSERT_EQ(ana.size(), 2u);
  EXPECT_EQ(ana[0].accepted.run_id, "ana");
  EXPECT_TRUE(ana[0].finished);
  EXPECT_EQ(ana[0].collision_count, 31u);
  EXPECT_EQ(ana[0].bag_path, "/bags/ana.bag");
  EXPECT_TRUE(ana[0].recording_ok);
  EXPECT_EQ(ana[0].stop_reason, "FINISHED");
  EXPECT_EQ(ana[1].accepted.run_id, "ana.2");
  EXPECT_FALSE(ana[1].finished);
  EXPECT_EQ(runs.list("").size(), 4u);  // everyone, anonymous runs included
  EXPECT_TRUE(runs.list("cy").empty());
}

TEST(ServedRuns, KeepsTheNewestRunsOnly) {
  ServedRuns runs;
  for (std::size_t k = 0; k <= collision_lab_ros::kServedRunsKept; ++k) runs.accepted(accepted("r" + std::to_string(k), ""));
  const auto all = runs.list("");
  ASSERT_EQ(all.size(), collision_lab_ros::kServedRunsKept);
  EXPECT_EQ(all.front().accepted.run_id, "r1");
  EXPECT_EQ(all.back().accepted.run_id, "r" + std::to_string(collision_lab_ros::kServedRunsKept));
}

TEST(MarkerFollow, AViewFollowsOneRunIdOrOneStudent) {
  MarkerViewParams everyone;
  EXPECT_TRUE(everyone.follows("anything"));

  MarkerViewParams run;
  run.follow_run_id = "pi";
  EXPECT_TRUE(run.follows("pi"));
  EXPECT_TRUE(run.follows("pi.2"));  // served as pi.2 when pi was taken
  EXPECT_TRUE(run.follows("pi.17"));
  EXPECT_FALSE(run.follows("pi."));
  EXPECT_FALSE(run.follows("pi.x"));
  EXPECT_FALSE(run.follows("pie"));
  EXPECT_FALSE(run.follows("p"));

  MarkerViewParams student;
  student.follow_student = "ana";
  EXPECT_TRUE(student.follows("ana"));
  EXPECT_TRUE(student.follows("ana.2"));
  EXPECT_TRUE(student.follows("ana.pi_by_hand"));
  EXPECT_TRUE(student.follows("ana.pi_by_hand.3"));
  EXPECT_FALSE(student.follows("anabel"));
  EXPECT_FALSE(student.follows("ben.ana"));
  EXPECT_FALSE(student.follows("run_20261126_011500_1"));

  collision_lab::Rejected rejected;
  rejected.student = "ana";
  rejected.run_id = "pi";
  EXPECT_TRUE(student.follows(rejected));
  EXPECT_TRUE(run.follows(rejected));
  rejected.student = "ben";
  EXPECT_FALSE(student.follows(rejected));
  rejected.run_id = "other";
  EXPECT_FALSE(run.follows(rejected));
}

TEST(CountParameter, WholeNumbersUpTo2To64Minus1AreTheirValue) {
  EXPECT_EQ(countParameter("max_bodies", 0.0).value, 0u);
  EXPECT_EQ(countParameter("max_bodies", 10000.0).value, 10000u);
  // 2^53 + 2 and the largest double below 2^64, 2^64 - 2^11: exact in a double.
  EXPECT_EQ(countParameter("max_collisions", 9007199254740994.0).value, 9007199254740994u);
  const CountParameter largest = countParameter("max_collisions", 18446744073709549568.0);
  EXPECT_EQ(largest.error, "");
  EXPECT_EQ(largest.value, 18446744073709549568u);
}

TEST(CountParameter, AnythingElseIsAnErrorNamingTheParameterTheValueAndTheRange) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const double value : {kInf, -kInf, nan, -1.0, -0.5, 2.5, 1e-300, 1.0e+30, 18446744073709551616.0}) {
    SCOPED_TRACE(value);
    const CountParameter count = countParameter("max_collisions", value);
    EXPECT_NE(count.error.find("~max_collisions = "), std::string::npos) << count.error;
    EXPECT_NE(count.error.find("from 0 to 18446744073709551615"), std::string::npos) << count.error;
  }
  EXPECT_EQ(countParameter("max_bodies", 1.0e+30).error,
            std::string("~max_bodies = 1e+30 is out of range; ") + kCountParameterRange);
  EXPECT_EQ(countParameter("max_bodies", kInf).error,
            std::string("~max_bodies = inf is out of range; ") + kCountParameterRange);
}

// One prediction type (issue 32): the rotation model's block of the Prediction message comes
// from the plan's core::Prediction, copied field by field without naming the model. Pi
// billiard (100, 1, inf): 31 impacts, at most ceil(pi / alpha) = 32 with alpha = atan(1/10),
// A and B first; psi = pi and no paper count or phi_BC (the paper's formulas are undefined
// with the wall C), as the CLI prints them.
TEST(MsgConversion, TheRotationModelsPredictionIsThePlans) {
  const double inf = std::numeric_limits<double>::infinity();
  const collision_lab::core::ScenePlan plan = collision_lab::core::planScene({{100, 1, inf}, {2, 1, 0}, {-1, 0, 0}, {}});
  ASSERT_FALSE(plan.error);
  const collision_lab::Prediction msg = toPredictionMsg(plan);
  const double alpha = std::atan(0.1);
  EXPECT_EQ(msg.model, collision_lab::Prediction::MODEL_THREE_BODY_ROTATION);
  EXPECT_EQ(msg.collision_count, 31u);
  EXPECT_TRUE(msg.collision_count_defined);
  EXPECT_FALSE(msg.infinite_collisions);
  EXPECT_EQ(msg.max_possible_collision_count, 32u);
  EXPECT_FALSE(msg.paper_collision_count_defined);
  EXPECT_EQ(msg.first_pair_index, collision_lab::Prediction::PAIR_AB);
  EXPECT_NEAR(msg.alpha, alpha, 1e-15);
  EXPECT_NEAR(msg.theta, 2 * alpha, 1e-15);
  EXPECT_NEAR(msg.omega, M_PI - alpha, 1e-15);
  EXPECT_NEAR(msg.psi, M_PI, 1e-15);
  EXPECT_TRUE(std::isnan(msg.phi_bc));
  const double root = std::tan(M_PI / 4 - alpha / 2);
  EXPECT_NEAR(msg.critical_restitution, root * root, 1e-15);
  EXPECT_NEAR(msg.spiral_angle, 2 * alpha, 1e-15);
  EXPECT_EQ(msg.energy_lost, 0.0);
  EXPECT_FALSE(msg.collapsed);
  ASSERT_EQ(msg.final_velocities.size(), 3u);
  EXPECT_NEAR(msg.final_velocities[0], 0.9988575955631184, 1e-12);
  EXPECT_EQ(msg.final_velocities[2], 0.0);
}

}  // namespace
