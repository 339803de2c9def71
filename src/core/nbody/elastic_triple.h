// Three elastic bodies whose impact count is known in advance (the three-body closed form,
// predictedImpactCount): the engine's working tier on velocities alone, with no
// decision taken (internal; not installed).
//
// Why no decision is needed. With three bodies the pairs alternate: after an impact its
// pair separates (e = 1), and only the other pair can meet next. The closed form gives the
// exact count N and the first pair, so impacts 1..N are known to be those pairs in turn, and
// nothing approaches after N. The queue, the impact times and their precision guard serve
// only to order events and publish times; a run that publishes neither needs none of them.
//
// What it computes. The engine's working tier without its queue: the double-double
// velocities after every impact by the same impact map (applyImpactMap, impact_rule.h), the
// same mass-weighted bounds (tier.h, rho) and the same range check. The intercepts, which the
// engine's checks read only through their sizes, are mapped in double, each with a bound on
// its distance from the engine's, so that every check is bounded from the safe side. The
// engine leaves that state only when its precision guard (tier.h, timeIsPrecise) hands an
// impact to 100 digits and adopts that tier's state; every other escalation (which pair is
// next, does a pair still approach) is followed in double-double, which keeps the state. So
// where the guard, replayed here with a margin of 2, never fires, the velocities are the
// engine's bit for bit. Where it may fire, the final velocities must be certified instead:
// a componentwise bound E_k on |v_k(computed) - v_k(exact)|, summed from each operation's
// rounding (double_double.h; the mass-weighted bound is loose for a light body next to a
// heavy one, whose error is the heavy body's), must keep v_k +- E_k strictly inside the
// rounding cell of its double, which is then the correctly rounded exact velocity. A run
// it can neither replay nor certify, or that leaves the engine's safe range, it declines:
// the engine runs it.
//
// The engine's bits are not always the correctly rounded ones: a body that ends nearly at
// rest after a long run keeps the absolute error of its fast past ((1e14, 1, 1e14) from
// (-1, 0, 0): A ends at 2.6e-15 m/s, 2 ulps off). So the replica's final velocities are
// checked against the engine's own mass-weighted bound (eu / sqrt(m_k)); where that does not
// certify them, the product of the run's impact maps (certifiedVelocitiesAfter) gives them
// certified, and only where neither can (an exact zero or tie) do the engine's bits stand.
//
// A long run is taken first by the filtered pass (issue 48, filteredTriplePass): the same
// impacts walked in double with a rigorous bound, its decisions checked (each impact's pair
// approaches, none after the last), the final state certified once by the product. Where the
// bound does not decide, the passes above run; since a certified value is the correctly
// rounded one, the answer is the same bits whichever pass gives it.
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <type_traits>
#include <utility>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/impact_rule.h"
#include "collision_lab/core/nbody/scene.h"
#include "double_double.h"
#include "fma_path.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {

/// The engine's energy and momentum drifts of a run from its final_velocities (and
/// energy_lost), as runEngine fills them (engine.cpp).
void fillEngineDrift(const Scene& scene, SceneSimulation& result);

/// How a run of runElasticTriple ended. Velocities in the scene's units [m/s].
struct ElasticTripleRun {
  std::uint64_t impact_count = 0;
  bool capped = false;     ///< stopped at the cap, more impacts due (the engine's kCap)
  bool cancelled = false;  ///< stopped by the cancel flag (the engine's kCancelled)
  std::array<double, 3> final_velocities{};
  bool certified = false;  ///< final_velocities are the exact ones correctly rounded
};

/// The velocities after `impacts` impacts of `scene` (three bodies, every e = 1, at most one
/// wall; the pairs in turn from first_pair), each the exact one correctly rounded, from the
/// product of the impact maps in 100 digits (elastic_triple_product.cpp; about 0.1 ms at any
/// count): certified, both ends of its error interval rounding to the same nonzero double. A
/// wall keeps its velocity. Empty when a body's is not certified (an exact zero or tie).
std::optional<std::array<double, 3>> certifiedVelocitiesAfter(const Scene& scene, std::uint64_t impacts,
                                                              std::size_t first_pair);
/// The same, body by body: each velocity that is certified (a wall's always).
std::array<std::optional<double>, 3> certifiedVelocityComponentsAfter(const Scene& scene, std::uint64_t impacts,
                                                                      std::size_t first_pair);

