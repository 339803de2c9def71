// One arithmetic tier of the N-body event engine (internal; not installed).
//
// State. Body k moves on the line x = b_k + v_k t between its impacts; the tier keeps the
// intercepts b [m] and velocities v [m/s] in its number type S. An impact of pair p maps
// (b, v) of its two bodies by the same linear impact map (impact_rule.h), so no body ever
// needs a time of its own, and the impact time t_p = (b_p - b_{p+1}) / (v_{p+1} - v_p)
// serves only to order the events.
//
// Error bounds. In mass-weighted coordinates B = sqrt(m) b and U = sqrt(m) v an impact
// applies the same linear map F = I - (1+e) n n^T (norm 1) to B and to U, in the exact
// process and in the computed one alike, as long as both see the same sequence of impacts.
// So the 2-norm of the error vector only grows by each impact's own rounding:
// ||U_computed - U_exact|| <= eu_, ||B_computed - B_exact|| <= eb_, with eu_, eb_ summed
// from a bound on each impact's rounding (rho()). A body's velocity is then off by at most
// eu_ / sqrt(m_k), and a pair's approach speed by eu_ (1/sqrt(m_p) + 1/sqrt(m_{p+1})).
// Walls are exact and take no part. In the exact tier every bound is 0.
//
// Decisions. The events are processed in the canonical order (exact time, then pair
// index). Each pair's leaf in the tournament tree holds a lower bound of its next impact
// time and PairState::upper an upper bound. The root is next when its upper bound is below every
// other lower bound; otherwise the candidates are compared with precise times (S
// arithmetic, tight bounds). What a tier cannot decide it reports as kAmbiguous: the
// caller then replays the run in a more precise tier and adopts that tier's state.
#pragma once

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "../correct_rounding.h"
#include "arithmetic.h"
#include "fma_path.h"
#include "group_collapse.h"
#include "spiral.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/impact_rule.h"
#include "collision_lab/core/nbody/scene.h"
#include "tournament_tree.h"
#include "viscoelastic.h"

namespace collision_lab {
namespace core {
namespace nbody_detail {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kUnit = 0x1p-53;           // unit roundoff of double
constexpr double kSlack = 1.0 + 0x1p-40;    // covers the rounding of evaluating a bound in double
constexpr double kTiny = 0x1p-1000;         // covers underflow in double-double, per operation
constexpr double kMaxMagnitude = 0x1p900;   // beyond this the engine stops: out of range
constexpr double kTimePrecision = 0x1p-42;  // relative precision of the published impact times

/// What does not change during a run, shared by the tiers (doubles, exact inputs).
struct SceneTables {
  explicit SceneTables(const Scene& scene);
  const Scene& scene;
  std::size_t pairs = 0;
  std::vector<double> sqrt_mass;      ///< sqrt(m) [kg^0.5]; 0 for a wall (it carries no error)
  std::vector<double> inv_sqrt_mass;  ///< 1 / sqrt(m) [kg^-0.5]; 0 for a wall
  std::vector<double> loss_factor;    ///< (1 - e^2) mu / 2 per pair [kg]
  std::vector<double> restitution;    ///< e per pair [1] (scene.restitutionOf, looked up once)
  /// Circumference of a ring [m] (0: none). Pair p's left body is scene.leftOf(p); across
  /// the seam (pair N-1) it is body 0 seen at x - L, so its gap gains L.
  double ring = 0.0;
};

/// kAmbiguous: a decision this tier cannot take; kImprecise: its state no longer pins down
/// the time of the impact it was about to perform (the precision guard); kExhausted: the
/// exact tier's numbers outgrew kExactBits (an accumulation of impacts not resolved);
/// kOverBudget: its replay outgrew the exactness budget; kCancelled: the cancel flag was seen inside
/// a higher tier's work. The last three leave the working tier at its last certified impact.
enum class StepKind : std::uint8_t {
  kImpact, kFinished, kMultipleCollision, kAmbiguous, kImprecise, kOutOfRange, kInconsistent, kExhausted,
  kOverBudget, kCancelled
};

/// The exactness cap. Impacts that accumulate towards an unrecognised collapse need the
/// exact tier for every step, with rationals that grow by some bits per impact, so each step
/// costs more than the last. When kExactStreak impacts in a row needed the exact tier and
/// its last one left a denominator above kExactBits, the run stops (truncated). Isolated
/// exact steps of a long run (exact ties) and runs of small exact ties never meet both.
constexpr unsigned kExactBits = 2048;
constexpr std::uint64_t kExactStreak = 256;

/// The exactness budget (EngineOptions::exact_work_budget, 10^11 bit^2 by default: the proof
/// of a four-body group collapse needs more than 10^10): the bound on the work of one exact
/// decision. A rational's size grows with the impacts in its causal past (each adds the bits
/// of a mass sum), so the exact tier's replay up to a decision deep into a long run with
/// double inputs (a crowding cluster in a gas) costs more with every impact, without bound.
/// The cost of a replay is counted as the sum over its impacts of the squared bits of the
/// largest denominator the impact leaves (the work of one rational operation grows about
/// so); a decision whose replay would exceed the budget is not taken: the run stops at its
/// last certified impact (StopReason::kPrecisionBudget). The exact tier's own runs of steps
/// are bounded by the exactness cap above; together, each decision costs at most a constant.

/// The predicted budget. The work of an accumulation's exact steps grows with every impact,
/// so a replay, or a run of exact steps towards the exactness cap, that is heading past
/// the budget is seen long before it gets there: its work so far plus the impacts
/// still due (to the replay's target; to kExactStreak in a row) at the mean work of its last
/// kWorkWindow impacts. When that exceeds the budget, the run stops at once, at its last
/// certified impact, having spent a fraction of it: a replay where the spent budget would
/// have stopped it (the same impacts; earlier only where an accumulation's numbers shrink
/// again); a run of exact steps before the exactness cap, which it would have reached some
/// impacts later. Either way the impacts are a prefix of the longer run's. The forecast
/// counts work (squared bits), never time, so the stop is the same on every machine.
constexpr std::size_t kWorkWindow = 32;

/// Work counted impact by impact [bit^2], with the forecast above.
class WorkForecast {
 public:
  void add(double work) {
    total_ += work;
    window_[added_ % kWorkWindow] = work;
    ++added_;
  }
  double total() const { return total_; }
  /// Forgets all work; nothing to do (no 272-byte fill on every impact) when none was added.
  void clear() {
    if (added_ != 0) *this = WorkForecast{};
  }
  /// The work so far plus `remaining` impacts at the mean of the last kWorkWindow (the work
  /// so far until that many were counted).
  double predicted(std::uint64_t remaining) const {
    if (added_ < kWorkWindow) return total_;
    double recent = 0.0;
    for (double w : window_) recent += w;
    return total_ + static_cast<double>(remaining) * (recent / static_cast<double>(kWorkWindow));
  }

 private:
  std::array<double, kWorkWindow> window_{};
  double total_ = 0.0;
  std::uint64_t added_ = 0;
};

/// 16 bytes, so that it is returned in registers: every step passes one up through several
/// calls, and a larger one goes through the stack, where its copies stall on store forwarding.
struct StepResult {
  StepResult() = default;
  StepResult(StepKind k, std::size_t p = 0, double t = 0.0, bool zero = false)
      : time(t), pair(static_cast<std::uint32_t>(p)), kind(k), at_zero(zero) {}
  /// Of a multiple collision [s]; of kOutOfRange, a lower bound of the next impact's time
  /// [s] (0 when none is known).
  double time = 0.0;
  std::uint32_t pair = 0;  ///< the impact's pair, or the lower pair of a multiple collision (< 2^32, as the tree's leaves)
  StepKind kind = StepKind::kImpact;
  bool at_zero = false;  ///< kAmbiguous on a value exactly 0 at this precision: likely an exact tie
};
static_assert(sizeof(StepResult) == 16, "returned in registers");

/// TC: bounds [s] of the time of a body's last impact (-inf: none yet); shared by the tiers.
struct Clock {
  double lo = -kInf, hi = -kInf;
};

/// Hidden: the tiers are internal to the library, so their calls bind directly (no PLT)
/// and stay open to the inliner.
template <class S>
class CL_NBODY_INTERNAL Tier {
 public:
  using Ar = Arithmetic<S>;

  explicit Tier(const SceneTables& tables) : tables_(tables), tree_(tables.pairs) {
    const Scene& scene = tables.scene;
    for (std::size_t k = 0; k < scene.size(); ++k) {
      bodies_.push_back({S(scene.positions[k]), S(scene.velocities[k])});
    }
    const RestitutionModelKind model = scene.restitution_model.kind;
    for (std::size_t p = 0; p < tables.pairs; ++p) {
      const std::size_t j = left(p);
      PairState pair;
      pair.map = makeImpactMap<S>(scene.masses[p], scene.masses[j], scene.restitutionOf(p));
      pair.scale = tables.inv_sqrt_mass[p] + tables.inv_sqrt_mass[j];
      pair.sqrt_heavy = tables.sqrt_mass[pair.map.heavy_is_i ? p : j];
      pair.sqrt_light = tables.sqrt_mass[pair.map.heavy_is_i ? j : p];
      pairs_.push_back(pair);
      if (model == RestitutionModelKind::kTc || model == RestitutionModelKind::kThreshold) {
        elastic_maps_.push_back(makeImpactMap<S>(scene.masses[p], scene.masses[j], 1.0));
      }
    }
    bonded_.assign(tables.pairs, 0);
    if (model == RestitutionModelKind::kTc) {
      clocks_.assign(scene.size(), Clock{});
      if constexpr (Ar::kExact) last_exact_.assign(scene.size(), S(0));
    }
  }

  /// Schedules every pair from the initial state.
  StepResult start() {
    for (std::size_t p = 0; p < tables_.pairs; ++p) {
      const StepResult r = schedule(p);
      if (r.kind != StepKind::kImpact) return r;
    }
    tree_.rebuild();
    return {};
  }

