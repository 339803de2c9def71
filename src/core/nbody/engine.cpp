#include "collision_lab/core/nbody/engine.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <deque>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "collision_lab/core/count_text.h"
#include "../correct_rounding.h"
#include "elastic_triple.h"
#include "fma_path.h"
#include "tier.h"
#include "units.h"

namespace collision_lab {
namespace core {

namespace nbody_detail {

SceneTables::SceneTables(const Scene& s) : scene(s), pairs(s.contactCount()), ring(s.ring) {
  for (std::size_t k = 0; k < s.size(); ++k) {
    const bool wall = s.isWall(k);
    sqrt_mass.push_back(wall ? 0.0 : std::sqrt(s.masses[k]));
    inv_sqrt_mass.push_back(wall ? 0.0 : 1.0 / std::sqrt(s.masses[k]));
  }
  for (std::size_t p = 0; p < pairs; ++p) {
    // The loss at unit approach speed, (1 - e^2) mu / 2: one home for the formula.
    restitution.push_back(s.restitutionOf(p));
    loss_factor.push_back(impactEnergyLost(s.masses[p], s.masses[s.leftOf(p)], 1.0, restitution.back()));
  }
}

namespace {

/// Runs of up to this many impacts whose final velocities the working tier's bound does not
/// certify replay at 100 digits to certify them (about 5 us per impact); longer ones name
/// them uncertified.
constexpr std::uint64_t kCertifyingReplay = 10'000;

/// q 2^e, exactly.
Rational scaledByPowerOfTwo(const Rational& q, int e) {
  const boost::multiprecision::cpp_int power = boost::multiprecision::cpp_int(1) << (e < 0 ? -e : e);
  return e < 0 ? Rational(q / power) : Rational(q * power);
}

template <class S>
struct NextTier;
template <bool kFma>
struct NextTier<BasicDD<kFma>> {
  using type = Float100;
};
template <>
struct NextTier<Float100> {
  using type = Rational;
};

/// Where the exact tier stands: its impacts and the bits of its last impact's numbers; and
/// how its budget stopped the run, if it did.
struct ExactProgress {
  std::uint64_t count = 0;
  unsigned bits = 0;
  std::uint64_t replay_target = 0;  ///< the impact a replay stopped for its budget had to reach
  std::uint64_t streak = 0;         ///< exact impacts in a row when the exactness cap stopped the run
  bool predicted = false;           ///< stopped on the forecast (tier.h, WorkForecast), not on the budget spent
};

/// Owns the tiers: the double-double one always, the others from their first use on. A
/// higher tier keeps its state between escalations, so each replays every impact at most
/// once over the whole run. W: the working tier's double-double, DD or (on the FMA path,
/// fma_path.h) DDFma, the same values either way.
template <class W>
class Driver {
 public:
  /// `cancel` (may be null) is read before every step of the exact tier, whose replays can be long.
  Driver(const Scene& scene, const EngineOptions& options)
      : tables_(scene), cancel_(options.cancel), budget_(options.exact_work_budget),
        forecast_(options.forecast_exact_work) {}

  StepResult start() { return startOrEscalate<W>(); }
  StepResult step(ImpactRecord* record) {
    const std::uint64_t exact = escalations_.exact_rational;
    const std::uint64_t escalated = exact + escalations_.high_precision;
    const StepResult r = stepOrEscalate<W>(record);
    exact_streak_ = escalations_.exact_rational > exact ? exact_streak_ + 1 : 0;
    if (exact_streak_ == 0) {
      streak_work_.clear();
    } else if (exact_ && exact_->count() == fast_->count()) {
      const double bits = exact_->exactBits();
      streak_work_.add(bits * bits);
    }
    if (r.kind == StepKind::kImpact && escalations_.exact_rational + escalations_.high_precision > escalated) {
      crowd_[crowd_next_++ % crowd_.size()] = r.pair;
    }
    return r;
  }

  /// The bodies of the last kCrowdWindow impacts that needed more than double-double, and of
  /// the decision that could not be taken (after kOverBudget), ascending.
  std::vector<std::size_t> crowdingBodies() const {
    std::vector<std::size_t> bodies;
    const std::size_t recorded = std::min<std::size_t>(crowd_next_, crowd_.size());
    for (std::size_t k = 0; k <= recorded; ++k) {
      const std::size_t pair = k < recorded ? crowd_[k] : undecided_pair_;
      if (pair == kNone) continue;
      bodies.push_back(pair);
      bodies.push_back(tables_.scene.leftOf(pair));  // body 0 across a ring's seam
    }
    std::sort(bodies.begin(), bodies.end());
    bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
    return bodies;
  }
  /// Where the exact tier stands (zeros when it never ran).
  ExactProgress exactProgress() const {
    ExactProgress progress = budget_stop_;
    if (exact_) {
      progress.count = exact_->count();
      progress.bits = exact_->exactBits();
    }
    return progress;
  }
  static constexpr std::size_t kCrowdWindow = 32;

  const Tier<W>& fast() const { return *fast_; }

  /// The working tier stopped out of range, its next impact due past the largest double: the
  /// run goes on in the exact tier alone (brought to the same impact by replay, within its
  /// budget), whose numbers have no range. Every later step is the exact tier's.
  StepResult stepBeyondRange(ImpactRecord* record) {
    if (!beyond_range_) {
      if (!exact_) {
        const StepResult r = startOrEscalate<Rational>();
        if (r.kind != StepKind::kImpact) return r;
      }
      // Every pair scheduled anew: a step the exact tier undid (restore) leaves its pairs'
      // schedules behind.
      const StepResult rescheduled = exact_->allowAnyMagnitude();
      if (rescheduled.kind != StepKind::kImpact) return rescheduled;
      const StepResult at = advanceTo<Rational>(fast_->count());
      if (at.kind != StepKind::kImpact) return at;
      beyond_range_ = true;
    }
    // Every step is exact: counted as one, and a streak, so that the tier's growing numbers
    // stop the run as they would in step() (kExhausted).
    const StepResult r = stepOrEscalate<Rational>(record);
    ++escalations_.exact_rational;
    ++escalations_.replayed_impacts;
    ++exact_streak_;
    const double bits = exact_->exactBits();
    streak_work_.add(bits * bits);
    return r;
  }
  bool beyondRange() const { return beyond_range_; }
  /// Beyond the range: the bodies at the exact time of the last impact, each rounded once
  /// [working units] (there, a double time is inf, or too coarse to place a body).
  void exactStateAtLastImpact(std::vector<double>& positions, std::vector<double>& velocities) const {
    exact_->stateAtLastImpact(positions, velocities);
  }

