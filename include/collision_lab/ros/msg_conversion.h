// Every conversion between collision_lab messages and the core's types, as free
// functions (like cartographer_ros/msg_conversion.h). Conversions copy values only; the
// caller fills header and run_id, the run's timeline (timeline_scale of Prediction and
// RunSummary), and the node-only fields of RunSummary (bag and publishing state,
// timeline_saturated, requested_run_id).
#pragma once

#include <array>
#include <cstdint>
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
#include "collision_lab/core/lab_run.h"
#include "collision_lab/core/scene.h"

namespace collision_lab_ros {

/// Reason codes of the node's own, beyond the core's validation reasons (Rejected.msg).
enum class NodeReason : std::uint8_t {
  kDuplicateRunId = collision_lab::Rejected::DUPLICATE_RUN_ID,
  kInvalidRunId = collision_lab::Rejected::INVALID_RUN_ID,
  kInvalidMode = collision_lab::Rejected::INVALID_MODE,
};

const char* nodeReasonName(NodeReason reason);

/// The first three values (bodies A, B, C); NaN for a body the list does not have.
std::array<double, 3> toArray(const std::vector<double>& values);
std::vector<double> toVector(const std::array<double, 3>& values);

collision_lab::core::ThreeBodyScene toScene(const collision_lab::InitialConditions& msg);
/// mode and max_collisions as given; header and run_id left for the caller.
collision_lab::InitialConditions toInitialConditions(const collision_lab::core::ThreeBodyScene& scene,
                                                     collision_lab::core::RunMode mode,
                                                     std::uint64_t max_collisions);

/// Empty for a value that is not one of InitialConditions::MODE_*.
std::optional<collision_lab::core::RunMode> toRunMode(std::uint8_t mode);

/// Prediction::PAIR_NONE for an empty pair.
std::uint32_t toPairCode(const std::optional<collision_lab::core::Pair>& pair);
std::optional<collision_lab::core::Pair> toPair(std::uint32_t code);

collision_lab::Prediction toPredictionMsg(const collision_lab::core::AnalyticPrediction& prediction);
collision_lab::core::AnalyticPrediction toPrediction(const collision_lab::Prediction& msg);

collision_lab::CollisionEvent toCollisionEventMsg(const collision_lab::core::LabEvent& event);
/// Inverse of toCollisionEventMsg: the message carries every field of a LabEvent.
collision_lab::core::LabEvent toLabEvent(const collision_lab::CollisionEvent& msg);

/// The plot topics' projections of a CollisionEvent (header and run_id included): each
/// field copies one element of the event's arrays (docs/messages.md).
collision_lab::Velocities toVelocitiesMsg(const collision_lab::CollisionEvent& event);
/// cumulative_energy_lost: the run's heat up to and including this event [J].
collision_lab::EnergyTransfer toEnergyTransferMsg(const collision_lab::CollisionEvent& event,
                                                  double cumulative_energy_lost);

/// The physics fields of a summary; published_events, events_not_published, bag_path,
/// recording_ok, recording_error, timeline_scale, timeline_saturated and
/// requested_run_id are the node's to fill.
collision_lab::RunSummary toRunSummaryMsg(const collision_lab::core::LabRunSummary& summary,
                                          const collision_lab::core::AnalyticPrediction& prediction,
                                          collision_lab::core::RunMode mode);

collision_lab::Rejected toRejectedMsg(const collision_lab::core::ValidationError& error);
collision_lab::Rejected toRejectedMsg(NodeReason reason, const std::string& field,
                                      const std::string& message);

}  // namespace collision_lab_ros
