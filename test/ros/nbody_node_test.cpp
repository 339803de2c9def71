// collision_lab_node with scenes of any size (nbody_node_test.test), through the real node:
// run summaries and events against hand-derived numbers (docs/physics.md, config/
// scenarios.yaml) and the exact rational reference of the core's tests
// (test/core/nbody/reference.h, which shares no code with the engine), ~max_bodies,
// N-body presets, and ~cancel of a run that would never end.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <boost/math/constants/constants.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/Cancel.h"
#include "collision_lab/RunPreset.h"
#include "collision_lab/RunScene.h"
#include "granular_gas.h"
#include "reference.h"
#include "run_collector.h"

namespace {

using collision_lab_test::callService;
using collision_lab_test::RunCollector;
using collision_lab_test::RunOutputs;
using collision_lab_test::waitUntil;
namespace fs = std::filesystem;
namespace reference = collision_lab::core::reference;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr char kRunPreset[] = "/collision_lab/collision_lab_node/run_preset";
constexpr char kCancel[] = "/collision_lab_to_cap/collision_lab_node/cancel";

std::string g_bag_directory;
RunCollector* g_node = nullptr;   // namespace collision_lab
RunCollector* g_small = nullptr;  // namespace collision_lab_small: ~max_bodies 4
RunCollector* g_to_cap = nullptr;  // namespace collision_lab_to_cap: ~simulate_to_cap true

collision_lab::InitialConditions scene(const std::string& run_id, std::vector<double> m, std::vector<double> x,
                                       std::vector<double> v, std::vector<double> e = {}) {
  collision_lab::InitialConditions input;
  input.header.stamp = ros::Time::now();
  input.run_id = run_id;
  input.masses = std::move(m), input.positions = std::move(x), input.velocities = std::move(v);
  input.restitution = std::move(e);
  return input;
}

const RunOutputs& run(RunCollector* node, const collision_lab::InitialConditions& input) {
  node->publish(input);
  return node->waitFor(input.run_id);
}

double toDouble(const reference::Rational& r) { return static_cast<double>(r); }

/// The node's run equals the exact reference: count, every impact's pair and time, final
/// velocities, heat; the per-body arrays and the plot topics agree with the summary.
void expectMatchesReference(const collision_lab::InitialConditions& input, const RunOutputs& out) {
  const collision_lab::core::Scene core_scene{input.masses, input.positions, input.velocities, input.restitution};
  const reference::Run exact = reference::simulate(core_scene, 100000);
  ASSERT_FALSE(exact.truncated);
  ASSERT_FALSE(exact.multiple_first);
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& s = out.summaries.front();
  // Nothing approaching is answered without simulating (model no_collisions).
  EXPECT_EQ(s.stop_reason, exact.events.empty() ? "NOT_SIMULATED" : "FINISHED");
  EXPECT_EQ(s.body_count, input.masses.size());
  ASSERT_EQ(s.collision_count, exact.events.size());
  ASSERT_EQ(out.events.size(), exact.events.size());
  for (std::size_t k = 0; k < exact.events.size(); ++k) {
    const auto& e = out.events[k];
    EXPECT_EQ(e.index, k + 1);
    EXPECT_EQ(e.pair_index, exact.events[k].pair) << "impact " << k + 1;
    const double t = toDouble(exact.events[k].time);
    EXPECT_NEAR(e.time, t, 1e-12 * std::max(1.0, t)) << "impact " << k + 1;
    EXPECT_NEAR(e.energy_lost, toDouble(exact.events[k].lost), 1e-12) << "impact " << k + 1;
    EXPECT_EQ(out.velocities[k].v.size(), input.masses.size());
  }
  EXPECT_LT(reference::energyNormError(core_scene, s.final_velocities, exact.velocities), 1e-12);
  EXPECT_NEAR(s.energy_lost, toDouble(exact.energy_lost), 1e-12 * std::max(1.0, toDouble(exact.energy_lost)));
  if (!out.events.empty()) {
    // The rebuilt state of the last impact is the end state; the plots carry it too.
    EXPECT_EQ(out.events.back().velocities_after, s.final_velocities);
    EXPECT_EQ(out.velocities.back().v, s.final_velocities);
    EXPECT_NEAR(out.energies.back().cumulative_energy_lost, s.energy_lost, 1e-12);
  }
}

// ---- Hand-derived scenes (config/scenarios.yaml, docs/physics.md) ----

TEST(NBodyNode, TwoCartsWithRestitution08PartAt08AndLose036J) {
  const auto& out = run(g_node, scene("two_carts_e08", {1, 1}, {1, 0}, {-1, 1}, {0.8}));
  ASSERT_EQ(out.summaries.size(), 1u) << (out.rejections.empty() ? "" : out.rejections.front().message);
  const auto& p = out.predictions.front();
  EXPECT_EQ(p.model_name, "two_body");
  EXPECT_EQ(p.model, collision_lab::Prediction::MODEL_TWO_BODY);
  EXPECT_FALSE(p.model_reason.empty());
  EXPECT_TRUE(p.collision_count_defined);
  EXPECT_EQ(p.collision_count, 1u);
  EXPECT_EQ(p.first_pair_index, 0u);
  EXPECT_NEAR(p.energy_lost, 0.36, 1e-15);
  EXPECT_FALSE(p.collapsed);
  EXPECT_TRUE(std::isnan(p.collapse_time));
  EXPECT_TRUE(std::isnan(p.critical_restitution));
  const auto& s = out.summaries.front();
  EXPECT_EQ(s.model_name, "two_body");
  EXPECT_EQ(s.collision_count, 1u);
  ASSERT_EQ(s.final_velocities.size(), 2u);
  EXPECT_NEAR(s.final_velocities[0], 0.8, 1e-15);
  EXPECT_NEAR(s.final_velocities[1], -0.8, 1e-15);
  EXPECT_NEAR(s.energy_lost, 0.36, 1e-15);
  ASSERT_EQ(out.events.size(), 1u);
  const auto& e = out.events.front();
  EXPECT_EQ(e.time, 0.5);
  EXPECT_EQ(e.position, 0.5);
  EXPECT_EQ(e.restitution, 0.8);
  EXPECT_NEAR(e.energy_lost, 0.36, 1e-15);
  EXPECT_NEAR(out.energies.front().cumulative_energy_lost, 0.36, 1e-15);
  EXPECT_TRUE(std::isnan(out.velocities.front().v_c));  // no third body
}

TEST(NBodyNode, CradleOfFivePassesTheVelocityDownTheLine) {
  const auto& out = run(g_node, scene("cradle_5", {1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}));
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& s = out.summaries.front();
  EXPECT_EQ(s.model_name, "ghosts");
  EXPECT_EQ(s.collision_count, 4u);
  EXPECT_EQ(s.final_velocities, (std::vector<double>{0, 0, 0, 0, -1}));
  EXPECT_EQ(s.energy_lost, 0.0);
  ASSERT_EQ(out.events.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    // Impact k + 1: pair k at t = k + 1 s, x = 3 - k m; body k + 1 takes -1 m/s.
    std::vector<double> after(5, 0.0);
    after[k + 1] = -1;
    EXPECT_EQ(out.events[k].pair_index, k);
    EXPECT_EQ(out.events[k].time, k + 1.0);
    EXPECT_EQ(out.events[k].position, 3.0 - k);
    EXPECT_EQ(out.events[k].velocities_after, after);
    EXPECT_EQ(out.velocities[k].v, after);
    EXPECT_EQ(out.events[k].total_energy, 0.5);
    EXPECT_EQ(out.events[k].total_momentum, -1.0);
  }
}

TEST(NBodyNode, BallBetweenWallsStopsAtTheCap) {
  auto input = scene("ball_between_walls", {kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0});
  input.max_collisions = 1000;
  const auto& out = run(g_node, input);
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& p = out.predictions.front();
  EXPECT_EQ(p.model_name, "two_walls_infinite");
  EXPECT_TRUE(p.infinite_collisions);
  EXPECT_FALSE(p.collision_count_defined);
  EXPECT_TRUE(p.final_velocities.empty());
  EXPECT_TRUE(std::isnan(p.energy_lost));
  const auto& s = out.summaries.front();
  EXPECT_EQ(s.collision_count, 1000u);
  EXPECT_TRUE(s.truncated);
  EXPECT_FALSE(s.cancelled);
  EXPECT_EQ(s.stop_reason, "CAP");
  EXPECT_EQ(s.final_velocities, (std::vector<double>{0, 1, 0}));  // an even number of bounces
  EXPECT_EQ(s.published_events, 200u);                           // ~max_published_events
  ASSERT_TRUE(s.recording_ok) << s.recording_error;
  rosbag::Bag bag(s.bag_path, rosbag::bagmode::Read);
  std::vector<collision_lab::CollisionEvent> events;
  for (const auto& m : rosbag::View(bag, rosbag::TopicQuery("/collision_lab/collision_events"))) {
    events.push_back(*m.instantiate<collision_lab::CollisionEvent>());
  }
  ASSERT_EQ(events.size(), 1000u);
  EXPECT_EQ(events.back().time, 999.5);  // bounce k at t = k - 1/2 s
  EXPECT_EQ(events.back().pair_index, 1u);
}

TEST(NBodyNode, BouncingBallWithRestitutionMatchesTheExactReference) {
  auto input = scene("bouncing_ball", {kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0}, {0.9});
  input.max_collisions = 50;
  const auto& out = run(g_node, input);
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& s = out.summaries.front();
  EXPECT_EQ(s.collision_count, 50u);
  EXPECT_EQ(s.stop_reason, "CAP");
  const reference::Run exact = reference::simulate({input.masses, input.positions, input.velocities, input.restitution}, 50);
  ASSERT_EQ(out.events.size(), 50u);
  for (std::size_t k = 0; k < 50; ++k) {
    EXPECT_NEAR(out.events[k].time, toDouble(exact.events[k].time), 1e-12 * out.events[k].time);
  }
  EXPECT_NEAR(s.final_velocities[1], toDouble(exact.velocities[1]), 1e-15);  // 0.9^50 m/s
  EXPECT_NEAR(std::fabs(s.final_velocities[1]), std::pow(0.9, 50), 1e-15);
  EXPECT_NEAR(s.energy_lost, toDouble(exact.energy_lost), 1e-15);
}

TEST(NBodyNode, ThreeEqualMassesCollapseAtE005) {
  const auto& out = run(g_node, scene("collapse_e005", {1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.05}));
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& p = out.predictions.front();
  EXPECT_EQ(p.model_name, "three_body_spiral");
  EXPECT_TRUE(p.collapsed);
  EXPECT_TRUE(p.infinite_collisions);
  EXPECT_NEAR(p.critical_restitution, 7 - 4 * std::sqrt(3.0), 1e-15);  // McNamara and Young
  EXPECT_NEAR(p.alpha, M_PI / 3, 1e-15);
  EXPECT_TRUE(std::isnan(p.spiral_angle));  // real eigenvalues: no spiral
  const auto& s = out.summaries.front();
  EXPECT_TRUE(s.collapsed);
  EXPECT_EQ(s.collapse_count, 1u);
  EXPECT_NEAR(s.collapse_time, p.collapse_time, 1e-12);
  ASSERT_EQ(s.final_velocities.size(), 3u);
  for (double v : s.final_velocities) EXPECT_NEAR(v, -1.0 / 3, 1e-15);
  EXPECT_NEAR(s.energy_lost, 1.0 / 3, 1e-15);  // 1/2 J before, 3 (1/2)(1/9) J after
  // The impacts before the collapse, then the collapse.
  ASSERT_EQ(out.events.size(), s.collision_count + 1);
  const reference::Run exact = reference::simulate({{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.05}}, s.collision_count);
  for (std::size_t k = 0; k < s.collision_count; ++k) {
    EXPECT_EQ(out.events[k].kind, collision_lab::CollisionEvent::KIND_IMPACT);
    EXPECT_EQ(out.events[k].pair_index, exact.events[k].pair) << "impact " << k + 1;
    EXPECT_NEAR(out.events[k].time, toDouble(exact.events[k].time), 1e-12) << "impact " << k + 1;
  }
  const auto& collapse = out.events.back();
  EXPECT_EQ(collapse.kind, collision_lab::CollisionEvent::KIND_COLLAPSE);
  EXPECT_EQ(collapse.first_moved, 0u);
  EXPECT_EQ(collapse.last_moved, 2u);
  EXPECT_EQ(collapse.time, s.collapse_time);
  EXPECT_NEAR(out.energies.back().cumulative_energy_lost, 1.0 / 3, 1e-12);
}

// A, B, C (1 kg each at x = 3, 2, 1 m, v = -1, 0, 0 m/s, e = 0.05) collapse; then D (1 kg
// at -10 m, 0.5 m/s, e = 0.5 with C) hits the cluster. By hand: the cluster's centre of mass
// is at 2 - t/3 m throughout, so the collapse is at x = 2 - t_c/3 and D meets the cluster
// at t = 14.4 s, x = -2.8 m. (Impacts of equal masses keep every velocity of A, B, C within
// [-1, 0] m/s, so C stays right of 1 - t m and D, at -10 + t/2 m, could not reach it before
// t = 22/3 s: after the collapse, about 3.5 s.) The cluster is one body of 3 kg at -1/3 m/s against
// 1 kg at 1/2 m/s: momentum -1/2 kg m/s, approach 5/6 m/s, so it leaves at
// (-1/2 + (1/2)(5/6))/4 = -1/48 m/s and D at (-1/2 - 3 (1/2)(5/6))/4 = -7/16 m/s, with
// (1 - e^2) mu A^2 / 2 = (3/4)(3/4)(25/36)/2 = 25/128 J of heat; the collapse turned 1/3 J.
TEST(NBodyNode, AnImpactAfterACollapseIsPublishedAfterTheCollapseAndMovesTheWholeCluster) {
  const auto input = scene("impact_after_collapse", {1, 1, 1, 1}, {3, 2, 1, -10}, {-1, 0, 0, 0.5}, {0.05, 0.05, 0.5});
  const auto& out = run(g_node, input);
  ASSERT_EQ(out.summaries.size(), 1u) << (out.rejections.empty() ? "" : out.rejections.front().message);
  const auto& s = out.summaries.front();
  EXPECT_TRUE(s.collapsed);
  EXPECT_EQ(s.collapse_count, 1u);
  EXPECT_EQ(s.cluster_impacts, 1u);
  const std::size_t k = s.collision_count;  // impacts 1..k-1 of A, B, C, the collapse, impact k
  ASSERT_GE(k, 2u);
  ASSERT_EQ(out.events.size(), k + 1);
  ASSERT_EQ(out.velocities.size(), k + 1);
  // The collapse record comes in its place: after the last impact of A, B, C, before D's.
  const auto& collapse = out.events[k - 1];
  ASSERT_EQ(collapse.kind, collision_lab::CollisionEvent::KIND_COLLAPSE);
  for (std::size_t j = 0; j < out.events.size(); ++j) {
    if (j != k - 1) {
      EXPECT_EQ(out.events[j].kind, collision_lab::CollisionEvent::KIND_IMPACT) << "record " << j;
    }
  }
  EXPECT_EQ(collapse.index, k - 1);
  EXPECT_EQ(collapse.first_moved, 0u);
  EXPECT_EQ(collapse.last_moved, 2u);
  EXPECT_EQ(collapse.time, s.collapse_time);
  // The limit of the exact impact times of A, B, C alone (their intervals shrink by about
  // 0.16 per pair of impacts, so 60 impacts pin it far below 1e-12 s).
  const reference::Run abc = reference::simulate({{1, 1, 1}, {3, 2, 1}, {-1, 0, 0}, {0.05, 0.05}}, 60);
  EXPECT_TRUE(abc.truncated);  // still colliding: a collapse
  EXPECT_NEAR(collapse.time, toDouble(abc.last_time), 1e-12);
  EXPECT_NEAR(collapse.position, 2 - collapse.time / 3, 1e-12);
  EXPECT_LE(out.events[k - 2].time, collapse.time);
  EXPECT_LE(out.events[k - 2].header.stamp, collapse.header.stamp);
  EXPECT_LE(collapse.header.stamp, out.events[k].header.stamp);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(out.velocities[k - 1].v[i], -1.0 / 3, 1e-15);
  EXPECT_EQ(out.velocities[k - 1].v[3], 0.5);  // D untouched so far

  const auto& impact = out.events[k];
  EXPECT_EQ(impact.index, k);
  EXPECT_EQ(impact.pair_index, 2u);
  EXPECT_TRUE(impact.cluster_impact);
  EXPECT_EQ(impact.first_moved, 0u);
  EXPECT_EQ(impact.last_moved, 3u);
  EXPECT_EQ(impact.restitution, 0.5);
  EXPECT_NEAR(impact.time, 14.4, 1e-12);
  EXPECT_NEAR(impact.position, -2.8, 1e-12);
  EXPECT_NEAR(impact.pair_velocities_before[0], -1.0 / 3, 1e-15);
  EXPECT_NEAR(impact.pair_velocities_after[0], -1.0 / 48, 1e-15);
  EXPECT_NEAR(impact.pair_velocities_after[1], -7.0 / 16, 1e-15);
  EXPECT_NEAR(impact.energy_lost, 25.0 / 128, 1e-15);
  const std::vector<double> by_hand{-1.0 / 48, -1.0 / 48, -1.0 / 48, -7.0 / 16};
  ASSERT_EQ(s.final_velocities.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(s.final_velocities[i], by_hand[i], 1e-15) << "body " << i;
    EXPECT_NEAR(impact.velocities_after[i], by_hand[i], 1e-15) << "body " << i;
    EXPECT_NEAR(out.velocities.back().v[i], by_hand[i], 1e-15) << "body " << i;
  }
  EXPECT_NEAR(s.energy_lost, 1.0 / 3 + 25.0 / 128, 1e-12);
  EXPECT_NEAR(out.energies.back().cumulative_energy_lost, 1.0 / 3 + 25.0 / 128, 1e-12);

  // The bag keeps the same order.
  ASSERT_TRUE(s.recording_ok) << s.recording_error;
  rosbag::Bag bag(s.bag_path, rosbag::bagmode::Read);
  std::vector<std::uint8_t> kinds;
  for (const auto& m : rosbag::View(bag, rosbag::TopicQuery("/collision_lab/collision_events"))) {
    kinds.push_back(m.instantiate<collision_lab::CollisionEvent>()->kind);
  }
  ASSERT_EQ(kinds.size(), k + 1);
  EXPECT_EQ(kinds[k - 1], collision_lab::CollisionEvent::KIND_COLLAPSE);
  EXPECT_EQ(kinds[k], collision_lab::CollisionEvent::KIND_IMPACT);
}

TEST(NBodyNode, CollapseTimeAtE006IsPhysicsMdsValue) {
  const auto& out = run(g_node, scene("collapse_e006", {1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.06}));
  ASSERT_EQ(out.summaries.size(), 1u);
  EXPECT_TRUE(out.summaries.front().collapsed);
  // The limit of the exact impact times (physics.md: 3.7313542986536 s).
  const double time = reference::collapseTime(collision_lab::core::Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.06}});
  EXPECT_NEAR(out.summaries.front().collapse_time, time, 1e-12);
  EXPECT_NEAR(out.predictions.front().collapse_time, time, 1e-12);
}