  /// f(tier) of the tier that leads the run: the working one, or the exact one beyond the
  /// range (stepBeyondRange).
  template <class F>
  decltype(auto) leading(F&& f) const {
    return beyond_range_ ? f(*exact_) : f(*fast_);
  }
  /// Impacts the run has taken.
  std::uint64_t count() const { return leading([](const auto& t) { return t.count(); }); }

  /// A lower bound [s] of the next impact's time after the working tier's last impact, from
  /// the exact tier brought to the same count (a pair it parks has its exact time, rounded
  /// down, as key): what an out-of-range stop says. 0 when the exact replay cannot be had.
  double exactNextTimeLowerBound() {
    if (advanceTo<Rational>(fast_->count()).kind != StepKind::kImpact) return 0.0;
    return exact_->nextTimeLowerBound();
  }


  /// Every body's velocity after the working tier's last impact [working units], correctly
  /// rounded where it can be certified: by the working tier's bound; where that does not
  /// decide and `replay` allows, by the 100-digit tier brought to the same count (a replay of
  /// the run, its bound 2^-300 or so), then by the exact tier (within its work budget). Empty
  /// where none decides.
  std::vector<std::optional<double>> certifiedVelocities(bool replay) {
    const std::size_t n = tables_.scene.masses.size();
    std::vector<std::optional<double>> velocities(n);
    const auto missing = [&velocities] {
      return std::any_of(velocities.begin(), velocities.end(), [](const auto& v) { return !v; });
    };
    if (beyond_range_) {
      for (std::size_t k = 0; k < n; ++k) velocities[k] = detail::nearestDouble(exact_->velocityValue(k));
      return velocities;
    }
    for (std::size_t k = 0; k < n; ++k) velocities[k] = fast_->certifiedVelocity(k);
    if (!missing() || !replay) return velocities;
    const std::uint64_t count = fast_->count();
    if (advanceTo<Float100>(count).kind == StepKind::kImpact) {
      for (std::size_t k = 0; k < n; ++k) {
        if (!velocities[k]) velocities[k] = high_->certifiedVelocity(k);
      }
    }
    if (missing() && advanceTo<Rational>(count).kind == StepKind::kImpact) {  // an exact zero or tie
      for (std::size_t k = 0; k < n; ++k) {
        if (!velocities[k]) velocities[k] = detail::nearestDouble(exact_->velocityValue(k));
      }
    }
    return velocities;
  }

  /// Body k's exact velocity after the working tier's last impact [working units], where the
  /// exact tier can be brought there within its budget.
  std::optional<Rational> exactVelocity(std::size_t k) {
    if (!beyond_range_ && advanceTo<Rational>(fast_->count()).kind != StepKind::kImpact) return std::nullopt;
    return exact_->velocityValue(k);
  }

  /// The heat of the run so far [working units], correctly rounded where it can be
  /// certified: the kinetic energy lost, E_0 - E, in the walls' frame (where the walls do no
  /// work: at most one wall velocity), from the working tier's velocities and bound, else
  /// (with `replay`) the 100-digit tier's, else the exact tier's. Empty where none decides,
  /// or with two walls moving apart.
  std::optional<double> certifiedHeat(bool replay) {
    const Scene& scene = tables_.scene;
    std::optional<double> frame;
    for (std::size_t k = 0; k < scene.size(); ++k) {
      if (!scene.isWall(k)) continue;
      if (frame && *frame != scene.velocities[k]) return std::nullopt;
      frame = scene.velocities[k];
    }
    const double f = frame.value_or(0.0);
    if (!beyond_range_) {
      if (const auto heat = heatFrom(*fast_, f)) return heat;
      if (!replay) return std::nullopt;
      const std::uint64_t count = fast_->count();
      if (advanceTo<Float100>(count).kind != StepKind::kImpact) return std::nullopt;
      if (const auto heat = heatFrom(*high_, f)) return heat;
      if (advanceTo<Rational>(count).kind != StepKind::kImpact) return std::nullopt;
    }
    Rational heat = 0;
    for (std::size_t k = 0; k < scene.size(); ++k) {
      if (scene.isWall(k)) continue;
      const Rational v0 = Rational(scene.velocities[k]) - Rational(f), v = exact_->velocityValue(k) - Rational(f);
      heat += Rational(scene.masses[k]) * (v0 * v0 - v * v) / 2;
    }
    return detail::nearestDouble(heat);
  }

  /// After the impact of `pair`: when two pairs have alternated for 8 impacts, asks the
  /// working tier whether their three clusters collapse, and resolves a collapse in every
  /// tier (each applies it when it reaches this impact count, replays included).
  StepResult afterImpact(std::size_t pair, SceneSimulation& result) {
    alternating_ = pair != last_ && pair == before_last_ ? alternating_ + 1 : 2;
    before_last_ = last_;
    last_ = pair;
    history_.push_back(pair);
    if (history_.size() > 3 * group_detail::kMaxPeriod) history_.pop_front();
    // The collapse tests assume each pair's constant e and an open line.
    if (tables_.ring != 0.0 || tables_.scene.restitution_model.kind != RestitutionModelKind::kConstant) return {};
    if (alternating_ < 8) return groupCollapse(result);
    const std::size_t p = std::min(last_, before_last_), q = std::max(last_, before_last_);
    const auto found = collapseCandidate(p, q, last_ == p);
    if (!found) return {};
    return resolve(*found, result);
  }