  bool pending() const { return tree_.minKey() < kInf; }
  /// The exact tier only: from now on its numbers have no range. Impacts past the tiers'
  /// range (kMaxMagnitude, whose times lie beyond the largest double) are ordered by their
  /// exact times and performed, where the other tiers stop out of range.
  /// Every pair is scheduled anew from the state (the same as start()).
  StepResult allowAnyMagnitude() {
    static_assert(Ar::kExact, "only exact numbers have no range");
    unbounded_ = true;
    return start();
  }
  /// A lower bound of the next impact's time [s] (inf: none is due).
  double nextTimeLowerBound() const { return tree_.minKey(); }
  std::uint64_t count() const { return count_; }
  std::uint64_t refinements() const { return refinements_; }
  std::uint64_t clusterImpacts() const { return cluster_impacts_; }
  std::uint64_t ruleElastic() const { return rule_elastic_; }
  std::size_t merged() const { return merged_; }
  double energyLost() const { return lost_ + lost_compensation_; }
  /// Time of the last impact [s], or of the one in progress (0 before the first).
  double lastTime() const { return Ar::sign(now_.A) > 0 ? Ar::toDouble(S(now_.G / now_.A)) : 0.0; }

  /// The time of the last impact [s] correctly rounded, where this tier's bound decides it
  /// (rounded once in the exact tier); 0 before the first; empty otherwise.
  std::optional<double> certifiedLastTime() const {
    if (!(Ar::sign(now_.A) > 0)) return 0.0;
    const Precise t = preciseNow();
    if (!t.ok) return std::nullopt;
    ImpactRecord scratch;
    const double value = publish(t.value, t.error, kImpactTime, scratch);
    if (scratch.uncertified != 0) return std::nullopt;
    return value;
  }

  /// Finds and performs the next impact (or reports why not). `record` may be null.
  StepResult step(ImpactRecord* record) {
    std::size_t next = tree_.minLeaf();
    if (!(tree_.minKey() < kInf)) return {StepKind::kFinished, 0, lastTime()};
    if (parked(next) && !unbounded_) return {StepKind::kOutOfRange, next, tree_.minKey()};  // may come at 2^900 or later
    if (parked(next) || !(pairs_[next].upper < tree_.minKeyExcluding(next))) {
      const StepResult r = resolveNext(next);
      if (r.kind != StepKind::kImpact) return r;
      next = r.pair;
    }
    return impact(next, record);
  }
  /// step() with every call it makes inlined into one function: the working tier's hot loop.
  CL_FLATTEN StepResult stepInlined(ImpactRecord* record) { return step(record); }
#if CL_HAS_FMA_PATH
  /// stepInlined() compiled for FMA (fma_path.h); only the FMA path's tier (DDFma) calls it.
  CL_FLATTEN CL_FMA_TARGET StepResult stepInlinedFma(ImpactRecord* record) { return step(record); }
#endif

  /// Takes over the state of a more precise tier at the same impact count.
  template <class From>
  void adopt(const Tier<From>& from) {
    constexpr double conversion = conversionError<S>();
    eu_ = from.eu_;
    eb_ = from.eb_;
    for (std::size_t k = 0; k < bodies_.size(); ++k) {
      BodyState& body = bodies_[k];
      body.b = convertTo<S>(from.bodies_[k].b);
      body.v = convertTo<S>(from.bodies_[k].v);
      eu_ += 2 * conversion * tables_.sqrt_mass[k] * std::fabs(Ar::toDouble(body.v));
      eb_ += 2 * conversion * tables_.sqrt_mass[k] * std::fabs(Ar::toDouble(body.b));
    }
    tree_ = from.tree_;
    for (std::size_t p = 0; p < pairs_.size(); ++p) pairs_[p].upper = from.pairs_[p].upper;
    count_ = from.count_;
    bonded_ = from.bonded_;
    cluster_impacts_ = from.cluster_impacts_;
    rule_elastic_ = from.rule_elastic_;
    clocks_ = from.clocks_;  // a less precise tier needs only their bounds
    merged_ = from.merged_;
    lost_ = from.lost_;
    lost_compensation_ = from.lost_compensation_;
    now_.pair = from.now_.pair;
    now_.G = convertTo<S>(from.now_.G);
    now_.A = convertTo<S>(from.now_.A);
    now_.eb = from.now_.eb;
    now_.eu = from.now_.eu;
    // The conversion of G and A; the other tier's rounding of them is below this tier's,
    // which preciseNow() counts.
    now_.extra = from.now_.extra + 2 * conversion * (std::fabs(Ar::toDouble(now_.G)) + std::fabs(Ar::toDouble(now_.A)));
    now_.upper = from.now_.upper;
  }

  /// Performs, in this tier's arithmetic, the impact of pair m that a more precise tier at
  /// the same count has just taken, and takes that tier's schedules of the three pairs it
  /// changed (bounds on exact times, whoever computed them): O(1), where adopt() is O(N).
  /// Returns false, changing nothing, when this tier's state cannot pin down the impact's
  /// time; adopt() then refreshes it.
  template <class From>
  bool follow(const Tier<From>& from, std::size_t m) {
    saveFor(m);
    if (collide(m, nullptr).kind != StepKind::kImpact) {
      restore(m);
      return false;
    }
    if (tables_.ring != 0.0) {  // no clusters on a ring (validate: every e > 0)
      for (std::size_t q : ringNeighbours(m)) setSchedule(q, from.tree_.key(q), from.pairs_[q].upper);
      updateRing(m);
      ++count_;
      return true;
    }
    const std::size_t lo = clusterLow(m), hi = clusterHigh(m + 1);
    const std::size_t first = lo > 0 ? lo - 1 : lo, last = std::min(hi, pairs_.size() - 1);
    for (std::size_t q = first; q <= last; ++q) setSchedule(q, from.tree_.key(q), from.pairs_[q].upper);
    tree_.update(first, last);
    ++count_;
    return true;
  }

  /// A resolved collapse: bodies first..last meet at `position` [m] at `time` [s].
  struct CollapseFound {
    std::size_t first = 0, last = 0;
    double time = 0.0, position = 0.0;
  };

  /// The bounds of the approach speeds of pairs p and q are within 2^-30 of their size: tight
  /// enough for collapseCandidate()'s tests. Double-double misses it where the masses span
  /// more than about 2^60: its error bound, in the energy norm, is of the heavy bodies' scale.
  bool pinsApproaches(std::size_t p, std::size_t q) const {
    const Approx a = approach(p), c = approach(q);
    return a.error + c.error <= 0x1p-30 * (std::fabs(a.value) + std::fabs(c.value));
  }

  /// Pairs p < q alternate with a cluster between them: do the three clusters collapse
  /// (spiral.h, dominates() or, next to r_c, ConeTest: every later check provably stays
  /// positive), and does nothing outside reach them before the collapse time? `q_next`: q hits next (else p). e < 1 on
  /// both pairs; an outer cluster may hold a wall (a body squeezed against it), not both
  /// and not the middle one. Conservative: "no" just lets the run go on.
  std::optional<CollapseFound> collapseCandidate(std::size_t p, std::size_t q, bool q_next) const {
    const Scene& scene = tables_.scene;
    const std::size_t lo = clusterLow(p), hi = clusterHigh(q + 1);
    if (clusterHigh(p + 1) != q || scene.restitutionOf(p) == 1.0 || scene.restitutionOf(q) == 1.0) return {};
    spiral_detail::Cycle cycle{{0.0, 0.0, 0.0}, scene.restitutionOf(p), scene.restitutionOf(q)};
    for (std::size_t k = lo; k <= hi; ++k) {
      const int part = k <= p ? 0 : (k <= q ? 1 : 2);
      if (!scene.isWall(k)) {
        cycle.m[part] += scene.masses[k];
      } else if (part == 1) {
        return {};
      } else {
        (part == 0 ? cycle.wall_a : cycle.wall_c) = true;
      }
    }
    if (cycle.wall_a && cycle.wall_c) return {};
    if (!pinsApproaches(p, q)) return {};
    const Approx a = approach(p), c = approach(q);
    const int pair = q_next ? 1 : 0;  // next to r_c, dominance may take ever more cycles: the exact test
    if (!spiral_detail::dominates(cycle, pair, a.value, c.value) &&
        !(spiral_detail::nearDoubleEigenvalue(cycle) &&
          spiral_detail::ConeTest(cycle).boxStaysInCone(pair, a.value, a.error, c.value, c.error))) {
      return {};
    }
    using spiral_detail::Rational;
    const auto exact = [](const S& x) {  // the tier's value as a rational (to within its bound)
      if constexpr (kIsDoubleDouble<S>) return Rational(x.hi) + Rational(x.lo);
      else if constexpr (std::is_same_v<S, Rational>) return x;
      else return Rational(Float100(x));
    };
    const Rational dv[2] = {exact(S(bodies_[p + 1].v - bodies_[p].v)), exact(S(bodies_[q + 1].v - bodies_[q].v))};
    const Rational db[2] = {exact(S(bodies_[p + 1].b - bodies_[p].b)), exact(S(bodies_[q + 1].b - bodies_[q].b))};
    CollapseFound found{lo, hi, spiral_detail::collapseTime(cycle, q_next ? 1 : 0, dv, db), 0.0};
    const double now = lastTime();
    if (!(found.time >= now) || !clearOfNeighbours(lo, hi, now, found.time)) return {};
    const Line line = limitLine(lo, hi);
    found.position = (line.intercept + line.velocity * found.time) / line.mass;
    return found;
  }