TEST(NBodyNode, NearCollapseAtE0072Takes63Impacts) {
  const auto input = scene("near_collapse", {1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.072});
  const auto& out = run(g_node, input);
  ASSERT_EQ(out.summaries.size(), 1u);
  EXPECT_EQ(out.summaries.front().collision_count, 63u);
  EXPECT_FALSE(out.summaries.front().collapsed);
  EXPECT_EQ(out.predictions.front().collision_count, 63u);
  EXPECT_GT(out.predictions.front().spiral_angle, 0.0);
  expectMatchesReference(input, out);
}

// ---- Seeded random scenes: N = 2..8 finite masses, one e per pair ----

TEST(NBodyNode, RandomMassesWithPerPairRestitutionMatchTheExactReference) {
  std::mt19937_64 rng(1212);
  std::uniform_real_distribution<double> mass(0.5, 5.0), gap(0.5, 2.0), speed(-1.0, 1.0), e(0.7, 1.0);
  for (int i = 0; i < 24; ++i) {
    const std::size_t n = 2 + i % 7;
    std::vector<double> m, x(n), v, r;
    x[n - 1] = 0;
    for (std::size_t k = n - 1; k-- > 0;) x[k] = x[k + 1] + gap(rng);
    for (std::size_t k = 0; k < n; ++k) m.push_back(mass(rng)), v.push_back(speed(rng));
    for (std::size_t k = 0; k + 1 < n; ++k) r.push_back(e(rng));
    const auto input = scene("random_" + std::to_string(i), m, x, v, r);
    SCOPED_TRACE(input.run_id);
    expectMatchesReference(input, run(g_node, input));
  }
}

