// libFuzzer target over the ROS-free core: validation, prediction, the lab run (the event
// engine's simulation), the closed-form model and the paper's printed formulas.
//
// Contract: for ANY bytes, nothing crashes, throws, or trips ASan/UBSan; for a scene that
// validate() accepts, the invariants checked below hold, and a violation aborts with a
// one-line reason (so libFuzzer saves the input as a crash).
//
// Input layout (fuzz/make_seeds.py writes the committed seeds in it):
//   byte 0   options: bit 0 a visitor watches every event (bit 1 unused; bits 0-1 chose
//            the working precision, since removed), bits 2-3 kept events (none, all,
//            first 3, none), bit 4 encoding (0 raw, 1 compact), bit 5 the second run answers over the
//            cap from the closed form (no simulation to the cap), bits 6-7 run mode
//   byte 1   max_collisions: kCaps[byte % kCaps.size()]
//   then 9 values, masses A B C, positions A B C, velocities A B C, each either
//     raw:     8 bytes, a little-endian IEEE double (any bit pattern, NaN and inf too), or
//     compact: int16 mantissa, int16 exponent (little-endian): mantissa * 10^(exp % 340);
//              mantissa -32768 / -32767 / -32766 stand for +inf / -inf / NaN.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "fuzz_input.h"
#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/core/nbody/models.h"
#include "collision_lab/core/paper.h"
#include "collision_lab/core/scene.h"

namespace cl = collision_lab::core;

namespace {

/// Collision caps: small enough that one iteration stays in milliseconds.
constexpr std::array<std::uint64_t, 10> kCaps = {0, 1, 2, 3, 5, 10, 100, 1000, 10000, 100000};
/// Caps for the slower paths (events kept or visited, the rotation model's values beside each impact).
constexpr std::uint64_t kSlowPathCap = 2000;
/// Runs short enough to cross-check against exact rationals (their cost grows about
/// cubically: 40 collisions of a scene mixing 1e30 kg and 1e-139 m/s take 1.3 s).
constexpr std::uint64_t kExactCrossCheckLimit = 20;

/// Known, reported core limits that remain (the seeds exact_escalation and time_overflow
/// reproduce them). The target steps around them so that fuzzing keeps looking for new
/// issues; COLLISION_LAB_FUZZ_KNOWN_ISSUES=check turns the detours off. (Fixed since the
/// first report, detours removed: out-of-range counts cast to uint64_t, underflowing mass
/// ratios, first contacts beyond the double range, maxPossible below 3, subnormal and
/// mass-weighted speeds in the count, energyTransfer overflow near DBL_MAX, and the
/// quadratic replays.)
///  - mass ratios between ~1e24 and the validated limit 1e100: the double error bound
///    exceeds the approach speeds, so every decision goes to the 100-digit closed form
///    (O(1), tens of microseconds each). Such runs are capped at kQuadraticCap here.
constexpr double kQuadraticMassRatio = 1e24;
constexpr std::uint64_t kQuadraticCap = 5;

bool skipKnownIssues() {
  static const bool skip = [] {
    const char* mode = std::getenv("COLLISION_LAB_FUZZ_KNOWN_ISSUES");
    return !(mode && std::strcmp(mode, "check") == 0);
  }();
  return skip;
}

using collision_lab::fuzz::Reader;

bool allFinite(const std::array<double, 3>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

bool allFinite(const Eigen::Vector3d& v) { return v.allFinite(); }

/// Per-particle velocity scale [m/s]: (|frame| + |u| / sqrt(m_max)) sqrt(m_max / m_i),
/// where u is the mass-weighted velocity in the wall's (or centre-of-mass) frame, whose
/// norm every impact conserves. It bounds |v_i| in exact arithmetic, and it is the
/// conditioning of the closed form: the rounding of the frame velocity in a heavy
/// body's component (eps |frame| sqrt(m_max)) reaches body i as eps |frame| sqrt(m_max / m_i).
/// Computed without squaring a velocity, so 1e-200 m/s does not underflow.
/// floor: the absolute error [m/s] of a mass-weighted component that fell below DBL_MIN
/// (subnormal, no relative precision left), seen as a velocity of particle i.
struct VelocityScales {
  std::array<double, 3> speed{};
  std::array<double, 3> floor{};
};

VelocityScales velocityScales(const cl::Scene& scene) {
  const int wall = wallIndex(scene);
  double mass_max = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (i != wall) mass_max = std::max(mass_max, scene.masses[i]);
  }
  double total = 0.0, momentum = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (i == wall) continue;
    total += scene.masses[i] / mass_max;
    momentum += scene.masses[i] / mass_max * scene.velocities[i];
  }
  const double frame = wall >= 0 ? scene.velocities[wall] : momentum / total;
  double dv_max = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (i != wall) dv_max = std::max(dv_max, std::fabs(scene.velocities[i] - frame));
  }
  double u_sq = 0.0;  // |u|^2 / (mass_max dv_max^2)
  for (int i = 0; i < 3; ++i) {
    if (i == wall || dv_max == 0.0) continue;
    const double dv = (scene.velocities[i] - frame) / dv_max;
    u_sq += scene.masses[i] / mass_max * dv * dv;
  }
  VelocityScales scales;
  for (int i = 0; i < 3; ++i) {
    const double inverse_sqrt_mass = i == wall ? 0.0 : std::sqrt(mass_max) / std::sqrt(scene.masses[i]);
    scales.speed[i] = std::fabs(frame) * std::max(1.0, inverse_sqrt_mass) + dv_max * std::sqrt(u_sq) * inverse_sqrt_mass;
    scales.floor[i] = std::numeric_limits<double>::min() * std::max(1.0, inverse_sqrt_mass);
  }
  return scales;
}

