#include "rotation_run.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>

#include "collision_lab/core/count_text.h"
#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/paper.h"
#include "collision_lab/core/precision.h"
#include "collision_lab/core/wedge.h"
#include "correct_rounding.h"
#include "float_ops.h"
#include "impact_energy.h"
#include "nbody/elastic_triple.h"
#include "nbody/units.h"

namespace collision_lab {
namespace core {

namespace {

/// In double, a zero always +0 (outputs must not show "-0").
template <class Vector>
std::array<double, 3> toArray(const Vector& v) {
  return {detail::toDouble(v(0)), detail::toDouble(v(1)), detail::toDouble(v(2))};
}

template <class T>
std::array<double, 3> toArray(const std::array<T, 3>& v) {
  return toArray(Eigen::Matrix<T, 3, 1>(v[0], v[1], v[2]));
}

/// The exact walk's budget (ExactInTurn): the bits its common denominator may reach. Each
/// impact adds the bits of its pair's Q (7 for masses 100 and 1, about 54 for random
/// doubles, none against a wall), and its cost grows with them; beyond the budget the
/// certified product of the impact maps (about 0.1 ms at any count) is the cheaper
/// certificate of a final state.
constexpr std::uint64_t kExactWalkBits = 16384;
/// Impacts up to which every impact's values (not only the final state) come from the exact
/// walk, within its budget; longer runs keep the closed form in double per impact.
constexpr std::uint64_t kExactEventLimit = 64;

/// The longest run whose final velocities the filtered walk (filteredVelocitiesAfter) tries
/// first: its bound grows with the count (on seeded scenes it decides 99% of runs of up to 4
/// impacts, 90% up to 16, a third up to 64, none longer).
constexpr std::uint64_t kFilteredWalkLimit = 64;

/// Does the exact walk of `count` impacts of these masses stay within kExactWalkBits?
bool exactWalkAffordable(const std::array<double, 3>& masses, std::uint64_t count) {
  std::uint64_t bits_per_impact = 0;
  for (int p = 0; p < 2; ++p) {
    if (std::isinf(masses[p]) || std::isinf(masses[p + 1])) continue;
    const exact::Rational sum = exact::Rational(masses[p]) + exact::Rational(masses[p + 1]);
    const exact::Rational f = exact::Rational(masses[p]) / sum;
    bits_per_impact = std::max<std::uint64_t>(bits_per_impact, msb(denominator(f)) + 1);
  }
  return bits_per_impact == 0 || count <= kExactWalkBits / bits_per_impact;
}

/// The certified product's own range (as the known-count pass checks it): no finite mass
/// ratio of a pair below 2^-900, where S = diag(sqrt(m / m_max)) would lose its bound.
bool productInRange(const std::array<double, 3>& masses) {
  for (int p = 0; p < 2; ++p) {
    const double light = std::min(masses[p], masses[p + 1]), heavy = std::max(masses[p], masses[p + 1]);
    if (!std::isinf(heavy) && !(light / heavy > 0x1p-900)) return false;
  }
  const double largest = largestFiniteMass(masses);
  for (const double m : masses) {
    if (!std::isinf(m) && !(m / largest > 0x1p-900)) return false;
  }
  return true;
}

/// The exact state after impacts n = 0, 1, 2, ... of a scene whose pairs alternate from its
/// first pair, each value rounded once: the model's (and the run's) per-impact values of a
/// short run, correctly rounded. The velocities are integers over one common denominator D:
/// an impact of the pair (i, j = i + 1), with f = m_i / (m_i + m_j) = P / Q, maps
/// N_i -> Q N_i + 2 (Q - P)(N_j - N_i), N_j -> Q N_j - 2 P (N_j - N_i), the third body's
/// N -> Q N, and D -> Q D: integer products only (rationals would reduce by a gcd at every
/// operation), the numbers growing by the bits of Q per impact. A wall (f = 1 or 0, Q = 1)
/// keeps its velocity.
class ExactInTurn {
 public:
  using Integer = boost::multiprecision::cpp_int;

  explicit ExactInTurn(const Scene& scene) : scene_(scene), first_(firstPair(scene).value_or(Pair::AB)) {
    for (int p = 0; p < 2; ++p) {
      const double m_i = scene.masses[p], m_j = scene.masses[p + 1];
      const exact::Rational f = std::isinf(m_i)   ? exact::Rational(1)
                                : std::isinf(m_j) ? exact::Rational(0)
                                                  : exact::Rational(m_i) / (exact::Rational(m_i) + exact::Rational(m_j));
      fraction_[p] = {numerator(f), denominator(f)};
    }
    // Masses over one power of two, m_k = mass_[k] / mass_scale_ (0 for a wall: it has no
    // kinetic energy or momentum of its own here).
    for (std::size_t k = 0; k < 3; ++k) {
      if (scene.isWall(k)) continue;
      mass_scale_ = boost::multiprecision::lcm(mass_scale_, denominator(exact::Rational(scene.masses[k])));
    }
    for (std::size_t k = 0; k < 3; ++k) {
      if (scene.isWall(k)) continue;
      const exact::Rational m(scene.masses[k]);
      mass_[k] = numerator(m) * (mass_scale_ / denominator(m));
    }
    for (std::size_t k = 0; k < 3; ++k) start_.scale = lcm(start_.scale, denominator(exact::Rational(scene.velocities[k])));
    for (std::size_t k = 0; k < 3; ++k) {
      const exact::Rational v(scene.velocities[k]);
      start_.top[k] = numerator(v) * (start_.scale / denominator(v));
    }
    restart();
  }

  /// The velocities after impact n [m/s], correctly rounded.
  std::array<double, 3> velocitiesAfter(std::uint64_t n) {
    moveTo(n);
    return rounded(state_);
  }

  /// The state before and after impact n >= 1 and its energies and momentum, each correctly
  /// rounded: the values of `state` that the exact walk knows (not the positions).
  void fillState(std::uint64_t n, ImpactModelValues& state) {
    state.energy_transfer = energyTransfer(n);
    state.velocities_before = rounded(before_);
    state.velocities_after = rounded(state_);
    // K = sum m_k N_k^2 / (2 mass_scale D^2), P = sum m_k N_k / (mass_scale D).
    Integer energy = 0, momentum = 0;
    const Integer energy_scale = 2 * mass_scale_ * state_.scale * state_.scale;
    for (std::size_t k = 0; k < 3; ++k) {
      state.kinetic_energy_after[k] = 0.0;
      if (scene_.isWall(k)) continue;
      const Integer kinetic = mass_[k] * state_.top[k] * state_.top[k];
      state.kinetic_energy_after[k] = detail::nearestDouble(kinetic, energy_scale);
      energy += kinetic;
      momentum += mass_[k] * state_.top[k];
    }
    state.total_energy = detail::nearestDouble(energy, energy_scale);
    state.total_momentum = detail::nearestDouble(momentum, mass_scale_ * state_.scale);
  }

