#include "collision_lab/core/lab_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "collision_lab/core/paper.h"
#include "collision_lab/core/precision.h"
#include "float_ops.h"
#include "impact_energy.h"

namespace collision_lab {
namespace core {

namespace {

/// What a run that was not simulated reports for the quantities it did not measure.
constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

/// In double, a zero always +0 (outputs must not show "-0").
template <class Vector>
std::array<double, 3> toArray(const Vector& v) {
  return {detail::toDouble(v(0)), detail::toDouble(v(1)), detail::toDouble(v(2))};
}

template <class T>
std::array<double, 3> toArray(const std::array<T, 3>& v) {
  return toArray(Eigen::Matrix<T, 3, 1>(v[0], v[1], v[2]));
}

/// The closed form in double; at 50 digits, whose exponent range has no end in sight,
/// where a finite-mass ratio beyond 2^1000 would underflow the light body's share of the
/// mass-weighted velocities (S = diag(sqrt(m / m_max))) in double.
class ClosedForm {
 public:
  explicit ClosedForm(const ThreeBodyScene& scene) : masses_(scene.masses) {
    int smallest = std::numeric_limits<int>::max(), largest = std::numeric_limits<int>::min();
    for (int i = 0; i < 3; ++i) {
      if (scene.isWall(i)) continue;
      smallest = std::min(smallest, std::ilogb(scene.masses[i]));
      largest = std::max(largest, std::ilogb(scene.masses[i]));
    }
    if (largest - smallest <= 1000) {
      fast_.emplace(scene);
    } else {
      wide_.emplace(scene);
    }
  }

  std::array<double, 3> velocitiesAfter(std::uint64_t n) const {
    return fast_ ? toArray(fast_->velocitiesAfter(n)) : toArray(wide_->velocitiesAfter(n));
  }
  std::array<double, 3> energyTransfer(std::uint64_t n) const {
    return fast_ ? toArray(fast_->energyTransfer(n)) : toArray(wide_->energyTransfer(n));
  }
  double psi() const { return fast_ ? fast_->psi() : static_cast<double>(wide_->psi()); }
  const std::array<double, 3>& masses() const { return masses_; }

 private:
  friend class ClosedFormInTurn;
  std::array<double, 3> masses_;
  std::optional<AnalyticModel<double>> fast_;
  std::optional<AnalyticModel<HighPrecision>> wide_;
};

/// A ClosedForm's velocities after collision n and the energies gained in it, for n = 1,
/// 2, 3, ... in turn: in double by the ClosedFormSequence recurrence (a few ns each), at
/// 50 digits directly.
class ClosedFormInTurn {
 public:
  explicit ClosedFormInTurn(const ClosedForm& model) : model_(model) {
    if (model.fast_) {
      sequence_.emplace(*model.fast_);
      previous_ = sequence_->velocitiesAfter(0);
    }
  }

  void describe(std::uint64_t n, LabEvent& lab) {
    if (!sequence_) {
      lab.predicted_velocities_after = model_.velocitiesAfter(n);
      lab.predicted_energy_transfer = model_.energyTransfer(n);
      return;
    }
    if (n == 0 || n - 1 != last_) previous_ = sequence_->velocitiesAfter(n - 1);
    const Eigen::Vector3d after = sequence_->velocitiesAfter(n);
    lab.predicted_velocities_after = toArray(after);
    lab.predicted_energy_transfer = energyTransfer(n);
    previous_ = after;
    last_ = n;
  }

 private:
  /// The closed form's energy gains in collision n from the state before it, previous_:
  /// in double where the gain is safely inside its range, else in the model's wider type.
  std::array<double, 3> energyTransfer(std::uint64_t n) const {
    const AnalyticModel<double>& model = *model_.fast_;
    const std::optional<Pair> first = model.firstPair();
    if (!first || n == 0) return {0.0, 0.0, 0.0};
    const Pair pair = n % 2 == 1 ? *first : otherPair(*first);
    const int i = pairIndex(pair);
    const std::array<double, 3> before{previous_(0), previous_(1), previous_(2)};
    const std::array<double, 3> gained = energy_.gained(pair, before, before[i + 1] - before[i]);
    const double size = std::fabs(gained[i]);
    constexpr double kSafe = 0x1p-900;  // no underflow or overflow on the way
    if (size > kSafe && size < 1 / kSafe) return gained;
    return toArray(model.energyTransfer(n, previous_));
  }

