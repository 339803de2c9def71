// The hand-written time-stepping script a student would write: move every body by v dt,
// then give each overlapping, approaching pair an elastic impulse (AB first, then BC).
// No position correction, no sub-stepping, no collision-time search.
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

SteppedRun runFixedStep(const core::ThreeBodyScene& scene, const StepConfig& config) {
  const auto& m = scene.masses;
  const double f_left[2] = {fraction(m[core::kA], m[core::kB]), fraction(m[core::kB], m[core::kC])};
  const double f_right[2] = {fraction(m[core::kB], m[core::kA]), fraction(m[core::kC], m[core::kB])};
  SteppedRun run;
  auto& x = run.positions;
  auto& v = run.velocities;
  x = scene.positions;
  v = scene.velocities;
  CollisionCounter counter(v);
  const double dt = config.dt;
  run.steps = stepCount(config);
  for (std::uint64_t step = 0; step < run.steps; ++step) {
    for (int i = 0; i < 3; ++i) x[i] += v[i] * dt;
    for (int pair = 0; pair < 2; ++pair) {
      const int left = pair;  // A of AB, B of BC: the body on the right of the pair
      const int right = pair + 1;
      const double approach = v[right] - v[left];
      if (x[left] <= x[right] && approach > 0) {
        v[left] += 2 * f_right[pair] * approach;
        v[right] -= 2 * f_left[pair] * approach;
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
          "Hand-written loop in double: x += v dt for all bodies, then for AB and then BC, "
          "if the pair overlaps (x_left <= x_right) and approaches, the exact elastic "
          "two-body impulse. Point masses, no position correction, no collision-time search.",
          runFixedStep};
}

std::uint64_t stepCount(const StepConfig& config) {
  return static_cast<std::uint64_t>(std::llround(config.end_time / config.dt));
}

}  // namespace bench
}  // namespace collision_lab