 private:
  /// x at 100 digits, exactly (a double-double's two parts fit its significand).
  template <class S>
  static Float100 exactlyWide(const S& x) {
    if constexpr (std::is_same_v<S, Float100>) {
      return x;
    } else {
      return Float100(x.hi) + Float100(x.lo);
    }
  }

  /// E_0 - E in the frame moving at `frame` [working units] from tier t's velocities and its
  /// bound on them (t inexact), at 100 digits, when the bound certifies its rounding.
  template <class S>
  std::optional<double> heatFrom(const Tier<S>& t, double frame) const {
    const Scene& scene = tables_.scene;
    Float100 initial = 0, now = 0, error = 0;
    for (std::size_t k = 0; k < scene.size(); ++k) {
      if (scene.isWall(k)) continue;
      const Float100 m(scene.masses[k]);
      const Float100 v0 = Float100(scene.velocities[k]) - frame;
      const Float100 v = exactlyWide(t.velocityValue(k)) - frame;
      const Float100 e(t.velocityBound(k));
      initial += m * v0 * v0 / 2;
      now += m * v * v / 2;
      error += m * (abs(v) * e + e * e / 2);
    }
    error += (initial + now) * ldexp(Float100(1), -300);
    return detail::certifiedNearest(initial - now, error);
  }

  /// When the exact tier has taken every one of the last kGroupStreak impacts (an
  /// accumulation) and they repeat a pattern of period 3 or more, asks it whether the group
  /// collapses (every 8th impact: each try costs a few exact matrix products).
  StepResult groupCollapse(SceneSimulation& result) {
    if (exact_streak_ < kGroupStreak || !exact_ || exact_->count() != fast_->count() || fast_->count() % 8 != 0) {
      return {};
    }
    const std::size_t n = history_.size();
    for (std::size_t period = 3; 3 * period <= n; ++period) {
      bool repeats = true;
      for (std::size_t k = n - 2 * period; k < n && repeats; ++k) repeats = history_[k] == history_[k - period];
      if (!repeats) continue;
      std::vector<std::size_t> pattern(history_.end() - period, history_.end());  // next: pattern[0]
      const auto found = exact_->groupCollapseCandidate(pattern);
      return found ? resolve(*found, result) : StepResult{};
    }
    return {};
  }

  /// The three-cluster collapse test (Tier::collapseCandidate) in double-double, or, where
  /// its bounds do not pin the approach speeds (extreme mass ratios), in the most precise
  /// tier that stands at the same impact (it took the last step; none: no answer yet).
  std::optional<typename Tier<W>::CollapseFound> collapseCandidate(std::size_t p, std::size_t q, bool q_next) const {
    if (fast_->pinsApproaches(p, q)) return fast_->collapseCandidate(p, q, q_next);
    const auto convert = [](const auto& found) -> std::optional<typename Tier<W>::CollapseFound> {
      if (!found) return {};
      return typename Tier<W>::CollapseFound{found->first, found->last, found->time, found->position};
    };
    if (exact_ && exact_->count() == fast_->count()) return convert(exact_->collapseCandidate(p, q, q_next));
    if (high_ && high_->count() == fast_->count()) return convert(high_->collapseCandidate(p, q, q_next));
    return {};
  }

  /// Records a proved collapse and applies it in every tier (each when it reaches this count).
  template <class Found>
  StepResult resolve(const Found& found, SceneSimulation& result) {
    collapses_.push_back({fast_->count(), found.first, found.last});
    result.collapses.push_back({found.first, found.last, found.time, found.position, fast_->count()});
    alternating_ = 0;
    last_ = before_last_ = kNone;
    history_.clear();
    const StepResult r = catchUp<W>();
    result.collapses.back().velocity = fast_->velocity(found.first);
    return r;
  }

 public:
  Escalations escalations() const {
    Escalations e = escalations_;
    e.refinements = fast_->refinements();
    return e;
  }

 private:
  template <class S>
  std::unique_ptr<Tier<S>>& tier() {
    if constexpr (std::is_same_v<S, W>) return fast_;
    if constexpr (std::is_same_v<S, Float100>) return high_;
    if constexpr (std::is_same_v<S, Rational>) return exact_;
  }

  template <class S>
  StepResult startOrEscalate() {
    auto& t = tier<S>();
    t = std::make_unique<Tier<S>>(tables_);
    StepResult r = t->start();
    if constexpr (!Arithmetic<S>::kExact) {
      if (r.kind == StepKind::kAmbiguous) {
        using H = typename NextTier<S>::type;
        r = startOrEscalate<H>();
        t->adopt(*tier<H>());
      }
    }
    return r;
  }