  /// A group whose impacts repeat `pattern` (pair indices, the next impact's first) over
  /// three or more units: does it collapse (group_collapse.h, proved in exact rationals),
  /// and does nothing outside reach it before? The exact tier only (others: no).
  std::optional<CollapseFound> groupCollapseCandidate(const std::vector<std::size_t>& pattern) const {
    if constexpr (!Ar::kExact) {
      return {};
    } else {
      const Scene& scene = tables_.scene;
      const auto [low, high] = std::minmax_element(pattern.begin(), pattern.end());
      const std::size_t lo = clusterLow(*low), hi = clusterHigh(*high + 1);
      std::vector<std::size_t> pairs;  // the group's pairs between units (global)
      for (std::size_t p = lo; p < hi; ++p) {
        if (!bonded_[p]) pairs.push_back(p);
      }
      if (pairs.size() < 3 || (scene.isWall(lo) && scene.isWall(hi))) return {};
      const auto unitMass = [&](std::size_t body, bool& wall) {
        Rational m = 0;
        wall = false;
        for (std::size_t k = clusterLow(body); k <= clusterHigh(body); ++k) {
          if (scene.isWall(k)) wall = true;
          else m += Rational(scene.masses[k]);
        }
        return m;
      };
      group_detail::GroupMaps maps;
      group_detail::Vec c, d;
      for (std::size_t p : pairs) {
        bool wall_l = false, wall_r = false;
        const Rational ml = unitMass(p, wall_l), mr = unitMass(p + 1, wall_r);
        const Rational e = Rational(scene.restitutionOf(p));
        maps.e.push_back(e);
        const Rational k = 1 + e;
        maps.share_down.push_back(wall_l ? Rational(0) : (wall_r ? k : Rational(k * mr / (ml + mr))));
        maps.share_up.push_back(wall_r ? Rational(0) : (wall_l ? k : Rational(k * ml / (ml + mr))));
        c.push_back(bodies_[p + 1].b - bodies_[p].b);
        d.push_back(bodies_[p + 1].v - bodies_[p].v);
      }
      std::vector<std::size_t> local;
      for (std::size_t p : pattern) {
        const auto it = std::find(pairs.begin(), pairs.end(), p);
        if (it == pairs.end()) return {};
        local.push_back(static_cast<std::size_t>(it - pairs.begin()));
      }
      const std::optional<double> time = group_detail::proveCollapse(maps, local, c, d);
      const double now = lastTime();
      if (!time || !(*time >= now) || !clearOfNeighbours(lo, hi, now, *time)) return {};
      const Line line = limitLine(lo, hi);
      return CollapseFound{lo, hi, *time, (line.intercept + line.velocity * *time) / line.mass};
    }
  }

  /// Bodies lo..hi become one cluster on their limit line (limitLine()): the centre of mass,
  /// b and v projected onto the mass-weighted mean (an orthogonal projection in mass-weighted
  /// coordinates, so the error bounds only gain the rounding); or, with a wall in the group,
  /// the wall's line (exact: the bounds stay). The heat of the remaining impacts, the group's
  /// kinetic energy about that line, is added to the loss.
  StepResult merge(std::size_t lo, std::size_t hi) {
    const Scene& scene = tables_.scene;
    const std::optional<std::size_t> wall = wallIn(lo, hi);
    S v = bodies_[wall.value_or(lo)].v, b = bodies_[wall.value_or(lo)].b;
    if (!wall) {
      S mass = S(0), momentum = S(0), intercept = S(0);
      for (std::size_t k = lo; k <= hi; ++k) {
        mass = mass + S(scene.masses[k]);
        momentum = momentum + S(scene.masses[k]) * bodies_[k].v;
        intercept = intercept + S(scene.masses[k]) * bodies_[k].b;
      }
      v = momentum / mass, b = intercept / mass;
    }
    double heat = 0.0, sqrt_mass = 0.0;
    for (std::size_t k = lo; k <= hi; ++k) {
      if (!scene.isWall(k)) {
        const double dv = Ar::toDouble(S(bodies_[k].v - v));
        heat += 0.5 * scene.masses[k] * dv * dv;
      }
      sqrt_mass += tables_.sqrt_mass[k];
      bodies_[k] = {b, v};
    }
    addLoss(heat);
    if constexpr (!Ar::kExact) {  // the exact tier's bounds stay 0: it must decide every tie
      if (!wall) {
        const double ops = 4.0 * static_cast<double>(hi - lo + 3) * Ar::kOpError * sqrt_mass;
        eu_ += ops * std::fabs(Ar::toDouble(v)) + kTiny;
        eb_ += ops * std::fabs(Ar::toDouble(b)) + kTiny;
      }
    }
    for (std::size_t k = lo; k < hi; ++k) bonded_[k] = 1, setSchedule(k, kInf, kInf);
    for (std::size_t r : {lo, hi + 1}) {
      if (r == 0 || r > pairs_.size()) continue;
      const StepResult res = schedule(r - 1);
      if (res.kind != StepKind::kImpact) return res;
    }
    tree_.update(lo > 0 ? lo - 1 : lo, std::min(hi, pairs_.size() - 1));
    ++merged_;
    return {};
  }

  /// The exact tier's last impact left a denominator above kExactBits (false in other tiers).
  bool oversized() const {
    if constexpr (std::is_same_v<S, Rational>) {
      if (count_ == 0) return false;
      for (std::size_t k : {now_.pair, left(now_.pair)}) {
        for (const S* x : {&bodies_[k].b, &bodies_[k].v}) {
          if (boost::multiprecision::msb(denominator(*x)) > kExactBits) return true;
        }
      }
    }
    return false;
  }

  /// Bits of the largest denominator that the last impact left in this tier's state (its
  /// two bodies; a cluster's members share their values): O(1). 0 in the inexact tiers.
  unsigned exactBits() const {
    unsigned bits = 0;
    if constexpr (std::is_same_v<S, Rational>) {
      if (count_ == 0) return 0;
      for (std::size_t k : {now_.pair, left(now_.pair)}) {  // across a ring's seam: body 0
        for (const S* x : {&bodies_[k].b, &bodies_[k].v}) {
          bits = std::max(bits, static_cast<unsigned>(boost::multiprecision::msb(denominator(*x))));
        }
      }
    }
    return bits;
  }

  /// Velocity of body k [m/s], rounded to double.
  double velocity(std::size_t k) const { return Ar::toDouble(bodies_[k].v); }

  /// Velocity of body k [m/s] in this tier's number type (exact in the exact tier).
  const S& velocityValue(std::size_t k) const { return bodies_[k].v; }

  /// Velocity of body k [m/s] correctly rounded, when every value within this tier's bound of
  /// it (eu_ / sqrt(m_k), widened by the rounding of forming the ends) rounds to the same
  /// normal double; a wall's, which never changes, always. Empty otherwise, and in the exact
  /// tier (whose caller rounds the exact value).
  std::optional<double> certifiedVelocity(std::size_t k) const {
    if (tables_.scene.isWall(k)) return velocity(k);
    if constexpr (Ar::kExact) {
      return std::nullopt;
    } else {
      const S& v = bodies_[k].v;
      const double bound = velocityBound(k);
      const double low = Ar::toDouble(S(v - S(bound))), high = Ar::toDouble(S(v + S(bound)));
      if (low != high || !(std::fabs(low) >= std::numeric_limits<double>::min())) return std::nullopt;
      return low;
    }
  }

  /// A bound on |velocityValue(k) - the exact velocity of body k| [m/s] (finite k; 0 in the
  /// exact tier), widened by the rounding of using it.
  double velocityBound(std::size_t k) const {
    if constexpr (Ar::kExact) return 0.0;
    const double size = std::fabs(Ar::toDouble(bodies_[k].v));
    return (eu_ / tables_.sqrt_mass[k] + 4 * Ar::kOpError * size) * kSlack + kTiny;
  }

  /// Positions [m] at time t [s] and velocities [m/s], rounded to double.
  void state(double t, std::vector<double>& positions, std::vector<double>& velocities) const {
    positions.resize(bodies_.size());
    velocities.resize(bodies_.size());
    for (std::size_t k = 0; k < bodies_.size(); ++k) {
      velocities[k] = Ar::toDouble(bodies_[k].v);
      positions[k] = wrap(Ar::toDouble(S(bodies_[k].b + S(bodies_[k].v * S(t)))));
    }
  }
  /// The exact tier only: the state at the exact time of the last impact (0 before the
  /// first), each value rounded once [working units] (no ring: its wrap is not applied).
  void stateAtLastImpact(std::vector<double>& positions, std::vector<double>& velocities) const {
    static_assert(Ar::kExact, "the exact time of the last impact is the exact tier's");
    const S t = Ar::sign(now_.A) > 0 ? S(now_.G / now_.A) : S(0);
    positions.resize(bodies_.size());
    velocities.resize(bodies_.size());
    for (std::size_t k = 0; k < bodies_.size(); ++k) {
      velocities[k] = detail::nearestDouble(bodies_[k].v);
      positions[k] = detail::nearestDouble(S(bodies_[k].b + bodies_[k].v * t));
    }
  }

 private:
  template <class>
  friend class Tier;

  /// Body k is at b + v t [m] at time t [s], between its impacts.
  struct BodyState {
    S b;  ///< intercept [m]
    S v;  ///< velocity [m/s]
  };
  /// What an impact needs of pair p (bodies p, p+1), in one cache line for double-double.
  struct alignas(64) PairState {
    ImpactMap<S> map;
    double upper = kInf;      ///< upper bound of the next impact time [s]
    double scale = 0.0;       ///< 1/sqrt(m_p) + 1/sqrt(m_p+1) [kg^-0.5], a wall counting 0
    double sqrt_heavy = 0.0;  ///< sqrt of the heavier mass [kg^0.5], 0 for a wall
    double sqrt_light = 0.0;  ///< sqrt of the lighter mass [kg^0.5]
  };

  /// kUnknownAtZero: undecided, and the value is exactly 0 at this precision, which in
  /// practice means an exact tie (equal velocities or times from structured inputs).
  enum class Decision { kYes, kNo, kUnknown, kUnknownAtZero };
  enum class Order { kLess, kEqual, kGreater, kUnknown, kUnknownAtZero };

  /// A double approximation of an exact-process quantity and a bound on its error.
  struct Approx {
    double value;
    double error;
  };
  /// A time in S and a bound on its distance to the exact time [s].
  struct Precise {
    S value;
    double error;
    bool ok;
  };
  /// The last impact: its gap G = b_p - b_{p+1} and approach speed A before it, with
  /// bounds (so its precise time can be formed later), and the upper bound of its time.
  struct Now {
    std::size_t pair = 0;
    S G{}, A{};
    double eb = 0.0, eu = 0.0;  ///< the state's bounds before the impact
    double extra = 0.0;         ///< what adoption added to the bounds of G and A
    double upper = 0.0;         ///< [s]
  };