// ---- The over-cap rule (runScene), as the CLI applies it (test/cli/nbody_cli_test.cpp) ----

/// The summary of a run over the cap that its model answered at once: not simulated, not
/// truncated, the model's count as the run's answer, and no event.
template <class Outputs>
void expectAnsweredByTheModel(const Outputs& out, const std::string& model, std::uint64_t count) {
  const auto& s = out.summaries.front();
  EXPECT_EQ(s.model_name, model);
  EXPECT_FALSE(s.simulated);
  EXPECT_FALSE(s.truncated);
  EXPECT_EQ(s.stop_reason, "NOT_SIMULATED");
  EXPECT_EQ(s.collision_count, count);
  EXPECT_EQ(s.predicted_collision_count, count);
  EXPECT_TRUE(out.events.empty());
}

// 10,000 equal masses 1 m apart with seeded velocities: the ghosts model predicts the
// inversions (counted here by the plain O(N^2) loop), more than the default cap of 10^7, so
// the model answers at once, though full mode asks for every event: the count, the
// initial velocities sorted (fastest on the right) and no event (failed before: simulated
// at ~130 impacts/s, days).
TEST(NBodyNode, TenThousandEqualMassesAreAnsweredByTheModel) {
  std::mt19937_64 rng(20);
  std::vector<double> m(10000, 1.0), x, v;
  for (int k = 0; k < 10000; ++k) {
    x.push_back(9999.0 - k);
    v.push_back(2.0 * static_cast<double>(rng() >> 11) * 0x1p-53 - 1.0);
  }
  std::uint64_t inversions = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    for (std::size_t j = i + 1; j < v.size(); ++j) inversions += v[i] < v[j];
  }
  ASSERT_GT(inversions, 10000000u);
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end(), std::greater<double>());
  const auto& out = run(g_node, scene("ghosts_over_cap", m, x, v));
  ASSERT_EQ(out.summaries.size(), 1u) << (out.rejections.empty() ? "" : out.rejections.front().message);
  expectAnsweredByTheModel(out, "ghosts", inversions);
  EXPECT_EQ(out.summaries.front().final_velocities, sorted);
}