  const ClosedForm& model_;
  detail::ImpactEnergy<double> energy_{model_.masses()};
  std::optional<ClosedFormSequence> sequence_;
  Eigen::Vector3d previous_;  // after collision last_
  std::uint64_t last_ = 0;
};

/// The paper's printed closed form at collisions n = 1, 2, 3, ... in turn, its angle
/// advanced by a RotationRecurrence.
class PaperInTurn {
 public:
  explicit PaperInTurn(const ThreeBodyScene& scene) : printed_(scene), rotation_(printed_.theta()) {}

  std::array<double, 3> velocitiesAfter(std::uint64_t n) {
    rotation_.moveTo(n / 2);
    return printed_.velocitiesAfter(n, rotation_.cos(), rotation_.sin());
  }

 private:
  paper::PrintedClosedForm printed_;
  RotationRecurrence rotation_;
};

/// Relative error in the energy norm: |S (a - b)| / |S v_0| with S = diag(sqrt(m)), in
/// the wall's frame. Scale-free, and the norm in which every impact is an isometry, so a
/// light body's rounding is weighed by the energy it carries.
class EnergyNormError {
 public:
  explicit EnergyNormError(const ThreeBodyScene& scene) : mass_max_(largestFiniteMass(scene.masses)) {
    const int wall = scene.wallIndex();
    for (int i = 0; i < 3; ++i) weight_[i] = i == wall ? 0.0 : scene.masses[i] / mass_max_;
    const double frame = wall >= 0 ? scene.velocities[wall] : 0.0;
    double norm_sq = 0.0;
    for (int i = 0; i < 3; ++i) {
      if (i == wall) continue;
      const double dv = scene.velocities[i] - frame;
      norm_sq += scene.masses[i] / mass_max_ * dv * dv;
    }
    initial_norm_ = norm_sq > 0.0 ? std::sqrt(norm_sq) : 1.0;
  }

  double operator()(const std::array<double, 3>& a, const std::array<double, 3>& b) const {
    return fromSquared(squared(a, b));
  }

  /// |S (a - b)|^2 with S scaled by 1/sqrt(m_max): the largest of many errors is
  /// fromSquared of the largest squared one (sqrt and division are monotone).
  double squared(const std::array<double, 3>& a, const std::array<double, 3>& b) const {
    double norm_sq = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double d = a[i] - b[i];
      norm_sq += weight_[i] * d * d;
    }
    return norm_sq;
  }
  double fromSquared(double norm_sq) const { return std::sqrt(norm_sq) / initial_norm_; }

 private:
  double mass_max_;
  std::array<double, 3> weight_{};  // m_i / m_max; 0 for a wall
  double initial_norm_ = 1.0;
};

/// The summary of a run that was not simulated (predict-only, or over the cap): the closed
/// form answers with its count and final state, complete, and nothing was measured.
void describeNotSimulated(RunResult& result) {
  LabRunSummary& summary = result.summary;
  summary.collision_count = result.prediction.collision_count;
  summary.final_velocities = result.prediction.final_velocities;
  summary.max_prediction_error = kNotMeasured;
  summary.energy_relative_drift = kNotMeasured;
  summary.momentum_relative_drift = kNotMeasured;
}

/// Simulated collisions beside the closed form and the paper's printed formulas, in turn.
class LabEvents {
 public:
  explicit LabEvents(const ThreeBodyScene& scene, const ClosedForm& model)
      : scene_(scene), wall_(scene.wallIndex()), closed_form_(model), paper_(scene), previous_before_(scene.velocities) {}

  /// The next event; `event` is collision previous + 1. The paper's BC energy formulas
  /// refer to the velocities before the collision before it, which this keeps.
  void describe(const ImpactEvent& event, LabEvent& lab) {
    closed_form_.describe(event.index, lab);
    lab.paper_velocities_after = paper_.velocitiesAfter(event.index);
    lab.paper_energy_transfer =
        paper::energyTransfer(scene_, event.index, event.pair, event.velocities_before, previous_before_);
    for (int i = 0; i < 3; ++i) {
      const double v = event.velocities_after[i];
      lab.kinetic_energy_after[i] = i == wall_ ? 0.0 : scene_.masses[i] * v * v / 2;
    }
    previous_before_ = event.velocities_before;
    lab.event = event;  // last: the engine has only just written it (store forwarding)
  }