  /// What an impact changes besides the tree (a failed step leaves the tree to be rebuilt by adopt()).
  /// One record per tier, reused (impact() and follow() never nest): a fresh one per impact,
  /// zero-filled and destroyed, cost about a tenth of an impact.
  struct Undo {
    BodyState i, j;
    double eu, eb, lost, lost_compensation;
    Now now;
    char bonded;
    std::uint64_t cluster_impacts;
    std::uint64_t rule_elastic;
    Clock clock_i, clock_j;  ///< TC only
    S exact_i, exact_j;      ///< TC in the exact tier only
    std::size_t lo;
    std::vector<BodyState> cluster;  ///< bodies lo..hi, only when a cluster takes part
  };

  double pairScale(std::size_t p) const { return pairs_[p].scale; }

  /// The left body of pair p: p + 1, or body 0 across a ring's seam.
  std::size_t left(std::size_t p) const { return p + 1 == bodies_.size() ? 0 : p + 1; }
  /// L [m] for the seam pair of a ring (its left body is seen at x - L), else 0.
  double offset(std::size_t p) const { return p + 1 == bodies_.size() ? tables_.ring : 0.0; }
  /// A position [m] on a ring brought into [0, L); unchanged without a ring.
  double wrap(double x) const {
    const double length = tables_.ring;
    if (length == 0.0) return x;
    const double y = x - length * std::floor(x / length);
    return y >= length || y < 0.0 ? 0.0 : y;
  }
  /// Pairs whose schedule an impact of pair m changes on a ring: m - 1, m, m + 1 (cyclic).
  std::array<std::size_t, 3> ringNeighbours(std::size_t m) const {
    const std::size_t n = pairs_.size();
    return {(m + n - 1) % n, m, (m + 1) % n};
  }
  void updateRing(std::size_t m) {
    if (m > 0 && m + 1 < pairs_.size()) return tree_.update(m - 1, m + 1);  // no wrap: one climb, as on a line
    for (std::size_t q : ringNeighbours(m)) tree_.update(q, q);
  }

  /// The line bodies lo..hi end on after their collapse, in double: the centre of mass
  /// (intercept / mass [m], velocity / mass [m/s] with mass [kg] the group's), or with a
  /// wall among them the wall's line (mass 1). The energy about it never grows: impacts
  /// inside the group lose energy in every frame, and against the wall in the wall's frame.
  struct Line {
    double mass = 0.0, intercept = 0.0, velocity = 0.0;
  };
  Line limitLine(std::size_t lo, std::size_t hi) const {
    if (const std::optional<std::size_t> wall = wallIn(lo, hi)) {
      return {1.0, Ar::toDouble(bodies_[*wall].b), Ar::toDouble(bodies_[*wall].v)};
    }
    Line line;
    for (std::size_t k = lo; k <= hi; ++k) {
      const double m = tables_.scene.masses[k];
      line.mass += m, line.intercept += m * Ar::toDouble(bodies_[k].b), line.velocity += m * Ar::toDouble(bodies_[k].v);
    }
    return line;
  }
  /// A wall among bodies lo..hi, if any.
  std::optional<std::size_t> wallIn(std::size_t lo, std::size_t hi) const {
    for (std::size_t k = lo; k <= hi; ++k) {
      if (tables_.scene.isWall(k)) return k;
    }
    return std::nullopt;
  }

  /// Nothing outside bodies lo..hi can reach them in [now, until]: the group stays within
  /// its extent at `now` widened by the fastest speed its energy about its limit line allows,
  /// the outer neighbours move freely (their other pairs have no impact before `until`).
  bool clearOfNeighbours(std::size_t lo, std::size_t hi, double now, double until) const {
    const Scene& scene = tables_.scene;
    const Line line = limitLine(lo, hi);
    const double centre = line.velocity / line.mass;
    double heat = 0.0, lightest = kInf;
    for (std::size_t k = lo; k <= hi; ++k) {
      if (scene.isWall(k)) continue;
      const double dv = Ar::toDouble(bodies_[k].v) - centre;
      heat += 0.5 * scene.masses[k] * dv * dv;
      lightest = std::min(lightest, scene.masses[k]);
    }
    const double spread = std::sqrt(2 * heat / lightest) * (1 + 0x1p-20), span = until - now;
    const auto at = [&](std::size_t k) { return Ar::toDouble(S(bodies_[k].b + S(bodies_[k].v * S(now)))); };
    const auto slack = [&](double x, double y, double v) {
      return 0x1p-30 * (std::fabs(x) + std::fabs(y) + span * (std::fabs(v) + std::fabs(centre) + spread));
    };
    if (lo > 0) {
      const std::size_t far = clusterLow(lo - 1);  // the neighbour may be a cluster
      if (far > 0 && !(tree_.key(far - 1) > until)) return false;
      const double x = at(lo - 1), v = Ar::toDouble(bodies_[lo - 1].v), y = at(lo);
      if (!(x + std::min(0.0, v) * span - (y + std::max(0.0, centre + spread) * span) > slack(x, y, v))) return false;
    }
    if (hi + 1 < bodies_.size()) {
      const std::size_t far = clusterHigh(hi + 1);
      if (far < pairs_.size() && !(tree_.key(far) > until)) return false;
      const double x = at(hi + 1), v = Ar::toDouble(bodies_[hi + 1].v), y = at(hi);
      if (!((y + std::min(0.0, centre - spread) * span) - (x + std::max(0.0, v) * span) > slack(x, y, v))) return false;
    }
    return true;
  }

  /// x - y as a double, with a bound on its distance to the exact difference of x and y.
  static Approx approxDifference(const S& x, const S& y) {
    if constexpr (kIsDoubleDouble<S>) {
      const double value = (x.hi - y.hi) + (x.lo - y.lo);
      return {value, 2.01 * kUnit * std::fabs(value) + 3 * kUnit * kUnit * (std::fabs(x.hi) + std::fabs(y.hi)) + kTiny};
    } else {
      const double value = Ar::toDouble(S(x - y));
      // kTiny: a difference that underflows in double must not read as exactly 0.
      return {value, 1.01 * (Ar::kOpError + Ar::kToDoubleError) * std::fabs(value) + kTiny};
    }
  }

  /// Approach speed v_{p+1} - v_p [m/s] in double, its error bound including the state's.
  Approx approach(std::size_t p) const {
    Approx a = approxDifference(bodies_[left(p)].v, bodies_[p].v);
    a.error = (a.error + eu_ * pairScale(p)) * kSlack;
    return a;
  }
  /// Gap at t = 0 of the two lines, G = b_p - b_{p+1} [m], likewise.
  Approx gap(std::size_t p) const {
    Approx g = approxDifference(bodies_[p].b, bodies_[left(p)].b);
    if (const double length = offset(p); length != 0.0) {  // the seam: G + L, rounded once more
      g.value += length;
      g.error += 2 * kUnit * std::fabs(g.value) + 2.02 * Ar::kOpError * (std::fabs(g.value) + length);
    }
    g.error = (g.error + eb_ * pairScale(p)) * kSlack;
    return g;
  }

  /// Sign decision on an S value known to within `error` of the exact one.
  static Decision positive(const S& value, double error) {
    if (Ar::sign(S(value - S(error))) > 0) return Decision::kYes;
    if (Ar::sign(S(value + S(error))) <= 0) return Decision::kNo;
    return Ar::sign(value) == 0 ? Decision::kUnknownAtZero : Decision::kUnknown;
  }

  /// Does pair p approach? `a` is approach(p).
  Decision decideApproach(std::size_t p, const Approx& a) {
    if (a.value - a.error > 0) return Decision::kYes;
    if (a.value + a.error <= 0) return Decision::kNo;
    ++refinements_;
    const S precise = bodies_[left(p)].v - bodies_[p].v;
    const double error = (eu_ * pairScale(p) + 1.01 * Ar::kOpError * std::fabs(Ar::toDouble(precise))) * kSlack;
    return positive(precise, error);
  }

  /// The time t = G / A [s] from S values with error bounds eG, eA (an inexact tier); !ok
  /// when A is not clearly positive at this precision.
  static Precise preciseTime(const S& G, double eG, const S& A, double eA) {
    const double a = Ar::toDouble(A) * (1 - 2 * Ar::kToDoubleError) - eA;
    if (!(a > 0.5 * Ar::toDouble(A))) return {S(), kInf, false};
    const S t = G / A;
    const double td = std::fabs(Ar::toDouble(t)) * (1 + 2 * Ar::kToDoubleError);
    const double error = ((eG + td * eA) / a + 2 * Ar::kOpError * td) * kSlack + kTiny;
    return {t, error, true};
  }

  /// Pair p's next impact time in S (p approaches). !ok when it does not (in the exact tier:
  /// a schedule out of step with the state, which the driver reports as an internal error).
  Precise preciseTime(std::size_t p) {
    ++refinements_;
    return timeOf(p);
  }
  /// preciseTime(p) without counting a refinement.
  Precise timeOf(std::size_t p) const {
    const S G = gapOf(p);
    const S A = bodies_[left(p)].v - bodies_[p].v;
    if constexpr (Ar::kExact) return Ar::sign(A) > 0 ? Precise{G / A, 0.0, true} : Precise{S(), kInf, false};
    const double eG =
        (eb_ * pairScale(p) + 2.02 * Ar::kOpError * (std::fabs(Ar::toDouble(G)) + offset(p))) * kSlack;
    const double eA = (eu_ * pairScale(p) + 1.01 * Ar::kOpError * std::fabs(Ar::toDouble(A))) * kSlack;
    return preciseTime(G, eG, A, eA);
  }

  /// G = b_p - b_left (+ L across the seam) [m] in S.
  S gapOf(std::size_t p) const {
    const S g = bodies_[p].b - bodies_[left(p)].b;
    return offset(p) == 0.0 ? g : S(g + S(offset(p)));
  }

