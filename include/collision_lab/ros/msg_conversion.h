// Every conversion between collision_lab messages and the core's types, as free
// functions (like cartographer_ros/msg_conversion.h). Conversions copy values only; the
// caller fills header and run_id, the run's timeline (timeline_scale of Prediction and
// RunSummary), and the node-only fields of RunSummary (bag and publishing state,
// timeline_saturated, requested_run_id, student).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include <vector>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"
#include "collision_lab/core/nbody/body_state_replay.h"
#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/core/nbody/models.h"
#include "collision_lab/core/nbody/scene.h"
#include "collision_lab/core/scene.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/event_record.h"
#include "collision_lab/service/envelope.h"

namespace collision_lab_ros {

/// Reason codes of the node's own, beyond the core's validation reasons (Rejected.msg).
enum class NodeReason : std::uint8_t {
  kDuplicateRunId = collision_lab::Rejected::DUPLICATE_RUN_ID,
  kInvalidRunId = collision_lab::Rejected::INVALID_RUN_ID,
  kInvalidMode = collision_lab::Rejected::INVALID_MODE,
  kTooManyBodies = collision_lab::Rejected::TOO_MANY_BODIES,
  kInvalidStudent = collision_lab::Rejected::INVALID_STUDENT,
};

const char* nodeReasonName(NodeReason reason);

/// The first three values (bodies A, B, C); NaN for a body the list does not have.
std::array<double, 3> toArray(const std::vector<double>& values);

/// Any N, the lists (restitution included) exactly as given: core::planScene judges them.
collision_lab::core::Scene toScene(const collision_lab::InitialConditions& msg);
/// mode and max_collisions as given; header and run_id left for the caller.
collision_lab::InitialConditions toInitialConditions(const collision_lab::core::Scene& scene,
                                                     collision_lab::core::RunMode mode,
                                                     std::uint64_t max_collisions);

/// Empty for a value that is not one of InitialConditions::MODE_*.
std::optional<collision_lab::core::RunMode> toRunMode(std::uint8_t mode);

/// Prediction::PAIR_NONE for an empty pair.
std::uint32_t toPairCode(const std::optional<collision_lab::core::Pair>& pair);
std::optional<collision_lab::core::Pair> toPair(std::uint32_t code);

/// The plan's model and prediction (core::planScene), as published before the run, for
/// every scene: the model's fields, plus its prediction (models.h), every field it gives
/// copied, none named by model. Precondition: !plan.error.
collision_lab::Prediction toPredictionMsg(const collision_lab::core::ScenePlan& plan);
/// The same into msg, which may hold an earlier run's: every field is set (header and
/// run_id to their defaults), and msg's strings and arrays keep their storage.
void fillPredictionMsg(const collision_lab::core::ScenePlan& plan, collision_lab::Prediction& msg);
/// The core notification a received or recorded CollisionEvent stands for, from its pair
/// fields (present for every N): KIND_IMPACT an impact record, KIND_COLLAPSE a collapse
/// notice (velocity: pair_velocities_after[0]). Applies it to replay; false, and the replay
/// unchanged, when its bodies do not fit the replay's scene.
bool replayEvent(collision_lab::core::BodyStateReplay& replay, const collision_lab::CollisionEvent& msg);

/// The plot topics' projections of a CollisionEvent (header and run_id included), with the
/// velocities v [m/s] of every body after it; delta and kinetic [J] likewise, and
/// cumulative_energy_lost the run's heat up to and including this event [J]
/// (docs/messages.md). The scalar fields copy bodies 0, 1, 2 (NaN beyond N).
collision_lab::Velocities toVelocitiesMsg(const collision_lab::CollisionEvent& event, std::vector<double> v);
collision_lab::EnergyTransfer toEnergyTransferMsg(const collision_lab::CollisionEvent& event,
                                                  std::vector<double> delta, std::vector<double> kinetic,
                                                  double cumulative_energy_lost);
/// The same from the event's own arrays (three-body events, or N <= FULL_STATE_MAX_BODIES).
collision_lab::Velocities toVelocitiesMsg(const collision_lab::CollisionEvent& event);
collision_lab::EnergyTransfer toEnergyTransferMsg(const collision_lab::CollisionEvent& event,
                                                  double cumulative_energy_lost);
/// The same into msg, which may hold an earlier event's: every field is set, and msg's
/// strings and arrays keep their storage.
void fillVelocitiesMsg(const collision_lab::CollisionEvent& event, collision_lab::Velocities& msg);
void fillEnergyTransferMsg(const collision_lab::CollisionEvent& event, double cumulative_energy_lost,
                           collision_lab::EnergyTransfer& msg);

/// The CollisionEvent of each of a run's notifications, in the order the run gives them
/// (impacts and collapses interleaved, engine.h): a copy of the one event record that the
/// CLI's reports write too (io::SceneEventState, event_record.h), so both carry the same
/// values, an impact's model block (ImpactRecord::model) included. The per-body arrays (positions at the event's time, velocities before and after,
/// energy transfer, kinetic energy) and the totals only for N <= FULL_STATE_MAX_BODIES
/// (NaN totals above). Header and run_id are the caller's to fill.
class SceneEventConverter {
 public:
  explicit SceneEventConverter(const collision_lab::core::Scene& scene);

