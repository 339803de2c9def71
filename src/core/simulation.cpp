#include "collision_lab/core/simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

#include <boost/multiprecision/cpp_bin_float.hpp>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/precision.h"
#include "float_ops.h"
#include "impact_energy.h"

namespace collision_lab {
namespace core {

namespace {

namespace mp = boost::multiprecision;

/// Up to this many impacts a 100-digit replay is cheaper than building the closed form.
constexpr std::uint64_t kShortReplay = 2000;
/// Every this many impacts a long run adopts the 100-digit closed-form state (~0.1 ns per
/// impact amortized), which keeps its velocities accurate over hundreds of millions.
constexpr std::uint64_t kResynchronizeInterval = std::uint64_t{1} << 20;

/// Safety factor of the forward error bound: a sign decision is trusted when
/// |approach speed| > (k + 2) * kBoundFactor * eps * velocity scale of the pair.
/// Each impact adds at most ~16 eps |u| of rounding in mass-weighted space, where the
/// maps are orthogonal and do not amplify earlier errors.
constexpr double kBoundFactor = 64.0;

using detail::absOf;
using detail::toDouble;

constexpr bool kLongDoubleIsWide =
    std::numeric_limits<long double>::max_exponent >= 4 * std::numeric_limits<double>::max_exponent;

/// The type of a run's times and positions in working precision Scalar: long double for
/// double and long double where its exponent range is far wider than double's, else
/// 50 digits. Times and positions of doubles need that range: a gap of 1e-200 m closed at
/// 1e150 m/s takes 1e-350 s, and one closed at a subnormal approach speed can take longer
/// than the largest double; the positions at such times can still be ordinary numbers.
template <class Scalar>
using WideOf = std::conditional_t<!std::is_floating_point_v<Scalar>, Scalar,
                                  std::conditional_t<kLongDoubleIsWide, long double, HighPrecision>>;

template <class T>
T epsilonOf() {
  return std::numeric_limits<T>::epsilon();
}

/// Impact coefficients of pair i (bodies i and i + 1) in precision T. An impact with
/// approach speed r = v[i + 1] - v[i] changes the heavier body by its small gain,
/// 2 m_light / (m_i + m_i+1) times r, and then sets the lighter one from the exact reversal
/// v'[i + 1] - v'[i] = -r. The reversal keeps the relative speed exact, so rounded
/// coefficients do not bias the energy, and the heavy body, whose error costs the most
/// energy, gets the smallest one.
template <class T>
struct PairCoefficients {
  int heavy;  ///< index of the heavier body (i on a tie)
  int light;  ///< index of the other one
  T heavy_gain;
  /// +1 when the heavy body is i, -1 when it is i + 1: the sign of r in its velocity.
  T sign;
};

template <class T>
PairCoefficients<T> pairCoefficients(const std::array<double, 3>& m, int i) {
  const int heavy = m[i] >= m[i + 1] ? i : i + 1;
  const int light = heavy == i ? i + 1 : i;
  const T sign = heavy == i ? T(1) : T(-1);
  if (std::isinf(m[heavy])) return {heavy, light, T(0), sign};
  return {heavy, light, T(2) / (T(1) + T(m[heavy]) / T(m[light])), sign};
}

template <class T>
struct Coefficients {
  std::array<PairCoefficients<T>, 2> pairs;  ///< by pair index
  explicit Coefficients(const std::array<double, 3>& m) : pairs{pairCoefficients<T>(m, 0), pairCoefficients<T>(m, 1)} {}
  const PairCoefficients<T>& of(Pair p) const { return pairs[pairIndex(p)]; }
};

/// Velocities as unevaluated sums hi + lo. The heavy body's increment is added with an
/// error-free TwoSum, so the rounding of millions of tiny increments to a heavy body's
/// velocity does not pile up.
template <class T>
struct CompensatedVelocities {
  std::array<T, 3> hi;
  std::array<T, 3> lo;

  explicit CompensatedVelocities(const std::array<double, 3>& v)
      : hi{T(v[0]), T(v[1]), T(v[2])}, lo{T(0), T(0), T(0)} {}

  T value(int i) const { return hi[i] + lo[i]; }
  std::array<T, 3> values() const { return {value(0), value(1), value(2)}; }