  Precise preciseNow() const {
    if constexpr (Ar::kExact) return {now_.G / now_.A, 0.0, true};
    const double scale = pairs_[now_.pair].scale;
    const double eG = (now_.eb * scale + 1.01 * Ar::kOpError * std::fabs(Ar::toDouble(now_.G)) + now_.extra) * kSlack;
    const double eA = (now_.eu * scale + 1.01 * Ar::kOpError * std::fabs(Ar::toDouble(now_.A)) + now_.extra) * kSlack;
    return preciseTime(now_.G, eG, now_.A, eA);
  }

  static Order compare(const Precise& x, const Precise& y) {
    if (!x.ok || !y.ok) return Order::kUnknown;
    const S difference = y.value - x.value;
    if constexpr (Ar::kExact) {
      const int s = Ar::sign(difference);
      return s > 0 ? Order::kLess : (s < 0 ? Order::kGreater : Order::kEqual);
    }
    const double error = (x.error + y.error + 2 * Ar::kOpError * std::fabs(Ar::toDouble(difference))) * kSlack;
    switch (positive(difference, error)) {
      case Decision::kYes: return Order::kLess;
      case Decision::kNo: return positive(S(-difference), error) == Decision::kYes ? Order::kGreater : Order::kUnknown;
      case Decision::kUnknownAtZero: return Order::kUnknownAtZero;
      case Decision::kUnknown: break;
    }
    return Order::kUnknown;
  }

  /// Outward-rounded bounds [s] of a time known to within `error` of `estimate`.
  static void widenBounds(double estimate, double error, double& lower, double& upper) {
    const double widen = error * kSlack + std::fabs(estimate) * 0x1p-50 + 0x1p-1070;
    lower = estimate - widen;
    upper = estimate + widen;
  }

  /// Bounds [s] of the time G / A from double approximations, with one division:
  /// 1 / (a - e) <= (1/a)(1 + 2 e/a) for e <= a/2. Meaningful when a.value - a.error > a.value / 2.
  static void coarseBounds(const Approx& a, const Approx& g, double& lower, double& upper) {
    const double inverse = 1.0 / a.value;
    const double estimate = g.value * inverse;
    const double t = std::fabs(estimate);
    const double error =
        (2 * kUnit * t + (g.error + t * (1 + 4 * kUnit) * a.error) * inverse * (1 + 2 * a.error * inverse)) * kSlack;
    widenBounds(estimate, error, lower, upper);
  }

  void setSchedule(std::size_t p, double lower, double upper) {
    tree_.set(p, lower);
    pairs_[p].upper = upper;
  }

  /// Decides whether pair p approaches and bounds its next impact time. The common cases
  /// take no branch on the answer, which is unpredictable.
  StepResult schedule(std::size_t p) {
    const Approx a = approach(p);
    const Approx g = gap(p);
    const bool yes = a.value - a.error > 0.5 * a.value;  // false for a.value <= 0
    const bool no = a.value + a.error <= 0;
    if (!(yes || no)) return scheduleCarefully(p, a);
    double bounds[2][2] = {{kInf, kInf}, {0.0, 0.0}};  // [yes][lower, upper]
    coarseBounds(a, g, bounds[1][0], bounds[1][1]);
    if (yes && !(bounds[1][1] < kMaxMagnitude)) {
      park(p, std::fmax(bounds[1][0], safeLowerBound(a, g)));
      return {};
    }
    setSchedule(p, bounds[yes][0], bounds[yes][1]);
    return {};
  }

  /// A pair whose impact may come at 2^900 or later (its upper bound says so), beyond the
  /// tiers' range, is parked: no upper bound (kInf), and as key a lower bound of its time
  /// (at most the largest double; 0 when none is known). It stops the run (out of range)
  /// only when it may be next: impacts certainly before it go on (step, resolveNext,
  /// reschedule). `lower` may be NaN (no bound).
  void park(std::size_t p, double lower) {
    setSchedule(p, lower >= 0 ? std::min(lower, std::numeric_limits<double>::max()) : 0.0, kInf);
  }
  /// Is pair p parked (due, with no upper bound)?
  bool parked(std::size_t p) const { return pairs_[p].upper == kInf && tree_.key(p) < kInf; }

  /// A lower bound [s] of the time G / A of an approaching pair from its double
  /// approximations, where the quotient may overflow (a subnormal approach speed): inf is
  /// a true bound there (the time is beyond the largest double). 0 when G's bound is not
  /// positive.
  static double safeLowerBound(const Approx& a, const Approx& g) {
    const double gap = g.value - g.error;       // rounds by half an ulp at most
    const double speed = a.value + a.error;     // likewise (exact when subnormal)
    if (!(gap > 0) || !(speed > 0)) return 0.0;
    return gap / speed * (1 - 0x1p-40);         // covers the three roundings
  }

  /// The rare case: the approach speed or the time is too close to call in double.
  StepResult scheduleCarefully(std::size_t p, const Approx& a) {
    double lower = kInf, upper = kInf;
    switch (decideApproach(p, a)) {
      case Decision::kUnknown: return {StepKind::kAmbiguous, p, lastTime()};
      case Decision::kUnknownAtZero: return {StepKind::kAmbiguous, p, lastTime(), true};
      case Decision::kNo: break;
      case Decision::kYes: {
        const Precise precise = preciseTime(p);
        if (!precise.ok) return {StepKind::kAmbiguous, p, lastTime()};
        const double estimate = Ar::toDouble(precise.value);
        widenBounds(estimate, precise.error + Ar::kToDoubleError * std::fabs(estimate), lower, upper);
        if (!(lower >= 0)) {  // the estimate overflowed: inf here when the time is beyond the largest double
          const double below = Ar::toDouble(S(precise.value - S(precise.error)));
          if (below > 0) lower = below * (1 - 0x1p-50);
        }
        if (!(upper < kMaxMagnitude)) {
          park(p, std::fmax(lower, safeLowerBound(a, gap(p))));
          return {};
        }
        break;
      }
    }
    setSchedule(p, lower, upper);
    return {};
  }

  /// After an impact of pair m: pair q (a neighbour) gets its new schedule, which must
  /// come strictly after the impact; exactly at it is a multiple collision.
  StepResult reschedule(std::size_t q, std::size_t m) {
    const StepResult r = schedule(q);
    // Not due (inf), or certainly after (a parked impact's upper bound is inf: not that).
    if (r.kind != StepKind::kImpact || !(tree_.key(q) <= now_.upper) || !(tree_.key(q) < kInf)) return r;
    if (parked(q) && !unbounded_) return {StepKind::kOutOfRange, q, lastTime()};  // cannot be ordered within the tiers' range
    switch (compare(preciseNow(), preciseTime(q))) {
      case Order::kLess: return {};
      case Order::kEqual: return {StepKind::kMultipleCollision, std::min(q, m), lastTime()};
      case Order::kGreater: return {StepKind::kInconsistent, q, lastTime()};
      case Order::kUnknownAtZero: return {StepKind::kAmbiguous, q, lastTime(), true};
      case Order::kUnknown: break;
    }
    return {StepKind::kAmbiguous, q, lastTime()};
  }

  /// The root's bounds overlap others: compare the candidates' precise times. Exact ties
  /// of disjoint pairs go in pair order; of pairs sharing a body, they are a multiple collision.
  StepResult resolveNext(std::size_t root) {
    std::vector<std::size_t> candidates;
    tree_.forEachAtMost(pairs_[root].upper, [&](std::size_t p) {
      if (tree_.key(p) < kInf) candidates.push_back(p);  // due (an unbounded root's reach: every due pair)
    });
    for (std::size_t p : candidates) {
      if (parked(p) && !unbounded_) return {StepKind::kOutOfRange, p, lastTime()};  // may come first, beyond the tiers' range
    }
    std::vector<Precise> times;
    std::size_t best = 0;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      times.push_back(preciseTime(candidates[k]));
      if (!times.back().ok) return {StepKind::kAmbiguous, candidates[k], lastTime()};
      if (times[k].value < times[best].value) best = k;
    }
    std::vector<std::size_t> tied{candidates[best]};
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (k == best) continue;
      const Order order = compare(times[best], times[k]);
      if (order == Order::kUnknown || order == Order::kGreater || order == Order::kUnknownAtZero) {
        return {StepKind::kAmbiguous, candidates[k], lastTime(), order == Order::kUnknownAtZero};
      }
      if (order == Order::kEqual) tied.push_back(candidates[k]);
    }
    std::sort(tied.begin(), tied.end());
    for (std::size_t k = 0; k + 1 < tied.size(); ++k) {
      if (tied[k + 1] == tied[k] + 1) {
        return {StepKind::kMultipleCollision, tied[k], Ar::toDouble(times[best].value)};
      }
    }
    // On a ring the seam pair N-1 and pair 0 share body 0 (for N > 2; N = 2 cannot tie).
    if (tables_.ring != 0.0 && tied.size() > 1 && tied.front() == 0 && tied.back() + 1 == bodies_.size() &&
        bodies_.size() > 2) {
      return {StepKind::kMultipleCollision, tied.back(), Ar::toDouble(times[best].value)};
    }
    return {StepKind::kImpact, tied.front(), 0.0};
  }

  /// Bound on the mass-weighted rounding error of one impact (see the header comment):
  /// 2 eta [ s_h (|q_h'| + 8 |inc|) + s_l (|q_l'| + |q_h'| + 8 |inc| + 2 |d|) ].
  double rho(std::size_t m, const ImpactChange<S>& change, const S& q_i, const S& q_j) const {
    const PairState& pair = pairs_[m];
    if (pair.map.exchange) return 0.0;  // a swap rounds nothing
    return rhoWith(pair.map.heavy_is_i, pair.sqrt_heavy, pair.sqrt_light, change, q_i, q_j);
  }
  /// rho() for square roots s_h, s_l of the heavier and lighter (total) masses.
  static double rhoWith(bool heavy_is_i, double s_h, double s_l, const ImpactChange<S>& change, const S& q_i,
                        const S& q_j) {
    if constexpr (Ar::kExact) return 0.0;
    const double q_h = std::fabs(Ar::toDouble(heavy_is_i ? q_i : q_j));
    const double q_l = std::fabs(Ar::toDouble(heavy_is_i ? q_j : q_i));
    const double inc = std::fabs(Ar::toDouble(change.heavy_increment));
    const double d = std::fabs(Ar::toDouble(change.difference));
    return 2 * Ar::kOpError * (s_h * (q_h + 8 * inc) + s_l * (q_l + q_h + 8 * inc + 2 * d)) + (s_h + s_l) * kTiny;
  }

