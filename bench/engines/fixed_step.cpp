// The hand-written time-stepping script a student would write: move every body by v dt,
// then give each overlapping, approaching pair the two-body impulse with its restitution
// (pairs in list order, right to left). No position correction, no sub-stepping, no
// collision-time search.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "engines.h"
#include "stepped.h"

namespace collision_lab {
namespace bench {

namespace {

/// m_i / (m_i + m_j); 1 when i is a wall, 0 when j is.
double fraction(double m_i, double m_j) {
  if (std::isinf(m_i)) return 1.0;
  if (std::isinf(m_j)) return 0.0;
  return m_i / (m_i + m_j);
}

/// The loop on n bodies held in Array: std::array<double, n> for the small n of the
/// benchmark scenes, so the compiler unrolls it as it would a hand-written three-body
/// script; std::vector<double> otherwise. Pair p's impulse: v_p += k_right[p] (v_{p+1} -
/// v_p), v_{p+1} -= k_left[p] (v_{p+1} - v_p). Collisions counted as by CollisionCounter.
template <class Array>
void stepLoop(Array& x, Array& v, const Array& k_left, const Array& k_right, double dt, std::uint64_t steps,
              std::uint64_t* collisions) {
  const std::size_t n = x.size();
  Array approaching = v;  // 1 while pair p approaches (last entry unused)
  for (std::size_t p = 0; p + 1 < n; ++p) approaching[p] = v[p + 1] > v[p];
  std::uint64_t count = 0;
  for (std::uint64_t step = 0; step < steps; ++step) {
    for (std::size_t i = 0; i < n; ++i) x[i] += v[i] * dt;
    for (std::size_t p = 0; p + 1 < n; ++p) {
      const double approach = v[p + 1] - v[p];
      if (x[p] <= x[p + 1] && approach > 0) {
        v[p] += k_right[p] * approach;
        v[p + 1] -= k_left[p] * approach;
      }
    }
    for (std::size_t p = 0; p + 1 < n; ++p) {
      const bool now = v[p + 1] > v[p];
      count += approaching[p] != 0 && !now;
      approaching[p] = now;
    }
  }
  *collisions = count;
}

template <std::size_t N>
void runFixed(SteppedRun& run, const std::vector<double>& k_left, const std::vector<double>& k_right, double dt) {
  std::array<double, N> x, v, kl{}, kr{};
  std::copy(run.positions.begin(), run.positions.end(), x.begin());
  std::copy(run.velocities.begin(), run.velocities.end(), v.begin());
  std::copy(k_left.begin(), k_left.end(), kl.begin());
  std::copy(k_right.begin(), k_right.end(), kr.begin());
  stepLoop(x, v, kl, kr, dt, run.steps, &run.collisions);
  run.positions.assign(x.begin(), x.end());
  run.velocities.assign(v.begin(), v.end());
}

SteppedRun runFixedStep(const core::Scene& scene, const StepConfig& config) {
  const auto& m = scene.masses;
  const std::size_t pairs = scene.pairCount();
  std::vector<double> k_left(scene.size()), k_right(scene.size());  // last entries unused
  for (std::size_t p = 0; p < pairs; ++p) {
    const double one_plus_e = 1.0 + scene.restitutionOf(p);
    k_left[p] = one_plus_e * fraction(m[p], m[p + 1]);
    k_right[p] = one_plus_e * fraction(m[p + 1], m[p]);
  }
  SteppedRun run;
  run.positions = scene.positions;
  run.velocities = scene.velocities;
  run.steps = stepCount(config);
  switch (scene.size()) {
    case 2: runFixed<2>(run, k_left, k_right, config.dt); break;
    case 3: runFixed<3>(run, k_left, k_right, config.dt); break;
    case 5: runFixed<5>(run, k_left, k_right, config.dt); break;
    default: stepLoop(run.positions, run.velocities, k_left, k_right, config.dt, run.steps, &run.collisions);
  }
  return run;
}

}  // namespace

SteppedMethod fixedStepMethod() {
  return {"fixed_step",
          "Hand-written loop in double: x += v dt for all bodies, then for each pair in "
          "list order (AB, BC, ...), if it overlaps (x_right <= x_left) and approaches, the "
          "exact two-body impulse with the pair's e (factor 1 + e). Point masses, no position "
          "correction, no collision-time search.",
          runFixedStep};
}

std::uint64_t stepCount(const StepConfig& config) {
  return static_cast<std::uint64_t>(std::llround(config.end_time / config.dt));
}

}  // namespace bench
}  // namespace collision_lab
