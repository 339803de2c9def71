#include "reference.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <boost/multiprecision/cpp_bin_float.hpp>

namespace collision_lab {
namespace core {
namespace reference {

namespace {

struct State {
  std::vector<bool> wall;
  std::vector<Rational> mass;  // unused for walls
  std::vector<Rational> e;     // per pair
  std::vector<Rational> x, v;
  std::vector<bool> stuck;  // per pair: stuck together by e = 0 (one cluster)
  Rational now;
  std::vector<std::optional<Rational>> last_impact;  // per body, for the TC model [s]
};

/// The restitution of an impact of pair p at approach speed `approach` (> 0), by the scene's
/// model (physics.md, "Restitution models"): the pair's e, or 1 where the model says elastic.
Rational restitutionOf(const Scene& scene, const State& s, std::size_t p, const Rational& approach) {
  const RestitutionModel& model = scene.restitution_model;
  switch (model.kind) {
    case RestitutionModelKind::kConstant: return s.e[p];
    case RestitutionModelKind::kThreshold: return approach < Rational(model.elastic_below) ? Rational(1) : s.e[p];
    case RestitutionModelKind::kTc:
      for (const std::size_t k : {p, p + 1}) {  // a body that has not collided waited forever
        if (!s.wall[k] && s.last_impact[k] && !(s.now - *s.last_impact[k] > Rational(model.tc))) return 1;
      }
      return s.e[p];
    case RestitutionModelKind::kViscoelastic: {
      // e(v) = 1 - C1 s + C2 s^2, s = (v / v*)^(1/5), at the exact speed (here to 600 bits),
      // clamped to [0, 1], rounded to the nearest double.
      using Deep = boost::multiprecision::number<boost::multiprecision::cpp_bin_float<600>>;
      const Deep x = Deep(numerator(approach)) / Deep(denominator(approach)) / Deep(model.viscoelastic_speed);
      const Deep root = pow(x, Deep(1) / 5);
      const Deep e = 1 - Deep(115344) / 100000 * root + Deep(79826) / 100000 * root * root;
      return Rational(e >= 1 ? 1.0 : static_cast<double>(e));
    }
  }
  return s.e[p];
}

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
  s.stuck.assign(n - 1, false);
  s.last_impact.assign(n, std::nullopt);
  return s;
}

bool approaches(const State& s, std::size_t p) { return !s.stuck[p] && s.v[p] < s.v[p + 1]; }

/// The bodies stuck to `body` on each side: [first, last].
std::pair<std::size_t, std::size_t> clusterOf(const State& s, std::size_t body) {
  std::size_t first = body, last = body;
  while (first > 0 && s.stuck[first - 1]) --first;
  while (last < s.stuck.size() && s.stuck[last]) ++last;
  return {first, last};
}

/// physics.md: v_i' = V - e m_j (v_i - v_j)/M, v_j' = V + e m_i (v_i - v_j)/M; against a
/// wall i: v_j' = v_i - e (v_j - v_i). A stuck cluster (e = 0 earlier) takes part as one body
/// of its total mass (a wall in it makes it a wall); e = 0 sticks the two sides.
Rational collide(const Scene& scene, State& s, std::size_t p) {
  const auto [first, p_last] = clusterOf(s, p);
  const auto [p_first, last] = clusterOf(s, p + 1);
  (void)p_last, (void)p_first;
  Rational mass_i = 0, mass_j = 0;
  bool wall_i = false, wall_j = false;
  for (std::size_t k = first; k <= last; ++k) {
    (k <= p ? wall_i : wall_j) = (k <= p ? wall_i : wall_j) || s.wall[k];
    (k <= p ? mass_i : mass_j) += s.mass[k];
  }
  const Rational v_i = s.v[p], v_j = s.v[p + 1];
  const Rational relative = v_i - v_j;
  const Rational e = restitutionOf(scene, s, p, v_j - v_i);
  Rational lost = 0, after_i = v_i, after_j = v_j;
  if (wall_i) {
    lost = (1 - e * e) * mass_j * relative * relative / 2;
    after_j = v_i - e * (v_j - v_i);
  } else if (wall_j) {
    lost = (1 - e * e) * mass_i * relative * relative / 2;
    after_i = v_j - e * (v_i - v_j);
  } else {
    const Rational total = mass_i + mass_j;
    const Rational centre = (mass_i * v_i + mass_j * v_j) / total;
    lost = (1 - e * e) * (mass_i * mass_j / total) * relative * relative / 2;
    after_i = centre - e * mass_j * relative / total;
    after_j = centre + e * mass_i * relative / total;
  }
  for (std::size_t k = first; k <= last; ++k) s.v[k] = k <= p ? after_i : after_j;
  if (e == 0) s.stuck[p] = true;
  s.last_impact[p] = s.last_impact[p + 1] = s.now;
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
    const Rational lost = collide(scene, s, p);
    // A neighbour that now approaches at zero gap hits in the same instant: the two impacts
    // form one multiple collision, which does not happen (the state stays as before it).
    const std::size_t outer_first = clusterOf(s, p).first, outer_last = clusterOf(s, p + 1).second;
    for (std::size_t q : {outer_first - 1, outer_last}) {
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
    run.events.push_back({p, s.now, s.x[p], lost, before.v[p], before.v[p + 1], s.v[p], s.v[p + 1]});
    run.last_time = s.now;
  }
  run.velocities = s.v;
  for (std::size_t k = 0; k < s.x.size(); ++k) run.positions.push_back(s.x[k] - s.v[k] * (s.now - run.last_time));
  return run;
}

RingRun simulateRing(const Scene& scene, std::uint64_t max_impacts) {
  const std::size_t n = scene.masses.size();
  if (!(scene.ring > 0) || n < 2) throw std::invalid_argument("simulateRing: not a ring");
  std::vector<Rational> m, x, v, e;
  for (std::size_t k = 0; k < n; ++k) {
    m.emplace_back(scene.masses[k]);
    x.emplace_back(scene.positions[k]);
    v.emplace_back(scene.velocities[k]);
    const double ek = scene.restitution.empty() ? 1.0
                                                : (scene.restitution.size() == 1 ? scene.restitution[0] : scene.restitution[k]);
    if (!(ek > 0)) throw std::invalid_argument("simulateRing: e = 0 on a ring");
    e.emplace_back(ek);
  }
  const Rational length(scene.ring);
  const auto left = [n](std::size_t p) { return p + 1 == n ? std::size_t{0} : p + 1; };
  RingRun run;
  Rational now = 0;
  while (run.events.size() < max_impacts) {
    std::optional<Rational> soonest;
    std::size_t hit = 0, ties = 0;
    for (std::size_t p = 0; p < n; ++p) {
      const std::size_t l = left(p);
      if (!(v[l] > v[p])) continue;
      const Rational gap = x[p] - x[l] + (l == 0 ? length : Rational(0));
      const Rational delay = gap / (v[l] - v[p]);
      if (!soonest || delay < *soonest) {
        soonest = delay;
        hit = p;
        ties = 0;
      } else if (delay == *soonest) {
        ++ties;
      }
    }
    if (!soonest) break;
    if (ties > 0) {
      run.multiple = true;
      break;
    }
    for (std::size_t k = 0; k < n; ++k) x[k] += v[k] * *soonest;
    now += *soonest;
    const std::size_t l = left(hit);
    const Rational total = m[hit] + m[l];
    const Rational centre = (m[hit] * v[hit] + m[l] * v[l]) / total;
    const Rational relative = v[hit] - v[l];
    v[hit] = centre - e[hit] * m[l] * relative / total;
    v[l] = centre + e[hit] * m[hit] * relative / total;
    run.events.push_back({hit, now, v[hit], v[l]});
  }
  run.velocities = v;
  return run;
}

double limitOfImpactTimes(const Run& run, std::size_t period) {
  const auto& ev = run.events;
  const std::size_t n = ev.size();
  if (n < 2 * period + 1) throw std::invalid_argument("limitOfImpactTimes: fewer than 2 periods of impacts");
  const Rational t1 = ev[n - 1 - 2 * period].time, t2 = ev[n - 1 - period].time, t3 = ev[n - 1].time;
  return static_cast<double>(Rational(t3 - (t3 - t2) * (t3 - t2) / ((t3 - t2) - (t2 - t1))));
}

double collapseTime(const Scene& scene, std::uint64_t impacts) {
  const Run run = simulate(scene, impacts);
  if (!run.truncated) throw std::invalid_argument("collapseTime: the scene does not collapse");
  return limitOfImpactTimes(run);
}

AlternationWalk alternationCount(const Scene& scene, std::uint64_t cap) {
  using boost::multiprecision::cpp_int;
  const State s = initial(scene);
  // Impact of pair p scaled by L: the hit pair's speed times -e L, the other's times L plus
  // k L times the hit pair's, with k = (1 + e) m_far / (m_far + m_near) (1 + e for a wall).
  struct Step {
    cpp_int self, other, transfer;
  };
  Step steps[2];
  for (int p = 0; p < 2; ++p) {
    const std::size_t far = p == 0 ? 0 : 2, near = 1;
    const Rational share = s.wall[far] ? Rational(1) : s.mass[far] / (s.mass[far] + s.mass[near]);
    const Rational e = s.e[p], k = (1 + e) * share;
    const cpp_int l = denominator(e) * denominator(k);
    steps[p] = {-numerator(e) * (l / denominator(e)), l, numerator(k) * (l / denominator(k))};
  }
  const Rational a0 = s.v[1] - s.v[0], c0 = s.v[2] - s.v[1];
  // Scale the initial speeds to integers.
  const cpp_int common = denominator(a0) * denominator(c0);
  cpp_int d[2] = {numerator(a0) * (common / denominator(a0)), numerator(c0) * (common / denominator(c0))};
  int pair = 0;
  if (d[0] > 0 && d[1] > 0) {
    pair = (s.x[0] - s.x[1]) / a0 < (s.x[1] - s.x[2]) / c0 ? 0 : 1;
  } else if (d[1] > 0) {
    pair = 1;
  }
  AlternationWalk walk;
  while (d[pair] > 0) {
    if (walk.count == cap) {
      walk.capped = true;
      break;
    }
    const Step& st = steps[pair];
    d[1 - pair] = st.other * d[1 - pair] + st.transfer * d[pair];
    d[pair] = st.self * d[pair];
    ++walk.count;
    pair = 1 - pair;
    const unsigned zero = ~0u;
    const unsigned shift = std::min(d[0] == 0 ? zero : lsb(abs(d[0])), d[1] == 0 ? zero : lsb(abs(d[1])));
    if (shift != zero && shift > 0) {
      for (cpp_int& x : d) x = x < 0 ? cpp_int(-(cpp_int(-x) >> shift)) : cpp_int(x >> shift);
    }
  }
  return walk;
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
