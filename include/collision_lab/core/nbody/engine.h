// The exact event engine for N bodies on a line: impact by impact, no time stepping.
//
// Every decision that changes the outcome (which pair is next, whether a pair approaches,
// whether two impacts are simultaneous) is taken as exact rational arithmetic on the input
// doubles would take it, in three tiers (adaptive precision, as in robust geometric
// predicates):
//   0. double-double state (about 106 bits) with a rigorous forward error bound, and double
//      time keys; a key too close to call is first re-taken from the double-double state;
//   1. what that cannot decide, a tier of 100-digit floats with its own bound decides: it
//      replays the run from the start (or from where it last stopped) to that impact and
//      takes the step; the working tier then follows that step in O(1);
//   2. what 100 digits cannot decide, exact rationals decide the same way, within a work
//      budget per decision (EngineOptions::exact_work_budget: a run beyond it stops at its last
//      certified impact, kPrecisionBudget; the cancel flag is read at each exact step). A value exactly
//      0 in double-double (in practice an exact tie: equal velocities or simultaneous
//      impacts, from inputs such as small integers, where rationals stay small) goes
//      straight to this tier.
// Equal masses with e = 1 swap their velocities without rounding, so scenes of equal
// masses keep an exact state. A tier whose state can no longer pin an impact's published
// time to 2^-42 (tiny approach speeds, as on the way to an inelastic collapse) hands that
// step to the next tier too and adopts its state.
// Restitution and clusters. An impact with e = 0 makes its two bodies one cluster at
// once; a recognised inelastic collapse (see Collapse) makes its bodies one cluster at the
// collapse time. A cluster is hit as ONE body of its total mass, with the restitution of the
// pair that touches. Why: its members are point masses at zero separation, so an impulse at
// its surface reaches all of them in the same instant, and the only outcome that keeps
// momentum, respects the pair's e and leaves no body inside another is the two-body rule
// with the total mass (the usual choice for aggregates). The alternative, resolving the
// internal impacts one after the other, is ill-defined for point masses: at zero separation
// every internal impact is simultaneous with the next, so its result depends on an
// arbitrary order (a multiple collision). The run counts these impacts (cluster_impacts).
// Restitution models (scene.h, RestitutionModel) choose each impact's e in every tier alike:
// TC compares the time since each body's last impact with t_c on the rigorous bounds of
// the two impact times, and what those cannot decide the exact tier decides with the exact
// times (equal counts as "not more than t_c": elastic); the threshold law decides
// "approach speed < v_0" like any sign; the viscoelastic law evaluates e(v) in double at
// the approach speed rounded to the nearest double, a rounding each tier certifies or
// hands to the next. Collapses are not recognised under a model, nor on a ring.
// A ring (scene.ring = L) adds pair N-1 across the seam; it has no walls and no clusters.
// Impacts happen in the canonical order: exact time, then pair index. Impacts of disjoint
// pairs at the same instant are all performed; two impacts sharing a body at the same
// instant are a multiple collision, which ends the run (its outcome is undefined for
// point masses). Nothing is stored per impact unless asked, so memory is O(N).
// Units. Each run takes place in working units: masses, positions and velocities scaled by
// the exact powers of two that bring the scene's largest of each near 1 (src/core/nbody/
// units.h). That changes no decision and no rounding, keeps every number of a run inside the
// tiers' range (2^900) wherever the scene lies in the double range, and every value the
// engine gives (records, collapses, progress, result) is in SI, rounded once.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "collision_lab/core/impact_model_values.h"
#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {

/// The published values of an impact, as bits of ImpactRecord::uncertified: those set are
/// not certified correctly rounded (physics.md, "How close the published values are"). Each
/// bit's name (impactValueName) is the event's field in JSON, CSV and CollisionEvent.msg.
enum ImpactValue : std::uint32_t {
  kImpactTime = 1u << 0,
  kImpactPosition = 1u << 1,
  kPairVelocitiesBefore = 1u << 2,
  kPairVelocitiesAfter = 1u << 3,
  kPairEnergyTransfer = 1u << 4,
  kImpactEnergyLost = 1u << 5,
  // Every body's state (the full state of an event), and the model block.
  kPositions = 1u << 6,
  kVelocitiesBefore = 1u << 7,
  kVelocitiesAfter = 1u << 8,
  kEnergyTransfer = 1u << 9,
  kKineticEnergyAfter = 1u << 10,
  kTotalEnergy = 1u << 11,
  kTotalMomentum = 1u << 12,
  kPredictedVelocitiesAfter = 1u << 13,
  kPredictedEnergyTransfer = 1u << 14,
  kPaperVelocitiesAfter = 1u << 15,
  kPaperEnergyTransfer = 1u << 16,
};
constexpr int kImpactValueCount = 17;
/// The event field of bit 1 << k (k < kImpactValueCount), e.g. "pair_velocities_after".
const char* impactValueName(int k);
/// The pair's own values, which every event carries.
constexpr std::uint32_t kPairValues = kImpactTime | kImpactPosition | kPairVelocitiesBefore | kPairVelocitiesAfter |
                                      kPairEnergyTransfer | kImpactEnergyLost;