  /// The exact velocities before impact n >= 1 [m/s].
  paper::ScaledState velocitiesBefore(std::uint64_t n) {
    moveTo(n);
    return {before_.top, before_.scale};
  }

  /// The kinetic energy each body gains in impact n >= 1 [J], correctly rounded; a wall's entry
  /// is minus the other body's (elastic: the pair's gains cancel), the third body's 0.
  std::array<double, 3> energyTransfer(std::uint64_t n) {
    moveTo(n);
    const int i = pairIndex(n % 2 == 1 ? first_ : otherPair(first_));
    // Before, over the new denominator: N Q / (D Q).
    const Integer& q = fraction_[i].second;
    const Integer scale = 2 * mass_scale_ * state_.scale * state_.scale;
    std::array<double, 3> gained{0.0, 0.0, 0.0};
    for (const int body : {i, i + 1}) {
      if (scene_.isWall(static_cast<std::size_t>(body))) continue;
      const Integer old_top = before_.top[body] * q;
      gained[body] = detail::nearestDouble(mass_[body] * (state_.top[body] * state_.top[body] - old_top * old_top), scale);
    }
    for (const int body : {i, i + 1}) {
      if (scene_.isWall(static_cast<std::size_t>(body))) gained[body] = detail::toDouble(-gained[2 * i + 1 - body]);
    }
    return gained;
  }

 private:
  struct State {
    std::array<Integer, 3> top;
    Integer scale = 1;  // the common denominator D
  };

  static std::array<double, 3> rounded(const State& v) {
    return {detail::nearestDouble(v.top[0], v.scale), detail::nearestDouble(v.top[1], v.scale),
            detail::nearestDouble(v.top[2], v.scale)};
  }
  void restart() {
    state_ = before_ = start_;
    n_ = 0;
  }
  void moveTo(std::uint64_t n) {
    if (n < n_) restart();
    while (n_ < n) {
      before_ = state_;
      const int i = pairIndex(n_ % 2 == 0 ? first_ : otherPair(first_));
      const auto& [p, q] = fraction_[i];
      const Integer approach = state_.top[i + 1] - state_.top[i];
      for (Integer& top : state_.top) top *= q;
      state_.top[i] += 2 * (q - p) * approach;
      state_.top[i + 1] -= 2 * p * approach;
      state_.scale *= q;
      ++n_;
    }
  }

  Scene scene_;
  Pair first_;
  std::array<std::pair<Integer, Integer>, 2> fraction_;  // P, Q of f = m_i / (m_i + m_j), by pair
  std::array<Integer, 3> mass_{};
  Integer mass_scale_ = 1;
  State start_, state_, before_;  // before_: the state before impact n_
  std::uint64_t n_ = 0;
};

/// The closed form in double; at 50 digits, whose exponent range has no end in sight,
/// where a finite-mass ratio beyond 2^1000 would underflow the light body's share of the
/// mass-weighted velocities (S = diag(sqrt(m / m_max))) in double.
class ClosedForm {
 public:
  /// `count`: the scene's predicted impacts; a run of at most kExactEventLimit of them (within
  /// the exact walk's budget) has its per-impact values from the exact walk (ExactInTurn).
  ClosedForm(const Scene& scene, std::uint64_t count)
      : masses_(triple(scene.masses)),
        // Energies are over the square of the walk's denominator: half the budget.
        exact_(count <= kExactEventLimit && exactWalkAffordable(masses_, 2 * count) ? std::optional<Scene>(scene)
                                                                                     : std::nullopt) {
    int smallest = std::numeric_limits<int>::max(), largest = std::numeric_limits<int>::min();
    for (int i = 0; i < 3; ++i) {
      if (scene.isWall(i)) continue;
      smallest = std::min(smallest, std::ilogb(scene.masses[i]));
      largest = std::max(largest, std::ilogb(scene.masses[i]));
    }
    if (largest - smallest <= 1000) {
      fast_.emplace(scene);
    } else {
      wide_.emplace(scene);
    }
  }

  std::array<double, 3> velocitiesAfter(std::uint64_t n) const {
    return fast_ ? toArray(fast_->velocitiesAfter(n)) : toArray(wide_->velocitiesAfter(n));
  }
  std::array<double, 3> energyTransfer(std::uint64_t n) const {
    return fast_ ? toArray(fast_->energyTransfer(n)) : toArray(wide_->energyTransfer(n));
  }
  double psi() const { return fast_ ? fast_->psi() : static_cast<double>(wide_->psi()); }
  const std::array<double, 3>& masses() const { return masses_; }

 private:
  friend class ClosedFormInTurn;
  std::array<double, 3> masses_;
  std::optional<Scene> exact_;
  std::optional<AnalyticModel<double>> fast_;
  std::optional<AnalyticModel<HighPrecision>> wide_;
};

/// A ClosedForm's velocities after impact n and the energies gained in it, for n = 1,
/// 2, 3, ... in turn: in double by the ClosedFormSequence recurrence (a few ns each), at
/// 50 digits directly.
class ClosedFormInTurn {
 public:
  explicit ClosedFormInTurn(const ClosedForm& model) : model_(model) {
    if (model.exact_) {
      exact_.emplace(*model.exact_);
    } else if (model.fast_) {
      sequence_.emplace(*model.fast_);
      previous_ = sequence_->velocitiesAfter(0);
    }
  }

  /// The velocities after impact n alone, as describe() gives them [m/s]; n = 1, 2, 3,
  /// ... in turn (not mixed with describe()).
  std::array<double, 3> velocitiesAfter(std::uint64_t n) {
    if (exact_) return exact_->velocitiesAfter(n);
    return sequence_ ? toArray(sequence_->velocitiesAfter(n)) : model_.velocitiesAfter(n);
  }

  /// The largest over i < count of sum_j weight_j (v[i]_j - velocitiesAfter(first + i)_j)^2
  /// (0 when count is 0); first, first + count, ... in turn, as velocitiesAfter.
  double largestSquaredError(std::uint64_t first, const std::array<double, 3>* v, std::size_t count,
                             const std::array<double, 3>& weight) {
    if (sequence_ && !exact_) return sequence_->largestSquaredError(first, v, count, weight);
    double largest = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      const std::array<double, 3> model = velocitiesAfter(first + i);
      double norm_sq = 0.0;
      for (int j = 0; j < 3; ++j) norm_sq += weight[j] * (v[i][j] - model[j]) * (v[i][j] - model[j]);
      largest = std::max(largest, norm_sq);
    }
    return largest;
  }

