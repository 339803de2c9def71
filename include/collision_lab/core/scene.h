// The three-body scene (A, B, C) of the paper and its validation.
// ROS-free: this header is part of collision_lab_core.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "collision_lab/core/nbody/scene.h"  // Reason, ValidationError, reasonName

namespace collision_lab {
namespace core {

/// Particle indices: A is rightmost, C leftmost (x_A > x_B > x_C).
enum Particle : int { kA = 0, kB = 1, kC = 2 };

/// The colliding pair. Values match the ROS message constants PAIR_AB / PAIR_BC.
enum class Pair : std::uint8_t { AB = 0, BC = 1 };

inline Pair otherPair(Pair p) { return p == Pair::AB ? Pair::BC : Pair::AB; }
inline const char* pairName(Pair p) { return p == Pair::AB ? "AB" : "BC"; }

/// Initial conditions in SI units. A mass of +inf makes A or C a wall that keeps its
/// (constant) velocity forever.
struct ThreeBodyScene {
  std::array<double, 3> masses{};      ///< [kg], +inf = wall (A or C only)
  std::array<double, 3> positions{};   ///< [m], strictly decreasing: x_A > x_B > x_C
  std::array<double, 3> velocities{};  ///< [m/s]

  bool isWall(int i) const;
  /// Index of the wall (kA or kC), or -1 when all three masses are finite.
  int wallIndex() const;
};

/// Checks a scene. Returns nothing when the scene is valid. Never throws for any input.
/// The triple-collision test is exact for the given doubles.
std::optional<ValidationError> validate(const ThreeBodyScene& scene);

}  // namespace core
}  // namespace collision_lab
