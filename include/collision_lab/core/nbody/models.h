// The model each scene needs: the cheapest one that is exact for it, and why.
//   no_collisions        N = 1, or no pair approaches: nothing happens, O(N)
//   two_walls_infinite   one body between walls at both ends that do not move apart, every
//                        e > 0: it bounces between them forever (the run stops at its cap)
//   box_infinite         two or more bodies in a box: walls at both ends that do not move
//                        apart, every e > 0: the bodies collide forever; nothing is
//                        predicted but that, and the exact event engine simulates the first
//                        impacts (a display's worth, or up to the cap with simulate_to_cap)
//   two_body             N = 2: at most one impact, closed form
//   three_body_rotation  N = 3, elastic, at most one wall, every momentum and kinetic energy in
//                        the wall's frame a double: the paper's rotation model (analytic.h);
//                        its count and final velocities in closed form, the paper's values
//                        beside them
//   ghosts               equal masses, elastic, no walls: the bodies exchange velocities, so
//                        they move like ghosts passing through each other; the count is the
//                        number of inversions, O(N log N), and the final velocities are the
//                        initial ones sorted. On a ring the ghosts meet forever: infinitely
//                        many impacts, the count by time t is the crossing count (ringCrossingsBy)
//   three_body_spiral    N = 3, at most one wall (at an end), one e < 1 for both pairs: the
//                        AB/BC cycle is a 2x2 map of trace T = (1+e)^2 cos^2(alpha) - 2e and
//                        determinant e^2; a spiral for e > r_c = tan^2(pi/4 - alpha/2),
//                        possibly an inelastic collapse for e <= r_c. A wall is the outer body
//                        of infinite mass (k = 1+e, cos^2 alpha = m/(m_B + m)); a collapse then
//                        ends on the wall's line. Collapse decided exactly, count and state in
//                        O(1) from closed forms (src/core/nbody/spiral.h), the walk only where
//                        those are too close to call; the collapse time is closed form.
//                        e = 0: the first pair sticks, and the third body hits that cluster as
//                        one body (engine.h, the cluster rule). Two different e: event_engine.
//   event_engine         anything else: no count formula exists; the exact event engine
//                        simulates every impact. So does every scene whose restitution model
//                        (scene.h, RestitutionModel) can change an impact's e, and every ring
//                        that is not ghosts.
// ROS-free; every function here never throws for a validated scene (short of memory).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace core {

/// Values are stable: append only.
enum class ModelKind : std::uint8_t {
  kNoCollisions = 0,
  kTwoWallsInfinite = 1,
  kTwoBody = 2,
  kThreeBodyRotation = 3,
  kGhosts = 4,
  kEventEngine = 5,
  kThreeBodySpiral = 6,
  kBoxInfinite = 7,
  kSticky = 8,
};

/// Machine-readable name, e.g. "three_body_rotation".
const char* modelKindName(ModelKind kind);

struct ModelChoice {
  ModelKind kind = ModelKind::kEventEngine;
  std::string reason;  ///< one line: why this model answers this scene
};

/// Precondition: validate(scene) passed.
ModelChoice chooseModel(const Scene& scene);

/// What a closed-form model predicts. Fields a model does not give stay empty.
struct Prediction {
  ModelKind kind = ModelKind::kNoCollisions;
  std::string reason;
  bool infinite = false;                      ///< infinitely many impacts
  std::optional<std::uint64_t> impact_count;  ///< the exact number of impacts
  std::vector<double> final_velocities;       ///< [m/s], listed like the bodies
  std::optional<double> impact_time;          ///< two_body: time of the impact [s]
  std::optional<double> impact_position;      ///< two_body: contact point [m]
  double energy_lost = 0.0;                   ///< kinetic energy turned into heat [J]
  // three_body_spiral only (and alpha, below, the opening angle of the three masses):
  std::optional<double> critical_restitution;  ///< r_c = tan^2(pi/4 - alpha/2) [1]; one e for both pairs only
  std::optional<double> spiral_angle;          ///< phi, cos(phi) = T / (2 sqrt(e_AB e_BC)), complex eigenvalues [rad]
  bool collapsed = false;                      ///< inelastic collapse (then infinite is true)
  std::optional<double> collapse_time;         ///< [s] since the start
  std::optional<double> collapse_position;     ///< where the three meet [m]
  // three_body_rotation (three elastic bodies) also gives critical_restitution (of its
  // alpha) and spiral_angle (theta = 2 alpha, the rotation per AB+BC cycle), and:
  std::optional<std::int64_t> paper_impact_count;          ///< the paper's eq. (3.22) as printed; empty where undefined
  std::optional<std::uint64_t> max_possible_impact_count;  ///< ceil(pi / alpha): no start of these masses has more, exact
  std::optional<double> alpha;   ///< opening angle of the escape cone, atan(sqrt(m_B M / (m_A m_C))) [rad]
  std::optional<double> theta;   ///< 2 alpha [rad]
  std::optional<double> omega;   ///< pi - alpha, the angle between the normals n_AB and n_BC [rad]
  std::optional<double> phi_bc;  ///< the paper's phi_BC, eq. (3.21) [rad]; NaN where undefined
  std::optional<double> psi;     ///< angle of u_perp from r_BC [rad]
  /// The pair p (bodies p and p + 1) that meets first, decided exactly; empty when no pair
  /// approaches or the model does not say.
  std::optional<std::size_t> first_pair_index;
  /// Every value above is the correctly rounded exact value of what it names (the paper's
  /// phi_bc and paper_impact_count the exact values of the formulas as printed), except those
  /// named here (by their summary key, e.g. "predicted_final_velocities"), which no
  /// certificate within the model's work budget could decide; they are within a few ulps.
  std::vector<std::string> uncertified;
};