 private:
  const ThreeBodyScene& scene_;
  int wall_;
  ClosedFormInTurn closed_form_;
  PaperInTurn paper_;
  std::array<double, 3> previous_before_;
};

/// Simulates, in full mode with every event put beside the prediction, and measures how
/// far the simulation is from the closed form.
void simulateBesidePrediction(const ThreeBodyScene& scene, const RunOptions& options, const LabEventVisitor& visitor,
                              RunResult& result) {
  LabRunSummary& summary = result.summary;
  const EnergyNormError relative_error(scene);
  const ClosedForm model(scene);
  SimulationOptions simulation_options;
  simulation_options.max_collisions = options.max_collisions;
  simulation_options.cancel = options.cancel;
  EventVisitor enrich;
  LabEvents lab_events(scene, model);
  LabEvent lab;
  double max_error_sq = 0.0;
  if (options.mode == RunMode::kFull) {
    enrich = [&](const ImpactEvent& event) {
      lab_events.describe(event, lab);
      max_error_sq = std::max(max_error_sq, relative_error.squared(event.velocities_after, lab.predicted_velocities_after));
      if (visitor) visitor(lab);
      if (options.events.keeps(event.index)) result.events.push_back(lab);
    };
  }
  const SimulationResult simulation = simulate(scene, simulation_options, options.precision, enrich);
  summary.max_prediction_error = relative_error.fromSquared(max_error_sq);
  summary.simulated = true;
  summary.collision_count = simulation.collision_count;
  summary.truncated = simulation.truncated;
  summary.cancelled = simulation.cancelled;
  if (simulation.cancelled) {
    summary.truncation_reason = "cancelled after " + std::to_string(simulation.collision_count) + " of " +
                                std::to_string(result.prediction.collision_count) + " predicted";
  } else if (simulation.truncated) {
    summary.truncation_reason = "stopped at max_collisions = " + std::to_string(options.max_collisions) + " of " +
                                std::to_string(result.prediction.collision_count) + " predicted";
  }
  summary.final_velocities = simulation.final_velocities;
  summary.energy_relative_drift = simulation.energy_relative_drift;
  summary.momentum_relative_drift = simulation.momentum_relative_drift;
  summary.escalation = simulation.escalation;
  const auto predicted_final = model.velocitiesAfter(simulation.collision_count);
  summary.max_prediction_error =
      std::max(summary.max_prediction_error, relative_error(simulation.final_velocities, predicted_final));
}

}  // namespace

AnalyticPrediction predict(const ThreeBodyScene& scene) {
  const ClosedForm model(scene);
  AnalyticPrediction prediction;
  prediction.collision_count = predictedCollisionCount(scene);
  prediction.paper_collision_count = paper::collisionCount(scene);
  prediction.max_possible_collision_count = maxPossibleCollisionCount(scene.masses);
  prediction.angles = anglesFor(scene.masses);
  prediction.phi_bc = paper::phiBC(scene);
  prediction.psi = model.psi();
  prediction.first_pair = firstPair(scene);
  prediction.final_velocities = toArray(model.velocitiesAfter(prediction.collision_count));
  return prediction;
}

RunResult runLab(const ThreeBodyScene& scene, const RunOptions& options, const LabEventVisitor& visitor) {
  const auto started = std::chrono::steady_clock::now();
  RunResult result = runLab(scene, options, predict(scene), visitor);
  result.summary.compute_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

RunResult runLab(const ThreeBodyScene& scene, const RunOptions& options, const AnalyticPrediction& prediction,
                 const LabEventVisitor& visitor) {
  const auto started = std::chrono::steady_clock::now();
  RunResult result;
  result.prediction = prediction;
  const bool over_cap = result.prediction.collision_count > options.max_collisions;
  const bool skipped = options.mode != RunMode::kPredictOnly && over_cap && options.skip_simulation_over_cap;
  if (options.mode == RunMode::kPredictOnly || skipped) {
    describeNotSimulated(result);
  } else {
    simulateBesidePrediction(scene, options, visitor, result);
  }
  result.summary.compute_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace core
}  // namespace collision_lab