/// Is `hi + lo` within `error` of x certainly rounded to hi (x strictly inside hi's rounding
/// cell)? hi + lo is a normalized double-double.
template <class W>
CL_DD_INLINE bool roundsTo(const W& value, double error) {
  if (error == 0.0) return true;  // exact: hi is nearest to hi + lo
  if (value.hi == 0.0) return false;
  constexpr double kMargin = 1.0 - 0x1p-20;  // covers the rounding of lo +- error
  const double up = 0.5 * (std::nextafter(value.hi, HUGE_VAL) - value.hi);
  const double down = 0.5 * (value.hi - std::nextafter(value.hi, -HUGE_VAL));
  return value.lo + error < up * kMargin && value.lo - error > -down * kMargin;
}

/// The two passes of runElasticTriple: the engine's replica (its precision guard watched),
/// and the certified one (componentwise bounds; the intercepts in double, for the range).
enum class ElasticTriplePass { kReplica, kCertified };

/// One pass in double-double W (DD or DDFma: the same bits); empty when it cannot answer
/// (kReplica: the guard may fire; kCertified: not certified; either: out of range).
template <ElasticTriplePass kPass, class W, class Visit>
CL_DD_INLINE std::optional<ElasticTripleRun> elasticTriplePass(const Scene& scene, std::uint64_t count,
                                                              std::size_t first_pair, std::uint64_t cap,
                                                              double time_limit, const std::atomic<bool>* cancel,
                                                              Visit& visit) {
  constexpr bool kReplica = kPass == ElasticTriplePass::kReplica;
  constexpr double kEta = kDoubleDoubleOpError;  // one double-double operation, relative
  constexpr double kSlack = 1.0 + 0x1p-40;       // the rounding of evaluating a bound in double
  constexpr double kTinyError = 0x1p-998;        // underflow in double-double, per bound (4 operations)
  // The engine's safe range (tier.h, kMaxMagnitude); 2^10 below it for intercepts in double.
  constexpr double kRange = kReplica ? 0x1p900 : 0x1p890;
  constexpr double kGuard = 0x1p-43;  // the engine's precision guard (2^-42), halved
  // An impact time |intercept difference| / |approach speed| near time_limit or beyond: the
  // engine decides whether the double format holds it (a generous margin: it only declines).
  const double time_bound = time_limit * (1 - 0x1p-20);
  std::array<double, 3> sqrt_mass{};  // 0 for a wall, as tier.h's tables
  for (int k = 0; k < 3; ++k) sqrt_mass[k] = scene.isWall(k) ? 0.0 : std::sqrt(scene.masses[k]);
  struct PairTables {
    ImpactMap<W> map;
    double gain;      // |c_h|, 0 for a wall
    double s_h, s_l;  // sqrt of the heavier and lighter mass, 0 for a wall
    double scale;     // 1/sqrt(m_p) + 1/sqrt(m_p+1), a wall counting 0
  };
  std::array<PairTables, 2> pairs;
  for (int p = 0; p < 2; ++p) {
    PairTables& pair = pairs[p];
    pair.map = makeImpactMap<W>(scene.masses[p], scene.masses[p + 1], 1.0);
    pair.gain = std::fabs(pair.map.heavy_gain.hi);
    pair.s_h = sqrt_mass[pair.map.heavy_is_i ? p : p + 1];
    pair.s_l = sqrt_mass[pair.map.heavy_is_i ? p + 1 : p];
    pair.scale = (sqrt_mass[p] > 0 ? 1 / sqrt_mass[p] : 0.0) + (sqrt_mass[p + 1] > 0 ? 1 / sqrt_mass[p + 1] : 0.0);
  }
  // tier.h, rho(): the engine's bound on one impact's mass-weighted rounding, from the sizes
  // of the heavy and light values after it, its increment and its difference; increasing in
  // each, so that upper bounds of them bound it.
  const auto rho_of = [](const PairTables& pair, double q_h, double q_l, double inc, double d) {
    if (pair.map.exchange) return 0.0;
    return 2 * kEta * (pair.s_h * (q_h + 8 * inc) + pair.s_l * (q_l + q_h + 8 * inc + 2 * d)) +
           (pair.s_h + pair.s_l) * 0x1p-1000;
  };
  const auto rho = [&rho_of](const PairTables& pair, const ImpactChange<W>& change, const W& q_i, const W& q_j) {
    return rho_of(pair, std::fabs((pair.map.heavy_is_i ? q_i : q_j).hi), std::fabs((pair.map.heavy_is_i ? q_j : q_i).hi),
                  std::fabs(change.heavy_increment.hi), std::fabs(change.difference.hi));
  };
  // kReplica reads the engine's double-double intercepts only through the sizes of their hi
  // parts, in its guard, range and time checks: bounds of them from the safe side serve, from
  // intercepts mapped in double, each within b_error[k] of the engine's (kU per operation
  // covers a double's rounding and the engine's double-double rounding with it).
  constexpr double kU = 0x1p-52;
  const auto hi_above = [](double x, double err) { return (std::fabs(x) + err) * (1 + kU); };
  const auto hi_below = [](double x, double err) { return std::max(0.0, (std::fabs(x) - err) * (1 - kU)); };
  std::array<W, 3> v = {W(scene.velocities[0]), W(scene.velocities[1]), W(scene.velocities[2])};
  std::array<double, 3> b_double = {scene.positions[0], scene.positions[1], scene.positions[2]};
  std::array<double, 3> b_error{};  // kReplica: |b_double[k] - the engine's intercept|; the inputs are exact
  std::array<double, 3> error{};  // E_k [m/s] (kCertified); the inputs are exact
  // The engine's mass-weighted bounds (tier.h; kReplica), from what its start adds when it
  // adopts a more precise tier's state (tier.h, adopt(): 2^-100 per conversion), so that
  // they bound the engine's either way.
  double eu = 0.0, eb = 0.0;
  for (int k = 0; k < 3; ++k) {
    eu += 2 * 0x1p-100 * sqrt_mass[k] * std::fabs(scene.velocities[k]);
    eb += 2 * 0x1p-100 * sqrt_mass[k] * std::fabs(scene.positions[k]);
  }
  // Both passes map the intercepts in double as the engine maps them in double-double
  // (applyImpactMap, e = 1: a swap, or heavy += g d and light = heavy -+ d); returns g d, or
  // d for a swap.
  const auto map_intercepts = [&b_double](const ImpactMap<W>& map, std::size_t p, double d) {
    if (map.exchange) {
      std::swap(b_double[p], b_double[p + 1]);
      return d;
    }
    double& bh = map.heavy_is_i ? b_double[p] : b_double[p + 1];
    double& bl = map.heavy_is_i ? b_double[p + 1] : b_double[p];
    const double increment = map.heavy_gain.hi * d;
    bh += increment;
    bl = map.light_factor == -1.0 ? bh - d : bh + d;
    return increment;
  };
  ElasticTripleRun run;
  const std::uint64_t target = count < cap ? count : cap;
  std::size_t p = first_pair;
  std::uint64_t n = 0;
  for (; n < target; ++n, p ^= 1) {
    if (cancel && n % 1024 == 0 && cancel->load(std::memory_order_relaxed)) {
      run.cancelled = true;
      break;
    }
    const PairTables& pair = pairs[p];
    const ImpactMap<W>& map = pair.map;
    W& vi = v[p];
    W& vj = v[p + 1];
    const ImpactChange<W> dv = applyImpactMap(map, vi, vj);
    if (!map.exchange && map.light_factor != 1.0 && map.light_factor != -1.0) return std::nullopt;  // elastic: never
    const double d = b_double[p + 1] - b_double[p];
    if constexpr (kReplica) {
      const double eu_before = eu, eb_before = eb;
      // The engine's intercept map, in double with bounds on the distance from its values.
      double& ei = b_error[p];
      double& ej = b_error[p + 1];
      const double d_error = (ei + ej + kU * std::fabs(d)) * kSlack + kTinyError;
      const double increment = map_intercepts(map, p, d);  // the gain's hi: within kU of the engine's gain
      double increment_error = d_error;
      if (map.exchange) {
        std::swap(ei, ej);
      } else {
        double& eh = map.heavy_is_i ? ei : ej;
        double& el = map.heavy_is_i ? ej : ei;
        increment_error = (pair.gain * d_error + 2 * kU * std::fabs(increment)) * kSlack + kTinyError;
        eh = (eh + increment_error + kU * std::fabs(map.heavy_is_i ? b_double[p] : b_double[p + 1])) * kSlack +
             kTinyError;
        el = (eh + d_error + kU * std::fabs(map.heavy_is_i ? b_double[p + 1] : b_double[p])) * kSlack + kTinyError;
      }
      const double heavy_after = map.heavy_is_i ? b_double[p] : b_double[p + 1];
      const double light_after = map.heavy_is_i ? b_double[p + 1] : b_double[p];
      const double heavy_error = map.heavy_is_i ? ei : ej, light_error = map.heavy_is_i ? ej : ei;
      eu += rho(pair, dv, vi, vj);
      eb += rho_of(pair, hi_above(heavy_after, heavy_error), hi_above(light_after, light_error),
                   hi_above(increment, increment_error), hi_above(d, d_error)) * kSlack;
      if (!(eu_before * pair.scale <= kGuard * std::fabs(dv.difference.hi) &&
            eb_before * pair.scale <= kGuard * hi_below(d, d_error))) {
        return std::nullopt;  // the engine may adopt a 100-digit state here
      }
      const double magnitude = hi_above(b_double[p], ei) + hi_above(b_double[p + 1], ej) + std::fabs(vi.hi) +
                               std::fabs(vj.hi);
      if (!(magnitude < kRange)) return std::nullopt;
      if (!(hi_above(d, d_error) < time_bound * std::fabs(dv.difference.hi))) return std::nullopt;
    } else {
      double& ei = error[p];
      double& ej = error[p + 1];
      const double difference_error = (ei + ej + kEta * std::fabs(dv.difference.hi)) * kSlack + kTinyError;
      if (!(std::fabs(d) < time_bound * std::fabs(dv.difference.hi))) return std::nullopt;
      if (map.exchange) {  // a swap rounds nothing
        std::swap(ei, ej);
      } else {
        double& eh = map.heavy_is_i ? ei : ej;
        double& el = map.heavy_is_i ? ej : ei;
        const W& heavy = map.heavy_is_i ? vi : vj;
        const W& light = map.heavy_is_i ? vj : vi;
        if (pair.s_h != 0.0) {  // not a wall: the increment g d rounds, and g itself (4 eta covers both)
          const double increment_error =
              (pair.gain * difference_error + 4 * kEta * std::fabs(dv.heavy_increment.hi)) * kSlack + kTinyError;
          eh = (eh + increment_error + kEta * std::fabs(heavy.hi)) * kSlack + kTinyError;
        }
        el = (eh + difference_error + kEta * std::fabs(light.hi)) * kSlack + kTinyError;
      }
      map_intercepts(map, p, d);
      const double magnitude =
          std::fabs(b_double[p]) + std::fabs(b_double[p + 1]) + std::fabs(vi.hi) + std::fabs(vj.hi);
      if (!(magnitude < kRange)) return std::nullopt;
    }
    visit(n + 1, std::array<double, 3>{v[0].hi, v[1].hi, v[2].hi});
  }
  run.certified = true;
  for (int k = 0; k < 3; ++k) {
    run.final_velocities[k] = v[k].hi;
    if (scene.isWall(k)) continue;
    // The replica's: within the engine's mass-weighted bound (tier.h) of the exact one.
    const double bound = kReplica ? eu / sqrt_mass[k] * kSlack : error[k];
    if (!roundsTo(v[k], bound)) {
      if (!kReplica) return std::nullopt;
      run.certified = false;
    }
  }
  run.impact_count = n;
  run.capped = !run.cancelled && count > cap;
  return run;
}