  /// A short run's exact state around impact n (ExactInTurn::fillState): false, and nothing
  /// filled, for a longer run.
  bool fillExactState(std::uint64_t n, ImpactModelValues& state) {
    if (!exact_) return false;
    exact_->fillState(n, state);
    return true;
  }

  /// Does every impact's values come from the exact walk (a short run)?
  bool exactEvents() const { return exact_.has_value(); }

  /// A short run's exact velocities before impact n; empty for a longer run.
  std::optional<paper::ScaledState> exactVelocitiesBefore(std::uint64_t n) {
    if (!exact_) return std::nullopt;
    return exact_->velocitiesBefore(n);
  }

  void describe(std::uint64_t n, ImpactModelValues& values) {
    if (exact_) {
      values.predicted_velocities_after = exact_->velocitiesAfter(n);
      values.predicted_energy_transfer = exact_->energyTransfer(n);
      return;
    }
    if (!sequence_) {
      values.predicted_velocities_after = model_.velocitiesAfter(n);
      values.predicted_energy_transfer = model_.energyTransfer(n);
      return;
    }
    if (n == 0 || n - 1 != last_) previous_ = sequence_->velocitiesAfter(n - 1);
    const Eigen::Vector3d after = sequence_->velocitiesAfter(n);
    values.predicted_velocities_after = toArray(after);
    values.predicted_energy_transfer = energyTransfer(n);
    previous_ = after;
    last_ = n;
  }

 private:
  /// The closed form's energy gains in impact n from the state before it, previous_:
  /// in double where the gain is safely inside its range, else in the model's wider type.
  std::array<double, 3> energyTransfer(std::uint64_t n) const {
    const AnalyticModel<double>& model = *model_.fast_;
    const std::optional<Pair> first = model.firstPair();
    if (!first || n == 0) return {0.0, 0.0, 0.0};
    const Pair pair = n % 2 == 1 ? *first : otherPair(*first);
    const int i = pairIndex(pair);
    const std::array<double, 3> before{previous_(0), previous_(1), previous_(2)};
    const std::array<double, 3> gained = energy_.gained(pair, before, before[i + 1] - before[i]);
    const double size = std::fabs(gained[i]);
    constexpr double kSafe = 0x1p-900;  // no underflow or overflow on the way
    if (size > kSafe && size < 1 / kSafe) return gained;
    return toArray(model.energyTransfer(n, previous_));
  }

  const ClosedForm& model_;
  std::optional<ExactInTurn> exact_;  // a short run's exact states
  detail::ImpactEnergy<double> energy_{model_.masses()};
  std::optional<ClosedFormSequence> sequence_;
  Eigen::Vector3d previous_;  // after impact last_
  std::uint64_t last_ = 0;
};

/// The paper's printed closed form at impacts n = 1, 2, 3, ... in turn: its exact values,
/// correctly rounded, for a short run (`exact`) without a wall; else in double, its angle
/// advanced by a RotationRecurrence (with a wall every value is NaN, inf / inf as printed).
class PaperInTurn {
 public:
  PaperInTurn(const Scene& scene, bool exact) : printed_(scene), rotation_(printed_.theta()) {
    if (exact && wallIndex(scene) < 0) exact_.emplace(scene);
  }

  std::array<double, 3> velocitiesAfter(std::uint64_t n) {
    if (exact_) return exact_->velocitiesAfter(n);
    rotation_.moveTo(n / 2);
    return printed_.velocitiesAfter(n, rotation_.cos(), rotation_.sin());
  }

 private:
  paper::PrintedClosedForm printed_;
  RotationRecurrence rotation_;
  std::optional<paper::ExactPrintedClosedForm> exact_;
};

/// Relative error in the energy norm: |S (a - b)| / |S v_0| with S = diag(sqrt(m)), in
/// the wall's frame. Scale-free, and the norm in which every impact is an isometry, so a
/// light body's rounding is weighed by the energy it carries.
class EnergyNormError {
 public:
  explicit EnergyNormError(const Scene& scene) : mass_max_(largestFiniteMass(triple(scene.masses))) {
    const int wall = wallIndex(scene);
    for (int i = 0; i < 3; ++i) weight_[i] = i == wall ? 0.0 : scene.masses[i] / mass_max_;
    const double frame = wall >= 0 ? scene.velocities[wall] : 0.0;
    double norm_sq = 0.0;
    for (int i = 0; i < 3; ++i) {
      if (i == wall) continue;
      const double dv = scene.velocities[i] - frame;
      norm_sq += scene.masses[i] / mass_max_ * dv * dv;
    }
    initial_norm_ = norm_sq > 0.0 ? std::sqrt(norm_sq) : 1.0;
  }

  double operator()(const std::array<double, 3>& a, const std::array<double, 3>& b) const {
    return fromSquared(squared(a, b));
  }

  /// |S (a - b)|^2 with S scaled by 1/sqrt(m_max): the largest of many errors is
  /// fromSquared of the largest squared one (sqrt and division are monotone).
  double squared(const std::array<double, 3>& a, const std::array<double, 3>& b) const {
    double norm_sq = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double d = a[i] - b[i];
      norm_sq += weight_[i] * d * d;
    }
    return norm_sq;
  }
  /// squared(a, b) = sum_i weights()_i (a_i - b_i)^2.
  const std::array<double, 3>& weights() const { return weight_; }
  double fromSquared(double norm_sq) const { return std::sqrt(norm_sq) / initial_norm_; }
  /// The squared norm whose relative error is `relative`: a comparison per impact without a
  /// square root or a division.
  double squaredOf(double relative) const {
    const double norm = relative * initial_norm_;
    return norm * norm;
  }

 private:
  double mass_max_;
  std::array<double, 3> weight_{};  // m_i / m_max; 0 for a wall
  double initial_norm_ = 1.0;
};

/// Simulated impacts beside the closed form and the paper's printed formulas, in turn.
class ModelBesideImpacts {
 public:
  explicit ModelBesideImpacts(const Scene& scene, const ClosedForm& model)
      : scene_(scene),
        wall_(wallIndex(scene)),
        closed_form_(model),
        paper_(scene, closed_form_.exactEvents()),
        previous_before_(triple(scene.velocities)) {
    if (closed_form_.exactEvents()) {
      exact_energy_.emplace(scene);
      previous_exact_before_ = closed_form_.exactVelocitiesBefore(1).value();  // the start
    }
  }

