#include "collision_lab/ros/msg_conversion.h"

#include <limits>

#include "collision_lab/core/nbody/models.h"
#include "collision_lab/core/wedge.h"

namespace collision_lab_ros {

using collision_lab::Rejected;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The interim node serves three elastic bodies only (issue 12 serves any scene).
constexpr char kThreeBodyRotationReason[] =
    "three elastic bodies: the paper's rotation by 2 alpha per AB+BC cycle, corrected";
}  // namespace

static_assert(collision_lab::InitialConditions::MODE_FULL ==
                  static_cast<std::uint8_t>(collision_lab::core::RunMode::kFull) &&
              collision_lab::InitialConditions::MODE_PREDICT_ONLY ==
                  static_cast<std::uint8_t>(collision_lab::core::RunMode::kPredictOnly) &&
              collision_lab::InitialConditions::MODE_SUMMARY_ONLY ==
                  static_cast<std::uint8_t>(collision_lab::core::RunMode::kSummaryOnly),
              "InitialConditions::MODE_* must match collision_lab::core::RunMode");
constexpr int kPairAB = static_cast<int>(collision_lab::core::Pair::AB);
constexpr int kPairBC = static_cast<int>(collision_lab::core::Pair::BC);
static_assert(collision_lab::CollisionEvent::PAIR_AB == kPairAB &&
              collision_lab::CollisionEvent::PAIR_BC == kPairBC &&
              collision_lab::Prediction::PAIR_AB == kPairAB &&
              collision_lab::Prediction::PAIR_BC == kPairBC,
              "PAIR_* must match collision_lab::core::Pair");
static_assert(Rejected::NON_FINITE_VALUE == static_cast<std::uint8_t>(collision_lab::core::Reason::kNonFiniteValue) &&
              Rejected::NON_POSITIVE_MASS == static_cast<std::uint8_t>(collision_lab::core::Reason::kNonPositiveMass) &&
              Rejected::TWO_WALLS == static_cast<std::uint8_t>(collision_lab::core::Reason::kTwoWalls) &&
              Rejected::INFINITE_MIDDLE_MASS ==
                  static_cast<std::uint8_t>(collision_lab::core::Reason::kInfiniteMiddleMass) &&
              Rejected::POSITIONS_NOT_ORDERED ==
                  static_cast<std::uint8_t>(collision_lab::core::Reason::kPositionsNotOrdered) &&
              Rejected::POSITIONS_COINCIDENT ==
                  static_cast<std::uint8_t>(collision_lab::core::Reason::kPositionsCoincident) &&
              Rejected::TRIPLE_COLLISION == static_cast<std::uint8_t>(collision_lab::core::Reason::kTripleCollision) &&
              Rejected::OVERFLOW == static_cast<std::uint8_t>(collision_lab::core::Reason::kOverflow),
              "Rejected reason codes must match collision_lab::core::Reason");

const char* nodeReasonName(NodeReason reason) {
  switch (reason) {
    case NodeReason::kDuplicateRunId: return "DUPLICATE_RUN_ID";
    case NodeReason::kInvalidRunId: return "INVALID_RUN_ID";
    case NodeReason::kInvalidMode: return "INVALID_MODE";
  }
  return "UNKNOWN";
}

std::array<double, 3> toArray(const std::vector<double>& values) {
  std::array<double, 3> result;
  for (std::size_t i = 0; i < result.size(); ++i) result[i] = i < values.size() ? values[i] : kNaN;
  return result;
}

std::vector<double> toVector(const std::array<double, 3>& values) {
  return {values.begin(), values.end()};
}

collision_lab::core::ThreeBodyScene toScene(const collision_lab::InitialConditions& msg) {
  collision_lab::core::ThreeBodyScene scene;
  scene.masses = toArray(msg.masses);
  scene.positions = toArray(msg.positions);
  scene.velocities = toArray(msg.velocities);
  return scene;
}

collision_lab::InitialConditions toInitialConditions(const collision_lab::core::ThreeBodyScene& scene,
                                                     collision_lab::core::RunMode mode,
                                                     std::uint64_t max_collisions) {
  collision_lab::InitialConditions msg;
  msg.mode = static_cast<std::uint8_t>(mode);
  msg.masses = toVector(scene.masses);
  msg.positions = toVector(scene.positions);
  msg.velocities = toVector(scene.velocities);
  msg.max_collisions = max_collisions;
  return msg;
}

std::optional<collision_lab::core::RunMode> toRunMode(std::uint8_t mode) {
  switch (mode) {
    case collision_lab::InitialConditions::MODE_FULL: return collision_lab::core::RunMode::kFull;
    case collision_lab::InitialConditions::MODE_PREDICT_ONLY: return collision_lab::core::RunMode::kPredictOnly;
    case collision_lab::InitialConditions::MODE_SUMMARY_ONLY: return collision_lab::core::RunMode::kSummaryOnly;
    default: return std::nullopt;
  }
}

