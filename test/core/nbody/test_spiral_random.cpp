// The three-body spiral model on 1,000 seeded random scenes, two thirds of them with e
// within 1e-9 of r_c (a third on each side): against the exact engine where it can reach
// the end, and everywhere against an independent impact-by-impact walk written here from
// physics.md in quadruple precision (not exact, but far from the model's code and margins).
//
// Why two references: just above r_c the count reaches 10^5 to 10^6 impacts while the
// approach speeds shrink below 10^-10000 of the velocities; no exact simulation (the engine
// or the rational reference) gets there in a test, but a walk in the centre-of-mass frame,
// rescaled by powers of two (times are invariant under scaling gaps and speeds together), does.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <boost/multiprecision/cpp_bin_float.hpp>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/models.h"
#include "reference.h"

namespace collision_lab {
namespace core {
namespace {

// Quadruple precision (113 bits): a walk of 10^5 impacts next to r_c needs it, since an
// error relative to the state can grow by the square of the eigenbasis conditioning. When
// its last decision is marginal, the walk is redone in 100 digits.
using Quad = __float128;
using Wide = boost::multiprecision::cpp_bin_float_100;

Quad magnitude(Quad x) { return x < 0 ? -x : x; }
Wide magnitude(const Wide& x) { return abs(x); }

template <class Real>
struct Walked {
  bool stopped = false;
  std::uint64_t count = 0;
  Real w[3] = {0, 0, 0};  ///< centre-of-mass frame velocities * 2^exponent [m/s]
  long exponent = 0;
  Real times[5] = {0, 0, 0, 0, 0};  ///< the last five impact times [s]
  double margin = 0.0;  ///< |approach| / |w| of the last check
};

/// Impact by impact, from physics.md: v_i' = V - e m_j (v_i - v_j)/M, v_j' = V + e m_i (v_i - v_j)/M.
/// e = 0: the pair sticks and the third body, if it approaches, sticks to that pair.
template <class Real>
Walked<Real> walk(const Scene& s, std::uint64_t cap) {
  const double* m = s.masses.data();
  const double e = s.restitution[0];
  const Real total = Real(m[0]) + m[1] + m[2];
  const Real centre = (Real(m[0]) * s.velocities[0] + Real(m[1]) * s.velocities[1] + Real(m[2]) * s.velocities[2]) / total;
  Walked<Real> r;
  Real w[3] = {s.velocities[0] - centre, s.velocities[1] - centre, s.velocities[2] - centre};
  Real gap[2] = {Real(s.positions[0]) - s.positions[1], Real(s.positions[1]) - s.positions[2]};
  Real now = 0;
  const auto approach = [&](int p) { return w[p + 1] - w[p]; };
  int pair = approach(0) > 0 && (approach(1) <= 0 || gap[0] / approach(0) < gap[1] / approach(1)) ? 0 : 1;
  while (approach(pair) > 0 && r.count < cap) {
    const Real dt = gap[pair] / approach(pair);
    gap[1 - pair] -= approach(1 - pair) * dt;
    gap[pair] = 0;
    now += dt;
    if (e == 0 && r.count == 1) {  // the third body hits the stuck pair: all three stick
      w[0] = w[1] = w[2] = 0;
    } else {
      const int i = pair, j = pair + 1;
      // Every product in Real: e * m_j in double would round the map's coefficient, and next
      // to r_c the spiral angle is so sensitive to it that the count moved by one (scene 709).
      const Real mass = Real(m[i]) + m[j], pair_centre = (m[i] * w[i] + m[j] * w[j]) / mass, rel = w[i] - w[j];
      w[i] = pair_centre - Real(e) * m[j] * rel / mass;
      w[j] = pair_centre + Real(e) * m[i] * rel / mass;
    }
    // Rounding leaves a small total momentum, which the impacts keep while the velocities
    // shrink by e per cycle: remove it, or it swamps them after a few hundred impacts.
    const Real drift = (m[0] * w[0] + m[1] * w[1] + m[2] * w[2]) / total;
    for (Real& x : w) x -= drift;
    ++r.count;
    for (int k = 0; k < 4; ++k) r.times[k] = r.times[k + 1];
    r.times[4] = now;
    pair = 1 - pair;
    int shift = 0;
    std::frexp(static_cast<double>(magnitude(w[0]) + magnitude(w[1]) + magnitude(w[2])), &shift);
    if (shift < -500) {  // rescale speeds and gaps together (exactly): the times stay the same
      const Real factor = static_cast<Real>(std::ldexp(1.0, -shift));
      for (Real& x : w) x *= factor;
      for (Real& x : gap) x *= factor;
      r.exponent += shift;
    }
  }
  r.stopped = !(approach(pair) > 0);
  r.margin = static_cast<double>(magnitude(approach(pair)) / (magnitude(w[0]) + magnitude(w[1]) + magnitude(w[2])));
  for (int k = 0; k < 3; ++k) r.w[k] = w[k];
  return r;
}

double criticalRestitution(const Scene& s) {
  const double* m = s.masses.data();
  const double alpha = std::atan(std::sqrt(m[1] * (m[0] + m[1] + m[2]) / (m[0] * m[2])));
  const double root = std::tan(M_PI / 4 - alpha / 2);
  return root * root;
}

Scene randomThreeBodies(std::mt19937_64& rng, int trial) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), gap(0.2, 2.0), decades(-1.0, 1.0), offset(0.0, 1e-9);
  const double set[] = {0.0, 0.3, 0.5, 0.8, 0.95};
  while (true) {
    Scene s;
    for (int k = 0; k < 3; ++k) s.masses.push_back(std::pow(10.0, decades(rng)));
    const double x2 = unit(rng), x1 = x2 + gap(rng), x0 = x1 + gap(rng);
    s.positions = {x0, x1, x2};
    for (int k = 0; k < 3; ++k) s.velocities.push_back(unit(rng));
    const double rc = criticalRestitution(s);
    const int kind = trial % 3;
    s.restitution = {kind == 0 ? set[trial / 3 % 5] : (kind == 1 ? rc + offset(rng) : rc - offset(rng))};
    if (!validate(s) && chooseModel(s).kind == ModelKind::kThreeBodySpiral) return s;
  }
}

TEST(SpiralModelRandom, EqualsTheSimulationOnAThousandScenes) {
  std::mt19937_64 rng(1111);
  constexpr std::uint64_t kCap = 1000000;
  int redone = 0, near = 0, long_spirals = 0, collapses = 0, engine_checked = 0, engine_collapses = 0, sticking = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const Scene s = randomThreeBodies(rng, trial);
    const std::string label = "scene " + std::to_string(trial) + ", e = " + std::to_string(s.restitution[0]);
    const Prediction p = predictThreeBodySpiral(s);
    const double rc = criticalRestitution(s);
    const bool near_rc = std::fabs(s.restitution[0] - rc) <= 1e-9;
    near += near_rc;
    sticking += s.restitution[0] == 0.0;
    ASSERT_TRUE(p.critical_restitution) << label;
    EXPECT_NEAR(*p.critical_restitution, rc, 1e-14) << label;
    Walked<Quad> w = walk<Quad>(s, p.collapsed && !near_rc ? 5000 : kCap);
    if (w.stopped && w.margin < 1e-12) {  // too close to call in quadruple precision
      const Walked<Wide> wide = walk<Wide>(s, kCap);
      w.stopped = wide.stopped, w.count = wide.count, w.exponent = wide.exponent;
      for (int k = 0; k < 3; ++k) w.w[k] = static_cast<Quad>(static_cast<double>(wide.w[k]));
      ++redone;
    }
    const double scale = std::fabs(s.velocities[0]) + std::fabs(s.velocities[1]) + std::fabs(s.velocities[2]);
    if (p.collapsed) {
      ++collapses;
      EXPECT_FALSE(w.stopped) << label << ": the walk stopped after " << w.count;
      // The impact times converge geometrically to the collapse time (slowly next to r_c).
      const Quad step = w.times[4] - w.times[2], curve = step - (w.times[2] - w.times[0]);
      const Quad limit = curve == 0 ? w.times[4] : w.times[4] - step * step / curve;
      EXPECT_NEAR(*p.collapse_time, static_cast<double>(limit), (near_rc ? 1e-6 : 1e-12) * *p.collapse_time) << label;
      for (double v : p.final_velocities) EXPECT_NEAR(v, p.final_velocities[0], 0.0) << label;
    } else {
      ASSERT_TRUE(p.impact_count) << label << ": " << p.reason;
      EXPECT_TRUE(w.stopped) << label;
      EXPECT_EQ(*p.impact_count, w.count) << label;
      long_spirals += *p.impact_count > 1000;
      const Quad centre = (Quad(s.masses[0]) * s.velocities[0] + Quad(s.masses[1]) * s.velocities[1] +
                           Quad(s.masses[2]) * s.velocities[2]) / (Quad(s.masses[0]) + s.masses[1] + s.masses[2]);
      for (int k = 0; k < 3; ++k) {
        const double v = static_cast<double>(centre) +
                         std::ldexp(static_cast<double>(w.w[k]), static_cast<int>(std::max(-20000L, w.exponent)));
        EXPECT_NEAR(p.final_velocities[k], v, 1e-12 * scale) << label;
      }
    }
    // The exact engine, where it reaches the end in a test (far from r_c, modest counts).
    if (near_rc || (p.impact_count && *p.impact_count > 200)) continue;
    ++engine_checked;
    EngineOptions options;
    options.max_impacts = 1000;
    const SceneSimulation run = runEngine(s, options);
    EXPECT_EQ(run.collapsed, p.collapsed) << label << ": " << run.stop_message;
    EXPECT_EQ(run.stop, StopReason::kFinished) << label << ": " << run.stop_message;
    if (p.collapsed && run.collapsed) {
      ++engine_collapses;
      EXPECT_NEAR(*run.collapse_time, *p.collapse_time, 1e-12 * *p.collapse_time) << label;
      EXPECT_NEAR(*run.collapse_position, *p.collapse_position, 1e-12 * (1 + std::fabs(*p.collapse_position))) << label;
    } else if (p.impact_count) {
      EXPECT_EQ(run.impact_count, *p.impact_count) << label;
    }
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(run.final_velocities[k], p.final_velocities[k], 1e-12 * scale) << label;
    EXPECT_NEAR(run.energy_lost, p.energy_lost, 1e-12 * scale * scale * 30) << label;
  }
  // The sample covers what the issue names.
  EXPECT_GE(near, 600);
  EXPECT_GT(long_spirals, 20);
  EXPECT_GT(collapses, 100);
  EXPECT_GT(engine_checked, 300);
  EXPECT_GT(engine_collapses, 0);
  EXPECT_GT(sticking, 40);
  EXPECT_LT(redone, 50);
}

}  // namespace
}  // namespace core
}  // namespace collision_lab
