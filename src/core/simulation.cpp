#include "collision_lab/core/simulation.h"

#include <cmath>
#include <limits>
#include <type_traits>

#include <boost/multiprecision/cpp_bin_float.hpp>

#include "collision_lab/core/analytic.h"
#include "collision_lab/core/exact.h"
#include "collision_lab/core/precision.h"

namespace collision_lab {

namespace {

namespace mp = boost::multiprecision;

/// Precision of the first escalation tier (100 digits) and of the last resort beyond the
/// exact-rational limit (500 digits).
using ReplayPrecision = mp::cpp_bin_float_100;
using DeepReplayPrecision = mp::number<mp::cpp_bin_float<500>>;

/// Up to this many impacts a 100-digit replay is cheaper than building the closed form.
constexpr std::uint64_t kShortReplay = 2000;
/// Every this many impacts a long run adopts the 100-digit closed-form state (~0.1 ns per
/// impact amortized), which keeps its velocities accurate over hundreds of millions.
constexpr std::uint64_t kResynchronizeInterval = std::uint64_t{1} << 20;

/// Longest run an exact rational replay is attempted for (its cost grows ~quadratically).
/// Reached only when 100 digits cannot tell the approach speed from zero.
constexpr std::uint64_t kExactReplayLimit = 20000;

/// Safety factor of the forward error bound: a sign decision is trusted when
/// |approach speed| > (k + 2) * kBoundFactor * eps * velocity scale of the pair.
/// Each impact adds at most ~16 eps |u| of rounding in mass-weighted space, where the
/// maps are orthogonal and do not amplify earlier errors.
constexpr double kBoundFactor = 64.0;

template <class T>
double toDouble(const T& value) {
  return static_cast<double>(value);
}

template <class T>
T epsilonOf() {
  return std::numeric_limits<T>::epsilon();
}

/// Per-pair impact coefficients in precision T. An impact with approach speed
/// r = v_right - v_left changes the heavier body by its small gain, 2 m_light / (m_l + m_r)
/// times r, and then sets the lighter one from the exact reversal v_r' - v_l' = -r. The
/// reversal keeps the relative speed exact, so rounded coefficients do not bias the
/// energy, and the heavy body, whose error costs the most energy, gets the smallest one.
template <class T>
struct PairCoefficients {
  bool heavy_is_left;
  T heavy_gain;
};

template <class T>
PairCoefficients<T> pairCoefficients(const std::array<double, 3>& m, int left) {
  const int right = left + 1;
  const bool heavy_is_left = m[left] >= m[right];
  const double heavy = heavy_is_left ? m[left] : m[right];
  const double light = heavy_is_left ? m[right] : m[left];
  if (std::isinf(heavy)) return {heavy_is_left, T(0)};
  return {heavy_is_left, T(2) / (T(1) + T(heavy) / T(light))};
}

template <class T>
struct Coefficients {
  PairCoefficients<T> ab;
  PairCoefficients<T> bc;
  explicit Coefficients(const std::array<double, 3>& m)
      : ab(pairCoefficients<T>(m, kA)), bc(pairCoefficients<T>(m, kB)) {}
  const PairCoefficients<T>& of(Pair p) const { return p == Pair::AB ? ab : bc; }
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

  /// Approach speed of the pair whose right-hand body is `left` (A for AB, B for BC).
  T approach(int left) const { return (hi[left + 1] - hi[left]) + (lo[left + 1] - lo[left]); }

  void add(int i, const T& increment) {
    const T sum = hi[i] + increment;
    const T increment_part = sum - hi[i];
    lo[i] += (hi[i] - (sum - increment_part)) + (increment - increment_part);
    hi[i] = sum;
  }

  /// Sets body i to (hi[from] + lo[from]) + sign * (speed_hi + speed_lo), keeping the
  /// rounding error of the leading sum: the light body's velocity swings far above its
  /// final value, and its rounding at the peak would otherwise stay in it.
  void setFrom(int i, int from, const T& sign, const T& speed_hi, const T& speed_lo) {
    const T term = sign * speed_hi;
    const T sum = hi[from] + term;
    const T term_part = sum - hi[from];
    lo[i] = (hi[from] - (sum - term_part)) + (term - term_part) + lo[from] + sign * speed_lo;
    hi[i] = sum;
  }

