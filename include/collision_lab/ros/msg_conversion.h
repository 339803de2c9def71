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

#include <boost/array.hpp>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"
#include "collision_lab/ros/core.h"

namespace collision_lab_ros {

/// Reason codes of the node's own, beyond the core's validation reasons (Rejected.msg).
enum class NodeReason : std::uint8_t {
  kDuplicateRunId = collision_lab::Rejected::DUPLICATE_RUN_ID,
  kInvalidRunId = collision_lab::Rejected::INVALID_RUN_ID,
  kInvalidMode = collision_lab::Rejected::INVALID_MODE,
};

const char* nodeReasonName(NodeReason reason);

std::array<double, 3> toArray(const boost::array<double, 3>& values);
boost::array<double, 3> toBoostArray(const std::array<double, 3>& values);

core::Scene toScene(const collision_lab::InitialConditions& msg);
/// mode and max_collisions as given; header and run_id left for the caller.
collision_lab::InitialConditions toInitialConditions(const core::Scene& scene,
                                                     core::RunMode mode,
                                                     std::uint64_t max_collisions);

/// Empty for a value that is not one of InitialConditions::MODE_*.
std::optional<core::RunMode> toRunMode(std::uint8_t mode);

/// Prediction::PAIR_NONE for an empty pair.
std::uint8_t toPairCode(const std::optional<core::Pair>& pair);
std::optional<core::Pair> toPair(std::uint8_t code);

collision_lab::Prediction toPredictionMsg(const core::Prediction& prediction);
core::Prediction toPrediction(const collision_lab::Prediction& msg);

collision_lab::CollisionEvent toCollisionEventMsg(const core::LabEvent& event);
/// Inverse of toCollisionEventMsg for the fields that message carries (not the energy
/// predictions and kinetic energies, which live in EnergyTransfer).
core::LabEvent toLabEvent(const collision_lab::CollisionEvent& msg);

collision_lab::Velocities toVelocitiesMsg(const core::LabEvent& event);
collision_lab::EnergyTransfer toEnergyTransferMsg(const core::LabEvent& event);

/// The physics fields of a summary; published_events, events_not_published, bag_path,
/// recording_ok, recording_error, timeline_scale, timeline_saturated and
/// requested_run_id are the node's to fill.
collision_lab::RunSummary toRunSummaryMsg(const core::RunSummary& summary,
                                          const core::Prediction& prediction,
                                          core::RunMode mode);

collision_lab::Rejected toRejectedMsg(const core::ValidationError& error);
collision_lab::Rejected toRejectedMsg(NodeReason reason, const std::string& field,
                                      const std::string& message);

}  // namespace collision_lab_ros