  /// One step of tier S; what it cannot decide, the next tier decides.
  template <class S>
  StepResult stepOrEscalate(ImpactRecord* record) {
    Tier<S>& t = *tier<S>();
    const std::uint64_t count = t.count();
    if (exact_streak_ >= kExactStreak && t.oversized()) {
      budget_stop_.streak = exact_streak_;
      return {StepKind::kExhausted, 0, t.lastTime()};
    }
    // The cap foreseen: the exact steps in a row, each dearer than the last, would spend the
    // budget before the cap.
    if constexpr (Arithmetic<S>::kExact) {
      if (forecast_ && exact_streak_ < kExactStreak && t.oversized() &&
          streak_work_.predicted(kExactStreak - exact_streak_) > budget_) {
        budget_stop_.streak = exact_streak_;
        budget_stop_.predicted = true;
        return {StepKind::kExhausted, 0, t.lastTime()};
      }
    }
    if constexpr (Arithmetic<S>::kExact) {
      if (cancel_ && cancel_->load(std::memory_order_relaxed)) return {StepKind::kCancelled, 0, t.lastTime()};
    }
    StepResult r;
    if constexpr (std::is_same_v<S, DD>) {
      r = t.stepInlined(record);
#if CL_HAS_FMA_PATH
    } else if constexpr (std::is_same_v<S, DDFma>) {
      r = t.stepInlinedFma(record);
#endif
    } else {
      r = t.step(record);
    }
    if constexpr (Arithmetic<S>::kExact) {
      if (r.kind == StepKind::kAmbiguous || r.kind == StepKind::kImprecise) r.kind = StepKind::kInconsistent;  // cannot happen
      return r;
    } else {
      if (r.kind != StepKind::kAmbiguous && r.kind != StepKind::kImprecise) return r;
      if constexpr (std::is_same_v<S, W>) undecided_pair_ = r.pair;
      // A value exactly 0 in double-double is in practice an exact tie, which 100 digits
      // cannot settle either: go straight to the rationals.
      if constexpr (std::is_same_v<S, W>) {
        if (r.at_zero) return escalate<S, Rational>(r, count, record);
      }
      return escalate<S, typename NextTier<S>::type>(r, count, record);
    }
  }

  /// Tier H takes the step that tier S could not; S then follows it in O(1), or adopts H's
  /// state when its own is too imprecise.
  template <class S, class H>
  StepResult escalate(const StepResult& r, std::uint64_t count, ImpactRecord* record) {
    ++(std::is_same_v<H, Float100> ? escalations_.high_precision : escalations_.exact_rational);
    const StepResult higher = advanceAndStep<H>(count, record);
    if (stopsRun(higher)) return higher;  // tier S keeps its state, at `count`
    Tier<S>& t = *tier<S>();
    const bool followed =
        r.kind == StepKind::kAmbiguous && higher.kind == StepKind::kImpact && t.follow(*tier<H>(), higher.pair);
    if (!followed) t.adopt(*tier<H>());
    // Velocities after that tier H did not certify: what this tier now holds.
    if (record && higher.kind == StepKind::kImpact && (record->uncertified & kPairVelocitiesAfter)) {
      record->velocities_after = {t.velocity(higher.pair), t.velocity(tables_.scene.leftOf(higher.pair))};
    }
    return higher;
  }

  /// Brings tier S to `target` impacts (creating it from the scene on first use), then
  /// takes the next step there.
  template <class S>
  StepResult advanceAndStep(std::uint64_t target, ImpactRecord* record) {
    const StepResult r = advanceTo<S>(target);
    if (r.kind != StepKind::kImpact) return r;
    return stepOrEscalate<S>(record);
  }

  /// Brings tier S to `target` impacts and applies the collapses due there.
  template <class S>
  StepResult advanceTo(std::uint64_t target) {
    if (!tier<S>()) {
      const StepResult r = startOrEscalate<S>();
      if (r.kind != StepKind::kImpact) return {StepKind::kInconsistent, r.pair, r.time};
    }
    skipAhead<S>(target);
    if (tier<S>()->count() > target) return {StepKind::kInconsistent, 0, 0.0};
    // A replay must retrace the impacts already taken; only the exact tier's size cap and
    // budget, or cancellation, may stop it.
    const auto failed = [](const StepResult& r) {
      return stopsRun(r) ? r : StepResult{StepKind::kInconsistent, r.pair, r.time};
    };
    WorkForecast work;  // of this replay in the exact tier [bit^2]
    for (;;) {
      const StepResult c = catchUp<S>();
      if (c.kind != StepKind::kImpact) return failed(c);
      if (tier<S>()->count() == target) return {};
      if constexpr (Arithmetic<S>::kExact) {
        const double bits = tier<S>()->exactBits();
        work.add(bits * bits);
        const bool spent = work.total() > budget_;
        if (spent || (forecast_ && work.predicted(target - tier<S>()->count()) > budget_)) {
          budget_stop_.replay_target = target;
          budget_stop_.predicted = !spent;
          return {StepKind::kOverBudget, 0, tier<S>()->lastTime()};
        }
      }
      const StepResult r = stepOrEscalate<S>(nullptr);
      if (r.kind != StepKind::kImpact) return failed(r);
      ++escalations_.replayed_impacts;
    }
  }

  /// The next tier may be ahead of tier S, at most at `target`: an exact tie goes from
  /// double-double straight to the rationals, past the 100-digit tier. Tier S then starts
  /// from that state, so its replay never asks the next tier to decide at a count it has
  /// already passed (it cannot go back: that was the tiers' disagreement).
  template <class S>
  void skipAhead(std::uint64_t target) {
    if constexpr (!Arithmetic<S>::kExact) {
      const auto& higher = tier<typename NextTier<S>::type>();
      Tier<S>& t = *tier<S>();
      if (higher && higher->count() > t.count() && higher->count() <= target) t.adopt(*higher);
    }
  }

  /// Applies to tier S the collapses due at its count; a neighbour's schedule it cannot
  /// decide there, the next tier decides (tier S then adopts its state).
  template <class S>
  StepResult catchUp() {
    Tier<S>& t = *tier<S>();
    while (t.merged() < collapses_.size() && collapses_[t.merged()].count == t.count()) {
      const CollapseEvent& c = collapses_[t.merged()];
      const StepResult r = t.merge(c.first, c.last);
      if (r.kind == StepKind::kImpact) continue;
      if constexpr (Arithmetic<S>::kExact) {
        return {StepKind::kInconsistent, r.pair, r.time};
      } else {
        const StepResult h = advanceTo<typename NextTier<S>::type>(t.count());
        if (h.kind != StepKind::kImpact) return h;
        t.adopt(*tier<typename NextTier<S>::type>());
      }
    }
    return {};
  }

  /// The exact tier stopped (or was stopped) before deciding: the run ends at the working
  /// tier's last certified impact.
  static bool stopsRun(const StepResult& r) {
    return r.kind == StepKind::kExhausted || r.kind == StepKind::kOverBudget || r.kind == StepKind::kCancelled;
  }