  /// Fills the model's values of the next impact, impact previous + 1, whose state
  /// (`values`' velocities) is filled. The paper's BC energy formulas refer to the
  /// velocities before the impact before it, which this keeps.
  /// Returns true when the impact's state was filled from the exact walk (a short run): the
  /// simulation's values name the same exact ones as the model's, rounded once (the engine's
  /// and the long-double totals can be ulps off).
  bool describe(std::uint64_t index, Pair pair, ImpactModelValues& values) {
    const bool exact_state = closed_form_.fillExactState(index, values);
    closed_form_.describe(index, values);
    values.paper_velocities_after = paper_.velocitiesAfter(index);
    if (exact_energy_) {
      paper::ScaledState before = closed_form_.exactVelocitiesBefore(index).value();
      values.paper_energy_transfer = exact_energy_->transfer(index, pair, before, previous_exact_before_);
      previous_exact_before_ = std::move(before);
    } else {
      values.paper_energy_transfer =
          paper::energyTransfer(scene_, index, pair, values.velocities_before, previous_before_);
    }
    if (!exact_state) {
      for (int i = 0; i < 3; ++i) {
        const double v = values.velocities_after[i];
        values.kinetic_energy_after[i] = i == wall_ ? 0.0 : scene_.masses[i] * v * v / 2;
      }
    }
    previous_before_ = values.velocities_before;
    return exact_state;
  }