// Galperin's billiard against a wall, m_B = 1 kg at rest and m_A = the double nearest 1e36
// kg at -1 m/s: N = floor(pi / alpha) collisions, alpha = atan(sqrt(m_B / m_A)), about
// 3.14e18, here in 50 digits; answered by the closed form at once, as by the CLI. The end
// state, by physics: m_A v_A^2 + m_B v_B^2 = m_A (the wall at rest), A moving away from B.
TEST(NBodyNode, AThreeBodyRunOf3e18CollisionsIsAnsweredByTheModel) {
  using Float50 = boost::multiprecision::cpp_bin_float_50;
  const double m_a = 1e36;
  const Float50 alpha = atan(sqrt(Float50(1) / Float50(m_a)));
  const auto galperin = static_cast<std::uint64_t>(floor(boost::math::constants::pi<Float50>() / alpha));
  ASSERT_GT(galperin, 3000000000000000000u);
  const auto& out = run(g_node, scene("galperin_1e36", {m_a, 1, kInf}, {2, 1, 0}, {-1, 0, 0}));
  ASSERT_EQ(out.summaries.size(), 1u) << (out.rejections.empty() ? "" : out.rejections.front().message);
  expectAnsweredByTheModel(out, "three_body_rotation", galperin);
  const auto& s = out.summaries.front();
  ASSERT_EQ(s.final_velocities.size(), 3u);
  const double v_a = s.final_velocities[0], v_b = s.final_velocities[1];
  EXPECT_NEAR(v_a * v_a + v_b * v_b / m_a, 1.0, 1e-12);
  EXPECT_GE(v_a, v_b);
}