/// The values of an event's full state that an N-body run's events derive from rounded
/// values (io's SceneEventState, core::BodyStateReplay): never certified.
constexpr std::uint32_t kReplayedStateValues = kPositions | kKineticEnergyAfter | kTotalEnergy | kTotalMomentum;
/// A collapse event's values that are not certified: the limit's time, point and velocity
/// come from the engine's state at the time, its energies from the replay.
constexpr std::uint32_t kCollapseValues =
    kImpactTime | kImpactPosition | kPairVelocitiesAfter | kPairEnergyTransfer | kImpactEnergyLost;

/// One impact of pair p (bodies p and p+1; on a ring's seam pair N-1, bodies N-1 and 0,
/// with first_moved = N-1 and last_moved = 0). Replaying the records (and the collapse notices,
/// CollapseVisitor) in order from the initial velocities rebuilds the velocity of every body:
/// an impact sets bodies first_moved..pair_index to velocities_after[0] and
/// pair_index+1..last_moved to velocities_after[1].
struct ImpactRecord {
  std::uint64_t index = 0;                    ///< 1-based impact number
  std::size_t pair_index = 0;                 ///< p; its name is pairName(p)
  double time = 0.0;                          ///< [s] since the start of the run
  double position = 0.0;                      ///< contact point [m]
  std::array<double, 2> velocities_before{};  ///< bodies p, p+1 [m/s]
  std::array<double, 2> velocities_after{};   ///< bodies p, p+1 [m/s]
  /// Kinetic energy gained by bodies p, p+1 [J]. A wall's entry is minus what the other
  /// body gained and the heat, so the two entries and energy_lost sum to zero.
  std::array<double, 2> energy_gained{};
  double energy_lost = 0.0;  ///< kinetic energy turned into heat, (1 - e^2) mu A^2 / 2 [J]
  /// The bodies the impact moved: p and p+1 for two single bodies; for a cluster impact
  /// (the cluster rule) the whole clusters on both sides, each moving as one.
  std::size_t first_moved = 0;
  std::size_t last_moved = 0;
  /// The answering model's values beside this impact (impact_model_values.h); empty for the
  /// engine's own records.
  std::optional<ImpactModelValues> model;
  /// ImpactValue bits: the values above (and in `model`) not certified correctly rounded.
  std::uint32_t uncertified = 0;
};

/// Why a run ended. Values are stable: append only.
enum class StopReason : std::uint8_t {
  kFinished = 0,           ///< no pair approaches any more
  kCap = 1,                ///< max_impacts reached, or the exactness cap of an unresolved accumulation (truncated)
  kCancelled = 2,          ///< the cancel flag was set (truncated)
  kMultipleCollision = 3,  ///< two impacts sharing a body at the same instant
  /// The next impact's time is beyond the largest double, or the scene's scales spread wider
  /// than the working units ("Units" above) bring into the tiers' range (truncated).
  kOutOfRange = 4,
  kInternalError = 5,      ///< the tiers disagreed (a bug; reported, never hidden)
  /// A decision needed exact arithmetic beyond its budget (EngineOptions::exact_work_budget): the run
  /// stops at its last certified impact, naming the crowding bodies (truncated).
  kPrecisionBudget = 6,
};

/// Machine-readable name, e.g. "MULTIPLE_COLLISION".
const char* stopReasonName(StopReason reason);

/// Progress of a long run.
struct EngineProgress {
  std::uint64_t impacts = 0;  ///< impacts so far
  double time = 0.0;          ///< time of the last impact [s]
};

