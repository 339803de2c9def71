// The FMA path (src/core/nbody/fma_path.h) computes the portable path's bits: every
// double-double operation, the known-count three-body passes and the engine's runs impact by
// impact. Skipped on a CPU without FMA (there only the portable path runs).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/scene.h"
#include "collision_lab/core/scene.h"
#include "double_double.h"
#include "elastic_triple.h"
#include "fma_path.h"
#include "units.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {
namespace {

#if CL_HAS_FMA_PATH

/// hi and lo, bit for bit (a -0 is not a +0).
template <class A, class B>
bool sameBits(const A& a, const B& b) {
  return std::memcmp(&a.hi, &b.hi, sizeof(double)) == 0 && std::memcmp(&a.lo, &b.lo, sizeof(double)) == 0;
}

/// Every operation of both instances on one pair of operands.
struct Results {
  std::array<double, 14> words;
};

template <class W>
CL_DD_INLINE Results operations(double xh, double xl, double yh, double yl, double s) {
  const W x(xh, xl, 0), y(yh, yl, 0);
  const W prod = twoProd<std::is_same_v<W, DDFma>>(xh, yh);
  const W sum = x + y, scaled = x * s, product = x * y, quotient = x / y, difference = x - y, sum2 = twoSum<std::is_same_v<W, DDFma>>(xh, yh);
  return {{prod.hi, prod.lo, sum.hi, sum.lo, scaled.hi, scaled.lo, product.hi, product.lo, quotient.hi, quotient.lo,
           difference.hi, difference.lo, sum2.hi, sum2.lo}};
}

Results portable(double xh, double xl, double yh, double yl, double s) { return operations<DD>(xh, xl, yh, yl, s); }
CL_FMA_TARGET Results withFma(double xh, double xl, double yh, double yl, double s) {
  return operations<DDFma>(xh, xl, yh, yl, s);
}

/// A normalized double-double near 2^exponent with a random sign and a random low word.
std::array<double, 2> randomWord(std::mt19937_64& rng, int exponent) {
  std::uniform_real_distribution<double> unit(1.0, 2.0);
  std::bernoulli_distribution negative(0.5);
  const double hi = std::ldexp(unit(rng), exponent) * (negative(rng) ? -1 : 1);
  const double lo = std::ldexp(unit(rng), exponent - 54) * (negative(rng) ? -1 : 1);
  const double s = hi + lo;
  return {s, lo - (s - hi)};
}

TEST(FmaPath, EveryDoubleDoubleOperationGivesThePortableBits) {
  if (!cpuHasFma()) GTEST_SKIP() << "this CPU has no FMA: only the portable path runs";
  std::mt19937_64 rng(20261128);
  std::uniform_int_distribution<int> exponent(-400, 400);
  std::uniform_real_distribution<double> unit(-2.0, 2.0);
  for (int k = 0; k < 200000; ++k) {
    const auto x = randomWord(rng, exponent(rng)), y = randomWord(rng, exponent(rng));
    const double s = std::ldexp(unit(rng), exponent(rng));
    const Results a = portable(x[0], x[1], y[0], y[1], s), b = withFma(x[0], x[1], y[0], y[1], s);
    ASSERT_EQ(std::memcmp(a.words.data(), b.words.data(), sizeof a.words), 0)
        << "operands " << x[0] << " + " << x[1] << ", " << y[0] << " + " << y[1] << ", " << s;
  }
}

/// A pass's every visited state and its end, hashed bit by bit (FNV-1a).
struct PassTrace {
  std::uint64_t hash = 1469598103934665603ull;
  std::uint64_t visits = 0;
  std::optional<ElasticTripleRun> run;
  void add(double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    for (int i = 0; i < 8; ++i) hash = (hash ^ ((bits >> (8 * i)) & 0xff)) * 1099511628211ull;
  }
};

template <ElasticTriplePass kPass, bool kFma>
PassTrace trace(const Scene& scene, std::uint64_t count, std::size_t first_pair) {
  PassTrace t;
  auto visit = [&t](std::uint64_t n, const std::array<double, 3>& v) {
    t.visits = n;
    for (double x : v) t.add(x);
  };
  const double inf = std::numeric_limits<double>::infinity();
  if constexpr (kFma) {
    t.run = runElasticTriplePassFma<kPass>(scene, count, first_pair, count, inf, nullptr, visit);
  } else {
    t.run = runElasticTriplePass<kPass>(scene, count, first_pair, count, inf, nullptr, visit);
  }
  if (t.run) {
    for (double v : t.run->final_velocities) t.add(v);
  }
  return t;
}

// Counts by the closed form (ceil(pi / alpha) - 1 for a block against a wall and for the
// symmetric heavy-light-heavy case); both passes run to the count and must agree.
TEST(FmaPath, KnownCountPassesGiveThePortableBitsImpactByImpact) {
  if (!cpuHasFma()) GTEST_SKIP() << "this CPU has no FMA: only the portable path runs";
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    Scene scene;
    std::uint64_t count;
    std::size_t first_pair;
  };
  const std::vector<Case> cases = {
      {threeBodies({100, 1, inf}, {2, 1, 0}, {-1, 0, 0}), 31, 0},
      {threeBodies({1e4, 1, inf}, {2, 1, 0}, {-1, 0, 0}), 314, 0},
      {threeBodies({1e10, 1, inf}, {2, 1, 0}, {-1, 0, 0}), 314159, 0},
      {threeBodies({1e12, 1, 1e12}, {1, 0, -1}, {-1, 0, 0}), 2221441, 0},
      {threeBodies({1e37, 1, inf}, {2, 1, 0}, {-1, 0, 0}), 200000, 0},  // a prefix: capped
      {threeBodies({3.7, 1.3, 5.1}, {1, 0, -1}, {-1, 0.25, 1}), 0, 0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(::testing::Message() << "masses " << c.scene.masses[0] << ", " << c.scene.masses[1] << ", "
                                      << c.scene.masses[2] << "; " << c.count << " impacts");
    const PassTrace replica = trace<ElasticTriplePass::kReplica, false>(c.scene, c.count, c.first_pair);
    const PassTrace replica_fma = trace<ElasticTriplePass::kReplica, true>(c.scene, c.count, c.first_pair);
    EXPECT_EQ(replica_fma.visits, replica.visits);
    EXPECT_EQ(replica_fma.hash, replica.hash);
    EXPECT_EQ(replica_fma.run.has_value(), replica.run.has_value());
    const PassTrace certified = trace<ElasticTriplePass::kCertified, false>(c.scene, c.count, c.first_pair);
    const PassTrace certified_fma = trace<ElasticTriplePass::kCertified, true>(c.scene, c.count, c.first_pair);
    EXPECT_EQ(certified_fma.visits, certified.visits);
    EXPECT_EQ(certified_fma.hash, certified.hash);
    EXPECT_EQ(certified_fma.run.has_value(), certified.run.has_value());
    // One of the passes answers (the replica, or the certified pass where the engine's
    // guard may fire, as for 1e37 against 1): the comparison covers every impact.
    EXPECT_TRUE(replica.run || certified.run);
    EXPECT_EQ(replica.run ? replica.visits : certified.visits, c.count);
  }
}

/// Every double of a run, in order: each impact's record, then the final state.
std::vector<double> runWords(bool fma, const Scene& scene, std::uint64_t cap, SceneSimulation& result) {
  std::vector<double> words;
  EngineOptions options;
  options.max_impacts = cap;
  result = runEngineOnPath(fma, scene, options, [&words](const ImpactRecord& r) {
    words.insert(words.end(), {static_cast<double>(r.index), static_cast<double>(r.pair_index), r.time, r.position,
                               r.velocities_before[0], r.velocities_before[1], r.velocities_after[0],
                               r.velocities_after[1], r.energy_gained[0], r.energy_gained[1], r.energy_lost});
  });
  words.push_back(result.final_time);
  words.insert(words.end(), result.final_positions.begin(), result.final_positions.end());
  words.insert(words.end(), result.final_velocities.begin(), result.final_velocities.end());
  words.push_back(result.energy_lost);
  return words;
}

// The engine on the FMA path (its working tier compiled for FMA, on DDFma) publishes the
// portable path's records bit for bit: elastic and inelastic gases (collapses and
// escalations to 100 digits and rationals among them), the TC and viscoelastic models, a
// ring, walls, and three bodies at mass ratios up to 1e12.
TEST(FmaPath, EngineRunsGiveThePortableBitsImpactByImpact) {
  if (!cpuHasFma()) GTEST_SKIP() << "this CPU has no FMA: only the portable path runs";
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), mass(1.0, 2.0);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Scene> scenes = {Scene{{1e12, 1, inf}, {2, 1, 0}, {-1, 0, 0}},
                               Scene{{1e6, 1, 1e6}, {2, 1, 0}, {-1, 0, 0.5}},
                               Scene{{3, 1, 0.5}, {2, 1, 0}, {-1, 0.25, 0.5}}};
  for (int k = 0; k < 12; ++k) {
    Scene gas;
    const int n = 20 + 10 * k;
    for (int b = 0; b < n; ++b) {
      gas.masses.push_back(mass(rng));
      gas.positions.push_back(static_cast<double>(n - b));
      gas.velocities.push_back(unit(rng));
    }
    switch (k % 6) {
      case 0: break;                                         // elastic
      case 1: gas.restitution = {0.5}; break;                // collapses
      case 2: gas.restitution = {0.9}; gas.restitution_model.kind = RestitutionModelKind::kTc;
              gas.restitution_model.tc = 1e-3; break;
      case 3: gas.restitution_model.kind = RestitutionModelKind::kViscoelastic;
              gas.restitution_model.viscoelastic_speed = 1.0; break;
      case 4: gas.restitution = {0.95}; gas.ring = n + 0.5; break;
      case 5: gas.masses.front() = inf; gas.masses.back() = inf; gas.restitution = {0.8}; break;
    }
    scenes.push_back(gas);
  }
  std::uint64_t escalated = 0, impacts = 0;
  for (const Scene& scene : scenes) {
    ASSERT_FALSE(validate(scene)) << scene.size() << " bodies";
    SceneSimulation portable, fma;
    const std::vector<double> a = runWords(false, scene, 20000, portable), b = runWords(true, scene, 20000, fma);
    SCOPED_TRACE(::testing::Message() << scene.size() << " bodies, " << portable.impact_count << " impacts");
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
    EXPECT_EQ(portable.stop, fma.stop);
    EXPECT_EQ(portable.impact_count, fma.impact_count);
    EXPECT_EQ(portable.collapses.size(), fma.collapses.size());
    EXPECT_EQ(portable.escalations.high_precision, fma.escalations.high_precision);
    EXPECT_EQ(portable.escalations.exact_rational, fma.escalations.exact_rational);
    escalated += portable.escalations.high_precision + portable.escalations.exact_rational;
    impacts += portable.impact_count;
  }
  RecordProperty("impacts", static_cast<int>(impacts));
  RecordProperty("escalations", static_cast<int>(escalated));
  EXPECT_GT(escalated, 0u);  // the adoption of a more precise tier's state into DDFma is covered
}