// Two walls: infinitely many impacts, said at once; 1,000 simulated for display, not the
// cap of 10^7 (B between walls 2 m apart at 1 m/s hits a wall every 2 s from t = 1 s).
TEST(NBodyNode, TwoWallsAreSimulatedForDisplayOnly) {
  const auto& out = run(g_node, scene("walls_display", {kInf, 1, kInf}, {2, 1, 0}, {0, 1, 0}));
  ASSERT_EQ(out.summaries.size(), 1u) << (out.rejections.empty() ? "" : out.rejections.front().message);
  EXPECT_TRUE(out.predictions.front().infinite_collisions);
  const auto& s = out.summaries.front();
  // The summary says it too (the node's log line and the service answer read it from here).
  EXPECT_TRUE(s.infinite_collisions);
  EXPECT_FALSE(s.predicted_collision_count_defined);
  EXPECT_TRUE(s.simulated);
  EXPECT_TRUE(s.truncated);
  EXPECT_EQ(s.collision_count, 1000u);
}

// ---- Modes: predict-only answers from the closed form ----

TEST(NBodyNode, PredictOnlyGhostsCountTheInversions) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> speed(-1.0, 1.0);
  std::vector<double> m(40, 1.0), x, v;
  for (int k = 0; k < 40; ++k) x.push_back(40.0 - k), v.push_back(speed(rng));
  std::uint64_t inversions = 0;  // pairs i < j with v_i < v_j, by brute force
  for (int i = 0; i < 40; ++i) {
    for (int j = i + 1; j < 40; ++j) inversions += v[i] < v[j];
  }
  auto input = scene("ghosts_predicted", m, x, v);
  input.mode = collision_lab::InitialConditions::MODE_PREDICT_ONLY;
  const auto& out = run(g_node, input);
  ASSERT_EQ(out.summaries.size(), 1u);
  EXPECT_EQ(out.predictions.front().model_name, "ghosts");
  EXPECT_EQ(out.predictions.front().collision_count, inversions);
  EXPECT_FALSE(out.summaries.front().simulated);
  EXPECT_EQ(out.summaries.front().stop_reason, "NOT_SIMULATED");
  EXPECT_EQ(out.summaries.front().predicted_collision_count, inversions);
  EXPECT_TRUE(out.events.empty());
}