struct EngineOptions {
  std::uint64_t max_impacts = 10'000'000;  ///< the run stops here, marked truncated
  std::uint64_t keep_events = 0;           ///< keep the first this many records in the result
  std::uint64_t progress_interval = std::uint64_t{1} << 20;  ///< impacts between progress calls (0: never)
  /// When set (by another thread or a signal handler), the run stops within 1024 impacts,
  /// or sooner inside a long exact-tier replay (read before each of its steps), marked
  /// truncated, with the summary of what was done.
  const std::atomic<bool>* cancel = nullptr;
  /// The work of one exact decision [bit^2, the squared bits of each replayed impact's
  /// numbers, summed]: a decision that needs more stops the run at its last certified impact
  /// (kPrecisionBudget). The default is the engine's (10^11: a four-body group collapse's
  /// proof needs 10^10); a smaller one stops sooner.
  double exact_work_budget = 1e11;
  /// Stop as soon as that work is foreseen (its growth so far, extrapolated), not when it is
  /// spent: the same stop, or (never seen) an earlier one with the same impacts before it.
  /// False only to measure what the forecast saves (the benchmarks, its test).
  bool forecast_exact_work = true;
};

/// How often the engine had to leave its working precision.
struct Escalations {
  std::uint64_t refinements = 0;       ///< decisions re-taken from the double-double state
  std::uint64_t high_precision = 0;    ///< replays in 100-digit floats
  std::uint64_t exact_rational = 0;    ///< replays in exact rationals
  std::uint64_t replayed_impacts = 0;  ///< impacts simulated by those replays
};

/// Three bodies that meet at one instant.
struct MultipleCollision {
  std::size_t first_body = 0;  ///< bodies first_body, first_body + 1, first_body + 2
  double time = 0.0;           ///< [s]
};

/// An inelastic collapse, resolved to its limit: infinitely many impacts of bodies
/// first_body..last_body before `time`, after which they move as one cluster at their
/// centre-of-mass velocity. Recognised for three bodies or clusters whose two pairs
/// alternate (the three-body closed form, src/core/nbody/spiral.h, decides that the impacts
/// never stop and gives the limit time), including a body (or cluster) squeezed between a
/// wall and another: there the wall is the outer cluster of infinite mass (k = 1 + e,
/// cos^2(alpha) = m_C/(m_B+m_C) with B the squeezed body and C the other; a collapse when
/// e is below tan^2(pi/4 - alpha/2) and the start lies in the approaching cone); all of
/// them end on the wall's line: they meet at the wall and move on with it; the energy
/// about it is lost (the wall absorbs the momentum). Also recognised: a group of 4 to 8
/// bodies or clusters whose impacts repeat a pattern of period 3 to 24, once the exact tier
/// takes every impact, when an invariant cone proves in exact rationals that the pattern never
/// breaks (src/core/nbody/group_collapse.h, docs/physics.md). Not recognised: larger groups
/// whose pattern that proof does not reach, a wall in the middle of the three, a body between two
/// walls (walls at one velocity: no collapse, the bounces slow down without end; walls
/// closing in: they meet, where nothing is defined), and a group that a body outside could
/// reach before the collapse time (conservative, even beyond a wall). Their impacts
/// soon need the exact tier at every step; the exactness cap (tier.h, kExactBits) then ends
/// the run as kCap, truncated, with a message saying so.
struct Collapse {
  std::size_t first_body = 0;
  std::size_t last_body = 0;
  double time = 0.0;                 ///< [s], the limit of the impact times
  double position = 0.0;             ///< where the bodies meet [m]
  std::uint64_t impacts_before = 0;  ///< impacts performed (and counted) before it was resolved
  double velocity = 0.0;             ///< the cluster's velocity after it [m/s]
  /// ImpactValue bits of its event's values not certified: all of kCollapseValues, unless a
  /// model's certified values replaced the engine's (scene_run.cpp).
  std::uint32_t uncertified = kCollapseValues;
};

