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

/// Pairs by index: pair i joins bodies i and i + 1 (AB: A and B, BC: B and C). Body i is
/// to the right of body i + 1, so pair i approaches when v[i + 1] > v[i].
inline int pairIndex(Pair p) { return static_cast<int>(p); }

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

/// The largest finite mass [kg]; walls (+inf) left out. The scale of mass-weighted
/// velocities throughout the core.
double largestFiniteMass(const std::array<double, 3>& masses);

/// Checks a scene. Returns nothing when the scene is valid. Never throws for any input.
/// The triple-collision test is exact for the given doubles.
std::optional<ValidationError> validate(const ThreeBodyScene& scene);

/// Which pair collides first, exactly for the given doubles; empty when neither pair
/// approaches. Precondition: validate(scene) passed (so the times are not tied).
std::optional<Pair> firstPair(const ThreeBodyScene& scene);

}  // namespace core
}  // namespace collision_lab
