// Every impact of an inelastic ring against the exact rational reference (reference.h,
// simulateRing), the seam pair included: which pair, when, and the velocities the pair's
// two bodies leave with. The seam pair's left body is body 0; before issue 32 an impact
// decided by a higher precision tier published body N (past the last) there: a wrong
// velocity (2.4e198 m/s) on a 3-body ring, a crash on a 4-body one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "collision_lab/core/nbody/engine.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

struct RingCheck {
  std::size_t impacts = 0;
  std::size_t seam_impacts = 0;
};

/// Runs the engine with every event kept, and compares each event with the reference.
RingCheck expectRingMatchesReference(const Scene& scene, std::uint64_t cap, const std::string& label) {
  EngineOptions options;
  options.max_impacts = cap;
  options.keep_events = cap;
  const SceneSimulation run = runEngine(scene, options);
  EXPECT_NE(run.stop, StopReason::kInternalError) << label << ": " << run.stop_message;
  const reference::RingRun exact = reference::simulateRing(scene, run.impacts.size());
  EXPECT_EQ(exact.events.size(), run.impacts.size()) << label;
  double speed = 0.0;  // the velocity scale [m/s]
  for (double v : scene.velocities) speed = std::max(speed, std::fabs(v));
  RingCheck check;
  for (std::size_t k = 0; k < std::min(exact.events.size(), run.impacts.size()); ++k) {
    const ImpactRecord& got = run.impacts[k];
    const reference::RingEvent& want = exact.events[k];
    const std::string at = label + ", impact " + std::to_string(k + 1);
    EXPECT_EQ(got.pair_index, want.pair) << at;
    if (got.pair_index != want.pair) break;
    const double t = static_cast<double>(want.time);
    EXPECT_NEAR(got.time, t, 1e-12 * std::fabs(t)) << at;
    EXPECT_NEAR(got.velocities_after[0], static_cast<double>(want.after_right), 1e-9 * speed) << at;
    EXPECT_NEAR(got.velocities_after[1], static_cast<double>(want.after_left), 1e-9 * speed) << at;
    ++check.impacts;
    check.seam_impacts += got.pair_index + 1 == scene.size();
  }
  for (std::size_t body : run.crowding_bodies) EXPECT_LT(body, scene.size()) << label;
  return check;
}

Scene ring(std::vector<double> masses, std::vector<double> positions, std::vector<double> velocities,
           std::vector<double> restitution, double length) {
  Scene s;
  s.masses = std::move(masses);
  s.positions = std::move(positions);
  s.velocities = std::move(velocities);
  s.restitution = std::move(restitution);
  s.ring = length;
  return s;
}

// The 3-body ring: impact 313 published 2.42e198 m/s where the exact value is -0.0049 m/s.
TEST(RingEvents, ThreeBodySeamVelocityIsExact) {
  const Scene s = ring({1.75, 2.75, 3.0}, {2.09375, 1.796875, 0.59375}, {0.0234375, 0.21875, -0.2265625},
                       {0.875, 0.8125, 0.46875}, 3.609375);
  const RingCheck check = expectRingMatchesReference(s, 1500, "3-body ring");
  EXPECT_GT(check.seam_impacts, 50u);
}

// The 4-body ring: with events, the engine crashed (SIGSEGV) after 400-700 impacts.
TEST(RingEvents, FourBodyRingWithEventsDoesNotCrash) {
  const Scene s = ring({2.0, 0.75, 2.5, 2.75}, {3.1875, 2.671875, 1.328125, 0.625},
                       {0.75, -0.7109375, -0.98828125, -0.6796875}, {0.40625}, 3.40625);
  const RingCheck check = expectRingMatchesReference(s, 1500, "4-body ring");
  EXPECT_GT(check.impacts, 700u);
  EXPECT_GT(check.seam_impacts, 100u);
}

// Seeded inelastic rings of dyadic numbers, as the exact reference drew them.
TEST(RingEvents, RandomInelasticRingsAgreeWithReference) {
  std::mt19937_64 rng(3232);
  std::size_t seam = 0;
  for (int trial = 0; trial < 28; ++trial) {
    const std::size_t n = 3 + trial % 3;
    std::uniform_int_distribution<int> mass(2, 12), speed(-64, 64), e(8, 31);
    const double length = 4.0;
    std::vector<double> m, x, v, r;
    std::vector<int> slots(63);  // distinct positions in (0, L), multiples of 1/16
    for (int k = 0; k < 63; ++k) slots[k] = k + 1;
    std::shuffle(slots.begin(), slots.end(), rng);
    slots.resize(n);
    std::sort(slots.begin(), slots.end(), std::greater<int>());
    for (std::size_t k = 0; k < n; ++k) {
      m.push_back(mass(rng) / 4.0);
      x.push_back(slots[k] / 16.0);
      v.push_back(speed(rng) / 64.0);
      r.push_back(e(rng) / 32.0);
    }
    seam += expectRingMatchesReference(ring(m, x, v, r, length), 300, "ring " + std::to_string(trial)).seam_impacts;
  }
  EXPECT_GT(seam, 200u);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