/// The simulation of a run: what runEngine measured and what runScene (scene_run.h) adds
/// beside the model's prediction. The one result of every run, simulated or answered by a
/// closed form alone.
struct SceneSimulation {
  bool simulated = false;  ///< false: answered by the closed form alone (or predict-only)
  /// The run's answer: simulated, or the model's count when not simulated (0 when the model
  /// gives none: predict-only without a count formula).
  std::uint64_t impact_count = 0;
  bool truncated = false;  ///< stopped with more impacts due: cap, cancelled, precision budget or out of range
  StopReason stop = StopReason::kFinished;
  std::string stop_message;  ///< one sentence: why the run ended
  std::optional<MultipleCollision> multiple_collision;
  double final_time = 0.0;               ///< time of the last impact [s] (0 without any)
  /// The run's last impacts came after the largest double [s]: counted, with exact
  /// velocities, their times (and final_time) published as +inf, as is any position past
  /// the largest double [m].
  bool time_beyond_range = false;
  std::vector<double> final_positions;   ///< at final_time [m]; empty when not simulated
  std::vector<double> final_velocities;  ///< [m/s]; the predicted ones when not simulated
  double energy_lost = 0.0;              ///< total kinetic energy turned into heat [J]; NaN: not known
  /// |E_end + energy_lost - E_0| / E_0, kinetic energies in the walls' frame (the lab frame
  /// without walls); NaN when two walls move at different velocities (not conserved), or
  /// when not simulated.
  double energy_relative_drift = 0.0;
  /// |p_end - p_0| / sum |m v_0| over the finite masses; NaN with a wall (not conserved), or
  /// when not simulated.
  double momentum_relative_drift = 0.0;
  /// The run's published values that are not certified correctly rounded, by their summary
  /// keys (e.g. "final_velocities"); empty when every one is (physics.md, "How close the
  /// published values are"). An event's own are its record's (ImpactRecord::uncertified).
  std::vector<std::string> uncertified;
  /// How often the engine left its working precision; zero when not simulated.
  Escalations escalations;
  /// An inelastic collapse was resolved (simulated) or is predicted (closed form alone):
  /// infinitely many impacts before collapse_time, then the bodies move as one cluster.
  bool collapsed = false;
  std::optional<double> collapse_time;      ///< of the first collapse [s]
  std::optional<double> collapse_position;  ///< where its bodies meet [m]
  /// Collapses resolved, in order (their infinitely many impacts are not in impact_count).
  std::vector<Collapse> collapses;
  /// Impacts in which a cluster (stuck by e = 0 or left by a collapse) met its neighbour as
  /// ONE body of its total mass, with the restitution of the pair that touches (the cluster rule).
  std::uint64_t cluster_impacts = 0;
  /// kPrecisionBudget or the exactness cap (kCap of an accumulation): the bodies (indices from
  /// 0, ascending) of the last impacts that needed
  /// more than double-double precision and of the decision left open; empty otherwise.
  std::vector<std::size_t> crowding_bodies;
  /// Impacts whose pair has e < 1 (or, viscoelastic, whose e(v) is 1) that the scene's
  /// restitution model made elastic (scene.h, RestitutionModel); 0 for the constant model.
  std::uint64_t rule_elastic_impacts = 0;
  /// runScene: simulated to the end and predicted with a finite count: the engine's count
  /// equals it. Empty otherwise.
  std::optional<bool> matches_prediction;
  /// runScene: the largest |S (v_sim - v_pred)| / |S v_0| [1] (S = diag(sqrt(m)) over the
  /// finite bodies, v_0 in the first wall's frame: the relative error in the energy norm)
  /// over the states the model predicts: every impact for the rotation model (three elastic
  /// bodies), the end of a finished run for any other closed form. NaN: not compared.
  double max_prediction_error = std::numeric_limits<double>::quiet_NaN();
  /// The impacts kept: runEngine's first options.keep_events; runScene's, those its
  /// options.lab.events selects when options.keep_events (the collapses between them are in
  /// `collapses`, each after impacts_before impacts), each with its model block where the
  /// model fills one (the rotation model's: three elastic bodies).
  std::vector<ImpactRecord> impacts;
};

/// Called for every impact, in order. May be empty.
using ImpactVisitor = std::function<void(const ImpactRecord&)>;
/// Called for every resolved collapse, in order with the impacts: right after the record of
/// impact number collapse.impacts_before, before the next impact. It sets bodies
/// first_body..last_body to collapse.velocity. May be empty.
using CollapseVisitor = std::function<void(const Collapse&)>;
/// Called every options.progress_interval impacts. May be empty.
using ProgressCallback = std::function<void(const EngineProgress&)>;

/// Runs the scene to its end, the cap, cancellation, a multiple collision or the exactness
/// budget. Its time grows with its impacts: the budget bounds the cost of each exact step.
/// Precondition: validate(scene) passed. Never throws for a valid scene (short of running
/// out of memory); the visitors and the progress callback may throw, which ends the run.
/// The records and notices carry the working tier's values rounded to double, as do
/// final_velocities, so their replay gives final_velocities exactly; the one exception is a
/// value within about 2^-100 (relative) of a rounding boundary of doubles when a more precise
/// tier's state is adopted, which can move its rounding by one unit in the last place.
SceneSimulation runEngine(const Scene& scene, const EngineOptions& options = {}, const ImpactVisitor& visitor = {},
                       const ProgressCallback& progress = {}, const CollapseVisitor& on_collapse = {});

}  // namespace core
}  // namespace collision_lab