/// After the last collision no pair approaches: v_A >= v_B >= v_C, up to `tolerance`
/// relative to the pair's velocity scale.
void checkEscaped(const std::array<double, 3>& v, const VelocityScales& scales, double tolerance) {
  auto allowance = [&](int i) { return tolerance * scales.speed[i] + scales.floor[i]; };
  FUZZ_CHECK(v[cl::kB] - v[cl::kA] <= allowance(cl::kA) + allowance(cl::kB), "A and B still approach at the end");
  FUZZ_CHECK(v[cl::kC] - v[cl::kB] <= allowance(cl::kB) + allowance(cl::kC), "B and C still approach at the end");
}

/// A generous bound on the rounding of a run's velocities: 64 eps per impact.
double engineTolerance(std::uint64_t count) { return 64 * std::numeric_limits<double>::epsilon() * double(count + 2); }

/// The pair of impact `index` (1-based): the first pair, then alternating.
cl::Pair pairOfImpact(const cl::Prediction& prediction, std::uint64_t index) {
  const cl::Pair first = *prediction.first_pair_index == 0 ? cl::Pair::AB : cl::Pair::BC;
  return index % 2 == 1 ? first : cl::otherPair(first);
}

void checkSimulation(const cl::Scene& scene, const cl::SceneSimulation& sim, const cl::Prediction& prediction,
                     std::uint64_t cap) {
  const std::uint64_t predicted = *prediction.impact_count;
  const std::array<double, 3> final_velocities = cl::triple(sim.final_velocities);
  // The one honest early stop: the next impact comes after the largest double.
  const bool out_of_range = sim.stop == cl::StopReason::kOutOfRange;
  FUZZ_CHECK(sim.stop == cl::StopReason::kFinished || sim.stop == cl::StopReason::kCap || out_of_range,
             "a three-body run finishes, reaches the cap or stops out of range");
  FUZZ_CHECK(sim.truncated == (predicted > cap || out_of_range),
             "truncated iff the predicted count exceeds the cap or the next impact is out of range");
  if (out_of_range) {
    FUZZ_CHECK(sim.impact_count < std::min(predicted, cap), "an out-of-range stop comes early");
  } else {
    FUZZ_CHECK(sim.impact_count == std::min(predicted, cap), "simulated count == predictedImpactCount (capped)");
  }
  FUZZ_CHECK(allFinite(final_velocities), "finite final velocities");
  FUZZ_CHECK(std::isfinite(sim.energy_relative_drift), "finite energy drift");
  const int wall = wallIndex(scene);
  if (wall >= 0) FUZZ_CHECK(final_velocities[wall] == scene.velocities[wall], "a wall keeps its velocity");
  if (!sim.truncated) checkEscaped(final_velocities, velocityScales(scene), engineTolerance(sim.impact_count));
  std::uint64_t index = 0;
  double time = 0.0;
  for (const cl::ImpactRecord& event : sim.impacts) {
    FUZZ_CHECK(event.index == ++index, "events numbered 1, 2, ...");
    FUZZ_CHECK(event.model.has_value(), "every event has its model block");
    FUZZ_CHECK(allFinite(event.model->velocities_after), "finite event velocities");
    FUZZ_CHECK(event.pair_index == static_cast<std::size_t>(cl::pairIndex(pairOfImpact(prediction, index))),
               "pairs alternate from the predicted first pair");
    // A time past the largest double is +inf (the summary's time_beyond_range); the places of
    // moving bodies are not known there.
    FUZZ_CHECK(!std::isnan(event.time) && event.time >= time, "event times non-decreasing");
    FUZZ_CHECK(std::isfinite(event.time) ? allFinite(event.model->positions) : sim.time_beyond_range,
               "finite event positions at finite times");
    time = event.time;
  }
}

