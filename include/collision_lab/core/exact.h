// The three-body velocity maps in boost::multiprecision::cpp_rational, exact for the input
// doubles: the rotation model's exact decisions (the first pair, a grazing last contact,
// the count where 500 digits cannot place u_perp), and ground truth for the tests. Cost grows with the size of the rationals (roughly
// quadratically in the impact count): meant for counts up to a few thousand.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <boost/multiprecision/cpp_int.hpp>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {
namespace exact {

using Rational = boost::multiprecision::cpp_rational;
using RationalState = std::array<Rational, 3>;

/// Applies one elastic impact of `pair` to `v`, exactly. Walls keep their velocity.
void applyImpact(const std::array<double, 3>& masses, Pair pair, RationalState& v);

/// Exact approach speed of `pair` in state `v` (> 0: approaching; 0: touching without
/// impact; < 0: separating).
Rational approachSpeed(Pair pair, const RationalState& v);

/// Exact comparison of the first contact times when both pairs approach:
/// < 0 when AB is first, > 0 when BC is first, 0 for a triple collision.
int compareFirstContactTimes(const Scene& scene);

/// Exact velocities after n alternating impacts starting with `first`.
RationalState velocitiesAfter(const Scene& scene, Pair first, std::uint64_t n);

/// The velocity maps walked from the start: D_AB and D_BC in turn from the first pair,
/// while the next pair approaches (exactly).
struct MapWalk {
  std::uint64_t impact_count = 0;
  bool truncated = false;
  std::optional<Pair> first_pair;
  std::vector<Pair> pairs;
  RationalState final_velocities;
};

/// The impacts of three elastic bodies, exactly, by the velocity maps alone (positions decide
/// only the first pair; no time is computed, so an impact after the largest double counts
/// too): the rotation model's exact count where 500 digits cannot place u_perp, and the
/// tests' reference. Not a simulation of the scene: the engine is the one simulator.
/// Precondition: validate(scene) passed.
MapWalk walkVelocityMaps(const Scene& scene, std::uint64_t max_impacts);

}  // namespace exact
}  // namespace core
}  // namespace collision_lab
