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

/// Initial conditions in SI units. Bodies are listed right to left: x_0 > x_1 > ... >
/// x_{N-1}. Pair p joins bodies p and p+1; it approaches iff v_p < v_{p+1}.
struct Scene {
  std::vector<double> masses;      ///< [kg]; +inf = a wall, allowed at index 0 and/or N-1 only
  std::vector<double> positions;   ///< [m], strictly decreasing
  std::vector<double> velocities;  ///< [m/s]
  /// Coefficients of restitution e in [0, 1] [1]: empty = elastic (e = 1); one value = every
  /// pair; N-1 values = one per pair. Each is taken as the exact value of its double.
  std::vector<double> restitution;

  std::size_t size() const { return masses.size(); }
  std::size_t pairCount() const { return masses.empty() ? 0 : masses.size() - 1; }
  bool isWall(std::size_t body) const;
  std::size_t wallCount() const;
  /// e of pair p [1]. Precondition: validate() passed and p < pairCount().
  double restitutionOf(std::size_t pair) const;
  /// True when every pair has e = 1 (including an empty restitution list).
  bool isElastic() const;
};

/// "A", "B", ..., "Z" for the first 26 bodies, then "#26", "#27", ... (the index).
std::string bodyName(std::size_t body);
/// "AB", "BC", ... while both bodies have letters, then "Z-#26", "#26-#27", ...
std::string pairName(std::size_t pair);

/// Why a scene was rejected. Values are stable (published and printed): append only.
/// Values 0..8 keep the meaning they have for the three-body scene.
enum class Reason : std::uint8_t {
  kOk = 0,
  kNonFiniteValue = 1,       ///< NaN or inf in a position or velocity, or NaN in a mass
  kNonPositiveMass = 2,      ///< mass <= 0
  kTwoWalls = 3,             ///< two walls with no finite body between them (N = 2)
  kInfiniteMiddleMass = 4,   ///< validate(ThreeBodyScene) only; validate(Scene) reports 13 for every N
  kPositionsNotOrdered = 5,  ///< not x_0 > x_1 > ... > x_{N-1}
  kPositionsCoincident = 6,  ///< two neighbouring positions are equal
  kTripleCollision = 7,      ///< two first contacts that share a body come at exactly the same instant
  kOverflow = 8,             ///< a value, or the first contact, leaves the double range; a count or mass ratio
  kUnequalLengths = 9,       ///< masses, positions and velocities differ in length
  kEmptyScene = 10,          ///< no bodies at all
  kRestitutionOutOfRange = 11,  ///< a restitution is NaN or outside [0, 1]
  kRestitutionCount = 12,    ///< restitution has neither 0, 1 nor N-1 values
  kWallNotAtEnd = 13,        ///< an infinite mass strictly inside the list
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
/// model) must allow at most 2^64 - 1 collisions and have no mass-ratio limit; other scenes,
/// which the event engine may simulate, a finite-mass ratio of at most 1e100.
std::optional<ValidationError> validate(const Scene& scene);

}  // namespace core
}  // namespace collision_lab
