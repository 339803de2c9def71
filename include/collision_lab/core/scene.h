// Scene description and input validation for three point masses on a line.
// ROS-free: this header is part of collision_lab_core.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace collision_lab {

/// Particle indices: A is rightmost, C leftmost (x_A > x_B > x_C).
enum Particle : int { kA = 0, kB = 1, kC = 2 };

/// The colliding pair. Values match the ROS message constants PAIR_AB / PAIR_BC.
enum class Pair : std::uint8_t { AB = 0, BC = 1 };

inline Pair otherPair(Pair p) { return p == Pair::AB ? Pair::BC : Pair::AB; }
inline const char* pairName(Pair p) { return p == Pair::AB ? "AB" : "BC"; }

/// Initial conditions in SI units. A mass of +inf makes A or C a wall that keeps its
/// (constant) velocity forever.
struct Scene {
  std::array<double, 3> masses{};      ///< [kg], +inf = wall (A or C only)
  std::array<double, 3> positions{};   ///< [m], strictly decreasing: x_A > x_B > x_C
  std::array<double, 3> velocities{};  ///< [m/s]

  bool isWall(int i) const;
  /// Index of the wall (kA or kC), or -1 when all three masses are finite.
  int wallIndex() const;
};

/// Why a scene was rejected. Values are stable: they are published in ROS messages and
/// printed by the CLI. Append only.
enum class Reason : std::uint8_t {
  kOk = 0,
  kNonFiniteValue = 1,      ///< NaN or inf in a position or velocity, or NaN in a mass
  kNonPositiveMass = 2,     ///< mass <= 0
  kTwoWalls = 3,            ///< both A and C have infinite mass
  kInfiniteMiddleMass = 4,  ///< B has infinite mass
  kPositionsNotOrdered = 5, ///< not x_A > x_B > x_C
  kPositionsCoincident = 6, ///< two positions are equal
  kTripleCollision = 7,     ///< the first two contacts happen at exactly the same time
  kOverflow = 8,            ///< a momentum, energy, gap or relative velocity overflows a double; the
                            ///< first contact comes after, or puts a body beyond, the largest double;
                            ///< or the masses allow more than 2^64 - 1 collisions
};

/// Machine-readable name of a reason, e.g. "TRIPLE_COLLISION".
const char* reasonName(Reason r);

struct ValidationError {
  Reason reason = Reason::kOk;
  std::string field;    ///< e.g. "velocities[1]", "masses", "positions"
  /// One sentence for people about the value in `field` ("v_B is NaN; ..."), which it does
  /// not repeat: front ends show field and message side by side.
  std::string message;
};

/// Checks a scene. Returns nothing when the scene is valid. Never throws for any input.
/// The triple-collision test is exact for the given doubles.
std::optional<ValidationError> validate(const Scene& scene);

}  // namespace collision_lab