  /// x rounded to double and published as `bit` of the record: correctly rounded when every
  /// value within `error` of it (a bound on |x - the exact value|; 0: x is exact) rounds to
  /// the same normal double, and in the exact tier; else the bit is set (not certified).
  static double publish(const S& x, double error, ImpactValue bit, ImpactRecord& record) {
    if constexpr (Ar::kExact) {
      return detail::nearestDouble(x);
    } else {
      const double value = Ar::toDouble(x);
      if (error == 0.0) return value;  // a double-double's head, or toDoubleNearest: x rounded once
      const double wide = (error + 2 * Ar::kOpError * std::fabs(value)) * kSlack + kTiny;
      if constexpr (!std::is_same_v<S, Float100>) {
        // The head's nearest rounding boundary lies at least |hi| 2^-54 away (half the gap
        // below a power of two): the tail and the bound well inside it decide at once.
        if (std::fabs(x.lo) + wide < std::fabs(value) * 0x1p-54 && std::fabs(value) >= 0x1p-960) return value;
      }
      const double low = Ar::toDouble(S(x - S(wide))), high = Ar::toDouble(S(x + S(wide)));
      if (low != high || !(std::fabs(low) >= std::numeric_limits<double>::min())) record.uncertified |= bit;
      return value;
    }
  }

  /// Bound on |v - the exact velocity| of body k [m/s] for the state bound eu (0 for a wall).
  double velocityError(std::size_t k, double eu) const { return eu * tables_.inv_sqrt_mass[k]; }  // a wall's is 0

  void recordBefore(std::size_t m, ImpactRecord& record) const {
    const std::size_t left_body = left(m);
    const BodyState& i = bodies_[m];
    const BodyState& j = bodies_[left_body];
    // The contact point is best extrapolated along the slower body's line.
    const bool i_slow = std::fabs(Ar::toDouble(i.v)) <= std::fabs(Ar::toDouble(j.v));
    const std::size_t slow_body = i_slow ? m : left_body;
    const BodyState& slow = bodies_[slow_body];
    record.uncertified = 0;
    const Precise time = timeOf(m);
    record.pair_index = m;
    record.first_moved = m;
    record.last_moved = left_body;
    if (!time.ok) {  // a pair that does not approach: cannot happen for the pair about to collide
      record.uncertified |= kImpactTime | kImpactPosition;
      record.time = Ar::toDouble(S(gapOf(m) / S(j.v - i.v)));
    } else {
      record.time = publish(time.value, time.error, kImpactTime, record);
    }
    // x = b + v t - L across the seam: the intercept's and velocity's bounds, the time's, and
    // the rounding of the two operations and of the seam's subtraction.
    const S at = S(slow.b + S(slow.v * time.value));
    S position = i_slow ? at : S(at - S(offset(m)));
    double position_error = 0.0;
    if constexpr (!Ar::kExact) {
      const double t = std::fabs(Ar::toDouble(time.value)), v = std::fabs(Ar::toDouble(slow.v));
      position_error = velocityError(slow_body, eb_) + t * velocityError(slow_body, eu_) + v * time.error +
                       2.02 * Ar::kOpError * (std::fabs(Ar::toDouble(slow.b)) + v * t + offset(m));
    }
    if (tables_.ring != 0.0) {  // into [0, L) in S: whole turns, the product of two doubles, exact
      const double turns = std::floor(Ar::toDouble(position) / tables_.ring);
      if (turns != 0.0) {
        position = S(position - S(S(turns) * S(tables_.ring)));
        position_error += 1.01 * Ar::kOpError * std::fabs(turns * tables_.ring);
      }
    }
    const double x = publish(position, time.ok ? position_error : kInf, kImpactPosition, record);
    record.position = wrap(x);
    if (record.position != x) record.uncertified |= kImpactPosition;  // the ring's wrap rounds
    record.velocities_before = {publish(i.v, velocityError(m, eu_), kPairVelocitiesBefore, record),
                                publish(j.v, velocityError(left_body, eu_), kPairVelocitiesBefore, record)};
  }

  /// The record after the impact of pair m, sides of masses `mass` (0 for a wall side, which
  /// `wall` marks; a cluster's total), exact in S when `mass_exact`, restitution e: the velocities after,
  /// the energies gained, and the heat (1 - e^2) mu A^2 / 2 at the approach speed A before
  /// (now_.A), each in S with its bound. A wall's entry is minus the other's gain and the heat.
  void recordAfter(std::size_t m, const S& before_i, const S& before_j, const std::array<S, 2>& mass,
                   const std::array<bool, 2>& wall, bool mass_exact, double e, ImpactRecord& record) const {
    const std::size_t body[2] = {m, left(m)};
    const S* before[2] = {&before_i, &before_j};
    std::array<S, 2> gained{S(0), S(0)};
    std::array<double, 2> gained_error{0.0, 0.0};
    for (int k = 0; k < 2; ++k) {
      const S& after = bodies_[body[k]].v;
      // Stuck (e = 0) to a wall: the wall's velocity, exactly.
      const bool on_wall = e == 0.0 && wall[1 - k];
      record.velocities_after[k] =
          publish(after, on_wall ? 0.0 : velocityError(body[k], eu_), kPairVelocitiesAfter, record);
      if (wall[k]) continue;
      // Bounced elastically off a wall at rest: it gains exactly nothing.
      if (e == 1.0 && wall[1 - k] && Ar::toDouble(bodies_[body[1 - k]].v) == 0.0) continue;
      // m/2 (v' - v)(v' + v), each factor within the bounds of v' and v.
      const S dv = after - *before[k], sum = after + *before[k];
      gained[k] = S(S(mass[k] * dv) * sum) * S(0.5);
      if constexpr (!Ar::kExact) {
        const double ev = velocityError(body[k], eu_) + velocityError(body[k], now_.eu);
        const double d = std::fabs(Ar::toDouble(dv)) * (1 + 2 * Ar::kOpError) + ev;
        const double s = std::fabs(Ar::toDouble(sum)) * (1 + 2 * Ar::kOpError) + ev;
        const double mk = std::fabs(Ar::toDouble(mass[k]));
        gained_error[k] = 0.5 * mk * (d * s - (d - ev) * (s - ev)) + 6 * Ar::kOpError * mk * d * s;
      }
    }
    S lost(0);
    double lost_error = 0.0;
    if (e != 1.0) {
      const S mu = wall[0] ? mass[1] : wall[1] ? mass[0] : S(S(mass[0] * mass[1]) / S(mass[0] + mass[1]));
      const S factor = S(S(S(1) - S(S(e) * S(e))) * mu) * S(0.5);
      lost = S(factor * now_.A) * now_.A;
      if constexpr (!Ar::kExact) {
        const double a = std::fabs(Ar::toDouble(now_.A));
        const double ea = now_.eu * pairs_[m].scale + now_.extra;
        const double f = std::fabs(Ar::toDouble(factor)) * (1 + 8 * Ar::kOpError);
        lost_error = f * (2 * a * ea + ea * ea) + 4 * Ar::kOpError * f * a * a;
      }
    }
    record.energy_lost = publish(lost, lost_error, kImpactEnergyLost, record);
    for (int k = 0; k < 2; ++k) {
      if (!wall[k]) continue;
      if (Ar::toDouble(bodies_[body[k]].v) == 0.0) continue;  // a wall at rest does no work: exactly 0
      gained[k] = S(-gained[1 - k]) - lost;
      gained_error[k] = gained_error[1 - k] + lost_error + 2 * Ar::kOpError * std::fabs(Ar::toDouble(gained[k]));
    }
    for (int k = 0; k < 2; ++k) {
      record.energy_gained[k] = publish(gained[k], gained_error[k], kPairEnergyTransfer, record);
    }
    if (!mass_exact) record.uncertified |= kPairEnergyTransfer | kImpactEnergyLost;
  }

  /// Precision guard: an impact's time t = G / A is published to about 1e-12. When this
  /// tier's state pins G or A down less well than 2^-42 of their size (tiny approach speeds,
  /// as on the way to an inelastic collapse), a more precise tier takes the step.
  bool timeIsPrecise(double scale) const {
    if constexpr (Ar::kExact) return true;
    return now_.eb * scale <= kTimePrecision * std::fabs(Ar::toDouble(now_.G)) &&
           now_.eu * scale <= kTimePrecision * std::fabs(Ar::toDouble(now_.A));
  }

  void addLoss(double loss) {
    // Neumaier summation: the total of many small losses keeps its digits.
    const double sum = lost_ + loss;
    lost_compensation_ += std::fabs(lost_) >= std::fabs(loss) ? (lost_ - sum) + loss : (loss - sum) + lost_;
    lost_ = sum;
  }

  /// Performs the impact of pair m. When a neighbour then hits at the same instant (a
  /// multiple collision, or a decision this tier cannot take), the impact is undone.
  StepResult impact(std::size_t m, ImpactRecord* record) {
    saveFor(m);
    StepResult r = collide(m, record);
    if (r.kind == StepKind::kImpact) r = scheduleAfter(m);
    if (r.kind != StepKind::kImpact) restore(m);
    return r;
  }

  /// Records in undo_ what an impact of pair m changes besides the tree.
  void saveFor(std::size_t m) {
    const std::size_t j = left(m);
    Undo& undo = undo_;
    undo.i = bodies_[m], undo.j = bodies_[j];
    undo.eu = eu_, undo.eb = eb_, undo.lost = lost_, undo.lost_compensation = lost_compensation_;
    undo.now = now_;
    undo.bonded = bonded_[m];
    undo.cluster_impacts = cluster_impacts_;
    undo.rule_elastic = rule_elastic_;
    if (!clocks_.empty()) undo.clock_i = clocks_[m], undo.clock_j = clocks_[j];
    if (!last_exact_.empty()) undo.exact_i = last_exact_[m], undo.exact_j = last_exact_[j];
    undo.lo = m;
    undo.cluster.clear();
    if (tables_.ring != 0.0) return;  // no clusters on a ring
    const std::size_t lo = clusterLow(m), hi = clusterHigh(m + 1);
    if (lo != m || hi != m + 1) undo.cluster.assign(bodies_.begin() + lo, bodies_.begin() + hi + 1), undo.lo = lo;
  }