std::uint32_t toPairCode(const std::optional<collision_lab::core::Pair>& pair) {
  return pair ? static_cast<std::uint32_t>(*pair) : collision_lab::Prediction::PAIR_NONE;
}

std::optional<collision_lab::core::Pair> toPair(std::uint32_t code) {
  switch (code) {
    case collision_lab::Prediction::PAIR_AB: return collision_lab::core::Pair::AB;
    case collision_lab::Prediction::PAIR_BC: return collision_lab::core::Pair::BC;
    default: return std::nullopt;
  }
}

collision_lab::Prediction toPredictionMsg(const collision_lab::core::AnalyticPrediction& prediction) {
  collision_lab::Prediction msg;
  msg.model = collision_lab::Prediction::MODEL_THREE_BODY_ROTATION;
  msg.model_name = collision_lab::core::modelKindName(collision_lab::core::ModelKind::kThreeBodyRotation);
  msg.model_reason = kThreeBodyRotationReason;
  msg.body_count = 3;
  msg.collision_count = prediction.collision_count;
  msg.collision_count_defined = true;
  msg.infinite_collisions = false;
  msg.paper_collision_count_defined = prediction.paper_collision_count.has_value();
  msg.paper_collision_count = prediction.paper_collision_count.value_or(0);
  msg.max_possible_collision_count = prediction.max_possible_collision_count;
  msg.alpha = prediction.angles.alpha;
  msg.theta = prediction.angles.theta;
  msg.omega = prediction.angles.omega;
  msg.phi_bc = prediction.phi_bc;
  msg.psi = prediction.psi;
  msg.first_pair_index = toPairCode(prediction.first_pair);
  msg.final_velocities = toVector(prediction.final_velocities);
  msg.energy_lost = 0.0;
  msg.collapsed = false;
  msg.collapse_time = kNaN;
  msg.collapse_position = kNaN;
  msg.critical_restitution = collision_lab::core::criticalRestitution(prediction.angles.alpha);
  msg.spiral_angle = prediction.angles.theta;
  return msg;
}

collision_lab::core::AnalyticPrediction toPrediction(const collision_lab::Prediction& msg) {
  collision_lab::core::AnalyticPrediction prediction;
  prediction.collision_count = msg.collision_count;
  if (msg.paper_collision_count_defined) prediction.paper_collision_count = msg.paper_collision_count;
  prediction.max_possible_collision_count = msg.max_possible_collision_count;
  prediction.angles.alpha = msg.alpha;
  prediction.angles.theta = msg.theta;
  prediction.angles.omega = msg.omega;
  prediction.phi_bc = msg.phi_bc;
  prediction.psi = msg.psi;
  prediction.first_pair = toPair(msg.first_pair_index);
  prediction.final_velocities = toArray(msg.final_velocities);
  return prediction;
}

collision_lab::CollisionEvent toCollisionEventMsg(const collision_lab::core::LabEvent& event) {
  const collision_lab::core::ImpactEvent& e = event.event;
  collision_lab::CollisionEvent msg;
  msg.kind = collision_lab::CollisionEvent::KIND_IMPACT;
  msg.index = e.index;
  msg.pair_index = static_cast<std::uint32_t>(e.pair);
  msg.time = e.time;
  msg.position = e.position;
  msg.restitution = 1.0;
  msg.first_moved = msg.pair_index;
  msg.last_moved = msg.pair_index + 1;
  msg.cluster_impact = false;
  for (std::size_t side = 0; side < 2; ++side) {
    const std::size_t body = msg.pair_index + side;
    msg.pair_velocities_before[side] = e.velocities_before[body];
    msg.pair_velocities_after[side] = e.velocities_after[body];
    msg.pair_energy_transfer[side] = e.energy_transfer[body];
  }
  msg.energy_lost = 0.0;
  msg.positions = toVector(e.positions);
  msg.velocities_before = toVector(e.velocities_before);
  msg.velocities_after = toVector(e.velocities_after);
  msg.predicted_velocities_after = toVector(event.predicted_velocities_after);
  msg.paper_velocities_after = toVector(event.paper_velocities_after);
  msg.energy_transfer = toVector(e.energy_transfer);
  msg.predicted_energy_transfer = toVector(event.predicted_energy_transfer);
  msg.paper_energy_transfer = toVector(event.paper_energy_transfer);
  msg.kinetic_energy_after = toVector(event.kinetic_energy_after);
  msg.total_energy = e.total_energy;
  msg.total_momentum = e.total_momentum;
  return msg;
}