  /// The velocities in type W (hi + lo summed in W).
  template <class W>
  std::array<W, 3> valuesAs() const {
    std::array<W, 3> out;
    for (int i = 0; i < 3; ++i) out[i] = W(hi[i]) + W(lo[i]);
    return out;
  }

  /// Approach speed v[i + 1] - v[i] of pair i.
  T approach(int i) const { return (hi[i + 1] - hi[i]) + (lo[i + 1] - lo[i]); }

  void add(int i, const T& increment) {
    const detail::TwoSum<T> sum = detail::twoSum(hi[i], increment);
    lo[i] += sum.error;
    hi[i] = sum.sum;
  }

  /// Sets body i to (hi[from] + lo[from]) + sign * (speed_hi + speed_lo), keeping the
  /// rounding error of the leading sum: the light body's velocity swings far above its
  /// final value, and its rounding at the peak would otherwise stay in it.
  void setFrom(int i, int from, const T& sign, const T& speed_hi, const T& speed_lo) {
    const detail::TwoSum<T> sum = detail::twoSum(hi[from], T(sign * speed_hi));
    lo[i] = sum.error + lo[from] + sign * speed_lo;
    hi[i] = sum.sum;
  }

  /// One impact of pair i (bodies i and i + 1) with coefficients c.
  void impact(const PairCoefficients<T>& c, int i) {
    // Approach speed as hi + lo, the leading difference split exactly.
    const detail::TwoSum<T> split = detail::twoSum(T(-hi[i]), hi[i + 1]);
    const T speed_hi = split.sum;
    const T speed_lo = split.error + (lo[i + 1] - lo[i]);
    const T speed = speed_hi + speed_lo;
    add(c.heavy, c.sign * (c.heavy_gain * speed));
    setFrom(c.light, c.heavy, -c.sign, speed_hi, speed_lo);
  }

  /// Takes over a more accurate state (a replay in higher precision or exact rationals).
  template <class Precise>
  void adopt(const std::array<Precise, 3>& precise) {
    for (int i = 0; i < 3; ++i) {
      if constexpr (std::is_floating_point_v<T>) {
        // Straight to T: a detour through double would round a long double's low part.
        hi[i] = static_cast<T>(precise[i]);
        lo[i] = static_cast<T>(Precise(precise[i] - Precise(hi[i])));
      } else {
        hi[i] = T(precise[i]);
        lo[i] = T(0);
      }
    }
  }
};

/// Velocities after k alternating impacts, replayed in precision T with the engine's own
/// impact formula. Cheaper than building the closed form when k is small.
template <class T>
std::array<T, 3> replay(const ThreeBodyScene& scene, Pair first, std::uint64_t k) {
  const Coefficients<T> coefficients(scene.masses);
  std::array<T, 3> v{T(scene.velocities[0]), T(scene.velocities[1]), T(scene.velocities[2])};
  Pair pair = first;
  for (std::uint64_t n = 0; n < k; ++n) {
    const int i = pairIndex(pair);
    const PairCoefficients<T>& c = coefficients.of(pair);
    const T approach = v[i + 1] - v[i];
    v[c.heavy] += c.sign * (c.heavy_gain * approach);
    v[c.light] = v[c.heavy] - c.sign * approach;
    pair = otherPair(pair);
  }
  return v;
}

/// Scales that bound rounding errors: in the wall's frame (or the lab frame without a
/// wall) kinetic energy is conserved, so |u| = sqrt(sum m v^2) bounds every mass-weighted
/// velocity, and a velocity error is at most |du| / sqrt(m).
class ErrorScale {
 public:
  explicit ErrorScale(const ThreeBodyScene& scene) {
    const int wall = scene.wallIndex();
    const long double frame = wall >= 0 ? scene.velocities[wall] : 0.0L;
    long double energy_norm_sq = 0.0L;
    long double mass_sum = 0.0L;
    for (int i = 0; i < 3; ++i) {
      if (i == wall) continue;
      const long double m = scene.masses[i];
      const long double dv = scene.velocities[i] - frame;
      energy_norm_sq += m * dv * dv;
      mass_sum += m;
    }
    const long double u = std::sqrt(energy_norm_sq) + 3.0L * std::fabs(frame) * std::sqrt(mass_sum);
    for (int i = 0; i < 3; ++i) {
      inverse_sqrt_mass_[i] = i == wall ? 0.0L : 1.0L / std::sqrt(static_cast<long double>(scene.masses[i]));
    }
    const long double min_scale = std::numeric_limits<double>::min();
    for (int i = 0; i < 2; ++i) {
      pair_scale_[i] = std::max(min_scale, u * (inverse_sqrt_mass_[i] + inverse_sqrt_mass_[i + 1]));
    }
  }