// ---- ~max_bodies ----

TEST(NBodyNode, MoreBodiesThanMaxBodiesAreRejectedClearly) {
  const auto& out = run(g_small, scene("five_bodies", {1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}));
  ASSERT_EQ(out.rejections.size(), 1u);
  const auto& r = out.rejections.front();
  EXPECT_EQ(r.reason, collision_lab::Rejected::TOO_MANY_BODIES);
  EXPECT_EQ(r.reason_name, "TOO_MANY_BODIES");
  EXPECT_EQ(r.field, "masses");
  EXPECT_EQ(r.message, "5 bodies are more than this node's ~max_bodies = 4; send a smaller scene, or start "
                       "the node with a larger ~max_bodies");
  EXPECT_TRUE(out.summaries.empty());
  const auto& four = run(g_small, scene("four_bodies", {1, 1, 1, 1}, {3, 2, 1, 0}, {-1, 0, 0, 0}));
  ASSERT_EQ(four.summaries.size(), 1u);
  EXPECT_EQ(four.summaries.front().collision_count, 3u);
}

// ---- Presets of any size ----

TEST(NBodyNode, RunPresetServesTheNBodyPresets) {
  collision_lab::RunPreset cradle;
  cradle.request.name = "cradle_5";
  cradle.request.run_id = "preset_cradle";
  ASSERT_TRUE(callService(kRunPreset, cradle));
  ASSERT_TRUE(cradle.response.ok) << cradle.response.message;
  EXPECT_EQ(cradle.response.summary.collision_count, 4u);
  EXPECT_EQ(cradle.response.summary.body_count, 5u);

  collision_lab::RunPreset collapse;
  collapse.request.name = "collapse_equal";
  ASSERT_TRUE(callService(kRunPreset, collapse));
  ASSERT_TRUE(collapse.response.ok) << collapse.response.message;
  EXPECT_TRUE(collapse.response.summary.collapsed);
  EXPECT_NEAR(collapse.response.summary.energy_lost, 1.0 / 3, 1e-15);
}