#if defined(__GNUC__)
#define CL_ALWAYS_INLINE __attribute__((always_inline))  // on a lambda: its body inlined where called
#else
#define CL_ALWAYS_INLINE
#endif

/// What the filtered pass found (filteredTriplePass).
enum class FilterVerdict {
  kDecided,      ///< every decision certified in double: the closed form's count holds
  kUndecided,    ///< a decision, the range or the time check needs the double-double passes
  kContradicted  ///< certified in double: the exact run departs from the closed form's count
};

struct FilteredTripleRun {
  FilterVerdict verdict = FilterVerdict::kUndecided;
  /// kDecided: count, capped, cancelled and the double walk's final velocities (not certified).
  ElasticTripleRun run;
};

/// The filtered pass (issue 48): the impacts walked in double, as a lean loop walks them,
/// each velocity carrying a rigorous componentwise bound E_k on its distance from the exact
/// one, and every decision taken from the double values where the bound decides it: impact
/// n's pair approaches (v_j - v_i > 0), and after the last impact neither pair does. A
/// decision the bound does not take (a grazing end, an exact tie), a value out of range, or
/// an impact time that may pass time_limit (the intercepts carry bounds by the same rules)
/// leaves the run kUndecided: the double-double passes take it.
/// Where the bound grows too wide, the walk is re-anchored at the certified state (reanchor).
/// A decision the bound takes against the closed form's count is kContradicted: the engine,
/// whose decisions are exact, runs the scene. The final velocities are the double walk's;
/// runElasticTriple certifies them once, by the product of the impact maps.
///
/// The bound. Each operation of the walk rounds by at most kU = 2u of its result (u = 2^-53;
/// below the normal range, by tiny): for d = v_j - v_i, E_d = E_i + E_j + kU |d|; for the
/// heavy body's increment g d (g within kU of the exact gain G), E_inc = |g| (1 + kU) E_d +
/// 3 kU |g d|; then E_h' = E_h + E_inc + kU |h'| and E_l' = E_h' + E_d + kU |l'| (l' = h' -+ d;
/// a wall's velocity is exact, a swap rounds nothing). The bounds are sums and products of
/// nonnegative doubles, each rounded to nearest, at most 8 roundings per impact deep, so the
/// computed E is at least (1 - u)^(8 n) of the true one: a decision uses kDecisionMargin E,
/// which covers that for n <= 2^40 (a longer run is not filtered). watch(n, v, e) sees the
/// velocities after impact n and their bounds (times kDecisionMargin) [the scene's units].
template <class Watch>
FilteredTripleRun filteredTriplePass(const Scene& scene, std::uint64_t count, std::size_t first_pair,
                                                std::uint64_t cap, double time_limit,
                                                const std::atomic<bool>* cancel, Watch& watch) {
  constexpr double kU = 0x1p-52;
  constexpr double kTiny = 0x1p-1060;  // covers an operation's underflow (2^-1075) several times over
  constexpr double kDecisionMargin = 1.0 + 0x1p-7;
  constexpr double kRange = 0x1p890;  // as the certified pass: far from overflow in any product here
  constexpr std::uint64_t kMaxFiltered = std::uint64_t{1} << 40;
  FilteredTripleRun result;
  const std::uint64_t target = count < cap ? count : cap;
  if (target > kMaxFiltered) return result;
  const double time_bound = time_limit * (1 - 0x1p-20);  // covers the rounding of the check
  struct PairTables {
    ImpactMap<double> map;
    double gain_up;  // |g| (1 + kU), rounded up; 0 for a wall
    bool wall;       // the heavy body is a wall: its velocity is exact
  };
  std::array<PairTables, 2> pairs;
  for (int p = 0; p < 2; ++p) {
    pairs[p].map = makeImpactMap<double>(scene.masses[p], scene.masses[p + 1], 1.0);
    pairs[p].gain_up = std::fabs(pairs[p].map.heavy_gain) * (1 + 0x1p-50);
    pairs[p].wall = scene.isWall(p) || scene.isWall(p + 1);
  }
  std::array<double, 3> v = {scene.velocities[0], scene.velocities[1], scene.velocities[2]};
  std::array<double, 3> b = {scene.positions[0], scene.positions[1], scene.positions[2]};
  std::array<double, 3> e{};  // E_k [the scene's units]; the inputs are exact
  std::array<double, 3> eb{};  // the intercepts' bounds, by the same rules (never re-anchored)
  const auto margin = [](std::array<double, 3> bound) {
    for (double& x : bound) x *= kDecisionMargin;
    return bound;
  };
  // One impact of pair P (0: AB, 1: BC) of kind K (kHeavyI, kHeavyJ, kExchange); false when
  // the run leaves the filter (result says why). The pairs alternate, so the loop below takes
  // them two at a time, every index and kind constant: the state stays in registers.
  enum Kind { kHeavyI, kHeavyJ, kExchange };
  const auto kind_of = [](const ImpactMap<double>& map) {
    return map.exchange ? kExchange : map.heavy_is_i ? kHeavyI : kHeavyJ;
  };
  std::uint64_t n = 0;
  // Where the bound grows too wide to decide (a long run's error is its whole past's), the
  // walk starts again from the certified state after impact n (the product of the impact
  // maps, each velocity within half an ulp of the exact one), at most kMaxAnchors times.
  constexpr int kMaxAnchors = 64;
  int anchors = 0;
  const auto reanchor = [&]() {
    if (anchors == kMaxAnchors) return false;
    ++anchors;
    const std::array<std::optional<double>, 3> exact = certifiedVelocityComponentsAfter(scene, n, first_pair);
    for (int k = 0; k < 3; ++k) {
      if (scene.isWall(k)) continue;  // exact throughout
      if (!exact[k]) return false;
      v[k] = *exact[k];
      e[k] = std::nextafter(std::fabs(v[k]), HUGE_VAL) - std::fabs(v[k]);  // an ulp: twice the rounding
    }
    return true;
  };
  const auto impact = [&](auto pair_index, auto pair_kind) CL_ALWAYS_INLINE {
    constexpr int p = decltype(pair_index)::value;
    constexpr Kind kind = decltype(pair_kind)::value;
    constexpr bool heavy_is_i = kind == kHeavyI;
    const PairTables& pair = pairs[p];
    double& vi = v[p];
    double& vj = v[p + 1];
    double& ei = e[p];
    double& ej = e[p + 1];
    double d = vj - vi;
    double ed = ei + ej + (kU * std::fabs(d) + kTiny);
    if (!(d > kDecisionMargin * ed)) [[unlikely]] {  // the pair may not approach
      if (-d >= kDecisionMargin * ed || !reanchor()) {
        result.verdict = -d >= kDecisionMargin * ed ? FilterVerdict::kContradicted : FilterVerdict::kUndecided;
        return false;
      }
      d = vj - vi;
      ed = ei + ej + (kU * std::fabs(d) + kTiny);
      if (!(d > kDecisionMargin * ed)) {
        result.verdict = -d >= kDecisionMargin * ed ? FilterVerdict::kContradicted : FilterVerdict::kUndecided;
        return false;
      }
    }
    // The impact time, |B_j - B_i| / D, at most (|db| + E_db) / (d - E_d): it may not pass
    // the largest double.
    const double db = b[p + 1] - b[p];
    const double edb = eb[p] + eb[p + 1] + (kU * std::fabs(db) + kTiny);
    if (!(std::fabs(db) + kDecisionMargin * edb < time_bound * (d - kDecisionMargin * ed))) return false;
    if constexpr (kind == kExchange) {
      std::swap(vi, vj);
      std::swap(ei, ej);
      std::swap(b[p], b[p + 1]);
      std::swap(eb[p], eb[p + 1]);
    } else {
      double& h = heavy_is_i ? vi : vj;
      double& l = heavy_is_i ? vj : vi;
      double& eh = heavy_is_i ? ei : ej;
      double& el = heavy_is_i ? ej : ei;
      double& bh = heavy_is_i ? b[p] : b[p + 1];
      double& bl = heavy_is_i ? b[p + 1] : b[p];
      const double gain = pair.map.heavy_gain;  // l' = h' - d when the heavy body is i, h' + d when j
      const double increment = gain * d;
      h += increment;
      l = heavy_is_i ? h - d : h + d;
      if (!pair.wall) eh += pair.gain_up * ed + (3 * kU * std::fabs(increment) + kU * std::fabs(h) + 2 * kTiny);
      el = eh + (ed + (kU * std::fabs(l) + kTiny));
      double& ebh = heavy_is_i ? eb[p] : eb[p + 1];
      double& ebl = heavy_is_i ? eb[p + 1] : eb[p];
      const double intercept_increment = gain * db;
      bh += intercept_increment;
      bl = heavy_is_i ? bh - db : bh + db;
      if (!pair.wall) {
        ebh += pair.gain_up * edb + (3 * kU * std::fabs(intercept_increment) + kU * std::fabs(bh) + 2 * kTiny);
      }
      ebl = ebh + (edb + (kU * std::fabs(bl) + kTiny));
    }
    if (!(std::fabs(b[p]) + std::fabs(b[p + 1]) + std::fabs(vi) + std::fabs(vj) < kRange)) return false;
    ++n;
    watch(n, v, margin(e));
    return true;
  };
  // The cancel flag, read every 1024 impacts (one impact later than the engine reads it when
  // the run starts with BC: n is odd at every check).
  const auto cancelled = [&] {
    if (!cancel || n % 1024 > 1 || !cancel->load(std::memory_order_relaxed)) return false;
    result.run.cancelled = true;
    return true;
  };
  const auto walk = [&](auto kind_ab, auto kind_bc) {
    using AB = std::integral_constant<int, 0>;
    using BC = std::integral_constant<int, 1>;
    bool walking = true;
    if (first_pair == 1 && n < target) walking = impact(BC{}, kind_bc);
    while (walking && n + 2 <= target) {
      if (cancelled()) break;
      walking = impact(AB{}, kind_ab) && impact(BC{}, kind_bc);
    }
    if (walking && n < target && !result.run.cancelled) walking = impact(AB{}, kind_ab);
    return walking;
  };
  // Nine instances of the loop, one per pair of kinds.
  const auto walk_bc = [&](auto kind_ab) {
    switch (kind_of(pairs[1].map)) {
      case kHeavyI: return walk(kind_ab, std::integral_constant<Kind, kHeavyI>{});
      case kHeavyJ: return walk(kind_ab, std::integral_constant<Kind, kHeavyJ>{});
      default: return walk(kind_ab, std::integral_constant<Kind, kExchange>{});
    }
  };
  bool walking = false;
  switch (kind_of(pairs[0].map)) {
    case kHeavyI: walking = walk_bc(std::integral_constant<Kind, kHeavyI>{}); break;
    case kHeavyJ: walking = walk_bc(std::integral_constant<Kind, kHeavyJ>{}); break;
    default: walking = walk_bc(std::integral_constant<Kind, kExchange>{}); break;
  }
  if (!walking) return result;
  if (!result.run.cancelled && n == count) {  // the end: neither pair approaches
    for (int q = 0; q < 2; ++q) {
      for (int attempt = 0; attempt < 2; ++attempt) {
        const double d = v[q + 1] - v[q];
        const double ed = e[q] + e[q + 1] + (kU * std::fabs(d) + kTiny);
        if (-d >= kDecisionMargin * ed) break;
        if (d > kDecisionMargin * ed || attempt == 1 || !reanchor()) {
          result.verdict = d > kDecisionMargin * ed ? FilterVerdict::kContradicted : FilterVerdict::kUndecided;
          return result;
        }
      }
    }
  }
  result.verdict = FilterVerdict::kDecided;
  result.run.impact_count = n;
  result.run.capped = !result.run.cancelled && count > cap;
  result.run.final_velocities = v;
  return result;
}