  void impact(const PairCoefficients<T>& c, int left) {
    const int right = left + 1;
    // Approach speed as hi + lo, the leading difference split exactly (TwoSum).
    const T speed_hi = hi[right] - hi[left];
    const T right_part = speed_hi + hi[left];
    const T speed_lo = ((hi[right] - right_part) + (right_part - speed_hi - hi[left])) + (lo[right] - lo[left]);
    const T speed = speed_hi + speed_lo;
    if (c.heavy_is_left) {
      add(left, c.heavy_gain * speed);
      setFrom(right, left, T(-1), speed_hi, speed_lo);
    } else {
      add(right, -(c.heavy_gain * speed));
      setFrom(left, right, T(1), speed_hi, speed_lo);
    }
  }

  /// Takes over a more accurate state (a replay in higher precision or exact rationals).
  template <class Precise>
  void adopt(const std::array<Precise, 3>& precise) {
    for (int i = 0; i < 3; ++i) {
      if constexpr (std::is_floating_point_v<T>) {
        hi[i] = T(static_cast<double>(precise[i]));
        lo[i] = T(static_cast<double>(Precise(precise[i] - Precise(static_cast<double>(hi[i])))));
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
std::array<T, 3> replay(const Scene& scene, Pair first, std::uint64_t k) {
  const Coefficients<T> coefficients(scene.masses);
  std::array<T, 3> v{T(scene.velocities[0]), T(scene.velocities[1]), T(scene.velocities[2])};
  Pair pair = first;
  for (std::uint64_t i = 0; i < k; ++i) {
    const int left = pair == Pair::AB ? kA : kB;
    const PairCoefficients<T>& c = coefficients.of(pair);
    const T approach = v[left + 1] - v[left];
    if (c.heavy_is_left) {
      v[left] += c.heavy_gain * approach;
      v[left + 1] = v[left] - approach;
    } else {
      v[left + 1] -= c.heavy_gain * approach;
      v[left] = v[left + 1] + approach;
    }
    pair = otherPair(pair);
  }
  return v;
}

/// Scales that bound rounding errors: in the wall's frame (or the lab frame without a
/// wall) kinetic energy is conserved, so |u| = sqrt(sum m v^2) bounds every mass-weighted
/// velocity, and a velocity error is at most |du| / sqrt(m).
class ErrorScale {
 public:
  explicit ErrorScale(const Scene& scene) {
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
    ab_ = std::max(min_scale, u * (inverse_sqrt_mass_[kA] + inverse_sqrt_mass_[kB]));
    bc_ = std::max(min_scale, u * (inverse_sqrt_mass_[kB] + inverse_sqrt_mass_[kC]));
  }

  /// Velocity scale [m/s] of the approach speed of `pair`.
  long double of(Pair pair) const { return pair == Pair::AB ? ab_ : bc_; }

  /// Bound on the rounding error of an approach speed after k impacts in precision T.
  template <class T>
  T bound(Pair pair, std::uint64_t k) const {
    return T(static_cast<double>(of(pair))) * T(kBoundFactor) * epsilonOf<T>() * T(static_cast<double>(k + 2));
  }

 private:
  long double inverse_sqrt_mass_[3]{};
  long double ab_ = 0.0L;
  long double bc_ = 0.0L;
};

template <class T>
T approachOf(Pair pair, const std::array<T, 3>& v) {
  return pair == Pair::AB ? T(v[kB] - v[kA]) : T(v[kC] - v[kB]);
}

/// Takes the sign decisions the working precision cannot, at 100 digits: a replay for
/// short runs, the closed-form state after k impacts (O(1) in k) for long ones; then
/// exact rationals for a zero to within that, then 500 digits beyond the rationals' reach.
/// The closed form holds for any alternating sequence, which every run is.
template <class Scalar>
class Escalation {
 public:
  Escalation(const Scene& scene, const ErrorScale& scale, Pair first) : scene_(scene), scale_(scale), first_(first) {}

  /// Does `pair` approach after k impacts, as exact arithmetic says? Hands the accurate
  /// state at k to `v`.
  bool approaches(std::uint64_t k, Pair pair, CompensatedVelocities<Scalar>& v, EscalationStats& stats) {
    ++stats.high_precision;
    const Precise precise = preciseState(k);
    const ReplayPrecision precise_approach = approachOf(pair, precise.velocities);
    if (mp::abs(precise_approach) > precise.bound_factor * scale_.bound<ReplayPrecision>(pair, k)) {
      v.adopt(precise.velocities);
      return precise_approach > 0;
    }
    if (k <= kExactReplayLimit) {
      ++stats.exact_rational;
      const exact::RationalState exact_state = exact::velocitiesAfter(scene_, first_, k);
      v.adopt(exact_state);
      return exact::approachSpeed(pair, exact_state) > 0;
    }
    // An exact zero this deep would need input doubles built for it over thousands of
    // impacts; 500 digits separate everything else.
    const AnalyticModel<DeepReplayPrecision> deep_model(scene_);
    const auto deep = stateOf(deep_model, k);
    v.adopt(deep);
    return approachOf(pair, deep) > closedFormFactor<DeepReplayPrecision>() * scale_.bound<DeepReplayPrecision>(pair, k);
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

  const Scene& scene_;
  const ErrorScale& scale_;
  Pair first_;
  std::optional<AnalyticModel<ReplayPrecision>> closed_form_;
};

struct Frame {
  double energy = 0.0;    // kinetic energy in the wall's frame (lab frame without a wall)
  double momentum = 0.0;  // lab-frame momentum of the finite masses
  double momentum_magnitude = 0.0;  // sum |m v|
};

template <class Scalar>
Frame measure(const Scene& scene, const std::array<Scalar, 3>& v) {
  const int wall = scene.wallIndex();
  const Scalar frame = wall >= 0 ? v[wall] : Scalar(0);
  Scalar energy = 0, momentum = 0, magnitude = 0;
  for (int i = 0; i < 3; ++i) {
    if (i == wall) continue;
    const Scalar m(scene.masses[i]);
    const Scalar dv = v[i] - frame;
    energy += m * dv * dv / 2;
    momentum += m * v[i];
    magnitude += m * (v[i] < 0 ? Scalar(-v[i]) : v[i]);
  }
  return {toDouble(energy), toDouble(momentum), toDouble(magnitude)};
}

/// Run time as an unevaluated sum hi + lo: thousands of short flights add up without
/// the rounding of each sum, which a fast light body would turn into position error.
template <class T>
struct CompensatedTime {
  T hi = 0;
  T lo = 0;

  void advance(const T& delay) {
    const T sum = hi + delay;
    const T delay_part = sum - hi;
    lo += (hi - (sum - delay_part)) + (delay - delay_part);
    hi = sum;
  }
  T since(const CompensatedTime& earlier) const { return (hi - earlier.hi) + (lo - earlier.lo); }
  T value() const { return hi + lo; }
};

/// Time, position and event bookkeeping of a run that reports events. Each body's path
/// is anchored where its velocity last changed.
template <class Scalar>
class Trajectory {
 public:
  explicit Trajectory(const Scene& scene) : scene_(scene) {
    for (int i = 0; i < 3; ++i) reference_position_[i] = Scalar(scene.positions[i]);
  }

  Scalar positionNow(int i, const std::array<Scalar, 3>& v) const {
    return reference_position_[i] + v[i] * now_.since(reference_time_[i]);
  }

  /// Delay until the next impact of `pair`, which approaches with speed `approach` > 0.
  Scalar delayToImpact(Pair pair, const std::array<Scalar, 3>& v, const Scalar& approach) const {
    const int left = pair == Pair::AB ? kA : kB;
    Scalar gap = positionNow(left, v) - positionNow(left + 1, v);
    if (gap < 0) gap = 0;  // rounding can put touching bodies a hair out of order
    return gap / approach;
  }

  ImpactEvent makeEvent(std::uint64_t index, Pair pair, const Scalar& delay, const std::array<Scalar, 3>& before,
                           const std::array<Scalar, 3>& after) {
    now_.advance(delay);
    ImpactEvent event;
    event.index = index;
    event.pair = pair;
    event.time = toDouble(now_.value());
    const int left = pair == Pair::AB ? kA : kB;
    const int right = left + 1;
    const int wall = scene_.wallIndex();
    std::array<Scalar, 3> positions;
    for (int i = 0; i < 3; ++i) {
      positions[i] = positionNow(i, before);
      event.velocities_before[i] = toDouble(before[i]);
      event.velocities_after[i] = toDouble(after[i]);
    }
    // The pair meets where the slower of the two is: a position extrapolated at speed v
    // is off by v times the time's rounding, so the slow body's is the accurate one.
    const Scalar speed_left = before[left] < 0 ? Scalar(-before[left]) : before[left];
    const Scalar speed_right = before[right] < 0 ? Scalar(-before[right]) : before[right];
    const Scalar contact = speed_left <= speed_right ? positions[left] : positions[right];
    positions[left] = positions[right] = contact;
    for (int i = 0; i < 3; ++i) event.positions[i] = toDouble(positions[i]);
    event.position = toDouble(contact);
    double gained_by_finite = 0.0;
    for (int i = 0; i < 3; ++i) {
      if (i == wall) continue;
      const Scalar m(scene_.masses[i]);
      const double gained = toDouble(m * (after[i] - before[i]) * (after[i] + before[i]) / 2);
      event.energy_transfer[i] = gained;
      gained_by_finite += gained;
      event.total_energy += toDouble(m * after[i] * after[i] / 2);
      event.total_momentum += toDouble(m * after[i]);
    }
    if (wall >= 0) event.energy_transfer[wall] = -gained_by_finite;

    // Re-anchor the bodies whose velocity changed (a wall's never does).
    for (int i : {left, right}) {
      if (i == wall) continue;
      reference_position_[i] = contact;
      reference_time_[i] = now_;
    }
    return event;
  }

  Scalar now() const { return now_.value(); }

 private:
  const Scene& scene_;
  std::array<Scalar, 3> reference_position_;
  std::array<CompensatedTime<Scalar>, 3> reference_time_{};
  CompensatedTime<Scalar> now_;
};

bool keepsEvent(const EventPolicy& policy, std::uint64_t index) {
  switch (policy.kind) {
    case EventPolicy::Kind::kNone: return false;
    case EventPolicy::Kind::kAll: return true;
    case EventPolicy::Kind::kFirstN: return index <= policy.first_n;
  }
  return false;
}

}  // namespace

std::optional<Pair> firstPair(const Scene& scene) {
  const auto& v = scene.velocities;
  const bool ab = v[kA] < v[kB];
  const bool bc = v[kB] < v[kC];
  if (ab && bc) return exact::compareFirstContactTimes(scene) < 0 ? Pair::AB : Pair::BC;
  if (ab) return Pair::AB;
  if (bc) return Pair::BC;
  return std::nullopt;
}

template <class Scalar>
SimulationResult simulate(const Scene& scene, const SimulationOptions& options, const EventVisitor& visitor) {
  SimulationResult result;
  result.first_pair = firstPair(scene);
  CompensatedVelocities<Scalar> v(scene.velocities);
  const Frame start = measure(scene, v.values());
  const bool tracks_events = options.events.kind != EventPolicy::Kind::kNone || static_cast<bool>(visitor);

  const Coefficients<Scalar> coefficients(scene.masses);
  const ErrorScale scale(scene);
  const Scalar step_bound_ab = scale.bound<Scalar>(Pair::AB, 0) / Scalar(2);  // bound(k) = (k+2) * step
  const Scalar step_bound_bc = scale.bound<Scalar>(Pair::BC, 0) / Scalar(2);
  EscalationStats& stats = result.escalation;

  // The error bound grows with the impacts since v was last exact to working precision.
  std::uint64_t exact_at = 0;
  std::optional<Escalation<Scalar>> escalation;

  // Does `pair` approach after k impacts? Exact decision; may refresh v.
  auto approaches = [&](Pair pair, std::uint64_t k) {
    ++stats.decisions;
    if (k - exact_at >= kResynchronizeInterval) {
      if (!escalation) escalation.emplace(scene, scale, *result.first_pair);
      escalation->resynchronize(k, v);
      exact_at = k;
    }
    const Scalar approach = v.approach(pair == Pair::AB ? kA : kB);
    const Scalar bound =
        (pair == Pair::AB ? step_bound_ab : step_bound_bc) * Scalar(static_cast<double>(k - exact_at + 2));
    if (approach > bound) return true;
    if (approach < -bound) return false;
    if (!escalation) escalation.emplace(scene, scale, *result.first_pair);
    exact_at = k;
    return escalation->approaches(k, pair, v, stats);
  };

  std::uint64_t k = 0;
  if (result.first_pair && !tracks_events) {
    // Count-only: after the first impact the pairs alternate and positions no longer
    // matter, so only velocities are modelled.
    Pair pair = *result.first_pair;
    while (approaches(pair, k)) {
      if (k == options.max_collisions) {
        result.truncated = true;
        break;
      }
      v.impact(coefficients.of(pair), pair == Pair::AB ? kA : kB);
      ++k;
      pair = otherPair(pair);
    }
  } else if (result.first_pair) {
    Trajectory<Scalar> trajectory(scene);
    Pair pair = *result.first_pair;
    while (approaches(pair, k)) {
      if (k == options.max_collisions) {
        result.truncated = true;
        break;
      }
      const int left = pair == Pair::AB ? kA : kB;
      const std::array<Scalar, 3> before = v.values();
      // The compensated approach speed: after an escalation it can be far below the
      // rounding of the velocities themselves.
      const Scalar approach = v.approach(left);
      const Scalar delay = trajectory.delayToImpact(pair, before, approach > 0 ? approach : Scalar(0));
      v.impact(coefficients.of(pair), left);
      ++k;
      const ImpactEvent event = trajectory.makeEvent(k, pair, delay, before, v.values());
      if (visitor) visitor(event);
      if (keepsEvent(options.events, k)) result.events.push_back(event);
      pair = otherPair(pair);
    }
    result.final_time = toDouble(trajectory.now());
    const std::array<Scalar, 3> final_velocities = v.values();
    for (int i = 0; i < 3; ++i) result.final_positions[i] = toDouble(trajectory.positionNow(i, final_velocities));
  }
  if (!tracks_events || !result.first_pair) {
    for (int i = 0; i < 3; ++i) {
      result.final_positions[i] = tracks_events ? scene.positions[i] : std::numeric_limits<double>::quiet_NaN();
    }
  }

  result.collision_count = k;
  const std::array<Scalar, 3> final_velocities = v.values();
  for (int i = 0; i < 3; ++i) result.final_velocities[i] = toDouble(final_velocities[i]);
  const Frame end = measure(scene, final_velocities);
  result.energy_relative_drift = start.energy > 0 ? std::fabs(end.energy - start.energy) / start.energy : 0.0;
  if (scene.wallIndex() >= 0) {
    result.momentum_relative_drift = std::numeric_limits<double>::quiet_NaN();
  } else {
    result.momentum_relative_drift =
        start.momentum_magnitude > 0 ? std::fabs(end.momentum - start.momentum) / start.momentum_magnitude : 0.0;
  }
  return result;
}

template SimulationResult simulate<double>(const Scene&, const SimulationOptions&, const EventVisitor&);
template SimulationResult simulate<long double>(const Scene&, const SimulationOptions&, const EventVisitor&);
template SimulationResult simulate<HighPrecision>(const Scene&, const SimulationOptions&, const EventVisitor&);

const char* precisionName(Precision p) {
  switch (p) {
    case Precision::kDouble: return "double";
    case Precision::kLongDouble: return "long_double";
    case Precision::kHigh: return "high";
  }
  return "unknown";
}

std::optional<Precision> parsePrecision(const std::string& name) {
  for (Precision p : {Precision::kDouble, Precision::kLongDouble, Precision::kHigh}) {
    if (name == precisionName(p)) return p;
  }
  return std::nullopt;
}

SimulationResult simulate(const Scene& scene, const SimulationOptions& options, Precision precision,
                          const EventVisitor& visitor) {
  switch (precision) {
    case Precision::kLongDouble: return simulate<long double>(scene, options, visitor);
    case Precision::kHigh: return simulate<HighPrecision>(scene, options, visitor);
    case Precision::kDouble: break;
  }
  return simulate<double>(scene, options, visitor);
}

}  // namespace collision_lab