// ---- ~cancel: a run that would never end (~simulate_to_cap: true, else 1,000 are shown) ----

TEST(NBodyNode, CancelStopsARunThatWouldNeverEndAndItsBagIsComplete) {
  collision_lab::Cancel idle;
  ASSERT_TRUE(callService(kCancel, idle));
  EXPECT_FALSE(idle.response.ok);
  EXPECT_EQ(idle.response.message, "no run in progress");

  // A ball between two walls with an unreachable cap: only ~cancel ends it.
  auto endless = scene("endless", {kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0});
  endless.max_collisions = std::uint64_t{1} << 62;
  g_to_cap->publish(endless);
  const auto queued = scene("after_endless", {1, 1}, {1, 0}, {-1, 1});
  g_to_cap->publish(queued);  // served by another worker, or after it
  ASSERT_TRUE(waitUntil([] { return g_to_cap->runs().count("endless") && g_to_cap->runs().at("endless").events.size() >= 10; },
                        "the endless run's first collisions"));

  collision_lab::Cancel other;
  other.request.run_id = "not_this_one";
  ASSERT_TRUE(callService(kCancel, other));
  EXPECT_FALSE(other.response.ok);
  EXPECT_EQ(other.response.message, "no run 'not_this_one' is waiting or in progress; nothing stopped");

  collision_lab::Cancel cancel;
  cancel.request.run_id = "endless";
  ASSERT_TRUE(callService(kCancel, cancel));
  EXPECT_TRUE(cancel.response.ok) << cancel.response.message;
  const RunOutputs& out = g_to_cap->waitFor("endless");
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& s = out.summaries.front();
  EXPECT_TRUE(s.cancelled);
  EXPECT_TRUE(s.truncated);
  EXPECT_EQ(s.stop_reason, "CANCELLED");
  EXPECT_GE(s.collision_count, 10u);
  ASSERT_TRUE(s.recording_ok) << s.recording_error;
  {
    rosbag::Bag bag(s.bag_path, rosbag::bagmode::Read);
    std::uint64_t index = 0;
    for (const auto& m : rosbag::View(bag, rosbag::TopicQuery("/collision_lab_to_cap/collision_events"))) {
      ASSERT_EQ(m.instantiate<collision_lab::CollisionEvent>()->index, ++index);
    }
    EXPECT_EQ(index, s.collision_count);
    EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/collision_lab_to_cap/run_summaries")).size(), 1u);
  }
  std::error_code ec;
  fs::remove(s.bag_path, ec);  // it may be large

  // Nothing lost: the input sent during the run is served.
  EXPECT_EQ(g_to_cap->waitFor("after_endless").summaries.size(), 1u);
}

