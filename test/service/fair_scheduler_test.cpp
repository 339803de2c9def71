// The lab node's run queue (fair_scheduler.h): round robin across students per lane,
// queue positions, removal, lanes chosen from the plan. No master needed.
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collision_lab/service/fair_scheduler.h"

namespace {

using collision_lab::service::chooseLane;
using collision_lab::service::FairScheduler;
using collision_lab::service::Lane;
using collision_lab::service::LaneLimits;
namespace core = collision_lab::core;
using Scheduler = FairScheduler<int>;

Scheduler::Entry entry(const std::string& run_id, const std::string& student, Lane lane = Lane::kLong) {
  return Scheduler::Entry{run_id, student, lane, 0};
}

std::vector<std::string> popAll(Scheduler& scheduler, bool short_only) {
  std::vector<std::string> ids;
  while (auto e = scheduler.pop(short_only)) ids.push_back(e->run_id);
  return ids;
}

TEST(FairScheduler, TenthRunOfOneStudentWaitsBehindAClassmatesFirst) {
  Scheduler scheduler;
  for (int i = 1; i <= 10; ++i) EXPECT_EQ(scheduler.push(entry("a" + std::to_string(i), "a")), std::size_t(i - 1));
  // b's first run is served right after a's first.
  EXPECT_EQ(scheduler.push(entry("b1", "b")), 1u);
  EXPECT_EQ(scheduler.push(entry("c1", "c")), 2u);
  EXPECT_EQ(scheduler.push(entry("b2", "b")), 4u);  // a1 b1 c1 a2 | b2
  std::vector<std::string> order;
  for (const auto* e : scheduler.order()) order.push_back(e->run_id);
  const std::vector<std::string> expected{"a1", "b1", "c1", "a2", "b2", "a3", "a4", "a5", "a6", "a7", "a8", "a9", "a10"};
  EXPECT_EQ(order, expected);
  EXPECT_EQ(popAll(scheduler, false), expected);
  EXPECT_EQ(scheduler.size(), 0u);
}

TEST(FairScheduler, AnonymousInputsCountAsOneStudent) {
  Scheduler scheduler;
  scheduler.push(entry("x1", ""));
  scheduler.push(entry("x2", ""));
  scheduler.push(entry("s1", "s"));
  EXPECT_EQ(popAll(scheduler, false), (std::vector<std::string>{"x1", "s1", "x2"}));
}

TEST(FairScheduler, ShortLaneWorkersTakeOnlyShortRunsAndOthersTakeShortFirst) {
  Scheduler scheduler;
  EXPECT_EQ(scheduler.push(entry("long1", "a", Lane::kLong)), 0u);
  EXPECT_EQ(scheduler.push(entry("short1", "a", Lane::kShort)), 0u);  // positions count per lane
  EXPECT_TRUE(scheduler.ready(true));
  EXPECT_EQ(scheduler.pop(true)->run_id, "short1");
  EXPECT_FALSE(scheduler.ready(true));
  EXPECT_FALSE(scheduler.pop(true).has_value());
  scheduler.push(entry("short2", "b", Lane::kShort));
  EXPECT_EQ(scheduler.pop(false)->run_id, "short2");
  EXPECT_EQ(scheduler.pop(false)->run_id, "long1");
}

TEST(FairScheduler, RemoveTakesAWaitingRunOutAndKeepsTheOrder) {
  Scheduler scheduler;
  scheduler.push(entry("a1", "a"));
  scheduler.push(entry("b1", "b"));
  scheduler.push(entry("a2", "a"));
  EXPECT_EQ(scheduler.remove("b1")->run_id, "b1");
  EXPECT_FALSE(scheduler.remove("b1").has_value());
  EXPECT_FALSE(scheduler.remove("nope").has_value());
  EXPECT_EQ(popAll(scheduler, false), (std::vector<std::string>{"a1", "a2"}));
}

TEST(FairScheduler, DrainEmptiesBothLanes) {
  Scheduler scheduler;
  scheduler.push(entry("a1", "a", Lane::kShort));
  scheduler.push(entry("a2", "a", Lane::kLong));
  EXPECT_EQ(scheduler.drain().size(), 2u);
  EXPECT_EQ(scheduler.size(), 0u);
  EXPECT_FALSE(scheduler.ready(false));
}

core::ScenePlan plan(std::vector<double> masses, std::vector<double> positions, std::vector<double> velocities) {
  core::Scene scene;
  scene.masses = std::move(masses);
  scene.positions = std::move(positions);
  scene.velocities = std::move(velocities);
  return core::planScene(scene);
}

core::SceneRunOptions runOptions(core::RunMode mode, std::uint64_t cap, bool simulate_to_cap) {
  core::SceneRunOptions options;
  options.lab.mode = mode;
  options.lab.events = mode == core::RunMode::kFull ? core::EventPolicy::all() : core::EventPolicy::none();
  options.lab.max_collisions = cap;
  options.simulate_to_cap = simulate_to_cap;
  return options;
}

TEST(ChooseLane, FromWhatThePlanKnows) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const LaneLimits limits;  // 100,000 impacts
  const auto full = core::RunMode::kFull, predict = core::RunMode::kPredictOnly;
  const auto pi31 = plan({100, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  ASSERT_FALSE(pi31.error);
  EXPECT_EQ(chooseLane(pi31, runOptions(full, 10'000'000, false), limits), Lane::kShort);
  // 3.14e8 impacts: long when simulated to a large cap, short when predict-only or when the
  // model answers over a smaller cap.
  const auto pi_big = plan({1e16, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  ASSERT_FALSE(pi_big.error);
  const std::uint64_t all = std::numeric_limits<std::uint64_t>::max();
  EXPECT_EQ(chooseLane(pi_big, runOptions(full, all, false), limits), Lane::kLong);
  EXPECT_EQ(chooseLane(pi_big, runOptions(predict, all, false), limits), Lane::kShort);
  EXPECT_EQ(chooseLane(pi_big, runOptions(full, 1000, false), limits), Lane::kShort);
  EXPECT_EQ(chooseLane(pi_big, runOptions(full, 1'000'000, true), limits), Lane::kLong);
  // Endless impacts between two walls: a display's worth (short), or the cap when asked for.
  const auto box = plan({kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0});
  ASSERT_FALSE(box.error);
  EXPECT_EQ(chooseLane(box, runOptions(full, 10'000'000, false), limits), Lane::kShort);
  EXPECT_EQ(chooseLane(box, runOptions(full, 10'000'000, true), limits), Lane::kLong);
  // A collapse the plan cannot count, of three bodies: the engine stops at it.
  core::Scene spiral;
  spiral.masses = {1, 1, 1};
  spiral.positions = {2, 1, 0};
  spiral.velocities = {-1, 0, 0};
  spiral.restitution = {0.05};
  const auto collapse = core::planScene(spiral);
  ASSERT_FALSE(collapse.error);
  EXPECT_FALSE(core::plannedImpacts(collapse, runOptions(full, 10'000'000, true)));
  EXPECT_EQ(chooseLane(collapse, runOptions(full, 10'000'000, true), limits), Lane::kShort);
}

// Where the plan counts nothing, the lane follows the measured cost, not the body count.
// (Failed before: 100 bodies with a cap of 100,000 were short whatever they cost, 101
// bodies that end in a few impacts were long.)
TEST(ChooseLane, ByMeasuredCostWhereThePlanCountsNothing) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> mass(1.0, 3.0), speed(-1.0, 1.0);
  std::vector<double> masses, positions, velocities;
  for (int i = 0; i < 100; ++i) {
    masses.push_back(mass(random));
    positions.push_back(100.0 - i);
    velocities.push_back(speed(random));
  }
  const auto gas = plan(masses, positions, velocities);
  ASSERT_FALSE(gas.error);
  const auto full = runOptions(core::RunMode::kFull, 100'000, false);
  ASSERT_FALSE(core::plannedImpacts(gas, full));
  LaneLimits limits;
  ASSERT_GT(core::runScene(gas, full).simulation.impact_count, limits.probe_impacts);  // more than the probe
  limits.short_max_seconds = 0.0;  // no estimate is short enough
  EXPECT_EQ(chooseLane(gas, full, limits), Lane::kLong);
  limits.short_max_seconds = 1e9;  // any estimate is
  EXPECT_EQ(chooseLane(gas, full, limits), Lane::kShort);
  // A cap above short_max_collisions is long, whatever the estimate: the run publishes and
  // records up to its cap.
  EXPECT_EQ(chooseLane(gas, runOptions(core::RunMode::kFull, 100'001, false), limits), Lane::kLong);

  // 101 bodies whose run ends within the probe: short, however little time is allowed.
  std::vector<double> apart_masses(101, 1.0), apart_positions, apart_velocities(101, 0.0);
  for (int i = 0; i < 101; ++i) apart_positions.push_back(101.0 - i);
  apart_masses[3] = 2.0;  // no model counts unequal masses
  apart_velocities[1] = 1.0;  // one impact: the rightmost body takes the velocity and leaves
  const auto apart = plan(apart_masses, apart_positions, apart_velocities);
  ASSERT_FALSE(apart.error);
  ASSERT_FALSE(core::plannedImpacts(apart, full));
  limits.short_max_seconds = 0.0;
  EXPECT_EQ(chooseLane(apart, full, limits), Lane::kShort);
}

}  // namespace