  /// Velocity scale [m/s] of the approach speed of `pair`.
  long double of(Pair pair) const { return pair_scale_[pairIndex(pair)]; }

  /// Bound on the rounding error of an approach speed after k impacts in precision T.
  template <class T>
  T bound(Pair pair, std::uint64_t k) const {
    return T(static_cast<double>(of(pair))) * T(kBoundFactor) * epsilonOf<T>() * T(static_cast<double>(k + 2));
  }

 private:
  long double inverse_sqrt_mass_[3]{};
  long double pair_scale_[2]{};  // by pair index
};

template <class T>
T approachOf(Pair pair, const std::array<T, 3>& v) {
  const int i = pairIndex(pair);
  return T(v[i + 1] - v[i]);
}

/// Takes the sign decisions the working precision cannot, at 100 digits: a replay for
/// short runs, the closed-form state after k impacts (O(1) in k) for long ones; then the
/// closed form at 500 digits; then exact rationals for a zero to within that.
/// The closed form holds for any alternating sequence, which every run is.
template <class Scalar>
class Escalation {
 public:
  Escalation(const ThreeBodyScene& scene, const ErrorScale& scale, Pair first) : scene_(scene), scale_(scale), first_(first) {}

  /// A sign decision taken above the working precision.
  struct Decision {
    bool approaches;
    ReplayPrecision approach;                  ///< the approach speed it saw, to 100 digits or better
    std::array<ReplayPrecision, 3> velocities;  ///< the state it saw (Scalar may not hold all of it)
  };

  /// Does `pair` approach after k impacts, as exact arithmetic says? Hands the accurate
  /// state at k to `v`.
  Decision decide(std::uint64_t k, Pair pair, CompensatedVelocities<Scalar>& v, EscalationStats& stats) {
    ++stats.high_precision;
    const Precise precise = preciseState(k);
    const ReplayPrecision precise_approach = approachOf(pair, precise.velocities);
    if (mp::abs(precise_approach) > precise.bound_factor * scale_.bound<ReplayPrecision>(pair, k)) {
      v.adopt(precise.velocities);
      return {precise_approach > 0, precise_approach, precise.velocities};
    }
    // Masses that span more than ~1e100 defeat 100 digits; 500 digits decide all but an
    // exact zero, in O(1) like the 100-digit closed form.
    if (!deep_closed_form_) deep_closed_form_.emplace(scene_);
    const auto deep = stateOf(*deep_closed_form_, k);
    const DeepPrecision deep_approach = approachOf(pair, deep);
    const bool deep_decides =
        mp::abs(deep_approach) > closedFormFactor<DeepPrecision>() * scale_.bound<DeepPrecision>(pair, k);
    if (deep_decides || k > kExactReplayLimit) {
      // Beyond the exact replay's reach, an exact zero would need input doubles built for
      // it over thousands of impacts: within 500 digits of zero counts as not approaching.
      v.adopt(deep);
      return {deep_decides && deep_approach > 0, static_cast<ReplayPrecision>(deep_approach), narrowed(deep)};
    }
    ++stats.exact_rational;
    const exact::RationalState exact_state = exact::velocitiesAfter(scene_, first_, k);
    v.adopt(exact_state);
    const exact::Rational approach = exact::approachSpeed(pair, exact_state);
    return {approach > 0, narrowed(approach), narrowed(exact_state)};
  }

  /// Replaces v by the 100-digit state after k impacts, so that rounding errors of very
  /// long runs do not accumulate.
  void resynchronize(std::uint64_t k, CompensatedVelocities<Scalar>& v) { v.adopt(preciseState(k).velocities); }

 private:
  struct Precise {
    std::array<ReplayPrecision, 3> velocities;
    ReplayPrecision bound_factor;  ///< times the replay bound of ErrorScale
  };

  Precise preciseState(std::uint64_t k) {
    if (k <= kShortReplay) return {replay<ReplayPrecision>(scene_, first_, k), ReplayPrecision(1)};
    if (!closed_form_) closed_form_.emplace(scene_);
    return {stateOf(*closed_form_, k), closedFormFactor<ReplayPrecision>()};
  }