/// elasticTriplePass, portable: the impact maps and the bounds inline into the loop.
template <ElasticTriplePass kPass, class Visit>
CL_FLATTEN std::optional<ElasticTripleRun> runElasticTriplePass(const Scene& scene, std::uint64_t count,
                                                                std::size_t first_pair, std::uint64_t cap,
                                                                double time_limit,
                                                                const std::atomic<bool>* cancel, Visit& visit) {
  return elasticTriplePass<kPass, DD>(scene, count, first_pair, cap, time_limit, cancel, visit);
}

#if CL_HAS_FMA_PATH
/// elasticTriplePass compiled for FMA (fma_path.h): the same bits, faster products.
template <ElasticTriplePass kPass, class Visit>
CL_FLATTEN CL_FMA_TARGET std::optional<ElasticTripleRun> runElasticTriplePassFma(
    const Scene& scene, std::uint64_t count, std::size_t first_pair, std::uint64_t cap, double time_limit,
    const std::atomic<bool>* cancel, Visit& visit) {
  return elasticTriplePass<kPass, DDFma>(scene, count, first_pair, cap, time_limit, cancel, visit);
}
#endif

/// One pass, on the FMA path where fmaPathEnabled() (the same bits either way).
template <ElasticTriplePass kPass, class Visit>
std::optional<ElasticTripleRun> runElasticTriplePassOnPath(const Scene& scene, std::uint64_t count,
                                                           std::size_t first_pair, std::uint64_t cap,
                                                           double time_limit, const std::atomic<bool>* cancel,
                                                           Visit& visit) {
#if CL_HAS_FMA_PATH
  if (fmaPathEnabled()) {
    return runElasticTriplePassFma<kPass>(scene, count, first_pair, cap, time_limit, cancel, visit);
  }
#endif
  return runElasticTriplePass<kPass>(scene, count, first_pair, cap, time_limit, cancel, visit);
}

