// Message <-> core conversions (no master).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "collision_lab/ros/lab_node.h"
#include "collision_lab/ros/msg_conversion.h"

namespace {

using namespace collision_lab_ros;
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(MsgConversion, SceneRoundTripKeepsWallsAndValues) {
  collision_lab::core::ThreeBodyScene scene;
  scene.masses = {kInf, 2.5, 1e-300};
  scene.positions = {3, 1, -0.1};
  scene.velocities = {-0.5, 0, 1e150};
  const auto msg = toInitialConditions(scene, collision_lab::core::RunMode::kSummaryOnly, 77);
  EXPECT_EQ(msg.mode, collision_lab::InitialConditions::MODE_SUMMARY_ONLY);
  EXPECT_EQ(msg.max_collisions, 77u);
  const collision_lab::core::ThreeBodyScene back = toScene(msg);
  EXPECT_EQ(back.masses, scene.masses);
  EXPECT_EQ(back.positions, scene.positions);
  EXPECT_EQ(back.velocities, scene.velocities);
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

TEST(MsgConversion, PredictionRoundTrip) {
  collision_lab::core::AnalyticPrediction p;
  p.collision_count = 2221441;
  p.paper_collision_count = -3;
  p.max_possible_collision_count = 2221442;
  p.angles = {0.1, 0.2, M_PI - 0.1};
  p.phi_bc = 0.3;
  p.psi = 4.5;
  p.first_pair = collision_lab::core::Pair::BC;
  p.final_velocities = {1, -2, 3};
  const collision_lab::core::AnalyticPrediction back = toPrediction(toPredictionMsg(p));
  EXPECT_EQ(back.collision_count, p.collision_count);
  EXPECT_EQ(back.paper_collision_count, p.paper_collision_count);
  EXPECT_EQ(back.max_possible_collision_count, p.max_possible_collision_count);
  EXPECT_EQ(back.angles.alpha, p.angles.alpha);
  EXPECT_EQ(back.angles.theta, p.angles.theta);
  EXPECT_EQ(back.angles.omega, p.angles.omega);
  EXPECT_EQ(back.phi_bc, p.phi_bc);
  EXPECT_EQ(back.psi, p.psi);
  EXPECT_EQ(back.first_pair, p.first_pair);
  EXPECT_EQ(back.final_velocities, p.final_velocities);

  p.paper_collision_count.reset();
  p.first_pair.reset();
  const auto msg = toPredictionMsg(p);
  EXPECT_FALSE(msg.paper_collision_count_defined);
  EXPECT_EQ(msg.first_pair_index, collision_lab::Prediction::PAIR_NONE);
  EXPECT_FALSE(toPrediction(msg).paper_collision_count);
  EXPECT_FALSE(toPrediction(msg).first_pair);
}

collision_lab::core::LabEvent sampleEvent() {
  collision_lab::core::LabEvent e;
  e.event.index = 42;
  e.event.pair = collision_lab::core::Pair::BC;
  e.event.time = 1.5;
  e.event.position = -0.25;
  e.event.positions = {1, -0.25, -0.25};
  e.event.velocities_before = {-1, 0.5, 1};
  e.event.velocities_after = {-1, 0.9, 0.2};
  e.event.energy_transfer = {0, 0.1, -0.1};
  e.event.total_energy = 3.25;
  e.event.total_momentum = -0.5;
  e.predicted_velocities_after = {-1, 0.9000001, 0.2};
  e.paper_velocities_after = {7, 8, 9};
  e.predicted_energy_transfer = {0, 0.11, -0.11};
  e.paper_energy_transfer = {0, 0.2, -0.2};
  e.kinetic_energy_after = {0.5, 0.81, 0.06};
  return e;
}

TEST(MsgConversion, CollisionEventRoundTrip) {
  const collision_lab::core::LabEvent e = sampleEvent();
  const auto msg = toCollisionEventMsg(e);
  EXPECT_EQ(msg.pair_index, collision_lab::CollisionEvent::PAIR_BC);
  const collision_lab::core::LabEvent back = toLabEvent(msg);
  EXPECT_EQ(back.event.index, e.event.index);
  EXPECT_EQ(back.event.pair, e.event.pair);
  EXPECT_EQ(back.event.time, e.event.time);
  EXPECT_EQ(back.event.position, e.event.position);
  EXPECT_EQ(back.event.positions, e.event.positions);
  EXPECT_EQ(back.event.velocities_before, e.event.velocities_before);
  EXPECT_EQ(back.event.velocities_after, e.event.velocities_after);
  EXPECT_EQ(back.event.energy_transfer, e.event.energy_transfer);
  EXPECT_EQ(back.event.total_energy, e.event.total_energy);
  EXPECT_EQ(back.event.total_momentum, e.event.total_momentum);
  EXPECT_EQ(back.predicted_velocities_after, e.predicted_velocities_after);
  EXPECT_EQ(back.paper_velocities_after, e.paper_velocities_after);
  EXPECT_EQ(back.predicted_energy_transfer, e.predicted_energy_transfer);
  EXPECT_EQ(back.paper_energy_transfer, e.paper_energy_transfer);
  EXPECT_EQ(back.kinetic_energy_after, e.kinetic_energy_after);
}

TEST(MsgConversion, PlotTopicsAreTheEventsSimulatedValues) {
  collision_lab::CollisionEvent event = toCollisionEventMsg(sampleEvent());
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

TEST(MsgConversion, RunSummaryPhysicsFields) {
  collision_lab::core::LabRunSummary s;
  s.collision_count = 10;
  s.truncated = true;
  s.truncation_reason = "cap";
  s.simulated = true;
  s.final_velocities = {1, 2, 3};
  s.max_prediction_error = 1e-15;
  s.energy_relative_drift = 2e-16;
  s.momentum_relative_drift = std::nan("");
  s.compute_time_s = 0.5;
  collision_lab::core::AnalyticPrediction p;
  p.collision_count = 11;
  const auto msg = toRunSummaryMsg(s, p, collision_lab::core::RunMode::kFull);
  EXPECT_EQ(msg.collision_count, 10u);
  EXPECT_TRUE(msg.truncated);
  EXPECT_EQ(msg.truncation_reason, "cap");
  EXPECT_EQ(msg.predicted_collision_count, 11u);
  EXPECT_FALSE(msg.paper_predicted_collision_count_defined);
  EXPECT_EQ(msg.final_velocities[2], 3.0);
  EXPECT_TRUE(std::isnan(msg.momentum_relative_drift));
  EXPECT_EQ(msg.compute_time, 0.5);
  EXPECT_EQ(msg.mode, collision_lab::InitialConditions::MODE_FULL);
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

TEST(RunId, OnlySafeFileNames) {
  EXPECT_EQ(runIdProblem("pi_digits_3_20261122T054855Z"), "");
  EXPECT_EQ(runIdProblem("a.b-c_D9"), "");
  EXPECT_NE(runIdProblem(""), "");
  EXPECT_NE(runIdProblem("../x"), "");
  EXPECT_NE(runIdProblem(".hidden"), "");
  EXPECT_NE(runIdProblem("a/b"), "");
  EXPECT_NE(runIdProblem("a b"), "");
  EXPECT_NE(runIdProblem(std::string(201, 'a')), "");
}

}  // namespace