 private:
  const Scene& scene_;
  int wall_;
  ClosedFormInTurn closed_form_;
  PaperInTurn paper_;
  std::array<double, 3> previous_before_;
  std::optional<paper::ExactPrintedEnergy> exact_energy_;  // a short run's
  paper::ScaledState previous_exact_before_;
};

/// The limits of one simulation of the three bodies.
struct SimulationOptions {
  std::uint64_t max_collisions = 10'000'000;  ///< stops the run cleanly; marks it truncated
  /// When set, the run stops within 1024 impacts, marked truncated and cancelled.
  const std::atomic<bool>* cancel = nullptr;
  /// The certified velocities after the predicted count [m/s], where the caller holds them
  /// (the prediction's): a replica that reaches the count without certifying its own takes
  /// them (runElasticTriple's end_state) instead of building the product again.
  std::optional<std::array<double, 3>> end_state;
};

/// The run of three elastic bodies whose count the closed form gives (`count`), without the
/// engine's queue (nbody/elastic_triple.h; a long run's decisions filtered in double), the
/// summary of every run that can be had so: its count, final velocities (certified correctly
/// rounded, or where no certificate can be had, an exact zero or tie, the engine's bit for
/// bit) and drifts, as simulateByEngine gives them; no final time or positions. An impact
/// that may come after the largest double [s] declines it. restart() is called before each
/// pass over the impacts (at most three); visit(first, v, count) sees the velocities [m/s]
/// after impacts first, ..., first + count - 1 in v[0 .. count) (runElasticTriple: the
/// engine's, or the filtered pass's double walk), in batches after the walk has taken them,
/// so that a visitor's work does not crowd the walk's registers: every impact of a pass
/// before accept() is called, and of a run before this returns (a pass that stops
/// unfinished drops its last batch: restart() follows). accept() says whether a filtered
/// pass may stand. Returns nothing when the run cannot be taken this way (then the engine
/// runs it). `progress` (RunOptions) sees every progress_interval-th impact, with no time
/// (NaN): with a visitor, as its batch is visited; with NoVisit, as the walk takes it.
struct NoVisit {};
constexpr std::size_t kVisitBatch = 256;

template <class Restart, class Visit, class Accept>
std::optional<SceneSimulation> simulateKnownCount(const Scene& scene, std::uint64_t count,
                                                   const SimulationOptions& options, const ProgressCallback& progress,
                                                   std::uint64_t progress_interval, Restart&& restart, Visit&& visit,
                                                   Accept&& accept) {
  if (scene.isWall(0) && scene.isWall(2)) return std::nullopt;
  const std::optional<Pair> first = firstPair(scene);
  if (count > 0 && !first) return std::nullopt;
  const nbody_detail::WorkingUnits units(scene);  // the engine's units (nbody/units.h)
  for (int p = 0; p < 2; ++p) {  // a heavy body's coefficient must not underflow
    const double light = std::min(units.scene.masses[p], units.scene.masses[p + 1]);
    const double heavy = std::max(units.scene.masses[p], units.scene.masses[p + 1]);
    if (!std::isinf(heavy) && !(light / heavy > 0x1p-900)) return std::nullopt;
  }
  const int shift = units.velocity_shift;
  const double to_si = std::ldexp(1.0, -shift);
  const nbody_detail::PowerOfTwo velocity_si(-shift);
  const auto si = [to_si, velocity_si](double v) {  // velocity_si(v), without long double where exact
    const double x = v * to_si;
    return std::fabs(x) >= std::numeric_limits<double>::min() ? x : velocity_si(v);
  };
  const std::uint64_t every = progress ? progress_interval : 0;
  // The largest working time whose SI value a double holds (as runEngine bounds it).
  const double time_limit = static_cast<double>(
      std::ldexp(static_cast<long double>(std::numeric_limits<double>::max()), units.timeShift()));
  const std::size_t first_pair = first == Pair::BC ? 1 : 0;
  // The caller's certified end state in the working units, where they hold it exactly.
  std::optional<std::array<double, 3>> end_state;
  if (options.end_state && detail::scalesExactly(*options.end_state, shift)) {
    end_state.emplace();
    for (int k = 0; k < 3; ++k) (*end_state)[k] = std::ldexp((*options.end_state)[k], shift);
  }
  const std::array<double, 3>* known_end = end_state ? &*end_state : nullptr;
  std::optional<nbody_detail::ElasticTripleRun> run;
  if constexpr (std::is_same_v<std::decay_t<Visit>, NoVisit>) {
    run = nbody_detail::runElasticTriple(
        units.scene, count, first_pair, options.max_collisions, time_limit, options.cancel, restart,
        [&](std::uint64_t n, const std::array<double, 3>&) {
          if (every != 0 && n % every == 0) progress(EngineProgress{n, std::numeric_limits<double>::quiet_NaN()});
        },
        accept, nbody_detail::KnownCountPath::kAuto, known_end);
  } else {
    std::array<std::array<double, 3>, kVisitBatch> batch, si_batch;  // working units, SI
    std::size_t batched = 0;
    std::uint64_t batch_end = 0;  // the impact after the batch's last
    const auto flush = [&] {
      const std::uint64_t batch_start = batch_end - batched;
      // Scaled by a power of two, exact unless a result is below the normal range; that
      // rare batch is converted again through velocity_si, from the working values.
      bool below_normal = false;
      for (std::size_t i = 0; i < batched; ++i) {
        for (int k = 0; k < 3; ++k) {
          const double x = batch[i][k] * to_si;
          below_normal |= std::fabs(x) < std::numeric_limits<double>::min() && x != 0.0;
          si_batch[i][k] = x;
        }
      }
      for (std::size_t i = 0; below_normal && i < batched; ++i) {
        for (int k = 0; k < 3; ++k) si_batch[i][k] = si(batch[i][k]);
      }
      visit(batch_start, si_batch.data(), batched);
      for (std::uint64_t n = batch_start; every != 0 && n < batch_end; ++n) {
        if (n % every == 0) progress(EngineProgress{n, std::numeric_limits<double>::quiet_NaN()});
      }
      batched = 0;
    };
    run = nbody_detail::runElasticTriple(
        units.scene, count, first_pair, options.max_collisions, time_limit, options.cancel,
        [&] {
          batched = 0;
          restart();
        },
        [&](std::uint64_t n, const std::array<double, 3>& v) {
          batch[batched++] = v;
          batch_end = n + 1;
          if (batched == kVisitBatch) flush();
        },
        [&] {
          flush();
          return accept();
        },
        nbody_detail::KnownCountPath::kAuto, known_end);
    flush();
  }
  if (!run) return std::nullopt;
  SceneSimulation result;
  result.simulated = true;
  result.impact_count = run->impact_count;
  result.truncated = run->capped || run->cancelled;
  result.stop = run->cancelled ? StopReason::kCancelled : run->capped ? StopReason::kCap : StopReason::kFinished;
  result.final_velocities.assign(run->final_velocities.begin(), run->final_velocities.end());
  if (!run->certified) result.uncertified.push_back("final_velocities");  // the engine's bits stand
  nbody_detail::fillEngineDrift(units.scene, result);  // in working units, where the run's values are
  for (double& v : result.final_velocities) v = velocity_si(v);
  return result;
}

/// The three bodies' run by the exact event engine (nbody/engine.h), the one simulator of
/// every scene: exact decisions and correctly rounded values, told as the engine's records
/// (the engine runs in its working units, nbody/units.h, and gives SI values) with the
/// state of every body in their model block (ImpactModelValues): the third body's position
/// at that time is computed here from its last impact (to rounding, in long double), and the
/// totals after it from the velocities; the visitor adds the model's values. Escalations: one decision per impact and the final one. A run the engine
/// ended otherwise than finished, capped or cancelled (out of range: the next impact comes
/// after the largest double) is truncated, with the engine's sentence in `stopped_otherwise`.
/// `final_state`, when set (the known count's summary), is the state after its last impact:
/// the record of that impact carries it, so that the last event and the summary agree.
SceneSimulation simulateByEngine(const Scene& scene, const SimulationOptions& options,
                                  const ProgressCallback& progress, std::uint64_t progress_interval,
                                  const std::function<void(ImpactRecord&)>& visitor, std::string& stopped_otherwise,
                                  const SceneSimulation* final_state = nullptr) {
  EngineOptions engine_options;
  engine_options.max_impacts = options.max_collisions;
  engine_options.progress_interval = progress ? progress_interval : 0;
  engine_options.cancel = options.cancel;
  // Velocities, and where body k was (since_position) at since_time[k].
  const auto positive = [](long double x) { return x == 0 ? 0.0 : static_cast<double>(x); };  // never -0
  std::array<double, 3> velocities{}, since_position = triple(scene.positions), since_time{};
  for (int k = 0; k < 3; ++k) velocities[k] = positive(scene.velocities[k]);
  const int wall = wallIndex(scene);
  ImpactRecord event;
  ImpactVisitor on_impact;
  std::array<bool, 3> velocity_uncertified{};  // set by an uncertified value
  const auto any = [](const std::array<bool, 3>& flags) { return flags[0] || flags[1] || flags[2]; };
  if (visitor) {
    on_impact = [&](const ImpactRecord& record) {
      const int i = static_cast<int>(record.pair_index);
      event = record;
      ImpactModelValues& state = event.model.emplace();
      state.velocities_before = velocities;
      // Positions and totals are computed here from rounded values.
      event.uncertified |= kPositions | kKineticEnergyAfter | kTotalEnergy | kTotalMomentum;
      if (any(velocity_uncertified)) event.uncertified |= kVelocitiesBefore;
      // The pair's velocities before are the tracked ones (the record's own may be a higher tier's).
      event.uncertified &= ~kPairVelocitiesBefore;
      if (velocity_uncertified[i] || velocity_uncertified[i + 1]) event.uncertified |= kPairVelocitiesBefore;
      if (record.uncertified & kPairEnergyTransfer) event.uncertified |= kEnergyTransfer;
      for (int k = 0; k < 3; ++k) {
        const long double elapsed = static_cast<long double>(record.time) - since_time[k];
        const long double position =
            velocities[k] == 0 ? since_position[k] : since_position[k] + velocities[k] * elapsed;
        // At a time past the largest double a moving body's place is not known here (NaN).
        state.positions[k] = std::isinf(record.time) && velocities[k] != 0 ? std::numeric_limits<double>::quiet_NaN()
                                                                            : positive(position);
      }
      const bool last = final_state && record.index == final_state->impact_count;
      const bool final_uncertified = last && std::find(final_state->uncertified.begin(), final_state->uncertified.end(),
                                                       "final_velocities") != final_state->uncertified.end();
      if (last) {
        event.velocities_after = {final_state->final_velocities[i], final_state->final_velocities[i + 1]};
        event.uncertified = (event.uncertified & ~kPairVelocitiesAfter) | (final_uncertified ? kPairVelocitiesAfter : 0u);
      }
      for (int side = 0; side < 2; ++side) {
        const int body = i + side;
        velocity_uncertified[body] = event.uncertified & kPairVelocitiesAfter;
        velocities[body] = event.velocities_after[side];
        state.positions[body] = record.position;
        since_position[body] = record.position;
        since_time[body] = record.time;
      }
      // Elastic: what one body gains the other loses, exactly (a wall's entry is minus the
      // ball's): the finite body's entry, or the left one's, sets both.
      const int side = scene.isWall(i) ? 1 : 0;
      state.energy_transfer[i + side] = record.energy_gained[side];
      state.energy_transfer[i + 1 - side] = positive(-static_cast<long double>(record.energy_gained[side]));
      if (last) {
        velocities = triple(final_state->final_velocities);  // the third body's too
        velocity_uncertified = {final_uncertified, final_uncertified, final_uncertified};
      }
      if (any(velocity_uncertified)) event.uncertified |= kVelocitiesAfter;
      state.velocities_after = velocities;
      long double energy = 0, momentum = 0;
      for (int k = 0; k < 3; ++k) {
        if (k == wall) continue;
        energy += static_cast<long double>(scene.masses[k]) * velocities[k] * velocities[k] / 2;
        momentum += static_cast<long double>(scene.masses[k]) * velocities[k];
      }
      state.total_energy = positive(energy);
      state.total_momentum = positive(momentum);
      visitor(event);
    };
  }
  const SceneSimulation engine = runEngine(scene, engine_options, on_impact, progress);
  SceneSimulation result;  // what the summary takes from the engine's run
  result.simulated = true;
  result.impact_count = engine.impact_count;
  result.truncated = engine.truncated || engine.stop != StopReason::kFinished;
  result.stop = engine.stop;
  result.time_beyond_range = engine.time_beyond_range;
  result.uncertified = engine.uncertified;
  if (engine.stop != StopReason::kFinished && engine.stop != StopReason::kCap && engine.stop != StopReason::kCancelled) {
    stopped_otherwise = engine.stop_message;
  }
  result.final_velocities = engine.final_velocities;
  result.energy_relative_drift = engine.energy_relative_drift;
  result.momentum_relative_drift = engine.momentum_relative_drift;
  result.escalations.high_precision = engine.escalations.high_precision;
  result.escalations.exact_rational = engine.escalations.exact_rational;
  return result;
}

/// The exact velocities after `count` impacts of the scene [m/s], each correctly rounded: the
/// exact walk within its budget, else the certified product of the impact maps (the paper's
/// powers of D), a wall's velocity unchanged; a velocity that the product cannot certify (an
/// exact zero or a tie) by the exact walk at up to 8 times its budget. A velocity that
/// neither decides keeps the closed form's double, and `certified` turns false.
std::array<double, 3> roundedVelocitiesAfter(const Scene& scene, std::uint64_t count, const ClosedForm& model,
                                             bool& certified) {
  const std::optional<Pair> first = firstPair(scene);
  std::array<double, 3> result = triple(scene.velocities);
  if (count == 0 || !first) {
    for (double& v : result) v = detail::toDouble(v);  // never -0
    return result;
  }
  const auto exactly = [&] { return ExactInTurn(scene).velocitiesAfter(count); };
  const std::array<double, 3> masses = triple(scene.masses);
  if (detail::kFilterable && count <= kFilteredWalkLimit) {
    const std::array<detail::Filtered, 3> walked = filteredVelocitiesAfter(scene, *first, count);
    std::array<std::optional<double>, 3> nearest;
    for (int k = 0; k < 3; ++k) nearest[k] = detail::filteredNearest(walked[k]);
    if (nearest[0] && nearest[1] && nearest[2]) return {*nearest[0], *nearest[1], *nearest[2]};
  }
  if (exactWalkAffordable(masses, count)) return exactly();
  std::array<std::optional<double>, 3> product;
  if (productInRange(masses)) {
    product = nbody_detail::certifiedVelocityComponentsAfter(scene, count, static_cast<std::size_t>(pairIndex(*first)));
  }
  if (product[0] && product[1] && product[2]) return {*product[0], *product[1], *product[2]};
  const std::array<double, 3> closed = model.velocitiesAfter(count);
  for (int k = 0; k < 3; ++k) {
    result[k] = product[k].value_or(closed[k]);
    certified = certified && product[k].has_value();
  }
  return result;
}

/// psi (analytic.h: the angle of the start's u_perp from r_BC towards r_AB) correctly rounded
/// [rad]: atan2(Y, X sqrt(scale)) with exact Y = v_B - v_C and, up to one positive factor,
/// X and scale from the wedge's vectors: no wall X = (m_B + m_C) v_A - m_B v_B - m_C v_C,
/// scale = m_A / (m_B m_C M); a wall A: X = -(m_B (v_B - v_A) + m_C (v_C - v_A)), scale =
/// 1 / (m_B m_C); a wall C: X = v_A - v_C, scale = m_A / m_B; in [0, 2 pi). Empty where it
/// is not certified.
std::optional<double> roundedPsi(const Scene& scene) {
  if (scene.isWall(kA) && scene.isWall(kC)) return std::nullopt;
  // Y, X and scale, exact (detail::ExactRational) or with a filter's bound (detail::Filtered).
  const auto arguments = [&scene](auto exact) {
    using T = decltype(exact);
    const T v_a(scene.velocities[kA]), v_b(scene.velocities[kB]), v_c(scene.velocities[kC]);
    const T m_b(scene.masses[kB]);
    const T y = v_b - v_c;
    if (scene.isWall(kA)) {
      const T m_c(scene.masses[kC]);
      return std::array<T, 3>{y, -(m_b * (v_b - v_a) + m_c * (v_c - v_a)), T(1) / (m_b * m_c)};
    }
    const T m_a(scene.masses[kA]);
    if (scene.isWall(kC)) return std::array<T, 3>{y, v_a - v_c, m_a / m_b};
    const T m_c(scene.masses[kC]);
    return std::array<T, 3>{y, (m_b + m_c) * v_a - m_b * v_b - m_c * v_c, m_a / (m_b * m_c * (m_a + m_b + m_c))};
  };
  if (detail::kFilterable) {
    const auto f = arguments(detail::Filtered());
    if (const auto rounded = detail::filteredAtan2Sqrt(f[0], f[1], f[2], true)) return rounded;
  }
  const auto a = arguments(detail::ExactRational());
  return detail::roundedAtan2Sqrt(a[0], a[1], a[2], true);
}

}  // namespace

