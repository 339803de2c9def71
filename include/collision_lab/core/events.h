// The policy every front end shares: which events a run keeps (EventPolicy). Every run's impact
// record is the engine's ImpactRecord (nbody/engine.h), with a model's values in its one
// optional block (impact_model_values.h).
#pragma once

#include <cstdint>

#include "collision_lab/core/scene.h"

namespace collision_lab {
namespace core {

/// Which events a run keeps (RunOptions::events, scene_run.h). Independent of the visitor,
/// which sees every event.
struct EventPolicy {
  enum class Kind { kNone, kAll, kFirstN };
  Kind kind = Kind::kNone;
  std::uint64_t first_n = 0;
  /// The lean record of long runs (the CLI's --full-state-every): of the events written,
  /// impact 1 and every full_state_every-th impact carry every body's state (and the model
  /// block); the others only their pair's. 1: every event carries it. How front ends write
  /// events; the run itself is the same.
  std::uint64_t full_state_every = 1;

  /// Does the record of impact `index` (1-based) carry every body's state?
  bool fullStateAt(std::uint64_t index) const {
    return full_state_every <= 1 || index == 1 || index % full_state_every == 0;
  }

  static EventPolicy none() { return {Kind::kNone, 0}; }
  static EventPolicy all() { return {Kind::kAll, 0}; }
  static EventPolicy firstN(std::uint64_t n) { return {Kind::kFirstN, n}; }

  /// Is the event of impact `index` (1-based) kept? The one place this is decided.
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

}  // namespace core
}  // namespace collision_lab