  static ReplayPrecision narrowed(const exact::Rational& q) {
    return ReplayPrecision(numerator(q)) / ReplayPrecision(denominator(q));
  }
  static ReplayPrecision narrowed(const DeepPrecision& x) { return static_cast<ReplayPrecision>(x); }
  template <class T>
  static std::array<ReplayPrecision, 3> narrowed(const std::array<T, 3>& state) {
    return {narrowed(state[0]), narrowed(state[1]), narrowed(state[2])};
  }

  template <class T>
  static std::array<T, 3> stateOf(const AnalyticModel<T>& model, std::uint64_t k) {
    const auto state = model.velocitiesAfter(k);
    return {state(0), state(1), state(2)};
  }

  /// The closed form's rotation angle k theta carries k rounding errors, and an angle
  /// error moves the state by up to 1/alpha times its scale.
  template <class T>
  T closedFormFactor() const {
    const T alpha(anglesFor(scene_.masses).alpha);
    return 16 * (1 + 1 / alpha);
  }

  const ThreeBodyScene& scene_;
  const ErrorScale& scale_;
  Pair first_;
  std::optional<AnalyticModel<ReplayPrecision>> closed_form_;
  std::optional<AnalyticModel<DeepPrecision>> deep_closed_form_;
};

/// Energy and momentum of the finite masses [J, kg m/s], in the wide type of the run.
template <class Wide>
struct Frame {
  Wide energy = 0;              // kinetic energy in the wall's frame (lab frame without a wall)
  Wide momentum = 0;            // lab-frame momentum
  Wide momentum_magnitude = 0;  // sum |m v|
};

template <class Wide>
Frame<Wide> measure(const ThreeBodyScene& scene, const std::array<Wide, 3>& v) {
  const int wall = scene.wallIndex();
  const Wide frame = wall >= 0 ? v[wall] : Wide(0);
  Frame<Wide> measured;
  for (int i = 0; i < 3; ++i) {
    if (i == wall) continue;
    const Wide m(scene.masses[i]);
    const Wide dv = v[i] - frame;
    measured.energy += m * dv * dv / 2;
    measured.momentum += m * v[i];
    measured.momentum_magnitude += m * absOf(v[i]);
  }
  return measured;
}

/// Gives working-unit values back in SI units as doubles: times 2^-shift, one rounding.
class ToSi {
 public:
  explicit ToSi(int shift)
      : shift_(shift),
        double_factor_(std::ldexp(1.0, -shift)),
        double_factor_exact_(shift >= 1 - std::numeric_limits<double>::max_exponent &&
                             shift <= std::numeric_limits<double>::digits - std::numeric_limits<double>::min_exponent),
        long_double_factor_(std::ldexp(1.0L, -shift)) {}

  template <class T>
  double operator()(const T& value) const {
    // A product with a power of two is rounded once, into the subnormals too.
    if constexpr (std::is_same_v<T, double>) {
      if (double_factor_exact_) return toDouble(value * double_factor_);
    }
    if constexpr (std::is_floating_point_v<T> && kLongDoubleIsWide) {
      return toDouble(static_cast<long double>(value) * long_double_factor_);
    } else {
      using std::ldexp;
      return toDouble(ldexp(value, -shift_));
    }
  }

 private:
  int shift_;
  double double_factor_;
  bool double_factor_exact_;  // 2^-shift is a double
  long double long_double_factor_;
};

/// Exact power-of-two units of a run: the engine works on velocities times 2^velocity
/// and positions times 2^position, so that both are near 1 and rounding stays relative
/// where tiny (even subnormal) values would meet underflow. The physics is invariant:
/// times scale by 2^(position - velocity), energies by 2^(2 velocity).
struct WorkingUnits {
  int velocity = 0;
  int position = 0;
  ToSi velocity_si{0}, position_si{0}, time_si{0}, energy_si{0};
};

ThreeBodyScene inWorkingUnits(const ThreeBodyScene& scene, WorkingUnits& units) {
  units.velocity = detail::shiftTowardsOne(scene.velocities);
  units.position = detail::shiftTowardsOne(scene.positions);
  units.velocity_si = ToSi(units.velocity);
  units.position_si = ToSi(units.position);
  units.time_si = ToSi(units.position - units.velocity);
  units.energy_si = ToSi(2 * units.velocity);
  ThreeBodyScene working = scene;
  for (double& v : working.velocities) v = std::ldexp(v, units.velocity);
  for (double& x : working.positions) x = std::ldexp(x, units.position);
  return working;
}

/// Run time as an unevaluated sum hi + lo: thousands of short flights add up without
/// the rounding of each sum, which a fast light body would turn into position error.
template <class T>
struct CompensatedTime {
  T hi = 0;
  T lo = 0;