/// Which passes runElasticTriple may take.
enum class KnownCountPath {
  kAuto,          ///< filtered where the run is long enough to repay its certificate, else double-double
  kFiltered,      ///< the filtered pass first at any length (tests)
  kDoubleDouble,  ///< the double-double passes only (tests, benchmarks)
};

/// Impacts from which kAuto takes the filtered pass: its certificate of the final state (the
/// product of the impact maps, about 0.1 ms) costs what double-double costs over some 5,000
/// impacts.
constexpr std::uint64_t kFilterFromImpacts = 8192;

/// Runs scene (three bodies, every e = 1, no ring; at most one wall), whose exact count is
/// `count` with first pair `first_pair` (0: AB, 1: BC), up to `cap` impacts, every impact
/// before `time_limit` [the scene's units of time; inf: any] (else it declines); the cancel flag
/// (may be null) is read every 1024 impacts, as the engine does.
/// A long run (KnownCountPath) is first taken by the filtered pass, in double: where it
/// decides every impact, its final velocities are certified by the product of the impact
/// maps, and accept() (called then) keeps it; where the bound contradicts the count, the run
/// declines (the engine decides). Otherwise, as the engine's replica, which stops where the
/// engine's precision guard may fire; then, if it stopped, certified. The final velocities
/// are certified wherever they can be (the header comment): where the replica's are not,
/// they come from certifiedVelocitiesAfter. restart() is called before each pass; after
/// impact n, visit(n, v) sees the velocities rounded to double (the engine's record values
/// in the replica; the double walk's in the filtered pass). Returns nothing when the engine
/// must run it (then visit has seen an unfinished pass). A certified final state is the same
/// whichever pass answers: the correctly rounded one. `end_state` (may be null): the
/// certified velocities after all `count` impacts, which the caller holds (the prediction's:
/// the same exact state, correctly rounded), so that a replica which reaches the count
/// without certifying its own takes them instead of building the product again.
template <class Restart, class Visit, class Accept>
std::optional<ElasticTripleRun> runElasticTriple(const Scene& scene, std::uint64_t count, std::size_t first_pair,
                                                 std::uint64_t cap, double time_limit, const std::atomic<bool>* cancel,
                                                 Restart&& restart, Visit&& visit, Accept&& accept,
                                                 KnownCountPath path = KnownCountPath::kAuto,
                                                 const std::array<double, 3>* end_state = nullptr) {
  // The run's final velocities from the product, where it certifies them (a wall's is exact
  // and keeps the pass's zero sign).
  const auto certify = [&](ElasticTripleRun& run) {
    const auto exact = certifiedVelocitiesAfter(scene, run.impact_count, first_pair);
    if (!exact) return false;
    for (int k = 0; k < 3; ++k) {
      if (!scene.isWall(k)) run.final_velocities[k] = (*exact)[k];
    }
    run.certified = true;
    return true;
  };
  const std::uint64_t target = count < cap ? count : cap;
  if (path == KnownCountPath::kFiltered || (path == KnownCountPath::kAuto && target >= kFilterFromImpacts)) {
    restart();
    auto watch = [&visit](std::uint64_t n, const std::array<double, 3>& v, const std::array<double, 3>&) {
      visit(n, v);
    };
    FilteredTripleRun filtered = filteredTriplePass(scene, count, first_pair, cap, time_limit, cancel, watch);
    if (filtered.verdict == FilterVerdict::kContradicted) return std::nullopt;
    if (filtered.verdict == FilterVerdict::kDecided && certify(filtered.run) && accept()) return filtered.run;
  }
  restart();
  if (auto run = runElasticTriplePassOnPath<ElasticTriplePass::kReplica>(scene, count, first_pair, cap, time_limit,
                                                                         cancel, visit)) {
    if (!run->certified && end_state && run->impact_count == count) {
      for (int k = 0; k < 3; ++k) {
        if (!scene.isWall(k)) run->final_velocities[k] = (*end_state)[k];
      }
      run->certified = true;
    } else if (!run->certified) {
      certify(*run);
    }
    return run;
  }
  restart();
  return runElasticTriplePassOnPath<ElasticTriplePass::kCertified>(scene, count, first_pair, cap, time_limit, cancel,
                                                                   visit);
}

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