  /// A collapse of bodies first..last, applied after `count` impacts.
  struct CollapseEvent {
    std::uint64_t count;
    std::size_t first, last;
  };
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

  std::vector<CollapseEvent> collapses_;
  std::size_t last_ = kNone, before_last_ = kNone;  ///< pairs of the last two impacts
  std::uint64_t alternating_ = 0;                   ///< impacts alternating between them
  std::uint64_t exact_streak_ = 0;                  ///< impacts in a row that needed the exact tier
  WorkForecast streak_work_;                        ///< the exact tier's work on those impacts [bit^2]
  ExactProgress budget_stop_;                       ///< how the exact tier's budget stopped the run
  std::array<std::size_t, kCrowdWindow> crowd_{};   ///< pairs of the last impacts that escalated (a ring)
  std::size_t crowd_next_ = 0;                      ///< impacts that escalated so far
  std::size_t undecided_pair_ = kNone;              ///< the pair of the last decision double-double could not take
  std::deque<std::size_t> history_;                 ///< pairs of the last impacts (3 kMaxPeriod at most)
  static constexpr std::uint64_t kGroupStreak = 16;
  SceneTables tables_;
  const std::atomic<bool>* cancel_;
  double budget_;   ///< EngineOptions::exact_work_budget [bit^2]
  bool forecast_;   ///< EngineOptions::forecast_exact_work
  std::unique_ptr<Tier<W>> fast_;
  std::unique_ptr<Tier<Float100>> high_;
  std::unique_ptr<Tier<Rational>> exact_;
  Escalations escalations_;
  bool beyond_range_ = false;          ///< stepBeyondRange(): the exact tier leads the run
};

std::string formatValue(double value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::string(buffer, end);
}

/// The frame in which kinetic energy is conserved: the walls' (the lab without walls).
/// Empty when two walls move at different velocities.
std::optional<double> energyFrame(const Scene& scene) {
  const std::size_t last = scene.size() - 1;
  const bool right = scene.isWall(0), left = scene.size() > 1 && scene.isWall(last);
  if (right && left && scene.velocities[0] != scene.velocities[last]) return std::nullopt;
  if (right) return scene.velocities[0];
  if (left) return scene.velocities[last];
  return 0.0;
}

void fillDrift(const Scene& scene, SceneSimulation& result) {
  long double e0 = 0, e1 = 0, p0 = 0, p1 = 0, magnitude = 0;
  const std::optional<double> frame = energyFrame(scene);
  for (std::size_t k = 0; k < scene.size(); ++k) {
    if (scene.isWall(k)) continue;
    const long double m = scene.masses[k];
    const long double v0 = scene.velocities[k], v1 = result.final_velocities[k];
    const long double w = frame.value_or(0.0);
    e0 += m * (v0 - w) * (v0 - w) / 2;
    e1 += m * (v1 - w) * (v1 - w) / 2;
    p0 += m * v0;
    p1 += m * v1;
    magnitude += m * std::fabs(v0);
  }
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (!frame) {
    result.energy_relative_drift = kNaN;
  } else {
    const long double error = std::fabs(e1 + result.energy_lost - e0);
    result.energy_relative_drift = static_cast<double>(e0 > 0 ? error / e0 : error);
  }
  result.momentum_relative_drift =
      scene.wallCount() > 0 ? kNaN : static_cast<double>(magnitude > 0 ? std::fabs(p1 - p0) / magnitude : 0.0L);
}

/// Ascending indices as ranges: "3-5, 9".
std::string indexRanges(const std::vector<std::size_t>& indices) {
  std::string text;
  for (std::size_t k = 0; k < indices.size();) {
    std::size_t end = k;
    while (end + 1 < indices.size() && indices[end + 1] == indices[end] + 1) ++end;
    text += (text.empty() ? "" : ", ") + std::to_string(indices[k]);
    if (end > k) text += "-" + std::to_string(indices[end]);
    k = end + 1;
  }
  return text;
}

/// The models that carry a run past an accumulation of constant-e impacts (none to name
/// when the scene already has a velocity-dependent model).
std::string modelAdvice(const Scene& scene) {
  if (scene.restitution_model.kind != RestitutionModelKind::kConstant) return "";
  return "; a model of the physics there goes on: --restitution-model tc or --restitution-model viscoelastic";
}

/// How a run met an impact past the largest double and the tiers' range.
enum class BeyondRange {
  kNotMet,        ///< it did not
  kGoneOn,        ///< the exact tier took the run on alone
  kNotEligible,   ///< the scene may not go on there (inelastic, a ring or a box)
  kReplayFailed,  ///< the exact replay to there exceeded its work budget
};

std::string stopMessage(const Scene& scene, const SceneSimulation& result, bool exhausted, BeyondRange beyond,
                        const ExactProgress& exact) {
  // "1 impact", "31,415 impacts".
  const std::string impacts = countText(result.impact_count) + (result.impact_count == 1 ? " impact" : " impacts");
  switch (result.stop) {
    case StopReason::kFinished: {
      std::string text = "no pair approaches any more after " + impacts + ": the run is complete";
      for (const Collapse& c : result.collapses) {
        text += "; bodies " + bodyName(c.first_body) + " to " + bodyName(c.last_body) +
                " collapsed (infinitely many impacts) at t = " + formatValue(c.time) + " s, x = " +
                formatValue(c.position) + " m, and move on as one";
      }
      if (result.cluster_impacts > 0) {
        text += "; " + countText(result.cluster_impacts) + " impacts hit a cluster as one body of its total mass";
      }
      if (result.rule_elastic_impacts > 0) {
        text += "; " + countText(result.rule_elastic_impacts) + " impacts made elastic by the " +
                restitutionModelName(scene.restitution_model.kind) + " restitution model";
      }
      return text;
    }
    case StopReason::kCap:
      if (exhausted && beyond == BeyondRange::kGoneOn) {
        return "stopped after " + impacts + " at the exactness cap (truncated): past t = " +
               formatValue(std::numeric_limits<double>::max()) +
               " s, the largest double, the run went on in exact rationals alone, and " +
               countText(kExactStreak) + " impacts in a row needed numbers of more than " +
               std::to_string(kExactBits) + " bits";
      }
      if (exhausted) {
        std::string foreseen;
        if (exact.predicted) {
          foreseen = ", foreseen after " + countText(exact.streak) + " exact impacts in a row: the " +
                     countText(kExactStreak - exact.streak) +
                     " more up to the cap would, at the work of the last ones (numbers of " + countText(exact.bits) +
                     " bits), spend more than the work budget of one decision";
        }
        return "stopped after " + impacts + " at the exactness cap (truncated)" + foreseen +
               ": the impacts accumulate, each needing exact arithmetic of more than " + std::to_string(kExactBits) +
               " bits: a collapse of a kind the engine does not resolve (engine.h, Collapse), or a spiral just above "
               "its critical restitution, whose approach speeds shrink by ever more bits (the three_body_spiral "
               "model counts it); the impacts crowd among bodies " +
               indexRanges(result.crowding_bodies) +
               " (indices from 0)" + modelAdvice(scene);
      }
      return "stopped at the cap of " + impacts + " (truncated)" +
             (scene.wallCount() == 2 ? "; two walls keep the bodies between them colliding forever" : "");
    case StopReason::kCancelled: return "cancelled after " + impacts + " (truncated)";
    case StopReason::kMultipleCollision: {
      const MultipleCollision& c = *result.multiple_collision;
      return bodyName(c.first_body) + ", " + bodyName(scene.leftOf(c.first_body)) + " and " +
             bodyName(scene.leftOf(scene.leftOf(c.first_body))) +
             " meet at the same instant t = " + formatValue(c.time) + " s after " + impacts +
             ": a multiple collision, whose outcome point masses do not define, so the run ends here";
    }
    case StopReason::kOutOfRange:
      if (beyond != BeyondRange::kNotMet) {
        const std::string why =
            beyond == BeyondRange::kReplayFailed
                ? "the exact replay to there, which goes on past it, would exceed its work budget"
                : "past it only the exact tier goes on, and only in elastic scenes without a ring or a box";
        return "stopped after " + impacts + " (truncated): the next impact comes after t = " +
               formatValue(std::numeric_limits<double>::max()) +
               " s, the largest double, and beyond the engine's working range (2^900 in its units); " + why +
               ", so the run cannot go on";
      }
      return "stopped after " + impacts + " (truncated): the next one would take a time, position or velocity "
             "beyond 2^900 in the run's working units (the powers of two of m, m/s and kg that bring the scene's "
             "largest position, velocity and mass near 1): the scene's own scales spread wider than one change of "
             "units brings into the range of a double";
    case StopReason::kInternalError:
      return "the engine's precision tiers disagreed after " + impacts + " (a bug, please report it); "
             "the run ends here";
    case StopReason::kPrecisionBudget:
      return "stopped after " + countText(result.impact_count) + " certified impacts (truncated): the next decision needs exact arithmetic, "
             "whose numbers grow with every impact of the run; its exact replay " +
             (exact.predicted ? "would exceed the work budget: after " + countText(exact.count) + " of the " +
                                    countText(exact.replay_target) + " impacts to replay, with numbers of " +
                                    countText(exact.bits) + " bits, the work so far and that of its last impacts " +
                                    "foresee more than the budget"
                              : "reached the work budget after " + countText(exact.count) +
                                    " impacts, with numbers of " + countText(exact.bits) + " bits") +
             ", so the next impact cannot be decided; the impacts crowd among bodies " +
             indexRanges(result.crowding_bodies) +
             " (indices from 0), as on the way to an inelastic collapse that the engine does not resolve" +
             modelAdvice(scene);
  }
  return "";
}

/// Maps a step that did not produce an impact to the way the run ends.
void finish(const StepResult& r, SceneSimulation& result) {
  switch (r.kind) {
    case StepKind::kImpact:
    case StepKind::kFinished: result.stop = StopReason::kFinished; break;
    case StepKind::kMultipleCollision:
      result.stop = StopReason::kMultipleCollision;
      result.multiple_collision = MultipleCollision{r.pair, r.time};
      break;
    case StepKind::kOutOfRange: result.stop = StopReason::kOutOfRange; break;
    case StepKind::kExhausted: result.stop = StopReason::kCap; break;
    case StepKind::kOverBudget: result.stop = StopReason::kPrecisionBudget; break;
    case StepKind::kCancelled: result.stop = StopReason::kCancelled; break;
    case StepKind::kAmbiguous:
    case StepKind::kImprecise:
    case StepKind::kInconsistent: result.stop = StopReason::kInternalError; break;
  }
}

}  // namespace

void fillEngineDrift(const Scene& scene, SceneSimulation& result) { fillDrift(scene, result); }

}  // namespace nbody_detail

const char* stopReasonName(StopReason reason) {
  switch (reason) {
    case StopReason::kFinished: return "FINISHED";
    case StopReason::kCap: return "CAP";
    case StopReason::kCancelled: return "CANCELLED";
    case StopReason::kMultipleCollision: return "MULTIPLE_COLLISION";
    case StopReason::kOutOfRange: return "OUT_OF_RANGE";
    case StopReason::kInternalError: return "INTERNAL_ERROR";
    case StopReason::kPrecisionBudget: return "PRECISION_BUDGET";
  }
  return "UNKNOWN";
}

const char* impactValueName(int k) {
  static const char* const kNames[kImpactValueCount] = {
      "time",           "position",          "pair_velocities_before",     "pair_velocities_after",
      "pair_energy_transfer", "energy_lost", "positions",                  "velocities_before",
      "velocities_after",     "energy_transfer", "kinetic_energy_after",   "total_energy",
      "total_momentum",       "predicted_velocities_after", "predicted_energy_transfer", "paper_velocities_after",
      "paper_energy_transfer"};
  return k >= 0 && k < kImpactValueCount ? kNames[k] : "";
}

namespace {

/// Names `key` in result.uncertified, once.
void nameUncertified(SceneSimulation& result, const char* key) {
  auto& keys = result.uncertified;
  if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
}

/// Certifies the run's final velocities and heat once (physics.md, "How close the published
/// values are"), in working units: a replay only for runs of up to kCertifyingReplay impacts;
/// a value none certifies keeps the working tier's and is named uncertified. A value
/// subnormal in SI rounds again when scaled there: such a velocity is returned, its exact
/// value scaled exactly and rounded [m/s], for after the conversion; such a heat is named.
template <class W>
std::vector<std::pair<std::size_t, double>> certifyFinalValues(nbody_detail::Driver<W>& driver,
                                                               const nbody_detail::WorkingUnits& units,
                                                               SceneSimulation& result) {
  using nbody_detail::Rational;
  const Scene& scene = units.scene;
  const bool replay = result.impact_count <= nbody_detail::kCertifyingReplay;
  const std::vector<std::optional<double>> certified = driver.certifiedVelocities(replay);
  for (std::size_t k = 0; k < certified.size(); ++k) {
    if (certified[k]) {
      result.final_velocities[k] = *certified[k];
    } else {
      nameUncertified(result, "final_velocities");
    }
  }
  if (result.energy_lost != 0.0) {  // an inelastic impact (elastic ones lose exactly 0)
    if (const auto heat = driver.certifiedHeat(replay)) {
      result.energy_lost = *heat;
    } else {
      nameUncertified(result, "energy_lost");
    }
  }
  const int to_si = -units.velocity_shift;
  std::vector<std::pair<std::size_t, double>> subnormal;
  for (std::size_t k = 0; k < result.final_velocities.size(); ++k) {
    const double v = result.final_velocities[k];
    if (v == 0 || scene.isWall(k) || !(std::fabs(std::ldexp(v, to_si)) < std::numeric_limits<double>::min())) continue;
    const std::optional<Rational> exact = replay ? driver.exactVelocity(k) : std::nullopt;
    if (exact) {
      subnormal.emplace_back(k, detail::nearestDouble(nbody_detail::scaledByPowerOfTwo(*exact, to_si)));
    } else {
      nameUncertified(result, "final_velocities");
    }
  }
  if (result.energy_lost != 0.0 &&
      std::fabs(std::ldexp(result.energy_lost, -units.energyShift())) < std::numeric_limits<double>::min()) {
    nameUncertified(result, "energy_lost");
  }
  return subnormal;
}

/// runEngine with the working tier W (nbody_detail::DD or DDFma).
template <class W>
SceneSimulation runEngineOn(const Scene& si_scene, const EngineOptions& options, const ImpactVisitor& visitor,
                            const ProgressCallback& progress, const CollapseVisitor& on_collapse) {
  using namespace nbody_detail;
  // The run takes place in working units (units.h); every value leaves it in SI.
  const WorkingUnits units(si_scene);
  const Scene& scene = units.scene;
  const ToSi si(units);
  // The largest working time [s * 2^timeShift] whose SI value a double holds (inf: any).
  constexpr double kLargest = std::numeric_limits<double>::max();
  const double time_limit = static_cast<double>(std::ldexp(static_cast<long double>(kLargest), units.timeShift()));
  // A value subnormal in SI is rounded a second time there: no longer certified.
  const auto toSiRecord = [&si](ImpactRecord& record) {
    const auto scaled = [&record](double x, ImpactValue bit) {
      if (x != 0 && std::fabs(x) < std::numeric_limits<double>::min()) record.uncertified |= bit;
      return x;
    };
    record.time = scaled(si.time(record.time), kImpactTime);
    record.position = scaled(si.position(record.position), kImpactPosition);
    for (double& v : record.velocities_before) v = scaled(si.velocity(v), kPairVelocitiesBefore);
    for (double& v : record.velocities_after) v = scaled(si.velocity(v), kPairVelocitiesAfter);
    for (double& e : record.energy_gained) e = scaled(si.energy(e), kPairEnergyTransfer);
    record.energy_lost = scaled(si.energy(record.energy_lost), kImpactEnergyLost);
  };
  const auto toSiCollapse = [&si](Collapse c) {
    c.time = si.time(c.time);
    c.position = si.position(c.position);
    c.velocity = si.velocity(c.velocity);
    return c;
  };
  SceneSimulation result;
  result.simulated = true;
  Driver<W> driver(scene, options);
  StepResult r = driver.start();
  const bool wants_records = static_cast<bool>(visitor) || options.keep_events > 0;
  ImpactRecord record;
  std::uint64_t& count = result.impact_count;
  bool beyond_doubles = false;  // the next impact's time [s] is beyond the largest double
  // Beyond the range the exact tier goes on alone only where the impacts are elastic (no
  // collapse to detect) and few (no ring, no box: their impacts never end).
  const bool may_go_beyond_range = scene.isElastic() &&
                                   scene.restitution_model.kind != RestitutionModelKind::kViscoelastic &&
                                   !scene.isRing() && !(scene.isWall(0) && scene.isWall(scene.size() - 1));
  while (r.kind == StepKind::kImpact) {
    if (!driver.leading([](const auto& t) { return t.pending(); })) break;
    if (count == options.max_impacts) {
      result.stop = StopReason::kCap;
      break;
    }
    if (options.cancel && count % 1024 == 0 && options.cancel->load(std::memory_order_relaxed)) {
      result.stop = StopReason::kCancelled;
      break;
    }
    ImpactRecord* const into = wants_records ? &record : nullptr;
    r = driver.beyondRange() ? driver.stepBeyondRange(into) : driver.step(into);
    // Out of range with the next impact past the largest double: counted all the same, in
    // the exact tier, its time +inf (time_beyond_range), where the scene may go there
    // (above); where the exact tier cannot be brought there (its budget), the out-of-range
    // stop stands.
    if (r.kind == StepKind::kOutOfRange && may_go_beyond_range && !driver.beyondRange() &&
        (!(r.time <= time_limit) || !(driver.exactNextTimeLowerBound() <= time_limit))) {
      beyond_doubles = true;
      const StepResult beyond = driver.stepBeyondRange(into);
      if (driver.beyondRange() || beyond.kind == StepKind::kCancelled) r = beyond;
    }
    if (r.kind != StepKind::kImpact) break;
    ++count;
    if (wants_records) {
      record.index = count;
      if (!units.identity()) toSiRecord(record);
      if (visitor) visitor(record);
      if (count <= options.keep_events) result.impacts.push_back(record);
    }
    if (!driver.beyondRange()) {  // beyond it every impact is elastic: no collapse to look for
      const std::size_t collapses = result.collapses.size();
      const StepResult collapse = driver.afterImpact(r.pair, result);
      if (collapse.kind != StepKind::kImpact) {
        r = collapse;
        break;
      }
      if (on_collapse && result.collapses.size() > collapses) on_collapse(toSiCollapse(result.collapses.back()));
    }
    if (progress && options.progress_interval > 0 && count % options.progress_interval == 0) {
      progress(EngineProgress{count, si.time(driver.leading([](const auto& t) { return t.lastTime(); }))});
    }
  }
  if (result.stop == StopReason::kFinished) finish(r, result);
  // A tier's out-of-range step bounds the next impact's time from below; where that bound
  // does not tell, the exact tier's does (once, at the stop): beyond the largest double?
  if (r.kind == StepKind::kOutOfRange && !beyond_doubles &&
      (!(r.time <= time_limit) || !(driver.exactNextTimeLowerBound() <= time_limit))) {
    beyond_doubles = true;
  }
  // Out of range: the double format cannot hold the run's next values; impacts were due.
  result.truncated = result.stop == StopReason::kCap || result.stop == StopReason::kCancelled ||
                     result.stop == StopReason::kPrecisionBudget || result.stop == StopReason::kOutOfRange;
  if (result.stop == StopReason::kPrecisionBudget || r.kind == StepKind::kExhausted) {
    result.crowding_bodies = driver.crowdingBodies();
  }
  result.final_time = driver.leading([](const auto& t) { return t.lastTime(); });
  if (const auto certified = driver.leading([](const auto& t) { return t.certifiedLastTime(); })) {
    result.final_time = *certified;
  } else {
    nameUncertified(result, "final_time");
  }
  result.collapsed = !result.collapses.empty();
  if (result.collapsed && !(result.collapses.back().time <= result.final_time)) {
    result.final_time = result.collapses.back().time;  // the engine's, from its state at the time
    nameUncertified(result, "final_time");
  }
  // An impact after the largest double [s] was counted and published with time +inf.
  result.time_beyond_range = !(result.final_time <= time_limit);
  driver.leading([&](const auto& t) {
    result.cluster_impacts = t.clusterImpacts();
    result.rule_elastic_impacts = t.ruleElastic();
    if (driver.beyondRange()) {
      driver.exactStateAtLastImpact(result.final_positions, result.final_velocities);
    } else {
      t.state(result.final_time, result.final_positions, result.final_velocities);
    }
    result.energy_lost = t.energyLost();
  });
  result.escalations = driver.escalations();  // the run's decisions, before any certifying replay
  // Set after the SI conversion: velocities subnormal in SI, correctly rounded there [m/s].
  const std::vector<std::pair<std::size_t, double>> subnormal_velocities = certifyFinalValues(driver, units, result);
  fillDrift(scene, result);  // relative: the same in any units
  // Back to SI.
  result.final_time = si.time(result.final_time);
  for (double& x : result.final_positions) x = si.position(x);
  for (double& v : result.final_velocities) v = si.velocity(v);
  for (const auto& [k, v] : subnormal_velocities) result.final_velocities[k] = v;
  result.energy_lost = si.energy(result.energy_lost);
  for (Collapse& c : result.collapses) c = toSiCollapse(c);
  if (result.collapsed) {
    result.collapse_time = result.collapses.front().time;
    result.collapse_position = result.collapses.front().position;
  }
  if (result.multiple_collision) result.multiple_collision->time = si.time(result.multiple_collision->time);
  const BeyondRange beyond = driver.beyondRange() ? BeyondRange::kGoneOn
                             : !beyond_doubles      ? BeyondRange::kNotMet
                             : may_go_beyond_range  ? BeyondRange::kReplayFailed
                                                    : BeyondRange::kNotEligible;
  result.stop_message = stopMessage(si_scene, result, r.kind == StepKind::kExhausted, beyond, driver.exactProgress());
  return result;
}

}  // namespace

SceneSimulation runEngine(const Scene& si_scene, const EngineOptions& options, const ImpactVisitor& visitor,
                          const ProgressCallback& progress, const CollapseVisitor& on_collapse) {
#if CL_HAS_FMA_PATH
  if (nbody_detail::fmaPathEnabled()) {
    return runEngineOn<nbody_detail::DDFma>(si_scene, options, visitor, progress, on_collapse);
  }
#endif
  return runEngineOn<nbody_detail::DD>(si_scene, options, visitor, progress, on_collapse);
}

namespace nbody_detail {

SceneSimulation runEngineOnPath(bool fma, const Scene& scene, const EngineOptions& options,
                                const ImpactVisitor& visitor) {
#if CL_HAS_FMA_PATH
  if (fma) return runEngineOn<DDFma>(scene, options, visitor, {}, {});
#endif
  (void)fma;
  return runEngineOn<DD>(scene, options, visitor, {}, {});
}

}  // namespace nbody_detail

}  // namespace core
}  // namespace collision_lab
