// libFuzzer target over the N-body path every front end takes: planScene (validation, model,
// prediction) and runScene (the event engine), with the event visitors on: any number of
// bodies, walls, rings, per-pair restitution and the restitution models.
//
// Contract: for ANY bytes, nothing crashes, throws, or trips ASan/UBSan; for a scene that
// planScene accepts, the invariants checked below hold, and a violation aborts with a
// one-line reason (so libFuzzer saves the input as a crash).
//
// Input layout (fuzz/make_seeds.py writes the committed seeds in it):
//   byte 0   options: bits 0-1 events (none, all, first 3, none), bit 2 ring, bits 3-4
//            restitution model (constant, tc, threshold, viscoelastic), bit 5 one
//            restitution per pair (else one for every pair), bit 6 simulate to the cap
//   byte 1   bodies N = 2 + byte % 7
//   byte 2   max_collisions: kCaps[byte % kCaps.size()]
//   then little-endian IEEE doubles (any bit pattern): N masses, N positions, N velocities,
//   the restitution (one, or one per pair: N - 1 on a line, N on a ring), the ring's
//   circumference (ring only), the model's parameter (tc, threshold or viscoelastic only).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "fuzz_input.h"
#include "collision_lab/core/scene_run.h"

namespace cl = collision_lab::core;

namespace {

/// Collision caps: small enough that one iteration stays in milliseconds; 1500 as the
/// issue's ring crash.
constexpr std::uint64_t kCaps[] = {0, 1, 10, 100, 1500};

using collision_lab::fuzz::Reader;

bool finite(const std::vector<double>& values) {
  for (double x : values) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

}  // namespace

/// One input (the libFuzzer entry below, and the corpus replay test).
int collisionLabNbodyFuzzOne(const std::uint8_t* data, std::size_t size) {
  Reader in(data, size);
  if (!in.has(3)) return 0;
  const std::uint8_t flags = in.byte();
  const std::size_t n = 2 + in.byte() % 7;
  const std::uint64_t cap = kCaps[in.byte() % (sizeof kCaps / sizeof kCaps[0])];
  const bool ring = flags & 0x4;
  const int model = (flags >> 3) & 0x3;
  const std::size_t restitutions = (flags & 0x20) ? (ring ? n : n - 1) : 1;
  if (!in.has(8 * (3 * n + restitutions + (ring ? 1 : 0) + (model != 0 ? 1 : 0)))) return 0;
  cl::Scene scene;
  scene.masses = in.rawDoubles(n);
  scene.positions = in.rawDoubles(n);
  scene.velocities = in.rawDoubles(n);
  scene.restitution = in.rawDoubles(restitutions);
  if (ring) scene.ring = in.rawDouble();
  switch (model) {
    case 1: scene.restitution_model.kind = cl::RestitutionModelKind::kTc; scene.restitution_model.tc = in.rawDouble(); break;
    case 2:
      scene.restitution_model.kind = cl::RestitutionModelKind::kThreshold;
      scene.restitution_model.elastic_below = in.rawDouble();
      break;
    case 3:
      scene.restitution_model.kind = cl::RestitutionModelKind::kViscoelastic;
      scene.restitution_model.viscoelastic_speed = in.rawDouble();
      break;
    default: break;
  }

  const cl::ScenePlan plan = cl::planScene(scene);
  if (plan.error) {
    FUZZ_CHECK(!plan.error->message.empty(), "a rejection has a message");
    return 0;
  }
  cl::SceneRunOptions options;
  options.lab.max_collisions = cap;
  const int events = flags & 0x3;
  options.lab.events = events == 1 ? cl::EventPolicy::all() : events == 2 ? cl::EventPolicy::firstN(3) : cl::EventPolicy::none();
  options.simulate_to_cap = flags & 0x40;
  std::uint64_t impacts = 0;
  bool beyond = false;  // an impact came after the largest double
  cl::SceneVisitors visitors;
  visitors.impact = [&](const cl::ImpactRecord& record) {
    FUZZ_CHECK(record.index == ++impacts, "impacts numbered 1, 2, ... in order");
    FUZZ_CHECK(record.pair_index < (ring ? n : n - 1), "an impact's pair exists");
    FUZZ_CHECK(record.first_moved < n && record.last_moved < n, "an impact moves bodies that exist");
    FUZZ_CHECK(ring || record.first_moved <= record.last_moved, "on a line, the moved bodies are in order");
    // A time past the largest double is +inf (time_beyond_range), a point past it +-inf.
    FUZZ_CHECK((std::isfinite(record.time) || record.time == HUGE_VAL) && !std::isnan(record.position),
               "an impact time finite or past the largest double, a point");
    beyond = beyond || std::isinf(record.time);
    FUZZ_CHECK(std::isfinite(record.velocities_after[0]) || std::isinf(scene.masses[record.pair_index]),
               "finite velocities after an impact");
    if (record.model) {
      FUZZ_CHECK(n == 3, "a model block beside the impacts of three bodies");
      FUZZ_CHECK(record.model->velocities_after[record.pair_index] == record.velocities_after[0],
                 "the model block's state agrees with the record");
    }
  };
  const cl::SceneRunResult result = cl::runScene(plan, options, visitors);
  const cl::SceneSimulation& sim = result.simulation;
  FUZZ_CHECK(!sim.stop_message.empty(), "every run says why it ended");
  FUZZ_CHECK(!beyond || sim.time_beyond_range, "an impact past the largest double is said in the summary");
  FUZZ_CHECK(sim.stop != cl::StopReason::kInternalError, "the tiers never disagree");
  FUZZ_CHECK(sim.final_velocities.size() == n, "one final velocity per body");
  FUZZ_CHECK(!sim.simulated || sim.impact_count <= cap, "a simulation stops at the cap");
  if (sim.simulated && !(result.prediction && cl::hasRotationValues(*result.prediction))) {
    FUZZ_CHECK(impacts == sim.impact_count, "the visitor sees every impact");
  }
  if (sim.stop == cl::StopReason::kFinished && sim.simulated) {
    FUZZ_CHECK(finite(sim.final_velocities), "finite final velocities of a finished run");
  }
  return 0;
}

#ifndef COLLISION_LAB_FUZZ_REPLAY
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return collisionLabNbodyFuzzOne(data, size);
}
#endif
