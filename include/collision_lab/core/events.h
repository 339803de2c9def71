// The three-body run's impact record and the policies every front end shares: which
// events a run keeps (EventPolicy) and how often its decisions left the working precision
// (EscalationStats). The run itself is the exact event engine's (nbody/engine.h), through
// runLab (lab_run.h).
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {

/// One elastic two-body impact. Every value is the double nearest to the exact one (and
/// never -0): a time below the smallest double rounds to 0, while positions keep their
/// digits. An impact after the largest double is never published: the run stops before it
/// (OUT_OF_RANGE, truncated).
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

/// Which events a run keeps (RunOptions::events, lab_run.h). Independent of the visitor,
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

/// Called for every collision, in order. May be empty.
using EventVisitor = std::function<void(const ImpactEvent&)>;

/// How often the adaptive path had to leave the working precision.
struct EscalationStats {
  std::uint64_t decisions = 0;        ///< sign decisions taken
  std::uint64_t high_precision = 0;   ///< decisions taken at 100 digits or more
  std::uint64_t exact_rational = 0;   ///< of those, decided by an exact rational replay
};

}  // namespace core
}  // namespace collision_lab