  void advance(const T& delay) {
    const detail::TwoSum<T> sum = detail::twoSum(hi, delay);
    lo += sum.error;
    hi = sum.sum;
  }
  T since(const CompensatedTime& earlier) const { return (hi - earlier.hi) + (lo - earlier.lo); }
  T value() const { return hi + lo; }
};

/// Zero, or a finite magnitude in T's normal range with room to spare: no underflow has
/// eaten digits, and no product of it can overflow.
template <class T>
bool inNormalRange(const T& x) {
  const T smallest = std::numeric_limits<T>::min() / epsilonOf<T>();
  return x == 0 || (absOf(x) >= smallest && absOf(x) <= 1 / smallest);
}

/// Time, position and event bookkeeping of a run that reports events, in working units
/// and precision T. Each body's path is anchored where its velocity last changed.
template <class T>
class Trajectory {
 public:
  using Value = T;

  /// One impact, computed but not yet committed.
  struct Impact {
    CompensatedTime<T> time;
    std::array<T, 3> positions;  ///< A, B, C; the pair at its contact point
    bool in_range = true;        ///< every time and position in T's normal range
  };

  explicit Trajectory(const ThreeBodyScene& working)
      : masses_(working.masses), wall_(working.wallIndex()), energy_(masses_), wide_energy_(masses_) {
    for (int i = 0; i < 3; ++i) reference_position_[i] = T(working.positions[i]);
  }

  /// The same state in a wider type, to go on where T's range ends.
  template <class Narrow>
  explicit Trajectory(const Trajectory<Narrow>& narrow)
      : masses_(narrow.masses_), wall_(narrow.wall_), energy_(masses_), wide_energy_(masses_) {
    now_ = widened(narrow.now_);
    for (int i = 0; i < 3; ++i) {
      reference_position_[i] = T(narrow.reference_position_[i]);
      reference_time_[i] = widened(narrow.reference_time_[i]);
    }
  }

  /// The next impact, of `pair` approaching at `approach` > 0 with the bodies at `v`.
  Impact next(Pair pair, const std::array<T, 3>& v, const T& approach) const {
    const int i = pairIndex(pair);
    Impact impact;
    T gap = positionAt(i, v, now_) - positionAt(i + 1, v, now_);
    if (gap < 0) gap = 0;  // rounding can put touching bodies a hair out of order
    impact.time = now_;
    impact.time.advance(gap / approach);
    for (int body = 0; body < 3; ++body) impact.positions[body] = positionAt(body, v, impact.time);
    // The pair meets where the slower of the two is: a position extrapolated at speed v
    // is off by v times the time's rounding, so the slow body's is the accurate one.
    const T contact = absOf(v[i]) <= absOf(v[i + 1]) ? impact.positions[i] : impact.positions[i + 1];
    impact.positions[i] = impact.positions[i + 1] = contact;
    impact.in_range = inNormalRange(approach) && inNormalRange(impact.time.value());
    for (const T& x : impact.positions) impact.in_range = impact.in_range && inNormalRange(x);
    return impact;
  }

  /// Commits `impact` of `pair` (velocities `before` -> `after`, approach speed
  /// `approach`, all in working units) and describes it in SI units in `event` (written in
  /// place: a returned copy of the freshly written event stalls on store forwarding).
  void commit(std::uint64_t index, Pair pair, const Impact& impact, const std::array<T, 3>& before,
              const std::array<T, 3>& after, const T& approach, const WorkingUnits& units, ImpactEvent& event) {
    now_ = impact.time;
    event.index = index;
    event.pair = pair;
    event.time = units.time_si(now_.value());
    const int pair_index = pairIndex(pair);
    event.position = units.position_si(impact.positions[pair_index]);
    for (int i = 0; i < 3; ++i) event.positions[i] = units.position_si(impact.positions[i]);
    if (!describeEnergies(energy_, pair, before, after, approach, units, event)) {
      describeEnergies(wide_energy_, pair, before, after, approach, units, event);
    }
    // Re-anchor the bodies whose velocity changed (a wall's never does).
    for (int i : {pair_index, pair_index + 1}) {
      if (i == wall_) continue;
      reference_position_[i] = impact.positions[pair_index];
      reference_time_[i] = now_;
    }
  }