// ---- Issue 21: a gas whose impacts crowd ends, or is cancelled, and the queue goes on ----

TEST(NBodyNode, ACrowdingGasEndsOrIsCancelledAndTheSceneQueuedAfterItIsAnswered) {
  // The seeded 100-body gas at e = 0.5 needs exact decisions after about 4,000 impacts (it
  // gave no answer before the exactness budget); a pi scene waits behind it.
  const collision_lab::core::Scene gas = collision_lab::core::testing_support::granularGas(100, 0.5, 1);
  g_node->publish(scene("gas_e05", gas.masses, gas.positions, gas.velocities, gas.restitution));
  g_node->publish(scene("pi_after_gas", {1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}));
  ASSERT_TRUE(waitUntil([] { return g_node->runs().count("gas_e05") && !g_node->runs().at("gas_e05").events.empty(); },
                        "the gas's first impacts"));
  collision_lab::Cancel cancel;
  cancel.request.run_id = "gas_e05";
  ASSERT_TRUE(callService("/collision_lab/collision_lab_node/cancel", cancel));
  const RunOutputs& out = g_node->waitFor("gas_e05");
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& s = out.summaries.front();
  EXPECT_TRUE(s.truncated);
  // The run either saw ~cancel or had already stopped at its exactness budget.
  EXPECT_EQ(s.stop_reason, cancel.response.ok ? "CANCELLED" : "PRECISION_BUDGET") << cancel.response.message;
  // m_A/m_B = 1e4 against a wall: floor(pi * 100) = 314 collisions (Galperin).
  const RunOutputs& pi = g_node->waitFor("pi_after_gas");
  ASSERT_EQ(pi.summaries.size(), 1u);
  EXPECT_EQ(pi.summaries.front().collision_count, 314u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "nbody_node_test");
  if (!ros::NodeHandle("~").getParam("bag_directory", g_bag_directory)) {
    ADD_FAILURE() << "~bag_directory must be set";
    return 1;
  }
  RunCollector node("collision_lab"), small("collision_lab_small"), to_cap("collision_lab_to_cap");
  g_node = &node;
  g_small = &small;
  g_to_cap = &to_cap;
  node.waitForConnection();
  small.waitForConnection();
  to_cap.waitForConnection();
  for (const char* service : {kRunPreset, kCancel}) {
    if (!ros::service::waitForService(service, ros::Duration(collision_lab_test::kWaitTimeout))) {
      ADD_FAILURE() << "no service " << service << " after " << collision_lab_test::kWaitTimeout << " s";
    }
  }
  const int result = RUN_ALL_TESTS();
  std::error_code ec;
  fs::remove_all(fs::path(g_bag_directory).parent_path(), ec);
  return result;
}