collision_lab::core::LabEvent toLabEvent(const collision_lab::CollisionEvent& msg) {
  collision_lab::core::LabEvent event;
  collision_lab::core::ImpactEvent& e = event.event;
  e.index = msg.index;
  e.pair = toPair(msg.pair_index).value_or(collision_lab::core::Pair::AB);
  e.time = msg.time;
  e.position = msg.position;
  e.positions = toArray(msg.positions);
  e.velocities_before = toArray(msg.velocities_before);
  e.velocities_after = toArray(msg.velocities_after);
  e.energy_transfer = toArray(msg.energy_transfer);
  e.total_energy = msg.total_energy;
  e.total_momentum = msg.total_momentum;
  event.predicted_velocities_after = toArray(msg.predicted_velocities_after);
  event.paper_velocities_after = toArray(msg.paper_velocities_after);
  event.predicted_energy_transfer = toArray(msg.predicted_energy_transfer);
  event.paper_energy_transfer = toArray(msg.paper_energy_transfer);
  event.kinetic_energy_after = toArray(msg.kinetic_energy_after);
  return event;
}

namespace {

/// A plot message of event, its scalar fields left for the caller.
template <class PlotMessage>
PlotMessage plotMessageOf(const collision_lab::CollisionEvent& event) {
  PlotMessage msg;
  msg.header = event.header;
  msg.run_id = event.run_id;
  msg.index = event.index;
  msg.time = event.time;
  return msg;
}

}  // namespace

collision_lab::Velocities toVelocitiesMsg(const collision_lab::CollisionEvent& event) {
  auto msg = plotMessageOf<collision_lab::Velocities>(event);
  msg.v = event.velocities_after;
  const std::array<double, 3> first_three = toArray(msg.v);
  msg.v_a = first_three[0];
  msg.v_b = first_three[1];
  msg.v_c = first_three[2];
  return msg;
}

collision_lab::EnergyTransfer toEnergyTransferMsg(const collision_lab::CollisionEvent& event,
                                                  double cumulative_energy_lost) {
  auto msg = plotMessageOf<collision_lab::EnergyTransfer>(event);
  msg.delta = event.energy_transfer;
  msg.kinetic = event.kinetic_energy_after;
  msg.energy_lost = event.energy_lost;
  msg.cumulative_energy_lost = cumulative_energy_lost;
  const std::array<double, 3> delta = toArray(msg.delta), kinetic = toArray(msg.kinetic);
  msg.delta_a = delta[0];
  msg.delta_b = delta[1];
  msg.delta_c = delta[2];
  msg.kinetic_a = kinetic[0];
  msg.kinetic_b = kinetic[1];
  msg.kinetic_c = kinetic[2];
  return msg;
}

collision_lab::RunSummary toRunSummaryMsg(const collision_lab::core::LabRunSummary& summary,
                                          const collision_lab::core::AnalyticPrediction& prediction,
                                          collision_lab::core::RunMode mode) {
  collision_lab::RunSummary msg;
  msg.mode = static_cast<std::uint8_t>(mode);
  msg.model = collision_lab::Prediction::MODEL_THREE_BODY_ROTATION;
  msg.model_name = collision_lab::core::modelKindName(collision_lab::core::ModelKind::kThreeBodyRotation);
  msg.model_reason = kThreeBodyRotationReason;
  msg.body_count = 3;
  msg.collision_count = summary.collision_count;
  msg.truncated = summary.truncated;
  msg.truncation_reason = summary.truncation_reason;
  msg.cancelled = summary.cancelled;
  msg.stop_reason = !summary.simulated ? "NOT_SIMULATED"
                    : summary.cancelled ? "CANCELLED"
                    : summary.truncated ? "CAP"
                                        : "FINISHED";
  msg.simulated = summary.simulated;
  msg.predicted_collision_count = prediction.collision_count;
  msg.predicted_collision_count_defined = true;
  msg.paper_predicted_collision_count_defined = prediction.paper_collision_count.has_value();
  msg.paper_predicted_collision_count = prediction.paper_collision_count.value_or(0);
  msg.final_velocities = toVector(summary.final_velocities);
  msg.energy_lost = 0.0;
  msg.collapsed = false;
  msg.collapse_time = kNaN;
  msg.collapse_position = kNaN;
  msg.collapse_count = 0;
  msg.cluster_impacts = 0;
  msg.critical_restitution = collision_lab::core::criticalRestitution(prediction.angles.alpha);
  msg.spiral_angle = prediction.angles.theta;
  msg.max_prediction_error = summary.max_prediction_error;
  msg.energy_relative_drift = summary.energy_relative_drift;
  msg.momentum_relative_drift = summary.momentum_relative_drift;
  msg.compute_time = summary.compute_time_s;
  return msg;
}

collision_lab::Rejected toRejectedMsg(const collision_lab::core::ValidationError& error) {
  collision_lab::Rejected msg;
  msg.reason = static_cast<std::uint8_t>(error.reason);
  msg.reason_name = collision_lab::core::reasonName(error.reason);
  msg.field = error.field;
  msg.message = error.message;
  return msg;
}

collision_lab::Rejected toRejectedMsg(NodeReason reason, const std::string& field,
                                      const std::string& message) {
  collision_lab::Rejected msg;
  msg.reason = static_cast<std::uint8_t>(reason);
  msg.reason_name = nodeReasonName(reason);
  msg.field = field;
  msg.message = message;
  return msg;
}

}  // namespace collision_lab_ros