  /// Time [working units] of the last impact (0 before any).
  T now() const { return now_.value(); }
  /// Position of body i [working units] at the last impact, moving at v.
  T positionNow(int i, const std::array<T, 3>& v) const { return positionAt(i, v, now_); }

 private:
  template <class U>
  friend class Trajectory;

  T positionAt(int i, const std::array<T, 3>& v, const CompensatedTime<T>& time) const {
    return reference_position_[i] + v[i] * time.since(reference_time_[i]);
  }

  /// The energies of an impact in precision E: the gains and the totals after it. False,
  /// with nothing written, when E is narrower than EnergyType<T> and a value leaves its
  /// normal range (a mass near 1e308, say): then the wider type answers.
  template <class E>
  bool describeEnergies(const detail::ImpactEnergy<E>& model, Pair pair, const std::array<T, 3>& before,
                        const std::array<T, 3>& after, const T& approach, const WorkingUnits& units,
                        ImpactEvent& event) const {
    const std::array<E, 3> gained = model.gained(pair, before, approach);
    E energy = 0, momentum = 0;
    for (int i = 0; i < 3; ++i) {
      if (i == wall_) continue;
      const E m(masses_[i]);
      energy += m * E(after[i]) * E(after[i]) / 2;
      momentum += m * E(after[i]);
    }
    bool in_range = inNormalRange(energy) && inNormalRange(momentum);
    for (const E& x : gained) in_range = in_range && inNormalRange(x);
    if (!in_range && !std::is_same_v<E, detail::EnergyType<T>>) return false;
    for (int i = 0; i < 3; ++i) event.energy_transfer[i] = units.energy_si(gained[i]);
    event.total_energy = units.energy_si(energy);
    event.total_momentum = units.velocity_si(momentum);
    return true;
  }

  template <class Narrow>
  static CompensatedTime<T> widened(const CompensatedTime<Narrow>& time) {
    return {T(time.hi), T(time.lo)};
  }

  std::array<double, 3> masses_;
  int wall_;
  detail::ImpactEnergy<T> energy_;
  detail::ImpactEnergy<detail::EnergyType<T>> wide_energy_;
  std::array<T, 3> reference_position_;
  std::array<CompensatedTime<T>, 3> reference_time_{};
  CompensatedTime<T> now_;
};

/// The sign decisions of one run: the fast path in Scalar with a forward error bound that
/// grows with the impacts since v was last exact to working precision, and an Escalation
/// where the bound cannot decide.
template <class Scalar>
class Decider {
 public:
  Decider(const ThreeBodyScene& working, Pair first, bool tracks_events)
      : working_(working),
        scale_(working),
        step_bound_{scale_.template bound<Scalar>(Pair::AB, 0) / Scalar(2),  // bound(k) = (k + 2) * step
                    scale_.template bound<Scalar>(Pair::BC, 0) / Scalar(2)},
        tracks_events_(tracks_events),
        first_(first) {}

  /// Does `pair` approach after k impacts? Exact decision; may refresh v.
  bool approaches(Pair pair, std::uint64_t k, CompensatedVelocities<Scalar>& v, EscalationStats& stats) {
    ++stats.decisions;
    precise_approach_.reset();
    precise_state_.reset();
    if (k - exact_at_ >= kResynchronizeInterval) {
      escalation().resynchronize(k, v);
      exact_at_ = k;
    }
    const Scalar approach = v.approach(pairIndex(pair));
    const Scalar bound = step_bound_[pairIndex(pair)] * Scalar(static_cast<double>(k - exact_at_ + 2));
    if (approach > bound && !(tracks_events_ && approach < resolution_)) return true;
    if (approach < -bound) return false;
    exact_at_ = k;
    const auto decision = escalation().decide(k, pair, v, stats);
    precise_approach_ = decision.approach;
    precise_state_ = decision.velocities;
    return decision.approaches;
  }