std::array<detail::Filtered, 3> filteredVelocitiesAfter(const Scene& scene, Pair first, std::uint64_t count) {
  using detail::Filtered;
  std::array<Filtered, 3> v;
  for (int k = 0; k < 3; ++k) v[k] = Filtered(scene.velocities[k]);
  // Each pair's coefficients, once: v_i' = ((m_i - m_j) v_i + 2 m_j v_j) / (m_i + m_j).
  struct Coefficients {
    Filtered difference, twice_right, twice_left, total;
  };
  std::array<Coefficients, 2> pair_coefficients;
  for (int i = 0; i < 2; ++i) {
    if (scene.isWall(i) || scene.isWall(i + 1)) continue;
    const Filtered m_i(scene.masses[i]), m_j(scene.masses[i + 1]);
    pair_coefficients[i] = {m_i - m_j, Filtered(2) * m_j, Filtered(2) * m_i, m_i + m_j};
  }
  Pair pair = first;
  for (std::uint64_t n = 0; n < count; ++n, pair = otherPair(pair)) {
    const int i = pairIndex(pair), j = i + 1;
    if (scene.isWall(i) || scene.isWall(j)) {  // the finite body reflects off the wall's velocity
      const int body = scene.isWall(i) ? j : i, wall = i + j - body;
      v[body] = Filtered(2) * v[wall] - v[body];
      continue;
    }
    const Coefficients& c = pair_coefficients[i];
    const Filtered left = (c.difference * v[i] + c.twice_right * v[j]) / c.total;
    v[j] = (c.twice_left * v[i] - c.difference * v[j]) / c.total;
    v[i] = left;
  }
  return v;
}