  /// Undoes the impact of pair m recorded by saveFor(m).
  void restore(std::size_t m) {
    const Undo& undo = undo_;
    const std::size_t j = left(m);
    bodies_[m] = undo.i, bodies_[j] = undo.j;
    std::copy(undo.cluster.begin(), undo.cluster.end(), bodies_.begin() + undo.lo);
    eu_ = undo.eu, eb_ = undo.eb, lost_ = undo.lost, lost_compensation_ = undo.lost_compensation;
    now_ = undo.now;
    bonded_[m] = undo.bonded;
    cluster_impacts_ = undo.cluster_impacts;
    rule_elastic_ = undo.rule_elastic;
    if (!clocks_.empty()) clocks_[m] = undo.clock_i, clocks_[j] = undo.clock_j;
    if (!last_exact_.empty()) last_exact_[m] = undo.exact_i, last_exact_[j] = undo.exact_j;
  }

  /// The first and last body of the cluster holding `body` (bodies stuck together by e = 0
  /// or by a collapse move as one).
  std::size_t clusterLow(std::size_t body) const {
    while (body > 0 && bonded_[body - 1]) --body;
    return body;
  }
  std::size_t clusterHigh(std::size_t body) const {
    while (body < bonded_.size() && bonded_[body]) ++body;
    return body;
  }

  /// The impact of pair m on its two bodies, with the error bounds, the heat and the record.
  StepResult collide(std::size_t m, ImpactRecord* record) {
    Rule rule;
    if (tables_.scene.restitution_model.kind != RestitutionModelKind::kConstant) {
      rule = ruleFor(m);
      if (rule.kind != StepKind::kImpact) return {rule.kind, m, lastTime(), rule.at_zero};
    } else {
      rule.e = tables_.restitution[m];
    }
    const std::size_t lo = tables_.ring != 0.0 ? m : clusterLow(m), hi = tables_.ring != 0.0 ? m + 1 : clusterHigh(m + 1);
    const StepResult r = lo == m && hi == m + 1 ? collideBodies(m, rule, record) : collideClusters(m, lo, hi, rule.e, record);
    if (r.kind != StepKind::kImpact) return r;
    if (rule.e == 0.0) bonded_[m] = 1;  // e = 0: they stick
    if (rule.made_elastic) ++rule_elastic_;
    if (!clocks_.empty()) startClocks(m);
    return r;
  }

  /// The restitution of the impact of pair m about to happen under the scene's model
  /// (scene.h, RestitutionModel), whether the model made it elastic, or kAmbiguous when this
  /// tier cannot decide it (at_zero: only the exact tier can).
  struct Rule {
    StepKind kind = StepKind::kImpact;
    double e = 1.0;
    bool made_elastic = false;
    bool at_zero = false;
  };
  Rule ruleFor(std::size_t m) {
    const Scene& scene = tables_.scene;
    const RestitutionModel& model = scene.restitution_model;
    const double base = tables_.restitution[m];
    const auto decided = [&](Decision elastic) {
      switch (elastic) {
        case Decision::kYes: return Rule{StepKind::kImpact, 1.0, base != 1.0, false};
        case Decision::kNo: return Rule{StepKind::kImpact, base, false, false};
        case Decision::kUnknownAtZero: return Rule{StepKind::kAmbiguous, 0.0, false, true};
        case Decision::kUnknown: break;
      }
      return Rule{StepKind::kAmbiguous, 0.0, false, false};
    };
    switch (model.kind) {
      case RestitutionModelKind::kConstant: break;
      case RestitutionModelKind::kTc: return decided(base == 1.0 ? Decision::kNo : tooSoon(m));
      case RestitutionModelKind::kThreshold: return decided(base == 1.0 ? Decision::kNo : slowerThan(m, model.elastic_below));
      case RestitutionModelKind::kViscoelastic: {
        Rule rule;
        const std::optional<double> e = viscoelasticE(m, model.viscoelastic_speed);
        if (!e) return {StepKind::kAmbiguous, 0.0, false, false};
        rule.e = *e;
        rule.made_elastic = rule.e == 1.0;
        return rule;
      }
    }
    return {StepKind::kImpact, base, false, false};
  }

  /// TC: is the impact of pair m elastic, i.e. was the last impact of one of its finite
  /// bodies at most t_c before it? Decided on the double bounds of the two impact times
  /// (tree key and PairState::upper, rigorous for every tier); what they cannot decide
  /// (a difference within about 2^-50 of t_c), only the exact tier decides, with the
  /// exact impact times.
  Decision tooSoon(std::size_t m) const {
    const double tc = tables_.scene.restitution_model.tc;
    const double now_lo = tree_.key(m), now_hi = pairs_[m].upper;
    bool unknown = false;
    for (std::size_t k : {m, left(m)}) {
      if (tables_.scene.isWall(k) || clocks_[k].hi == -kInf) continue;  // no clock, or waited forever
      const double low = now_lo - clocks_[k].hi, high = now_hi - clocks_[k].lo;
      if (high + std::fabs(high) * 0x1p-51 <= tc) return Decision::kYes;
      if (low - std::fabs(low) * 0x1p-51 > tc) continue;
      if constexpr (Ar::kExact) {
        const S since = S(gapOf(m) / S(bodies_[left(m)].v - bodies_[m].v)) - last_exact_[k];
        if (Ar::sign(S(since - S(tc))) <= 0) return Decision::kYes;
      } else {
        unknown = true;
      }
    }
    return unknown ? Decision::kUnknownAtZero : Decision::kNo;
  }

  /// TC: bodies m and left(m) had their last impact now (the bounds of its time, and in the
  /// exact tier the exact time). Called after the impact: gapOf and the velocities have
  /// changed, so the exact time comes from now_ (G and A before it).
  void startClocks(std::size_t m) {
    const Clock now{tree_.key(m), pairs_[m].upper};
    for (std::size_t k : {m, left(m)}) {
      clocks_[k] = now;
      if constexpr (Ar::kExact) last_exact_[k] = now_.G / now_.A;
    }
  }

  /// Threshold law: is pair m's approach speed below v0 [m/s]?
  Decision slowerThan(std::size_t m, double v0) {
    const Approx a = approach(m);
    if ((a.value + a.error) * (1 + 0x1p-50) < v0) return Decision::kYes;
    if ((a.value - a.error) * (1 - 0x1p-50) >= v0) return Decision::kNo;
    const S difference = S(v0) - S(bodies_[left(m)].v - bodies_[m].v);
    const double error =
        (eu_ * pairScale(m) + 2.02 * Ar::kOpError * (std::fabs(a.value) + v0 + std::fabs(Ar::toDouble(difference)))) *
        kSlack;
    if constexpr (Ar::kExact) return Ar::sign(difference) > 0 ? Decision::kYes : Decision::kNo;
    return positive(difference, error);
  }

  /// Viscoelastic law: e of pair m's impact, the correctly rounded value of e(v) at the exact
  /// approach speed v (viscoelastic.h), the same in every tier: an inexact tier answers only
  /// when every speed within its bound of its own gives the same double.
  std::optional<double> viscoelasticE(std::size_t m, double v_star) const {
    const S speed = bodies_[left(m)].v - bodies_[m].v;
    if constexpr (Ar::kExact) {
      return viscoelasticAt(speed, v_star);
    } else {
      const double d = Ar::toDouble(speed);
      // The state's bound on the speed and the rounding of forming it.
      const double error = (eu_ * pairScale(m) + 4.04 * Ar::kOpError * std::fabs(d)) * kSlack + kTiny;
      if constexpr (std::is_same_v<S, Float100>) {
        if (!(d - 2 * error > 0)) return std::nullopt;
        return viscoelasticNear(speed, Float100(error), v_star);
      } else {
        // The double-double speed in long double (within 2^-63 of it), and the bound widened
        // by that and by forming the ends.
        const long double v = static_cast<long double>(speed.hi) + speed.lo;
        const long double wider = (error + std::fabs(v) * 0x1p-62L) * (1 + 0x1p-60L);
        if (!(v - wider > 0)) return std::nullopt;
        if (const auto e = viscoelasticOver(v, wider, v_star)) return e;
        // Next to a rounding boundary (a few impacts in 100): the same speed and bound in
        // double-double, then at 128 bits, without a replay in the 100-digit tier.
        if (!(d - 2 * error > 0)) return std::nullopt;
        if (const auto e = viscoelasticDD(DD(speed.hi, speed.lo, 0), error, v_star)) return e;
        return viscoelasticNear(Float100(speed.hi) + speed.lo, Float100(error), v_star);
      }
    }
  }