  /// The approach speed and state seen by the last decision when it was taken above the
  /// working precision (else empty): an event's time, positions and energy use them.
  const std::optional<ReplayPrecision>& preciseApproach() const { return precise_approach_; }
  const std::optional<std::array<ReplayPrecision, 3>>& preciseState() const { return precise_state_; }

 private:
  Escalation<Scalar>& escalation() {
    if (!escalation_) escalation_.emplace(working_, scale_, first_);
    return *escalation_;
  }

  const ThreeBodyScene& working_;
  const ErrorScale scale_;
  const std::array<Scalar, 2> step_bound_;  // by pair index
  // Below this a positive approach speed may have lost digits to underflow, which an
  // event's time would inherit.
  const Scalar resolution_ = std::numeric_limits<Scalar>::min() / epsilonOf<Scalar>();
  const bool tracks_events_;
  const Pair first_;
  std::uint64_t exact_at_ = 0;
  std::optional<Escalation<Scalar>> escalation_;
  std::optional<ReplayPrecision> precise_approach_;
  std::optional<std::array<ReplayPrecision, 3>> precise_state_;
};

/// One call of simulate(): the run's state, and one member function per phase.
template <class Scalar>
class EngineRun {
 public:
  using Wide = WideOf<Scalar>;

  EngineRun(const ThreeBodyScene& scene, const SimulationOptions& options, const EventVisitor& visitor)
      : scene_(scene),
        options_(options),
        visitor_(visitor),
        working_(inWorkingUnits(scene, units_)),
        v_(working_.velocities),
        coefficients_(scene.masses),
        tracks_events_(options.events.kind != EventPolicy::Kind::kNone || static_cast<bool>(visitor)) {
    result_.first_pair = firstPair(scene);
  }

  SimulationResult run() {
    const Frame<Wide> start = measure(working_, v_.template valuesAs<Wide>());
    if (result_.first_pair) {
      Decider<Scalar> decider(working_, *result_.first_pair, tracks_events_);
      if (tracks_events_) {
        runWithEvents(decider);
      } else {
        countImpacts(decider);
      }
    } else {
      for (int i = 0; i < 3; ++i) result_.final_positions[i] = notModelled(scene_.positions[i]);
    }
    finish(start);
    return std::move(result_);
  }

 private:
  /// Does `pair` collide next? False when it does not approach, and when max_collisions
  /// or the cancel flag (read every 1024 collisions) stops the run (marked truncated).
  bool nextImpact(Decider<Scalar>& decider, Pair pair) {
    if (!decider.approaches(pair, k_, v_, result_.escalation)) return false;
    if (k_ == options_.max_collisions) {
      result_.truncated = true;
      return false;
    }
    if (options_.cancel && (k_ & 1023) == 1023 && options_.cancel->load(std::memory_order_relaxed)) {
      result_.truncated = result_.cancelled = true;
      return false;
    }
    return true;
  }

  /// Count-only: after the first impact the pairs alternate and positions no longer
  /// matter, so only velocities are modelled.
  void countImpacts(Decider<Scalar>& decider) {
    Pair pair = *result_.first_pair;
    while (nextImpact(decider, pair)) {
      v_.impact(coefficients_.of(pair), pairIndex(pair));
      ++k_;
      pair = otherPair(pair);
    }
    for (int i = 0; i < 3; ++i) result_.final_positions[i] = notModelled(scene_.positions[i]);
  }

  /// Every impact with its event: times and positions in Scalar while they stay in its
  /// range, in Wide from there on.
  void runWithEvents(Decider<Scalar>& decider) {
    Trajectory<Scalar> narrow(working_);
    std::optional<Trajectory<Wide>> wide;
    Pair pair = *result_.first_pair;
    while (nextImpact(decider, pair)) {
      // Velocities as the run reports them everywhere, whichever type timed the impact.
      std::array<double, 3> before;
      for (int i = 0; i < 3; ++i) before[i] = units_.velocity_si(v_.value(i));
      ImpactEvent event;
      if (wide || !impactOn(narrow, pair, decider, event)) {
        if (!wide) wide.emplace(narrow);
        impactOn(*wide, pair, decider, event);
      }
      event.velocities_before = before;
      for (int i = 0; i < 3; ++i) event.velocities_after[i] = units_.velocity_si(v_.value(i));
      if (visitor_) visitor_(event);
      if (options_.events.keeps(k_)) result_.events.push_back(event);
      pair = otherPair(pair);
    }
    for (int i = 0; i < 3; ++i) {
      result_.final_positions[i] = wide ? units_.position_si(wide->positionNow(i, v_.template valuesAs<Wide>()))
                                        : units_.position_si(narrow.positionNow(i, v_.values()));
    }
    result_.final_time = wide ? units_.time_si(wide->now()) : units_.time_si(narrow.now());
  }

