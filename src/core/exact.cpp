#include "collision_lab/core/exact.h"

#include <cmath>
#include <limits>

namespace collision_lab {
namespace core {
namespace exact {

namespace {

/// m_i / (m_i + m_j) exactly; 1 for a wall i, 0 when j is the wall.
Rational massFraction(double m_i, double m_j) {
  if (std::isinf(m_i)) return Rational(1);
  if (std::isinf(m_j)) return Rational(0);
  const Rational mi(m_i);
  return mi / (mi + Rational(m_j));
}

/// The input velocities as exact rationals.
RationalState initialVelocities(const Scene& scene) {
  return {Rational(scene.velocities[0]), Rational(scene.velocities[1]), Rational(scene.velocities[2])};
}

}  // namespace

void applyImpact(const std::array<double, 3>& masses, Pair pair, RationalState& v) {
  const int i = pairIndex(pair);  // the pair's bodies are i and i + 1
  const Rational approach = approachSpeed(pair, v);
  const Rational f_i = massFraction(masses[i], masses[i + 1]);
  v[i] += 2 * (1 - f_i) * approach;
  v[i + 1] -= 2 * f_i * approach;
}

Rational approachSpeed(Pair pair, const RationalState& v) {
  const int i = pairIndex(pair);
  return v[i + 1] - v[i];
}

int compareFirstContactTimes(const Scene& scene) {
  const auto& x = scene.positions;
  const auto& v = scene.velocities;
  // t_AB - t_BC has the sign of (x_A - x_B)(v_C - v_B) - (x_B - x_C)(v_B - v_A), both
  // approach speeds being positive. Fast path: double with a forward error bound.
  const double p_ab = (x[kA] - x[kB]) * (v[kC] - v[kB]);
  const double p_bc = (x[kB] - x[kC]) * (v[kB] - v[kA]);
  const double difference = p_ab - p_bc;
  const double bound = 8.0 * std::numeric_limits<double>::epsilon() * (std::fabs(p_ab) + std::fabs(p_bc));
  if (std::isfinite(difference) && std::isfinite(bound) && std::fabs(difference) > bound) {
    return difference < 0 ? -1 : 1;
  }
  const Rational exact_ab = (Rational(x[kA]) - Rational(x[kB])) * (Rational(v[kC]) - Rational(v[kB]));
  const Rational exact_bc = (Rational(x[kB]) - Rational(x[kC])) * (Rational(v[kB]) - Rational(v[kA]));
  return exact_ab < exact_bc ? -1 : (exact_ab > exact_bc ? 1 : 0);
}

RationalState velocitiesAfter(const Scene& scene, Pair first, std::uint64_t n) {
  RationalState v = initialVelocities(scene);
  Pair pair = first;
  for (std::uint64_t i = 0; i < n; ++i) {
    applyImpact(triple(scene.masses), pair, v);
    pair = otherPair(pair);
  }
  return v;
}

MapWalk walkVelocityMaps(const Scene& scene, std::uint64_t max_impacts) {
  MapWalk run;
  RationalState v = initialVelocities(scene);
  const bool ab = approachSpeed(Pair::AB, v) > 0;
  const bool bc = approachSpeed(Pair::BC, v) > 0;
  if (ab && bc) {
    run.first_pair = compareFirstContactTimes(scene) < 0 ? Pair::AB : Pair::BC;
  } else if (ab) {
    run.first_pair = Pair::AB;
  } else if (bc) {
    run.first_pair = Pair::BC;
  }
  if (run.first_pair) {
    Pair pair = *run.first_pair;
    while (approachSpeed(pair, v) > 0) {
      if (run.impact_count == max_impacts) {
        run.truncated = true;
        break;
      }
      applyImpact(triple(scene.masses), pair, v);
      run.pairs.push_back(pair);
      ++run.impact_count;
      pair = otherPair(pair);
    }
  }
  run.final_velocities = v;
  return run;
}

}  // namespace exact
}  // namespace core
}  // namespace collision_lab