void fillRotationPrediction(const Scene& scene, Prediction& prediction) {
  const std::array<double, 3> masses = triple(scene.masses);
  const std::uint64_t count = predictedImpactCount(scene);
  const ClosedForm model(scene, count);
  const detail::RoundedAngles angles = detail::roundedAngles(masses);
  prediction.impact_count = count;
  bool certified = true;
  const std::array<double, 3> final_velocities = roundedVelocitiesAfter(scene, count, model, certified);
  if (!certified) prediction.uncertified.push_back("predicted_final_velocities");
  prediction.final_velocities.assign(final_velocities.begin(), final_velocities.end());
  prediction.energy_lost = 0.0;  // elastic
  prediction.critical_restitution = angles.critical_restitution;
  prediction.spiral_angle = angles.theta;
  bool paper_certified = true;
  prediction.paper_impact_count = paper::impactCount(scene, &paper_certified);
  if (!paper_certified) prediction.uncertified.push_back("paper_predicted_collision_count");
  paper_certified = true;
  prediction.max_possible_impact_count = maxPossibleImpactCount(masses);
  prediction.alpha = angles.alpha;
  prediction.theta = angles.theta;
  prediction.omega = angles.omega;
  prediction.phi_bc = paper::phiBC(scene, &paper_certified);
  if (!paper_certified) prediction.uncertified.push_back("phi_bc");
  if (const std::optional<double> psi = roundedPsi(scene)) {
    prediction.psi = *psi;
  } else {
    prediction.psi = model.psi();
    prediction.uncertified.push_back("psi");
  }
  if (const std::optional<Pair> first = firstPair(scene)) prediction.first_pair_index = static_cast<std::size_t>(pairIndex(*first));
}

/// Simulates (full or summary mode), with every event put beside the prediction in full
/// mode, and measures how far the simulation is from the closed form.
/// An impact's values that the exact walk gives a short run, each correctly rounded (the
/// positions are still the run's; ExactInTurn::fillState, ModelBesideImpacts).
constexpr std::uint32_t kExactWalkValues = (kPairValues & ~(kImpactTime | kImpactPosition | kImpactEnergyLost)) |
                                           kVelocitiesBefore | kVelocitiesAfter | kEnergyTransfer |
                                           kKineticEnergyAfter | kTotalEnergy | kTotalMomentum |
                                           kPredictedVelocitiesAfter | kPredictedEnergyTransfer |
                                           kPaperVelocitiesAfter | kPaperEnergyTransfer;

/// The finite bodies' kinetic energy at the start in the lab frame [J] (the smallest
/// normal double when none): the scale of an impact's energy transfers.
double kineticEnergyScale(const Scene& scene) {
  long double energy = 0;
  for (std::size_t k = 0; k < scene.size(); ++k) {
    if (!scene.isWall(k)) energy += static_cast<long double>(scene.masses[k]) * scene.velocities[k] * scene.velocities[k] / 2;
  }
  return std::max(static_cast<double>(energy), std::numeric_limits<double>::min());
}

/// Agreement of the closed form in double with the run's certified values, in the energy
/// norm relative to the start (and energies relative to the start's): far above its
/// rounding, far below any fault.
constexpr double kClosedFormAgreement = 0x1p-40;

/// A long run's impact (no exact walk): the closed form names the same exact state as the
/// run. Where the run's values are certified and the closed form in double agrees with them
/// to its own precision, they are the model's values, correctly rounded; otherwise the
/// closed form's doubles stand, flagged. The paper's printed values are in double (flagged
/// where they are numbers; NaN where undefined).
void certifyPrediction(ImpactRecord& event, const EnergyNormError& relative_error, double energy_scale) {
  ImpactModelValues& values = *event.model;
  if (!(event.uncertified & kVelocitiesAfter) &&
      relative_error(values.velocities_after, values.predicted_velocities_after) <= kClosedFormAgreement) {
    values.predicted_velocities_after = values.velocities_after;
  } else {
    event.uncertified |= kPredictedVelocitiesAfter;
  }
  bool energies_agree = !(event.uncertified & kEnergyTransfer);
  for (int k = 0; k < 3 && energies_agree; ++k) {
    energies_agree = std::fabs(values.energy_transfer[k] - values.predicted_energy_transfer[k]) <=
                     kClosedFormAgreement * energy_scale;
  }
  if (energies_agree) {
    values.predicted_energy_transfer = values.energy_transfer;
  } else {
    event.uncertified |= kPredictedEnergyTransfer;
  }
  const auto numbers = [](const std::array<double, 3>& v) {
    return !std::isnan(v[0]) || !std::isnan(v[1]) || !std::isnan(v[2]);
  };
  if (numbers(values.paper_velocities_after)) event.uncertified |= kPaperVelocitiesAfter;
  if (numbers(values.paper_energy_transfer)) event.uncertified |= kPaperEnergyTransfer;
}