  /// One impact of the event engine (KIND_IMPACT).
  collision_lab::CollisionEvent impact(const collision_lab::core::ImpactRecord& record);
  /// One resolved inelastic collapse (KIND_COLLAPSE): its bodies move on as one cluster.
  collision_lab::CollisionEvent collapse(const collision_lab::core::Collapse& collapse);
  /// The same into msg, which may hold an earlier event: every field but header and
  /// run_id is set, and msg's arrays keep their storage.
  void impact(const collision_lab::core::ImpactRecord& record, collision_lab::CollisionEvent& msg);
  void collapse(const collision_lab::core::Collapse& collapse, collision_lab::CollisionEvent& msg);

  /// The plot messages of the last event converted: their arrays have length N for
  /// N <= FULL_STATE_MAX_BODIES (O(N) each, the event's own) and are empty above it, like
  /// the event's; the scalar fields (bodies 0, 1, 2) are always filled.
  collision_lab::Velocities velocitiesMsg(const collision_lab::CollisionEvent& event) const;
  collision_lab::EnergyTransfer energyTransferMsg(const collision_lab::CollisionEvent& event) const;
  /// The same into msg, which may hold an earlier event's: every field is set, and msg's
  /// strings and arrays keep their storage.
  void velocitiesMsg(const collision_lab::CollisionEvent& event, collision_lab::Velocities& msg) const;
  void energyTransferMsg(const collision_lab::CollisionEvent& event, collision_lab::EnergyTransfer& msg) const;
  /// The state after the last event converted, every body's for any N (RunProgress's).
  const collision_lab::core::BodyStateReplay& replay() const { return state_.replay(); }

 private:
  /// The message of one record of state_, into msg (every field but header and run_id).
  static void toMsg(const collision_lab::io::EventRecord& record, collision_lab::CollisionEvent& msg);

  collision_lab::io::SceneEventState state_;
  bool full_state_;
};

/// The physics fields of a summary, from the run's one SceneSimulation for every scene,
/// plus the rotation model's block when it answered (its predicted and paper's counts, and
/// its prediction error at every impact); published_events, events_not_published, bag_path,
/// recording_ok, recording_error, timeline_scale, timeline_saturated,
/// requested_run_id and student are the node's to fill.
collision_lab::RunSummary toRunSummaryMsg(const collision_lab::core::SceneRunResult& result,
                                          std::size_t body_count, collision_lab::core::RunMode mode);
/// The same into msg, which may hold an earlier run's: every field is set (the node's to
/// their defaults), and msg's strings and arrays keep their storage.
void fillRunSummaryMsg(const collision_lab::core::SceneRunResult& result, std::size_t body_count,
                       collision_lab::core::RunMode mode, collision_lab::RunSummary& msg);

collision_lab::Rejected toRejectedMsg(const collision_lab::core::ValidationError& error);
collision_lab::Rejected toRejectedMsg(NodeReason reason, const std::string& field,
                                      const std::string& message);
/// An input outside the envelope (service::checkEnvelope), under its node reason.
collision_lab::Rejected toRejectedMsg(const collision_lab::service::EnvelopeRefusal& refusal);

}  // namespace collision_lab_ros
