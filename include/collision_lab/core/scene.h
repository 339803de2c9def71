// The three bodies (A, B, C) of the paper as the rotation model reads a Scene of three bodies.
// ROS-free: this header is part of collision_lab_core.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

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

/// A scene of three bodies A, B, C with these values (zeros by default), elastic.
Scene threeBodies(const std::array<double, 3>& masses = {}, const std::array<double, 3>& positions = {},
                  const std::array<double, 3>& velocities = {});

/// The three values of a three-body scene's field (masses, positions or velocities), as the
/// rotation model reads them. Precondition: three values.
std::array<double, 3> triple(const std::vector<double>& values);

/// The wall of a three-body scene (kA or kC; A's when both are walls), or -1 when all three
/// masses are finite. Precondition: scene.size() == 3.
int wallIndex(const Scene& scene);

/// The largest finite mass [kg]; walls (+inf) left out. The scale of mass-weighted
/// velocities throughout the rotation model.
double largestFiniteMass(const std::array<double, 3>& masses);

/// Which pair of a three-body scene collides first, exactly for the given doubles; empty
/// when neither pair approaches. Precondition: scene.size() == 3 and validate(scene) passed
/// (so the times are not tied).
std::optional<Pair> firstPair(const Scene& scene);

}  // namespace core
}  // namespace collision_lab