/// Plans and runs a valid scene as the front ends do.
cl::SceneSimulation runPlanned(const cl::ScenePlan& plan, const cl::SceneRunOptions& options,
                               const cl::ImpactVisitor& visitor = {}) {
  cl::SceneVisitors visitors;
  visitors.impact = visitor;
  return cl::runScene(plan, options, visitors).simulation;
}

void checkModel(const cl::Scene& scene, const cl::Prediction& prediction) {
  // AnalyticModel<double> needs finite-mass ratios up to about 2^1000 (analytic.h); beyond,
  // the rotation model takes 50 digits, checked through the prediction above.
  int smallest = std::numeric_limits<int>::max(), largest = std::numeric_limits<int>::min();
  for (int i = 0; i < 3; ++i) {
    if (scene.isWall(i)) continue;
    smallest = std::min(smallest, std::ilogb(scene.masses[i]));
    largest = std::max(largest, std::ilogb(scene.masses[i]));
  }
  if (largest - smallest > 1000) return;
  const cl::AnalyticModel<double> model(scene);
  const double alpha = model.alpha();
  FUZZ_CHECK(alpha > 0 && alpha <= M_PI / 2 + 1e-12, "alpha in (0, pi/2]");
  const double psi = model.psi();
  FUZZ_CHECK(psi >= 0 && psi < 2 * M_PI + 1e-12, "psi in [0, 2 pi)");
  const VelocityScales scales = velocityScales(scene);
  for (const std::uint64_t n : {std::uint64_t{0}, std::uint64_t{1}, *prediction.impact_count}) {
    const Eigen::Vector3d after = model.velocitiesAfter(n);
    FUZZ_CHECK(allFinite(after), "finite closed-form velocities");
    for (const std::uint64_t k : {n, n + 1}) {
      const std::array<double, 3> gained = model.energyTransfer(k);
      FUZZ_CHECK(allFinite(gained), "finite closed-form energy transfer");
    }
  }
  const Eigen::Vector3d last = model.velocitiesAfter(*prediction.impact_count);
  checkEscaped({last(0), last(1), last(2)}, scales, 1e-9);
}

void exercisePaper(const cl::Scene& scene, std::uint64_t count) {
  // Printed formulas may be NaN or wrong by design (physics.md, Errata); they must only
  // answer without crashing or undefined behaviour.
  const cl::paper::PrintedClosedForm printed(scene);
  for (const std::uint64_t n : {count, count + 1}) {
    const double angle = static_cast<double>(n / 2) * printed.theta();
    (void)printed.velocitiesAfter(n, std::cos(angle), std::sin(angle));
  }
  (void)cl::paper::phiBC(scene);
  (void)cl::paper::omega(cl::triple(scene.masses));
  (void)cl::paper::impactCount(scene);
  const std::array<double, 3> v = cl::triple(scene.velocities);
  (void)cl::paper::energyTransfer(scene, 1, cl::Pair::AB, v, v);
  (void)cl::paper::energyTransfer(scene, 2, cl::Pair::BC, v, v);
}

}  // namespace

