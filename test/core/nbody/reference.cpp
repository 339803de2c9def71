#include "reference.h"

#include <algorithm>
#include <cmath>

namespace collision_lab {
namespace core {
namespace reference {

namespace {

struct State {
  std::vector<bool> wall;
  std::vector<Rational> mass;  // unused for walls
  std::vector<Rational> e;     // per pair
  std::vector<Rational> x, v;
  Rational now;
};

State initial(const Scene& scene) {
  State s;
  const std::size_t n = scene.masses.size();
  for (std::size_t k = 0; k < n; ++k) {
    s.wall.push_back(std::isinf(scene.masses[k]));
    s.mass.push_back(s.wall[k] ? Rational(0) : Rational(scene.masses[k]));
    s.x.emplace_back(scene.positions[k]);
    s.v.emplace_back(scene.velocities[k]);
  }
  for (std::size_t p = 0; p + 1 < n; ++p) {
    const double e = scene.restitution.empty() ? 1.0
                                               : (scene.restitution.size() == 1 ? scene.restitution[0] : scene.restitution[p]);
    s.e.emplace_back(e);
  }
  return s;
}

bool approaches(const State& s, std::size_t p) { return s.v[p] < s.v[p + 1]; }

/// physics.md: v_i' = V - e m_j (v_i - v_j)/M, v_j' = V + e m_i (v_i - v_j)/M; against a
/// wall i: v_j' = v_i - e (v_j - v_i).
Rational collide(State& s, std::size_t p) {
  const std::size_t i = p, j = p + 1;
  const Rational relative = s.v[i] - s.v[j];
  const Rational& e = s.e[p];
  Rational lost = 0;
  if (s.wall[i]) {
    lost = (1 - e * e) * s.mass[j] * relative * relative / 2;
    s.v[j] = s.v[i] - e * (s.v[j] - s.v[i]);
  } else if (s.wall[j]) {
    lost = (1 - e * e) * s.mass[i] * relative * relative / 2;
    s.v[i] = s.v[j] - e * (s.v[i] - s.v[j]);
  } else {
    const Rational total = s.mass[i] + s.mass[j];
    const Rational centre = (s.mass[i] * s.v[i] + s.mass[j] * s.v[j]) / total;
    lost = (1 - e * e) * (s.mass[i] * s.mass[j] / total) * relative * relative / 2;
    s.v[i] = centre - e * s.mass[j] * relative / total;
    s.v[j] = centre + e * s.mass[i] * relative / total;
  }
  return lost;
}

}  // namespace

Run simulate(const Scene& scene, std::uint64_t max_impacts) {
  State s = initial(scene);
  Run run;
  const std::size_t pairs = s.x.size() - 1;
  while (true) {
    std::optional<Rational> soonest;
    std::vector<std::size_t> tied;
    for (std::size_t p = 0; p < pairs; ++p) {
      if (!approaches(s, p)) continue;
      const Rational delay = (s.x[p] - s.x[p + 1]) / (s.v[p + 1] - s.v[p]);
      if (!soonest || delay < *soonest) {
        soonest = delay;
        tied.assign(1, p);
      } else if (delay == *soonest) {
        tied.push_back(p);
      }
    }
    if (!soonest) break;
    if (run.events.size() == max_impacts) {
      run.truncated = true;
      break;
    }
    for (std::size_t k = 0; k + 1 < tied.size(); ++k) {
      if (tied[k + 1] == tied[k] + 1) {
        run.multiple_first = tied[k];
        run.multiple_time = s.now + *soonest;
        break;
      }
    }
    if (run.multiple_first) break;
    for (std::size_t k = 0; k < s.x.size(); ++k) s.x[k] += s.v[k] * *soonest;
    s.now += *soonest;
    const std::size_t p = tied.front();
    const State before = s;
    const Rational lost = collide(s, p);
    // A neighbour that now approaches at zero gap hits in the same instant: the two impacts
    // form one multiple collision, which does not happen (the state stays as before it).
    for (std::size_t q : {p - 1, p + 1}) {
      if (!run.multiple_first && q < pairs && approaches(s, q) && s.x[q] == s.x[q + 1]) {
        run.multiple_first = std::min(p, q);
        run.multiple_time = s.now;
      }
    }
    if (run.multiple_first) {
      s = before;
      break;
    }
    run.energy_lost += lost;
    run.events.push_back({p, s.now, s.x[p], lost});
    run.last_time = s.now;
  }
  run.velocities = s.v;
  for (std::size_t k = 0; k < s.x.size(); ++k) run.positions.push_back(s.x[k] - s.v[k] * (s.now - run.last_time));
  return run;
}

double energyNormError(const Scene& scene, const std::vector<double>& velocities,
                       const std::vector<Rational>& reference) {
  double mass_max = 0.0, frame = 0.0;
  for (std::size_t k = 0; k < scene.masses.size(); ++k) {
    if (std::isinf(scene.masses[k])) {
      frame = scene.velocities[k];
    } else {
      mass_max = std::max(mass_max, scene.masses[k]);
    }
  }
  double error_sq = 0.0, norm_sq = 0.0;
  for (std::size_t k = 0; k < scene.masses.size(); ++k) {
    if (std::isinf(scene.masses[k])) continue;
    const double w = scene.masses[k] / mass_max;
    const double d = static_cast<double>(Rational(velocities[k]) - reference[k]);
    error_sq += w * d * d;
    norm_sq += w * (scene.velocities[k] - frame) * (scene.velocities[k] - frame);
  }
  return norm_sq > 0 ? std::sqrt(error_sq / norm_sq) : std::sqrt(error_sq);
}

}  // namespace reference
}  // namespace core
}  // namespace collision_lab
