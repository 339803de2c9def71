#include "collision_lab/ros/msg_conversion.h"

#include <algorithm>
#include <cmath>
#include <limits>


namespace collision_lab_ros {

using collision_lab::Rejected;
namespace core = collision_lab::core;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double valueOr(const std::optional<double>& value) { return value.value_or(kNaN); }
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
              Rejected::OVERFLOW == static_cast<std::uint8_t>(collision_lab::core::Reason::kOverflow) &&
              Rejected::UNEQUAL_LENGTHS == static_cast<std::uint8_t>(core::Reason::kUnequalLengths) &&
              Rejected::EMPTY_SCENE == static_cast<std::uint8_t>(core::Reason::kEmptyScene) &&
              Rejected::RESTITUTION_OUT_OF_RANGE ==
                  static_cast<std::uint8_t>(core::Reason::kRestitutionOutOfRange) &&
              Rejected::RESTITUTION_COUNT == static_cast<std::uint8_t>(core::Reason::kRestitutionCount) &&
              Rejected::WALL_NOT_AT_END == static_cast<std::uint8_t>(core::Reason::kWallNotAtEnd) &&
              Rejected::RESTITUTION_MODEL == static_cast<std::uint8_t>(core::Reason::kRestitutionModel) &&
              Rejected::RING == static_cast<std::uint8_t>(core::Reason::kRing),
              "Rejected reason codes must match collision_lab::core::Reason");
static_assert(collision_lab::Prediction::MODEL_NO_COLLISIONS == static_cast<std::uint8_t>(core::ModelKind::kNoCollisions) &&
              collision_lab::Prediction::MODEL_TWO_WALLS_INFINITE ==
                  static_cast<std::uint8_t>(core::ModelKind::kTwoWallsInfinite) &&
              collision_lab::Prediction::MODEL_TWO_BODY == static_cast<std::uint8_t>(core::ModelKind::kTwoBody) &&
              collision_lab::Prediction::MODEL_THREE_BODY_ROTATION ==
                  static_cast<std::uint8_t>(core::ModelKind::kThreeBodyRotation) &&
              collision_lab::Prediction::MODEL_GHOSTS == static_cast<std::uint8_t>(core::ModelKind::kGhosts) &&
              collision_lab::Prediction::MODEL_EVENT_ENGINE == static_cast<std::uint8_t>(core::ModelKind::kEventEngine) &&
              collision_lab::Prediction::MODEL_THREE_BODY_SPIRAL ==
                  static_cast<std::uint8_t>(core::ModelKind::kThreeBodySpiral),
              "Prediction::MODEL_* must match collision_lab::core::ModelKind");

const char* nodeReasonName(NodeReason reason) {
  switch (reason) {
    case NodeReason::kDuplicateRunId: return "DUPLICATE_RUN_ID";
    case NodeReason::kInvalidRunId: return "INVALID_RUN_ID";
    case NodeReason::kInvalidMode: return "INVALID_MODE";
    case NodeReason::kTooManyBodies: return "TOO_MANY_BODIES";
    case NodeReason::kInvalidStudent: return "INVALID_STUDENT";
  }
  return "UNKNOWN";
}

std::array<double, 3> toArray(const std::vector<double>& values) {
  std::array<double, 3> result;
  for (std::size_t i = 0; i < result.size(); ++i) result[i] = i < values.size() ? values[i] : kNaN;
  return result;
}

static_assert(collision_lab::InitialConditions::RESTITUTION_CONSTANT ==
                      static_cast<std::uint8_t>(core::RestitutionModelKind::kConstant) &&
                  collision_lab::InitialConditions::RESTITUTION_TC == static_cast<std::uint8_t>(core::RestitutionModelKind::kTc) &&
                  collision_lab::InitialConditions::RESTITUTION_VISCOELASTIC ==
                      static_cast<std::uint8_t>(core::RestitutionModelKind::kViscoelastic) &&
                  collision_lab::InitialConditions::RESTITUTION_THRESHOLD ==
                      static_cast<std::uint8_t>(core::RestitutionModelKind::kThreshold),
              "InitialConditions restitution models must match collision_lab::core::RestitutionModelKind");

