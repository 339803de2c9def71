// The hand-written time-stepping script a student would write: move every body by v dt,
// then give each overlapping, approaching pair the two-body impulse with its restitution
// (pairs in list order, right to left). No position correction, no sub-stepping, no
// collision-time search.
#include <cmath>

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

SteppedRun runFixedStep(const core::Scene& scene, const StepConfig& config) {
  const auto& m = scene.masses;
  const std::size_t pairs = scene.pairCount();
  // Pair p's impulse: v_p += k_right (v_{p+1} - v_p), v_{p+1} -= k_left (v_{p+1} - v_p).
  std::vector<double> k_left(pairs), k_right(pairs);
  for (std::size_t p = 0; p < pairs; ++p) {
    const double one_plus_e = 1.0 + scene.restitutionOf(p);
    k_left[p] = one_plus_e * fraction(m[p], m[p + 1]);
    k_right[p] = one_plus_e * fraction(m[p + 1], m[p]);
  }
  SteppedRun run;
  auto& x = run.positions;
  auto& v = run.velocities;
  x = scene.positions;
  v = scene.velocities;
  CollisionCounter counter(v);
  const double dt = config.dt;
  run.steps = stepCount(config);
  for (std::uint64_t step = 0; step < run.steps; ++step) {
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += v[i] * dt;
    for (std::size_t p = 0; p < pairs; ++p) {
      const double approach = v[p + 1] - v[p];
      if (x[p] <= x[p + 1] && approach > 0) {
        v[p] += k_right[p] * approach;
        v[p + 1] -= k_left[p] * approach;
      }
    }
    counter.update(v);
  }
  run.collisions = counter.count();
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
