#include "collision_lab/core/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision_lab/core/exact.h"

namespace collision_lab {
namespace core {

Scene threeBodies(const std::array<double, 3>& masses, const std::array<double, 3>& positions,
                  const std::array<double, 3>& velocities) {
  return Scene{{masses.begin(), masses.end()}, {positions.begin(), positions.end()}, {velocities.begin(), velocities.end()}};
}

std::array<double, 3> triple(const std::vector<double>& values) { return {values.at(0), values.at(1), values.at(2)}; }

int wallIndex(const Scene& scene) {
  if (scene.isWall(kA)) return kA;
  if (scene.isWall(kC)) return kC;
  return -1;
}

double largestFiniteMass(const std::array<double, 3>& masses) {
  double largest = 0.0;
  for (double m : masses) {
    if (!std::isinf(m)) largest = std::max(largest, m);
  }
  return largest;
}

std::optional<Pair> firstPair(const Scene& scene) {
  const auto& v = scene.velocities;
  const bool ab = v[kA] < v[kB];
  const bool bc = v[kB] < v[kC];
  if (ab && bc) return exact::compareFirstContactTimes(scene) < 0 ? Pair::AB : Pair::BC;
  if (ab) return Pair::AB;
  if (bc) return Pair::BC;
  return std::nullopt;
}

}  // namespace core
}  // namespace collision_lab