#else

TEST(FmaPath, NotBuiltOnThisTarget) { GTEST_SKIP() << "no FMA path on this target: only the portable path"; }

#endif

// The replica pass's contract (elastic_triple.h): where it answers, its final velocities are
// the engine's, bit for bit; where the engine's precision guard may fire, it declines. Its
// intercepts are doubles with bounds on their distance from the engine's: this checks that
// those bounds keep it on the safe side, against runEngine itself, on seeded scenes from
// equal masses to ratios of 1e12, walls, near-grazing ends, and the extreme (1e37, 1, wall),
// where the guard fires.
TEST(KnownCountPass, TheReplicaAnswersOnlyWithTheEnginesBits) {
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), decades(-6.0, 6.0);
  std::uniform_int_distribution<int> kind(0, 5);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<Scene> scenes = {Scene{{1e37, 1, inf}, {2, 1, 0}, {-1, 0, 0}},
                               Scene{{3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}},
                               Scene{{1e4, 1, inf}, {2, 1, 0}, {-1, 0, 0}}};
  while (scenes.size() < 400) {
    Scene s = threeBodies();
    for (double& m : s.masses) m = std::pow(10.0, decades(rng));
    if (kind(rng) == 0) s.masses[kind(rng) % 2 == 0 ? 0 : 2] = inf;
    s.positions = {2.0 + unit(rng), 0.5 * unit(rng), -2.0 + unit(rng)};
    for (double& v : s.velocities) v = kind(rng) == 1 ? 1e-9 * unit(rng) : unit(rng);
    if (!validate(s)) scenes.push_back(s);
  }
  int answered = 0, declined = 0;
  for (const Scene& si : scenes) {
    const WorkingUnits units(si);
    const Scene& scene = units.scene;  // the pass and the engine, both in the engine's units
    const std::optional<Pair> first = firstPair(scene);
    const std::uint64_t count = std::min<std::uint64_t>(predictedImpactCount(scene), 20000);
    if (!first || (scene.isWall(0) && scene.isWall(2))) continue;
    auto ignore = [](std::uint64_t, const std::array<double, 3>&) {};
    const std::optional<ElasticTripleRun> replica = runElasticTriplePass<ElasticTriplePass::kReplica>(
        scene, count, *first == Pair::BC ? 1 : 0, count, inf, nullptr, ignore);
    if (!replica) {
      ++declined;
      continue;
    }
    ++answered;
    EngineOptions options;
    options.max_impacts = count;
    const SceneSimulation engine = runEngine(scene, options);
    SCOPED_TRACE(::testing::Message() << "masses " << si.masses[0] << ", " << si.masses[1] << ", " << si.masses[2]
                                      << "; velocities " << si.velocities[0] << ", " << si.velocities[1] << ", "
                                      << si.velocities[2]);
    ASSERT_EQ(engine.impact_count, replica->impact_count);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(std::memcmp(&engine.final_velocities[k], &replica->final_velocities[k], sizeof(double)), 0)
          << "body " << k << ": engine " << engine.final_velocities[k] << ", replica " << replica->final_velocities[k];
    }
  }
  RecordProperty("answered", answered);
  RecordProperty("declined", declined);
  EXPECT_GT(answered, 300);  // the check covers most scenes
  EXPECT_GE(declined, 1);    // (1e37, 1, wall): the engine's guard fires there
  // The guard on the intercepts, which the replica reads in double: A meets B 1e-6 m away
  // while the heavy C (1e12 kg) waits at -1e6 m. The bound the replica keeps of the engine's
  // intercept error, sqrt(m_C) |x_C| 2^-99 = 1.6e-18 from the start, is more than 2^-43 of
  // the impact's intercept difference (1e-6): the engine's guard may fire, so the replica
  // must decline (it does with the intercepts in double-double too).
  const Scene near_heavy{{1, 1, 1e12}, {1e-6, 0, -1e6}, {-1, 0, 0}};
  ASSERT_FALSE(validate(near_heavy));
  const WorkingUnits units(near_heavy);
  auto ignore = [](std::uint64_t, const std::array<double, 3>&) {};
  const std::uint64_t count = predictedImpactCount(units.scene);
  ASSERT_GE(count, 1u);
  EXPECT_FALSE((runElasticTriplePass<ElasticTriplePass::kReplica>(units.scene, count, 0, count, inf, nullptr, ignore)));
}

}  // namespace
}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
