// Exact event-driven simulation: collision by collision, no time stepping.
//
// Every decision that changes the outcome (which pair hits first, does a pair still
// approach) is taken as exact rational arithmetic on the input doubles would take it:
// a fast path in the working precision with a forward error bound, escalating to the
// closed-form state at 100 digits (O(1) in the collision index) and then to an exact
// rational replay only when a decision falls inside the bound (adaptive precision, as in
// robust geometric predicates). After an escalation the engine adopts the accurate state
// and its error bound starts again from there.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "collision_lab/core/precision.h"
#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {

/// One elastic two-body impact. Every value is the double nearest to the exact one (and
/// never -0): a time beyond the largest double is +inf (only the first contact is
/// validated to be representable), one below the smallest rounds to 0, while positions
/// keep their digits.
struct ImpactEvent {
  std::uint64_t index = 0;                    ///< 1-based collision number
  Pair pair = Pair::AB;
  double time = 0.0;                          ///< [s] since the start of the run
  double position = 0.0;                      ///< contact point [m]
  std::array<double, 3> positions{};          ///< A, B, C at the impact [m]
  std::array<double, 3> velocities_before{};  ///< [m/s]
  std::array<double, 3> velocities_after{};   ///< [m/s]
  std::array<double, 3> energy_transfer{};    ///< kinetic energy gained by A, B, C [J]
  double total_energy = 0.0;                  ///< kinetic energy of the finite masses after [J]
  double total_momentum = 0.0;                ///< momentum of the finite masses after [kg m/s]
};

/// Which events a run keeps in SimulationResult::events. Independent of the visitor,
/// which sees every event.
struct EventPolicy {
  enum class Kind { kNone, kAll, kFirstN };
  Kind kind = Kind::kNone;
  std::uint64_t first_n = 0;

  static EventPolicy none() { return {Kind::kNone, 0}; }
  static EventPolicy all() { return {Kind::kAll, 0}; }
  static EventPolicy firstN(std::uint64_t n) { return {Kind::kFirstN, n}; }

  /// Is the event of collision `index` (1-based) kept? The one place this is decided.
  bool keeps(std::uint64_t index) const {
    switch (kind) {
      case Kind::kNone: return false;
      case Kind::kAll: return true;
      case Kind::kFirstN: return index <= first_n;
    }
    return false;
  }
  /// Is an event between impacts (a collapse after `impacts_before` impacts) kept? Under
  /// firstN(N) it is when it comes before impact N + 1, as the impacts around it would be.
  bool keepsAfter(std::uint64_t impacts_before) const {
    return kind == Kind::kAll || (kind == Kind::kFirstN && impacts_before <= first_n);
  }
};

struct SimulationOptions {
  std::uint64_t max_collisions = 10'000'000;  ///< stops the run cleanly; marks it truncated
  EventPolicy events = EventPolicy::none();
  /// When set (by a signal handler or another thread), the run stops within 1024
  /// collisions, marked truncated and cancelled, with the summary of what was done.
  const std::atomic<bool>* cancel = nullptr;
};

/// Called for every collision, in order. May be empty.
using EventVisitor = std::function<void(const ImpactEvent&)>;

/// How often the adaptive path had to leave the working precision.
struct EscalationStats {
  std::uint64_t decisions = 0;        ///< sign decisions taken
  std::uint64_t high_precision = 0;   ///< decisions sent to the 100-digit closed form
  std::uint64_t exact_rational = 0;   ///< of those, decided by an exact rational replay
};

struct SimulationResult {
  std::uint64_t collision_count = 0;
  bool truncated = false;                 ///< stopped by max_collisions or cancelled
  bool cancelled = false;                 ///< stopped by SimulationOptions::cancel
  std::optional<Pair> first_pair;         ///< empty when nothing ever collides
  std::array<double, 3> final_velocities{};  ///< [m/s]
  /// Positions [m] at final_time [s]: the time of the last collision (0 without any).
  /// Only computed when events are kept or visited; otherwise NaN ("not modelled").
  std::array<double, 3> final_positions{};
  double final_time = 0.0;
  double energy_relative_drift = 0.0;     ///< |E_end - E_0| / E_0, in the wall's frame
  /// |p_end - p_0| / sum |m v|; NaN with a wall, which does not conserve momentum.
  double momentum_relative_drift = 0.0;
  EscalationStats escalation;
  std::vector<ImpactEvent> events;     ///< as EventPolicy says
};

/// Runs the scene to the end (or to max_collisions). Scalar is double, long double or
/// HighPrecision. Precondition: validate(scene) passed. Never throws for a valid scene.
template <class Scalar>
SimulationResult simulate(const ThreeBodyScene& scene, const SimulationOptions& options,
                          const EventVisitor& visitor = {});

/// The same with the working precision chosen at run time (precision.h).
SimulationResult simulate(const ThreeBodyScene& scene, const SimulationOptions& options,
                          Precision precision, const EventVisitor& visitor = {});

}  // namespace core
}  // namespace collision_lab