core::Scene toScene(const collision_lab::InitialConditions& msg) {
  core::Scene scene{msg.masses, msg.positions, msg.velocities, msg.restitution};
  // An unknown model number stays unknown, for validate() to reject (RESTITUTION_MODEL).
  scene.restitution_model = {static_cast<core::RestitutionModelKind>(msg.restitution_model), msg.tc,
                             msg.viscoelastic_speed, msg.elastic_below};
  scene.ring = msg.ring;
  return scene;
}

collision_lab::InitialConditions toInitialConditions(const core::Scene& scene, core::RunMode mode,
                                                     std::uint64_t max_collisions) {
  collision_lab::InitialConditions msg;
  msg.mode = static_cast<std::uint8_t>(mode);
  msg.masses = scene.masses;
  msg.positions = scene.positions;
  msg.velocities = scene.velocities;
  msg.restitution = scene.restitution;
  msg.restitution_model = static_cast<std::uint8_t>(scene.restitution_model.kind);
  msg.tc = scene.restitution_model.tc;
  msg.elastic_below = scene.restitution_model.elastic_below;
  msg.viscoelastic_speed = scene.restitution_model.viscoelastic_speed;
  msg.ring = scene.ring;
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

namespace {

/// Resets msg to a default message without giving up its strings' and arrays' storage
/// (copy assignment from an empty one keeps it; assigning a temporary would not).
template <class Message>
void resetKeepingStorage(Message& msg) {
  static const Message kDefault;
  msg = kDefault;
}

/// The fields every model fills the same way, into msg; the rest say "not given".
void modelPrediction(const core::ModelChoice& model, std::size_t body_count, collision_lab::Prediction& msg) {
  resetKeepingStorage(msg);
  msg.model = static_cast<std::uint8_t>(model.kind);
  msg.model_name = core::modelKindName(model.kind);
  msg.model_reason = model.reason;
  msg.body_count = static_cast<std::uint32_t>(body_count);
  msg.alpha = msg.theta = msg.omega = msg.phi_bc = msg.psi = kNaN;
  msg.first_pair_index = collision_lab::Prediction::PAIR_NONE;
  msg.energy_lost = msg.collapse_time = msg.collapse_position = kNaN;
  msg.critical_restitution = msg.spiral_angle = kNaN;
}

}  // namespace

collision_lab::Prediction toPredictionMsg(const core::ScenePlan& plan) {
  collision_lab::Prediction msg;
  fillPredictionMsg(plan, msg);
  return msg;
}

void fillPredictionMsg(const core::ScenePlan& plan, collision_lab::Prediction& msg) {
  modelPrediction(plan.model, plan.scene.size(), msg);
  if (!plan.prediction) return;  // event_engine: no closed form
  const core::Prediction& p = *plan.prediction;
  msg.collision_count = p.impact_count.value_or(0);
  msg.collision_count_defined = p.impact_count.has_value();
  msg.infinite_collisions = p.infinite;
  if (p.first_pair_index) msg.first_pair_index = static_cast<std::uint32_t>(*p.first_pair_index);
  msg.paper_collision_count_defined = p.paper_impact_count.has_value();
  msg.paper_collision_count = p.paper_impact_count.value_or(0);
  msg.max_possible_collision_count = p.max_possible_impact_count.value_or(0);
  msg.theta = valueOr(p.theta);
  msg.omega = valueOr(p.omega);
  msg.phi_bc = valueOr(p.phi_bc);
  msg.psi = valueOr(p.psi);
  msg.final_velocities = p.final_velocities;
  if (!p.final_velocities.empty()) msg.energy_lost = p.energy_lost;
  msg.collapsed = p.collapsed;
  msg.collapse_time = valueOr(p.collapse_time);
  msg.collapse_position = valueOr(p.collapse_position);
  msg.critical_restitution = valueOr(p.critical_restitution);
  msg.spiral_angle = valueOr(p.spiral_angle);
  msg.alpha = valueOr(p.alpha);
}

namespace {

/// The fields a plot message copies from its event; the rest are the caller's.
template <class PlotMessage>
void fillPlotMessage(const collision_lab::CollisionEvent& event, PlotMessage& msg) {
  msg.header = event.header;
  msg.run_id = event.run_id;
  msg.index = event.index;
  msg.time = event.time;
}

/// Velocities of msg.v already set: the rest from event.
void finishVelocitiesMsg(const collision_lab::CollisionEvent& event, collision_lab::Velocities& msg) {
  fillPlotMessage(event, msg);
  const std::array<double, 3> v = toArray(msg.v);
  msg.v_a = v[0];
  msg.v_b = v[1];
  msg.v_c = v[2];
}

/// EnergyTransfer of msg.delta and msg.kinetic already set: the rest from event.
void finishEnergyTransferMsg(const collision_lab::CollisionEvent& event, double cumulative_energy_lost,
                             collision_lab::EnergyTransfer& msg) {
  fillPlotMessage(event, msg);
  msg.energy_lost = event.energy_lost;
  msg.cumulative_energy_lost = cumulative_energy_lost;
  const std::array<double, 3> d = toArray(msg.delta), k = toArray(msg.kinetic);
  msg.delta_a = d[0];
  msg.delta_b = d[1];
  msg.delta_c = d[2];
  msg.kinetic_a = k[0];
  msg.kinetic_b = k[1];
  msg.kinetic_c = k[2];
}

}  // namespace

bool replayEvent(core::BodyStateReplay& replay, const collision_lab::CollisionEvent& msg) {
  if (msg.kind == collision_lab::CollisionEvent::KIND_COLLAPSE) {
    core::Collapse collapse;
    collapse.first_body = msg.first_moved;
    collapse.last_body = msg.last_moved;
    collapse.time = msg.time;
    collapse.position = msg.position;
    collapse.impacts_before = msg.index;
    collapse.velocity = msg.pair_velocities_after[0];
    return replay.apply(collapse);
  }
  core::ImpactRecord record;
  record.index = msg.index;
  record.pair_index = msg.pair_index;
  record.time = msg.time;
  record.position = msg.position;
  for (std::size_t side = 0; side < 2; ++side) {
    record.velocities_before[side] = msg.pair_velocities_before[side];
    record.velocities_after[side] = msg.pair_velocities_after[side];
    record.energy_gained[side] = msg.pair_energy_transfer[side];
  }
  record.energy_lost = msg.energy_lost;
  record.first_moved = msg.first_moved;
  record.last_moved = msg.last_moved;
  return replay.apply(record);
}

collision_lab::Velocities toVelocitiesMsg(const collision_lab::CollisionEvent& event, std::vector<double> v) {
  collision_lab::Velocities msg;
  msg.v = std::move(v);
  finishVelocitiesMsg(event, msg);
  return msg;
}

collision_lab::EnergyTransfer toEnergyTransferMsg(const collision_lab::CollisionEvent& event,
                                                  std::vector<double> delta, std::vector<double> kinetic,
                                                  double cumulative_energy_lost) {
  collision_lab::EnergyTransfer msg;
  msg.delta = std::move(delta);
  msg.kinetic = std::move(kinetic);
  finishEnergyTransferMsg(event, cumulative_energy_lost, msg);
  return msg;
}

collision_lab::Velocities toVelocitiesMsg(const collision_lab::CollisionEvent& event) {
  collision_lab::Velocities msg;
  fillVelocitiesMsg(event, msg);
  return msg;
}

collision_lab::EnergyTransfer toEnergyTransferMsg(const collision_lab::CollisionEvent& event,
                                                  double cumulative_energy_lost) {
  collision_lab::EnergyTransfer msg;
  fillEnergyTransferMsg(event, cumulative_energy_lost, msg);
  return msg;
}

void fillVelocitiesMsg(const collision_lab::CollisionEvent& event, collision_lab::Velocities& msg) {
  msg.v = event.velocities_after;
  finishVelocitiesMsg(event, msg);
}

void fillEnergyTransferMsg(const collision_lab::CollisionEvent& event, double cumulative_energy_lost,
                           collision_lab::EnergyTransfer& msg) {
  msg.delta = event.energy_transfer;
  msg.kinetic = event.kinetic_energy_after;
  finishEnergyTransferMsg(event, cumulative_energy_lost, msg);
}

// ---- SceneEventConverter ----

static_assert(collision_lab::io::kFullStateMaxBodies == collision_lab::CollisionEvent::FULL_STATE_MAX_BODIES,
              "the event record's full-state limit must be CollisionEvent's");

SceneEventConverter::SceneEventConverter(const core::Scene& scene)
    : state_(scene), full_state_(scene.size() <= collision_lab::CollisionEvent::FULL_STATE_MAX_BODIES) {}

void SceneEventConverter::toMsg(const collision_lab::io::EventRecord& r, collision_lab::CollisionEvent& msg) {
  msg.kind = r.collapse ? collision_lab::CollisionEvent::KIND_COLLAPSE : collision_lab::CollisionEvent::KIND_IMPACT;
  msg.index = r.index;
  msg.pair_index = static_cast<std::uint32_t>(r.pair_index);
  msg.time = r.time;
  msg.position = r.position;
  msg.restitution = r.restitution;
  msg.first_moved = static_cast<std::uint32_t>(r.first_moved);
  msg.last_moved = static_cast<std::uint32_t>(r.last_moved);
  msg.cluster_impact = r.cluster_impact;
  for (std::size_t side = 0; side < 2; ++side) {
    msg.pair_velocities_before[side] = r.pair_velocities_before[side];
    msg.pair_velocities_after[side] = r.pair_velocities_after[side];
    msg.pair_energy_transfer[side] = r.pair_energy_transfer[side];
  }
  msg.energy_lost = r.energy_lost;
  msg.uncertified.clear();
  for (int k = 0; k < core::kImpactValueCount; ++k) {
    if (r.uncertified & (1u << k)) msg.uncertified.emplace_back(core::impactValueName(k));
  }
  // The model block's values where the impact has one; empty arrays otherwise.
  const auto copy = [](const std::array<double, 3>* values, std::vector<double>& to) {
    if (values) {
      to.assign(values->begin(), values->end());
    } else {
      to.clear();
    }
  };
  copy(r.predicted_velocities_after, msg.predicted_velocities_after);
  copy(r.paper_velocities_after, msg.paper_velocities_after);
  copy(r.predicted_energy_transfer, msg.predicted_energy_transfer);
  copy(r.paper_energy_transfer, msg.paper_energy_transfer);
  if (!r.full_state) {
    msg.positions.clear();
    msg.velocities_before.clear();
    msg.velocities_after.clear();
    msg.energy_transfer.clear();
    msg.kinetic_energy_after.clear();
    msg.total_energy = msg.total_momentum = kNaN;
    return;
  }
  const std::size_t n = r.bodies;
  msg.positions.assign(r.positions, r.positions + n);
  msg.velocities_before.assign(r.velocities_before, r.velocities_before + n);
  msg.velocities_after.assign(r.velocities_after, r.velocities_after + n);
  msg.energy_transfer.assign(r.energy_transfer, r.energy_transfer + n);
  msg.kinetic_energy_after.assign(r.kinetic_energy_after, r.kinetic_energy_after + n);
  msg.total_energy = r.total_energy;
  msg.total_momentum = r.total_momentum;
}

collision_lab::CollisionEvent SceneEventConverter::impact(const core::ImpactRecord& record) {
  collision_lab::CollisionEvent msg;
  impact(record, msg);
  return msg;
}

collision_lab::CollisionEvent SceneEventConverter::collapse(const core::Collapse& collapse) {
  collision_lab::CollisionEvent msg;
  this->collapse(collapse, msg);
  return msg;
}

void SceneEventConverter::impact(const core::ImpactRecord& record, collision_lab::CollisionEvent& msg) {
  toMsg(state_.impact(record), msg);
}

void SceneEventConverter::collapse(const core::Collapse& collapse, collision_lab::CollisionEvent& msg) {
  toMsg(state_.collapse(collapse), msg);
}

collision_lab::Velocities SceneEventConverter::velocitiesMsg(const collision_lab::CollisionEvent& event) const {
  collision_lab::Velocities msg;
  velocitiesMsg(event, msg);
  return msg;
}

collision_lab::EnergyTransfer SceneEventConverter::energyTransferMsg(const collision_lab::CollisionEvent& event) const {
  collision_lab::EnergyTransfer msg;
  energyTransferMsg(event, msg);
  return msg;
}

void SceneEventConverter::velocitiesMsg(const collision_lab::CollisionEvent& event, collision_lab::Velocities& msg) const {
  if (full_state_) return fillVelocitiesMsg(event, msg);
  // Above the limit the arrays stay empty, as the event's; bodies 0, 1, 2 give the scalars.
  const std::vector<double>& v = state_.replay().velocities();
  msg.v.assign(v.begin(), v.begin() + 3);
  finishVelocitiesMsg(event, msg);
  msg.v.clear();
}

void SceneEventConverter::energyTransferMsg(const collision_lab::CollisionEvent& event,
                                            collision_lab::EnergyTransfer& msg) const {
  const core::BodyStateReplay& replay = state_.replay();
  if (full_state_) return fillEnergyTransferMsg(event, replay.heat(), msg);
  msg.delta.resize(3);
  msg.kinetic.resize(3);
  for (std::size_t i = 0; i < 3; ++i) {
    msg.delta[i] = replay.energyGained(i);
    msg.kinetic[i] = replay.kinetic(i);
  }
  finishEnergyTransferMsg(event, replay.heat(), msg);
  msg.delta.clear();
  msg.kinetic.clear();
}

namespace {

/// The summary's model fields and the "not given" values of the rest, into msg.
void modelSummary(const core::ModelChoice& model, std::size_t body_count, core::RunMode mode,
                  collision_lab::RunSummary& msg) {
  resetKeepingStorage(msg);
  msg.mode = static_cast<std::uint8_t>(mode);
  msg.model = static_cast<std::uint8_t>(model.kind);
  msg.model_name = core::modelKindName(model.kind);
  msg.model_reason = model.reason;
  msg.body_count = static_cast<std::uint32_t>(body_count);
  msg.energy_lost = msg.collapse_time = msg.collapse_position = kNaN;
  msg.critical_restitution = msg.spiral_angle = kNaN;
}

}  // namespace

collision_lab::RunSummary toRunSummaryMsg(const core::SceneRunResult& result, std::size_t body_count,
                                          core::RunMode mode) {
  collision_lab::RunSummary msg;
  fillRunSummaryMsg(result, body_count, mode, msg);
  return msg;
}

void fillRunSummaryMsg(const core::SceneRunResult& result, std::size_t body_count, core::RunMode mode,
                       collision_lab::RunSummary& msg) {
  const core::SceneSimulation& s = result.simulation;
  modelSummary(result.model, body_count, mode, msg);
  msg.collision_count = s.impact_count;  // the run's answer, simulated or from the model
  msg.truncated = s.truncated;
  if (s.truncated) msg.truncation_reason = s.stop_message;  // else empty (reset above)
  msg.cancelled = s.simulated && s.stop == core::StopReason::kCancelled;
  msg.stop_reason = s.simulated ? core::stopReasonName(s.stop) : "NOT_SIMULATED";
  msg.simulated = s.simulated;
  if (const auto& p = result.prediction) {
    msg.predicted_collision_count = p->impact_count.value_or(0);
    msg.predicted_collision_count_defined = p->impact_count.has_value();
    msg.infinite_collisions = p->infinite;
    msg.critical_restitution = valueOr(p->critical_restitution);
    msg.spiral_angle = valueOr(p->spiral_angle);
    msg.paper_predicted_collision_count_defined = p->paper_impact_count.has_value();
    msg.paper_predicted_collision_count = p->paper_impact_count.value_or(0);
  }
  msg.final_velocities = s.final_velocities;
  msg.energy_lost = s.energy_lost;
  msg.collapsed = s.collapsed;
  msg.collapse_time = valueOr(s.collapse_time);
  msg.collapse_position = valueOr(s.collapse_position);
  msg.collapse_count = static_cast<std::uint32_t>(s.collapses.size());
  msg.cluster_impacts = s.cluster_impacts;
  msg.rule_elastic_impacts = s.rule_elastic_impacts;
  msg.max_prediction_error = s.max_prediction_error;
  msg.energy_relative_drift = s.energy_relative_drift;
  msg.momentum_relative_drift = s.momentum_relative_drift;
  msg.compute_time = result.compute_time_s;
  msg.uncertified_values = core::uncertifiedValues(result);
  msg.time_beyond_range = s.time_beyond_range;
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

collision_lab::Rejected toRejectedMsg(const collision_lab::service::EnvelopeRefusal& refusal) {
  using Reason = collision_lab::service::EnvelopeRefusal::Reason;
  const NodeReason reason = [&] {
    switch (refusal.reason) {
      case Reason::kInvalidStudent: return NodeReason::kInvalidStudent;
      case Reason::kInvalidRunId: return NodeReason::kInvalidRunId;
      case Reason::kInvalidMode: return NodeReason::kInvalidMode;
      case Reason::kTooManyBodies: break;
    }
    return NodeReason::kTooManyBodies;
  }();
  return toRejectedMsg(reason, refusal.field, refusal.message);
}

}  // namespace collision_lab_ros