  /// The cluster rule: clusters lo..m and m+1..hi meet as two bodies of their total masses,
  /// with pair m's restitution; every member takes its cluster's new line.
  StepResult collideClusters(std::size_t m, std::size_t lo, std::size_t hi, double e, ImpactRecord* record) {
    const Scene& scene = tables_.scene;
    S mass[2] = {S(0), S(0)};
    bool wall[2] = {false, false};
    double mass_d[2] = {0.0, 0.0};
    for (std::size_t k = lo; k <= hi; ++k) {
      const int side = k <= m ? 0 : 1;
      wall[side] = wall[side] || scene.isWall(k);
      if (!scene.isWall(k)) mass[side] = mass[side] + S(scene.masses[k]), mass_d[side] += scene.masses[k];
    }
    for (int side = 0; side < 2; ++side) {
      if (wall[side]) mass_d[side] = kInf;
    }
    const ImpactMap<S> map = makeClusterImpactMap<S>(mass[0], wall[0], mass[1], wall[1], e, mass_d[0] >= mass_d[1]);
    BodyState& i = bodies_[m];
    BodyState& j = bodies_[m + 1];
    now_.pair = m;
    now_.upper = pairs_[m].upper;
    const S before_i = i.v, before_j = j.v;
    if (record) recordBefore(m, *record), record->first_moved = lo, record->last_moved = hi;
    now_.eu = eu_, now_.eb = eb_, now_.extra = 0.0;
    const ImpactChange<S> dv = applyImpactMap(map, i.v, j.v);
    const ImpactChange<S> db = applyImpactMap(map, i.b, j.b);
    const double s_h = wall[map.heavy_is_i ? 0 : 1] ? 0.0 : std::sqrt(mass_d[map.heavy_is_i ? 0 : 1]);
    const double s_l = std::sqrt(mass_d[map.heavy_is_i ? 1 : 0]);
    // The sums of the masses round too: (hi - lo) more operations on the increment.
    const double sums = static_cast<double>(hi - lo) * 4 * Ar::kOpError * (s_h + s_l);
    eu_ += rhoWith(map.heavy_is_i, s_h, s_l, dv, i.v, j.v) + sums * std::fabs(Ar::toDouble(dv.heavy_increment));
    eb_ += rhoWith(map.heavy_is_i, s_h, s_l, db, i.b, j.b) + sums * std::fabs(Ar::toDouble(db.heavy_increment));
    for (std::size_t k = lo; k <= hi; ++k) bodies_[k] = k <= m ? i : j;
    now_.A = dv.difference;
    now_.G = -db.difference;
    if (!timeIsPrecise(pairs_[m].scale)) return {StepKind::kImprecise, m, 0.0};
    const double lost = impactEnergyLost(mass_d[0], mass_d[1], Ar::toDouble(now_.A), e);
    if (lost != 0.0) addLoss(lost);
    if (record) {
      recordAfter(m, before_i, before_j, {mass[0], mass[1]}, {wall[0], wall[1]}, massSumsExact(lo, hi), e, *record);
    }
    ++cluster_impacts_;
    const double magnitude = std::fabs(Ar::toDouble(i.b)) + std::fabs(Ar::toDouble(j.b)) +
                             std::fabs(Ar::toDouble(i.v)) + std::fabs(Ar::toDouble(j.v));
    if (!(magnitude < kMaxMagnitude) && !unbounded_) return {StepKind::kOutOfRange, m, lastTime()};
    return {StepKind::kImpact, m, 0.0};
  }

  /// Are the sums of the masses of bodies lo..hi exact in S? Always in the exact tier; at 100
  /// digits (333 bits) when their exponents span less than 260 bits (a double's 53 and the
  /// carries of up to 2^20 terms within the rest); never in double-double.
  bool massSumsExact(std::size_t lo, std::size_t hi) const {
    if constexpr (Ar::kExact) return true;
    if constexpr (!std::is_same_v<S, Float100>) return false;
    int smallest = std::numeric_limits<int>::max(), largest = std::numeric_limits<int>::min();
    for (std::size_t k = lo; k <= hi; ++k) {
      if (tables_.scene.isWall(k)) continue;
      smallest = std::min(smallest, std::ilogb(tables_.scene.masses[k]));
      largest = std::max(largest, std::ilogb(tables_.scene.masses[k]));
    }
    return hi - lo < (1u << 20) && largest - smallest < 260;
  }

  /// The impact of pair m on its two single bodies.
  StepResult collideBodies(std::size_t m, const Rule& rule, ImpactRecord* record) {
    PairState& pair = pairs_[m];
    const std::size_t left_body = left(m);
    BodyState& i = bodies_[m];
    BodyState& j = bodies_[left_body];
    // The pair's own map; the model's e, when it differs: the elastic map, or e(v)'s.
    const bool own = rule.e == tables_.restitution[m];
    const Scene& scene = tables_.scene;
    ImpactMap<S> computed;
    const ImpactMap<S>* chosen = own ? &pair.map : (rule.e == 1.0 ? &elastic_maps_[m] : &computed);
    if (chosen == &computed) computed = makeImpactMap<S>(scene.masses[m], scene.masses[left_body], rule.e);
    const ImpactMap<S>& map = *chosen;
    now_.pair = m;
    now_.upper = pair.upper;
    const S before_i = i.v, before_j = j.v;
    if (record) recordBefore(m, *record);
    const double length = offset(m);
    if (length != 0.0) {  // across the seam the left body is met at b - L; its rounding counts
      j.b = j.b - S(length);
      eb_ += 1.01 * Ar::kOpError * tables_.sqrt_mass[left_body] * std::fabs(Ar::toDouble(j.b)) + kTiny;
    }
    now_.eu = eu_;
    now_.eb = eb_;
    now_.extra = 0.0;
    const ImpactChange<S> dv = applyImpactMap(map, i.v, j.v);
    const ImpactChange<S> db = applyImpactMap(map, i.b, j.b);
    eu_ += map.exchange ? 0.0 : rhoWith(map.heavy_is_i, pair.sqrt_heavy, pair.sqrt_light, dv, i.v, j.v);
    eb_ += map.exchange ? 0.0 : rhoWith(map.heavy_is_i, pair.sqrt_heavy, pair.sqrt_light, db, i.b, j.b);
    if (length != 0.0) {
      j.b = j.b + S(length);
      eb_ += 1.01 * Ar::kOpError * tables_.sqrt_mass[left_body] * std::fabs(Ar::toDouble(j.b)) + kTiny;
    }
    now_.A = dv.difference;
    now_.G = -db.difference;
    if (!timeIsPrecise(pair.scale)) return {StepKind::kImprecise, m, 0.0};
    double lost = 0.0;
    if (std::fabs(map.light_factor) != 1.0) {  // e < 1
      const double approach_speed = Ar::toDouble(now_.A);
      lost = own ? tables_.loss_factor[m] * approach_speed * approach_speed
                 : impactEnergyLost(scene.masses[m], scene.masses[left_body], approach_speed, rule.e);
      addLoss(lost);
    }
    if (record) {
      const auto mass_of = [&scene](std::size_t k) { return scene.isWall(k) ? S(0) : S(scene.masses[k]); };
      recordAfter(m, before_i, before_j, {mass_of(m), mass_of(left_body)},
                  {scene.isWall(m), scene.isWall(left_body)}, true, rule.e, *record);
    }
    const double magnitude = std::fabs(Ar::toDouble(i.b)) + std::fabs(Ar::toDouble(j.b)) +
                             std::fabs(Ar::toDouble(i.v)) + std::fabs(Ar::toDouble(j.v));
    if (!(magnitude < kMaxMagnitude) && !unbounded_) return {StepKind::kOutOfRange, m, lastTime()};
    return {StepKind::kImpact, m, 0.0};
  }

  /// Asks the cache for what the next step reads first (the likely next pair and its
  /// bodies), while the driver does its bookkeeping.
  void prefetchNext() const {
    const std::size_t next = tree_.minLeaf();
    if (next >= pairs_.size()) return;
    __builtin_prefetch(&pairs_[next]);
    __builtin_prefetch(&bodies_[next]);
    __builtin_prefetch(&bodies_[left(next)]);
    // Its impact reschedules the pairs on either side, which read the bodies beyond.
    if (next > 0) __builtin_prefetch(&pairs_[next - 1]), __builtin_prefetch(&bodies_[next - 1]);
    if (next + 1 < pairs_.size()) __builtin_prefetch(&pairs_[next + 1]);
    if (next + 2 < bodies_.size()) __builtin_prefetch(&bodies_[next + 2]);
  }

  /// Pair m separates (e > 0) or moves on together (e = 0): no impact; its neighbours get
  /// new schedules.
  StepResult scheduleAfter(std::size_t m) {
    setSchedule(m, kInf, kInf);
    if (tables_.ring != 0.0 && pairs_.size() > 1) {  // no clusters on a ring; the neighbours are cyclic
      const std::array<std::size_t, 3> around = ringNeighbours(m);
      for (std::size_t q : {around[0], around[2]}) {
        const StepResult r = reschedule(q, m);
        if (r.kind != StepKind::kImpact) return r;
      }
      updateRing(m);
      ++count_;
      return {StepKind::kImpact, m, 0.0};
    }
    // The pairs at the outer ends of the two clusters (m - 1 and m + 1 for single bodies).
    const std::size_t lo = clusterLow(m), hi = clusterHigh(m + 1);
    if (lo > 0) {
      const StepResult r = reschedule(lo - 1, m);
      if (r.kind != StepKind::kImpact) return r;
    }
    if (hi < pairs_.size()) {
      const StepResult r = reschedule(hi, m);
      if (r.kind != StepKind::kImpact) return r;
    }
    tree_.update(lo > 0 ? lo - 1 : lo, std::min(hi, pairs_.size() - 1));
    ++count_;
    prefetchNext();
    return {StepKind::kImpact, m, 0.0};
  }

  const SceneTables& tables_;
  std::vector<BodyState> bodies_;
  std::vector<PairState> pairs_;
  TournamentTree tree_;  ///< per pair: lower bound of the next impact time [s]
  std::vector<char> bonded_;           ///< per pair: its two bodies move as one (a cluster)
  std::uint64_t cluster_impacts_ = 0;  ///< impacts in which a cluster met a body as one body
  std::uint64_t rule_elastic_ = 0;     ///< impacts the restitution model made elastic
  std::vector<ImpactMap<S>> elastic_maps_;  ///< per pair, e = 1 (TC and threshold only)
  std::vector<Clock> clocks_;               ///< per body, TC only
  std::vector<S> last_exact_;               ///< per body, TC in the exact tier only: last impact time [s]
  std::size_t merged_ = 0;             ///< collapses applied (the driver's list, in order)
  bool unbounded_ = false;     ///< allowAnyMagnitude() (the exact tier past the range)
  double eu_ = 0.0;            ///< bound on ||U_computed - U_exact|| [kg^0.5 m/s]
  double eb_ = 0.0;            ///< bound on ||B_computed - B_exact|| [kg^0.5 m]
  std::uint64_t count_ = 0;
  std::uint64_t refinements_ = 0;
  double lost_ = 0.0, lost_compensation_ = 0.0;  ///< kinetic energy lost so far [J]
  Now now_;
  Undo undo_;  ///< saveFor()'s record of the impact in progress
};

}  // namespace nbody_detail
}  // namespace core
}  // namespace collision_lab