/// One input (the libFuzzer entry below, and the corpus replay test).
int collisionLabCoreFuzzOne(const std::uint8_t* data, std::size_t size) {
  Reader in(data, size);
  if (!in.has(2)) return 0;
  const std::uint8_t flags = in.byte();
  const std::uint64_t cap = kCaps[in.byte() % kCaps.size()];
  const bool compact = flags & 0x10;
  if (!in.has(compact ? 9 * 4 : 9 * 8)) return 0;
  cl::Scene scene = cl::threeBodies();
  for (auto* values : {&scene.masses, &scene.positions, &scene.velocities}) {
    for (double& value : *values) value = compact ? in.compactDouble() : in.rawDouble();
  }

  const auto error = cl::validate(scene);
  if (error) {
    FUZZ_CHECK(error->reason != cl::Reason::kOk && !error->message.empty(), "a rejection has a reason and a message");
    return 0;
  }
  // Everything below requires a valid scene.
  FUZZ_CHECK(std::isfinite(scene.positions[0]) && std::isfinite(scene.velocities[0]), "validate accepts finite values only");
  double mass_min = std::numeric_limits<double>::infinity(), mass_max = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (scene.isWall(i)) continue;
    mass_min = std::min(mass_min, scene.masses[i]);
    mass_max = std::max(mass_max, scene.masses[i]);
  }
  const std::uint64_t known_issue_cap =
      skipKnownIssues() && mass_max / mass_min > kQuadraticMassRatio ? kQuadraticCap : kCaps.back();

  const cl::ScenePlan plan = cl::planScene(scene);
  FUZZ_CHECK(!plan.error, "planScene accepts what validate accepts");
  // Three elastic bodies beyond the rotation model's range (and two walls) are the
  // engine's alone, fuzzed by nbody_fuzzer.
  if (!plan.prediction || !cl::hasRotationValues(*plan.prediction)) return 0;
  const cl::Prediction& prediction = *plan.prediction;
  FUZZ_CHECK(prediction.impact_count.has_value(), "the rotation model gives a count");
  const std::uint64_t predicted = *prediction.impact_count;
  const std::uint64_t max_possible = cl::maxPossibleImpactCount(cl::triple(scene.masses));
  FUZZ_CHECK(prediction.max_possible_impact_count == max_possible, "the prediction reports maxPossibleImpactCount");
  FUZZ_CHECK(predicted <= max_possible, "count <= ceil(pi / alpha)");
  const std::optional<cl::Pair> first = cl::firstPair(scene);
  FUZZ_CHECK(prediction.first_pair_index.has_value() == first.has_value() &&
                 (!first || *prediction.first_pair_index == static_cast<std::size_t>(cl::pairIndex(*first))),
             "the prediction reports firstPair");
  FUZZ_CHECK(first.has_value() || predicted == 0, "no first pair, no collisions");
  FUZZ_CHECK(prediction.final_velocities.size() == 3 && allFinite(cl::triple(prediction.final_velocities)),
             "finite predicted final velocities");
  checkModel(scene, prediction);
  exercisePaper(scene, predicted);

  const bool watched = flags & 0x1;
  const int events = (flags >> 2) & 0x3;
  cl::SceneRunOptions options;
  options.lab.events =
      events == 1 ? cl::EventPolicy::all() : events == 2 ? cl::EventPolicy::firstN(3) : cl::EventPolicy::none();
  const bool slow_path = watched || events == 1;
  options.lab.max_collisions = std::min({cap, slow_path ? kSlowPathCap : cap, known_issue_cap});
  options.simulate_to_cap = true;
  std::uint64_t watched_events = 0;
  cl::ImpactVisitor watch;
  if (watched) watch = [&watched_events](const cl::ImpactRecord&) { ++watched_events; };
  const cl::SceneSimulation sim = runPlanned(plan, options, watch);
  checkSimulation(scene, sim, prediction, options.lab.max_collisions);
  if (watched) FUZZ_CHECK(watched_events == sim.impact_count, "the visitor sees every impact");

  if (predicted <= kExactCrossCheckLimit) {
    const cl::exact::MapWalk truth = cl::exact::walkVelocityMaps(scene, kExactCrossCheckLimit + 1);
    FUZZ_CHECK(!truth.truncated && truth.impact_count == predicted, "predictedImpactCount == exact rational count");
  }

  cl::SceneRunOptions run_options;
  run_options.lab.max_collisions = std::min({cap, kSlowPathCap, known_issue_cap});
  run_options.lab.mode = static_cast<cl::RunMode>((flags >> 6) % 3);
  run_options.simulate_to_cap = !(flags & 0x20);
  run_options.lab.events = cl::EventPolicy::firstN(3);
  const cl::SceneSimulation run = runPlanned(plan, run_options);
  FUZZ_CHECK(allFinite(cl::triple(run.final_velocities)), "finite lab-run final velocities");
  // The over-cap rule: answering over the cap from the closed form is complete.
  const bool over_cap = predicted > run_options.lab.max_collisions;
  const bool simulates = run_options.lab.mode != cl::RunMode::kPredictOnly && !(over_cap && !run_options.simulate_to_cap);
  FUZZ_CHECK(run.simulated == simulates, "a lab run simulates unless predict-only or answered over the cap");
  FUZZ_CHECK(run.truncated == (simulates && (over_cap || run.stop == cl::StopReason::kOutOfRange)),
             "a lab run is truncated iff it simulates and the prediction exceeds the cap, or it stops out of range");
  return 0;
}

#ifndef COLLISION_LAB_FUZZ_REPLAY
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return collisionLabCoreFuzzOne(data, size);
}
#endif