  /// One impact of `pair` on `path`, described in `event`; false, with nothing changed,
  /// when it leaves the range of a narrow path's type.
  template <class Path>
  bool impactOn(Path& path, Pair pair, const Decider<Scalar>& decider, ImpactEvent& event) {
    using T = typename Path::Value;
    const int i = pairIndex(pair);
    // The state to the last digit the run knows: the precise one after an escalation
    // (where even a velocity that Scalar cannot hold moves a body over a long flight),
    // else the compensated one; never the approach speed as a difference of `before`.
    std::array<T, 3> before = v_.template valuesAs<T>();
    bool held = true;
    if (const auto& precise_state = decider.preciseState()) {
      for (int body = 0; body < 3; ++body) {
        before[body] = static_cast<T>((*precise_state)[body]);
        held = held && ((*precise_state)[body] == 0 || (before[body] != 0 && inNormalRange(before[body])));
      }
    }
    const auto& precise_approach = decider.preciseApproach();
    const T approach = precise_approach ? static_cast<T>(*precise_approach) : T(v_.approach(i));
    const auto impact = path.next(pair, before, approach);
    if (!(impact.in_range && held) && !std::is_same_v<T, Wide>) return false;
    v_.impact(coefficients_.of(pair), i);
    ++k_;
    path.commit(k_, pair, impact, before, v_.template valuesAs<T>(), approach, units_, event);
    return true;
  }

  /// A position the run did not model: the start's when events are tracked (nothing
  /// moved), else NaN.
  double notModelled(double start) const {
    return tracks_events_ ? toDouble(start) : std::numeric_limits<double>::quiet_NaN();
  }

  /// Count, final velocities and the drifts of energy and momentum since `start`.
  void finish(const Frame<Wide>& start) {
    result_.collision_count = k_;
    for (int i = 0; i < 3; ++i) result_.final_velocities[i] = units_.velocity_si(v_.value(i));
    const Frame<Wide> end = measure(working_, v_.template valuesAs<Wide>());
    result_.energy_relative_drift =
        start.energy > 0 ? toDouble(absOf(Wide(end.energy - start.energy)) / start.energy) : 0.0;
    if (scene_.wallIndex() >= 0) {
      result_.momentum_relative_drift = std::numeric_limits<double>::quiet_NaN();
    } else {
      result_.momentum_relative_drift =
          start.momentum_magnitude > 0
              ? toDouble(absOf(Wide(end.momentum - start.momentum)) / start.momentum_magnitude)
              : 0.0;
    }
  }

  const ThreeBodyScene& scene_;
  const SimulationOptions& options_;
  const EventVisitor& visitor_;
  WorkingUnits units_;
  const ThreeBodyScene working_;
  CompensatedVelocities<Scalar> v_;
  const Coefficients<Scalar> coefficients_;
  const bool tracks_events_;
  SimulationResult result_;
  std::uint64_t k_ = 0;  // impacts so far
};

}  // namespace

template <class Scalar>
SimulationResult simulate(const ThreeBodyScene& scene, const SimulationOptions& options, const EventVisitor& visitor) {
  return EngineRun<Scalar>(scene, options, visitor).run();
}

template SimulationResult simulate<double>(const ThreeBodyScene&, const SimulationOptions&, const EventVisitor&);
template SimulationResult simulate<long double>(const ThreeBodyScene&, const SimulationOptions&, const EventVisitor&);
template SimulationResult simulate<HighPrecision>(const ThreeBodyScene&, const SimulationOptions&, const EventVisitor&);

SimulationResult simulate(const ThreeBodyScene& scene, const SimulationOptions& options, Precision precision,
                          const EventVisitor& visitor) {
  switch (precision) {
    case Precision::kLongDouble: return simulate<long double>(scene, options, visitor);
    case Precision::kHigh: return simulate<HighPrecision>(scene, options, visitor);
    case Precision::kDouble: break;
  }
  return simulate<double>(scene, options, visitor);
}

}  // namespace core
}  // namespace collision_lab
