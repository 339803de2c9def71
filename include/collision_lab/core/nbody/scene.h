// A scene of N >= 1 point masses on a line, listed right to left, and its validation.
// ROS-free: part of collision_lab_core.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace collision_lab {
namespace core {

/// How the restitution of an impact is chosen (docs/physics.md, "Restitution models").
/// Values are stable (published): append only.
enum class RestitutionModelKind : std::uint8_t {
  kConstant = 0,      ///< each pair's e, always (the default)
  kTc = 1,            ///< TC model (Luding and McNamara 1998): elastic unless both bodies' last impacts are > t_c ago
  kViscoelastic = 2,  ///< e(v) of viscoelastic spheres (Brilliantov, Spahn, Hertzsch and Poschel 1996)
  kThreshold = 3,     ///< e = 1 below an approach speed v_0, the pair's e from v_0 on
};

/// Machine-readable name: "constant", "tc", "viscoelastic", "threshold".
const char* restitutionModelName(RestitutionModelKind kind);

/// The restitution model and its parameter (only the one its kind uses is read).
struct RestitutionModel {
  RestitutionModelKind kind = RestitutionModelKind::kConstant;
  /// kTc: t_c [s], > 0 and finite. An impact dissipates (the pair's e) only when the time
  /// since the last impact of each of its finite bodies is strictly greater than t_c; a
  /// body that has had no impact counts as having waited forever, and a wall has no clock.
  double tc = 0.0;
  /// kViscoelastic: v* [m/s], > 0 and finite: e(v) = 1 - C1 s + C2 s^2 with s = (v / v*)^(1/5),
  /// C1 = 1.15344, C2 = 0.79826, clamped to [0, 1]; v* = (A alpha^(2/5))^-5 of the paper's
  /// material constants. The pair's e is not used (the scene's restitution must be elastic).
  double viscoelastic_speed = 0.0;
  /// kThreshold: v_0 [m/s], > 0 and finite: e = 1 when the approach speed is < v_0.
  double elastic_below = 0.0;
};

/// Initial conditions in SI units. Bodies are listed right to left: x_0 > x_1 > ... >
/// x_{N-1}. Pair p joins bodies p and p+1; it approaches iff v_p < v_{p+1}.
struct Scene {
  std::vector<double> masses;      ///< [kg]; +inf = a wall, allowed at index 0 and/or N-1 only
  std::vector<double> positions;   ///< [m], strictly decreasing
  std::vector<double> velocities;  ///< [m/s]
  /// Coefficients of restitution e in [0, 1] [1]: empty = elastic (e = 1); one value = every
  /// pair; N-1 values = one per pair. Each is taken as the exact value of its double.
  std::vector<double> restitution;
  RestitutionModel restitution_model;  ///< the default: each pair's constant e
  /// Circumference L [m] of a ring (periodic boundary); 0 = no ring (an open line). On a
  /// ring, positions lie in [0, L), still strictly decreasing, no body is a wall, no pair
  /// has e = 0 (clusters are not supported there), and
  /// body N-1 meets body 0 across the seam: contact pair N-1 joins body N-1 (right) and
  /// body 0 at x_0 - L (left). restitution then has 0, 1 or N values (N >= 2).
  double ring = 0.0;

  std::size_t size() const { return masses.size(); }
  std::size_t pairCount() const { return masses.empty() ? 0 : masses.size() - 1; }
  bool isRing() const { return ring != 0.0; }
  /// Pairs that can touch: pairCount(), plus the seam pair N-1 on a ring of N >= 2 bodies.
  std::size_t contactCount() const { return isRing() && size() >= 2 ? size() : pairCount(); }
  /// The left body of contact pair p: p + 1, or 0 for the seam pair of a ring.
  std::size_t leftOf(std::size_t pair) const { return pair + 1 == size() ? 0 : pair + 1; }
  bool isWall(std::size_t body) const;
  std::size_t wallCount() const;
  /// e of pair p [1]. Precondition: validate() passed and p < contactCount().
  double restitutionOf(std::size_t pair) const;
  /// True when every pair has e = 1 (including an empty restitution list).
  bool isElastic() const;
};

/// "A", "B", ..., "Z" for the first 26 bodies, then "#26", "#27", ... (the index).
std::string bodyName(std::size_t body);
/// "AB", "BC", ... while both bodies have letters, then "Z-#26", "#26-#27", ...
std::string pairName(std::size_t pair);
/// The pair of an impact: pairName(pair_index), or across a ring's seam (the only impact
/// whose last_moved is below its pair_index) the last body and A: "EA", "#30-A".
std::string impactPairName(std::size_t pair_index, std::size_t last_moved);

/// Why a scene was rejected. Values are stable (published and printed): append only.
/// Values 0..8 keep the meaning they have for the three-body scene.
enum class Reason : std::uint8_t {
  kOk = 0,
  kNonFiniteValue = 1,       ///< NaN or inf in a position or velocity, or NaN in a mass
  kNonPositiveMass = 2,      ///< mass <= 0
  kTwoWalls = 3,             ///< two walls with no finite body between them (N = 2)
  kInfiniteMiddleMass = 4,   ///< no longer reported (validate reports 13 for every N); the value stays published
  kPositionsNotOrdered = 5,  ///< not x_0 > x_1 > ... > x_{N-1}
  kPositionsCoincident = 6,  ///< two neighbouring positions are equal
  kTripleCollision = 7,      ///< two first contacts that share a body come at exactly the same instant
  kOverflow = 8,             ///< a value, or the first contact, leaves the double range; a count or mass ratio
  kUnequalLengths = 9,       ///< masses, positions and velocities differ in length
  kEmptyScene = 10,          ///< no bodies at all
  kRestitutionOutOfRange = 11,  ///< a restitution is NaN or outside [0, 1]
  kRestitutionCount = 12,    ///< restitution has neither 0, 1 nor N-1 values
  kWallNotAtEnd = 13,        ///< an infinite mass strictly inside the list
  kRestitutionModel = 14,    ///< the restitution model's parameter is not positive and finite, or conflicts with restitution
  kRing = 15,                ///< a ring that is not a positive finite circumference, a position outside [0, L), a wall or e = 0 on it
};

/// Machine-readable name of a reason, e.g. "UNEQUAL_LENGTHS".
const char* reasonName(Reason reason);

struct ValidationError {
  Reason reason = Reason::kOk;
  std::string field;    ///< e.g. "velocities[1]", "masses", "restitution"
  /// One sentence for people about the value in `field` ("v_B is NaN; ..."), which it does
  /// not repeat: front ends show field and message side by side.
  std::string message;
};

/// Checks a scene: the one validation of every N and every restitution (the front ends call
/// it through planScene, scene_run.h). Returns nothing when the scene is valid. Never throws for any
/// input (short of running out of memory). The first contact (its multiple-collision test,
/// its time and the positions then, which must be doubles) is decided exactly for the given
/// doubles. Two walls with bodies between them are valid. Three elastic bodies (the rotation
/// model) must allow at most 2^64 - 1 impacts and have no mass-ratio limit; other scenes,
/// which the event engine may simulate, a finite-mass ratio of at most 1e100.
std::optional<ValidationError> validate(const Scene& scene);

}  // namespace core
}  // namespace collision_lab
