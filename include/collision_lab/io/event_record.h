// The one record of an event of any scene (impact or collapse), from which every front end
// writes it: the CLI's JSON and CSV reports (scene_report.h) and the ROS node's
// CollisionEvent (msg_conversion.h). ROS-free.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "collision_lab/core/events.h"
#include "collision_lab/core/nbody/body_state_replay.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/scene.h"

namespace collision_lab {
namespace io {

/// Bodies at most for which an event record carries the full state (every body's arrays);
/// CollisionEvent::FULL_STATE_MAX_BODIES, the ROS message's limit, which the record mirrors.
constexpr std::size_t kFullStateMaxBodies = 64;

/// One event of any scene, in the one schema of JSON and CSV (docs/cli.md "Events"): the
/// fields of msg/CollisionEvent.msg. Pointers refer to the caller's arrays; a null pointer
/// (or full_state false) prints as JSON null and an empty CSV cell.
struct EventRecord {
  bool collapse = false;
  std::uint64_t index = 0;     ///< impact number; a collapse: the impacts before it
  std::size_t pair_index = 0;  ///< a collapse: its first body
  double time = 0.0, position = 0.0, restitution = 1.0;
  std::size_t first_moved = 0, last_moved = 0;
  bool cluster_impact = false;
  std::array<double, 2> pair_velocities_before{}, pair_velocities_after{}, pair_energy_transfer{};
  double energy_lost = 0.0;
  bool full_state = false;  ///< the arrays below have `bodies` entries
  std::size_t bodies = 0;
  const double* positions = nullptr;
  const double* velocities_before = nullptr;
  const double* velocities_after = nullptr;
  const double* energy_transfer = nullptr;
  const double* kinetic_energy_after = nullptr;
  double total_energy = 0.0, total_momentum = 0.0;
  /// The model block's values (core::ImpactModelValues), where the impact has one; null
  /// otherwise.
  const std::array<double, 3>* predicted_velocities_after = nullptr;
  const std::array<double, 3>* predicted_energy_transfer = nullptr;
  const std::array<double, 3>* paper_velocities_after = nullptr;
  const std::array<double, 3>* paper_energy_transfer = nullptr;
  /// core::ImpactValue bits: the record's values not certified correctly rounded (the JSON's
  /// "uncertified": their names; the CSV has no such column).
  std::uint32_t uncertified = 0;
};

/// The record's pair as the reports name it: core::pairName ("AB"), or across a ring's seam
/// the two bodies' names ("CA", "#30-A").
std::string eventPairName(const EventRecord& record);

/// The record's full state, pair energy transfers and model values from an impact's model
/// block (core::ImpactModelValues, as the run computed them); the record refers to `values`.
void fillFromModelBlock(EventRecord& record, const core::ImpactModelValues& values);

/// The bodies' state through an N-body run, from its impacts and collapses in order, for
/// their records (core::BodyStateReplay): the per-body arrays of a record only for scenes
/// of at most kFullStateMaxBodies bodies. An impact with a model block (ImpactRecord::model)
/// takes its per-body arrays, totals and model values from the block, as the run computed
/// them. A record refers to this object's arrays or to the impact's block, valid until the
/// next impact() or collapse() and while the impact lives.
class SceneEventState {
 public:
  /// `policy`: which impacts' records carry every body's state (EventPolicy::fullStateAt;
  /// the others, the lean record, only their pair's). Collapses always carry it.
  explicit SceneEventState(const core::Scene& scene, const core::EventPolicy& policy = {});
  EventRecord impact(const core::ImpactRecord& impact);
  EventRecord collapse(const core::Collapse& collapse);
  /// The replay behind the records: the state after the last impact() or collapse().
  const core::BodyStateReplay& replay() const { return replay_; }

 private:
  void fill(EventRecord& record, bool velocities_before_uncertified);
  static void lean(EventRecord& record);

  core::Scene scene_;
  bool full_state_;
  core::EventPolicy policy_;
  core::BodyStateReplay replay_;  ///< the one replay of the records (core/nbody/body_state_replay.h)
  std::vector<char> velocity_uncertified_;  ///< per body: its velocity came from an uncertified value
  std::size_t velocities_uncertified_ = 0;  ///< bodies whose velocity is
  /// Marks bodies first..last (first > last: the two of a ring's seam) as moved to a
  /// velocity certified or not.
  void moved(std::size_t first, std::size_t last, bool uncertified);
  std::vector<double> positions_, before_, gain_;  ///< the record's arrays (full state only)
};

}  // namespace io
}  // namespace collision_lab