SceneSimulation simulateRotationScene(const Scene& scene, const Prediction& prediction,
                                      const SceneRunOptions& options, const SceneVisitors& visitors) {
  const RunOptions& lab = options.lab;
  const std::uint64_t predicted_count = prediction.impact_count.value_or(0);
  const EnergyNormError relative_error(scene);
  const ClosedForm model(scene, predicted_count);
  SimulationOptions simulation_options;
  simulation_options.max_collisions = lab.max_collisions;
  simulation_options.cancel = options.cancel;
  // The prediction's certified final velocities are the exact state after the predicted
  // count, correctly rounded: the run takes them there rather than certify that state again.
  const bool prediction_certified =
      std::find(prediction.uncertified.begin(), prediction.uncertified.end(), "predicted_final_velocities") ==
      prediction.uncertified.end();
  if (prediction_certified && prediction.final_velocities.size() == 3) {
    simulation_options.end_state = triple(prediction.final_velocities);
  }
  const EventPolicy events = options.keep_events ? lab.events : EventPolicy::none();
  const ProgressCallback& progress = visitors.progress;
  const std::uint64_t progress_interval = progress ? options.progress_interval : 0;
  SceneSimulation simulation;
  std::function<void(ImpactRecord&)> enrich;
  // Built at the first impact the engine publishes: a summary from the known count needs
  // none of it, and its paper's exact closed form was most of a short summary run's cost.
  std::optional<ModelBesideImpacts> beside;
  double max_error_sq = 0.0;
  // The closed form and the run name the same exact state after every impact: a difference
  // within the closed form's rounding (kClosedFormAgreement) is none; a larger one, a fault.
  const double agreement_sq = relative_error.squaredOf(kClosedFormAgreement);
  const auto disagreement = [&relative_error, agreement_sq](const std::array<double, 3>& run,
                                                            const std::array<double, 3>& model) {
    const double error_sq = relative_error.squared(run, model);
    return error_sq <= agreement_sq ? 0.0 : error_sq;
  };
  const double energy_scale = kineticEnergyScale(scene);
  if (lab.mode == RunMode::kFull) {
    enrich = [&](ImpactRecord& event) {
      ImpactModelValues& values = *event.model;
      if (!beside) beside.emplace(scene, model);
      const bool exact_walk = beside->describe(event.index, event.pair_index == 0 ? Pair::AB : Pair::BC, values);
      if (exact_walk) {
        for (std::size_t side = 0; side < 2; ++side) {  // the pair's entries of the record too
          const std::size_t body = event.pair_index + side;
          event.velocities_before[side] = values.velocities_before[body];
          event.velocities_after[side] = values.velocities_after[body];
          event.energy_gained[side] = values.energy_transfer[body];
        }
        event.uncertified &= ~kExactWalkValues;
      }
      max_error_sq = std::max(max_error_sq, disagreement(values.velocities_after, values.predicted_velocities_after));
      if (!exact_walk) certifyPrediction(event, relative_error, energy_scale);
      if (visitors.impact) visitors.impact(event);
      if (events.keeps(event.index)) simulation.impacts.push_back(event);
    };
  }
  std::string stopped_otherwise;
  // The summary comes from the known count wherever it can be had, with events or without:
  // events only watch (the engine's run publishes them), so a run's summary, its escalations
  // included, is the same whatever it shows. The count, the final state, the drifts and (in
  // full mode) the largest prediction error need no decision.
  const bool publishes = lab.mode == RunMode::kFull && (visitors.impact || events.kind != EventPolicy::Kind::kNone);
  const ProgressCallback known_progress = publishes ? ProgressCallback{} : progress;  // else the engine's
  double known_error_sq = 0.0;
  std::optional<SceneSimulation> known;
  if (lab.mode == RunMode::kFull) {
    std::optional<ClosedFormInTurn> predicted;
    known = simulateKnownCount(
        scene, predicted_count, simulation_options, known_progress, progress_interval,
        [&] {
          predicted.emplace(model);
          known_error_sq = 0.0;
        },
        [&](std::uint64_t first, const std::array<double, 3>* v, std::size_t count) {
          const double error_sq = predicted->largestSquaredError(first, v, count, relative_error.weights());
          if (error_sq > agreement_sq) known_error_sq = std::max(known_error_sq, error_sq);
        },
        // The filtered pass's double walk stands for the run where it too agrees with the
        // closed form within kClosedFormAgreement at every impact; else the double-double
        // passes measure the disagreement.
        [&] { return known_error_sq == 0.0; });
  } else {
    known = simulateKnownCount(
        scene, predicted_count, simulation_options, known_progress, progress_interval, [] {}, NoVisit{},
        [] { return true; });
  }
  std::optional<SceneSimulation> by_engine;
  if (publishes || !known) {
    by_engine = simulateByEngine(scene, simulation_options, progress, progress_interval, enrich, stopped_otherwise,
                                 known ? &*known : nullptr);
  }
  // The engine's run is the summary where the known count declined, or where the engine
  // published fewer impacts (cancelled while it published them).
  const bool from_known = known && (!by_engine || by_engine->impact_count == known->impact_count);
  simulation.time_beyond_range = by_engine && by_engine->time_beyond_range;  // the published events' times
  if (from_known) {
    by_engine = known;
    max_error_sq = known_error_sq;
    stopped_otherwise.clear();
  }
  const SceneSimulation& run = *by_engine;
  simulation.simulated = true;
  simulation.impact_count = run.impact_count;
  simulation.truncated = run.truncated;
  simulation.stop = run.stop;  // the engine's reason
  if (run.stop == StopReason::kCancelled) {
    simulation.stop_message =
        "cancelled after " + countText(run.impact_count) + " of " + countText(predicted_count) + " predicted";
  } else if (!stopped_otherwise.empty()) {
    simulation.stop_message = stopped_otherwise;
  } else if (run.truncated) {
    simulation.stop_message = "stopped at max_collisions = " + countText(lab.max_collisions) + " of " +
                              countText(predicted_count) + " predicted";
  } else {
    simulation.stop_message =
        "no pair approaches any more after " + std::to_string(run.impact_count) + " impacts: the run is complete";
  }
  simulation.final_velocities = run.final_velocities;
  simulation.uncertified = run.uncertified;
  // At the model's count the model's certified velocities name the same exact values: an
  // uncertified run value within a few ulps of them gives way to them.
  if (!simulation.uncertified.empty() && run.impact_count == predicted_count && prediction_certified) {
    if (detail::withinUlps(run.final_velocities, prediction.final_velocities)) {
      simulation.final_velocities = prediction.final_velocities;
      simulation.uncertified.clear();
    }
  }
  simulation.energy_lost = 0.0;  // elastic
  simulation.energy_relative_drift = run.energy_relative_drift;
  simulation.momentum_relative_drift = run.momentum_relative_drift;
  // The rotation model predicts every impact: its error is the largest over them all.
  // At the predicted count the prediction's own (correctly rounded) final velocities.
  const std::array<double, 3> predicted_end = run.impact_count == predicted_count
                                                  ? triple(prediction.final_velocities)
                                                  : ClosedFormInTurn(model).velocitiesAfter(run.impact_count);
  simulation.max_prediction_error =
      relative_error.fromSquared(std::max(max_error_sq, disagreement(triple(run.final_velocities), predicted_end)));
  if (!run.truncated) simulation.matches_prediction = run.impact_count == predicted_count;
  simulation.escalations = run.escalations;
  return simulation;
}

}  // namespace core
}  // namespace collision_lab