/// Each requires the scene its model is chosen for (chooseModel) and validate() passed.
Prediction predictNoCollisions(const Scene& scene);
/// two_walls_infinite or box_infinite: infinitely many impacts, nothing else predicted.
Prediction predictTwoWalls(const Scene& scene);
Prediction predictTwoBody(const Scene& scene);

/// The one impact of two approaching bodies (a two_body scene whose pair approaches), from
/// exact rationals, each value the correctly rounded exact one: when [s] and where [m] it
/// happens, the velocities after it [m/s], the energy each body gains [J] (a wall's entry is
/// minus the other's gain and the heat, as in the engine's ImpactRecord) and the heat [J].
struct TwoBodyImpact {
  double time = 0.0;
  double position = 0.0;
  std::array<double, 2> velocities_after{};
  std::array<double, 2> energy_gained{};
  double energy_lost = 0.0;
};
TwoBodyImpact exactTwoBodyImpact(const Scene& scene);
Prediction predictGhosts(const Scene& scene);
/// Every pair e = 0, no ring: the final groups are the blocks of the weighted isotonic
/// regression of the initial velocities (pool-adjacent-violators, O(N)); each group moves at
/// sum m v / sum m (a wall's group at the wall's velocity), computed exactly and rounded once.
/// Each impact merges two groups, so the count is N - groups; the heat [J] is the kinetic
/// energy each group loses in its own frame, exact and rounded once.
Prediction predictSticky(const Scene& scene);
/// No impact_count when the walk cannot decide within 2^26 impacts (or, for a borderline
/// decision, within the 3000 impacts walked in rationals); the reason then says so.
Prediction predictThreeBodySpiral(const Scene& scene);

/// The prediction carries the rotation model's values (three elastic bodies): their run puts
/// the closed form and the paper's values beside every impact.
inline bool hasRotationValues(const Prediction& prediction) { return prediction.max_possible_impact_count.has_value(); }

/// Three elastic bodies (three_body_rotation): the rotation model's closed form (analytic.h)
/// and the paper's printed values, all exact decisions for the given doubles.
Prediction predictThreeBodyRotation(const Scene& scene);

/// The prediction of chooseModel(scene)'s model. Empty for event_engine (no formula: run
/// the engine). Three elastic bodies that never meet (no_collisions) also get the rotation
/// model's values (count 0, angles, the paper's values; its final velocities).
/// hasRotationValues tells a prediction that carries them.
std::optional<Prediction> predict(const Scene& scene);

/// The period of a ball between two walls at rest (three bodies, A and C walls standing
/// still, B moving, every pair elastic): B is back where it started, moving as it started,
/// every `time` = 2 (x_A - x_C) / |v_B| [s], exact and rounded once, after `impacts` = 2
/// impacts (one on each wall). Empty for any other scene, and where the time overflows.
struct WallPeriod {
  double time = 0.0;          ///< [s]
  std::uint64_t impacts = 2;  ///< per period [1]
};
std::optional<WallPeriod> wallToWallPeriod(const Scene& scene);

/// Equal masses on a ring (elastic): the number of crossings of the ghosts (each moving at
/// its initial velocity round the ring of circumference scene.ring) in (0, t] [s], i.e. the
/// impacts by time t; a crossing exactly at t counts. In double (the crossing times are
/// rounded), O(N^2). Precondition: scene.isRing(), validate() passed, t >= 0.
std::uint64_t ringCrossingsBy(const Scene& scene, double t);

/// Number of pairs i < j with v_i < v_j (equal values are not inversions), by merge sort:
/// O(N log N) time, O(N) memory; exact in 64 bits for N up to 6e9.
std::uint64_t countInversions(const std::vector<double>& velocities);

}  // namespace core
}  // namespace collision_lab
