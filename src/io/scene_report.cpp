#include "collision_lab/io/scene_report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <sstream>

#include "collision_lab/io/temperature_csv.h"
#include "event_pipeline.h"
#include "report_text.h"

namespace collision_lab {
namespace io {

SceneEventState::SceneEventState(const core::Scene& scene, const core::EventPolicy& policy)
    : scene_(scene), full_state_(scene.size() <= kFullStateMaxBodies), policy_(policy), replay_(scene),
      velocity_uncertified_(scene.size(), 0) {}

void SceneEventState::moved(std::size_t first, std::size_t last, bool uncertified) {
  const auto mark = [&](std::size_t k) {
    velocities_uncertified_ += static_cast<std::size_t>(uncertified) - velocity_uncertified_[k];
    velocity_uncertified_[k] = uncertified;
  };
  if (first > last) return mark(first), mark(last);
  for (std::size_t k = first; k <= last; ++k) mark(k);
}

void SceneEventState::fill(EventRecord& r, bool velocities_before_uncertified) {
  r.full_state = full_state_;
  if (!full_state_) return;
  // Positions, kinetic energies and totals come from the replay's rounded values; the
  // velocities are the records' (certified when every one that set them is).
  r.uncertified |= core::kReplayedStateValues;
  if (velocities_before_uncertified) r.uncertified |= core::kVelocitiesBefore;
  if (velocities_uncertified_ > 0) r.uncertified |= core::kVelocitiesAfter;
  const std::size_t n = replay_.size();
  r.bodies = n;
  positions_ = replay_.positions(r.time);
  before_.resize(n);
  gain_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    before_[i] = replay_.velocityBefore(i);
    gain_[i] = replay_.energyGained(i);
  }
  r.total_energy = replay_.totalKineticEnergy();
  r.total_momentum = replay_.momentum();
  r.positions = positions_.data();
  r.velocities_before = before_.data();
  r.velocities_after = replay_.velocities().data();
  r.energy_transfer = gain_.data();
  r.kinetic_energy_after = replay_.kineticEnergies().data();
}

EventRecord SceneEventState::impact(const core::ImpactRecord& impact) {
  const std::size_t p = impact.pair_index, left = scene_.leftOf(p);  // left: body 0 across a ring's seam
  EventRecord r;
  r.index = impact.index;
  r.pair_index = p;
  r.time = impact.time;
  r.position = impact.position;
  r.restitution = scene_.restitutionOf(p);
  r.first_moved = impact.first_moved;
  r.last_moved = impact.last_moved;
  r.cluster_impact = impact.first_moved != p || impact.last_moved != left;
  for (std::size_t side = 0; side < 2; ++side) {
    r.pair_velocities_before[side] = impact.velocities_before[side];
    r.pair_velocities_after[side] = impact.velocities_after[side];
    r.pair_energy_transfer[side] = impact.energy_gained[side];  // a wall's: minus the other's gain and the heat
  }
  r.energy_lost = impact.energy_lost;
  r.uncertified = impact.uncertified;
  const bool before_uncertified = velocities_uncertified_ > 0;
  replay_.apply(impact);
  moved(impact.first_moved, impact.last_moved, impact.uncertified & core::kPairVelocitiesAfter);
  if (impact.model) {
    fillFromModelBlock(r, *impact.model);
    if (!policy_.fullStateAt(impact.index)) lean(r);
    return r;
  }
  if (!policy_.fullStateAt(impact.index)) return r;  // the lean record: the pair's values
  fill(r, before_uncertified);
  if (full_state_ && !r.cluster_impact) {
    // Two single bodies: their entries are the engine's gains, as the pair's fields.
    gain_[p] = r.pair_energy_transfer[0];
    gain_[left] = r.pair_energy_transfer[1];
    if (r.uncertified & core::kPairEnergyTransfer) r.uncertified |= core::kEnergyTransfer;
  } else if (full_state_) {
    r.uncertified |= core::kEnergyTransfer;  // a cluster's gain shared out by the replay
  }
  return r;
}

void fillFromModelBlock(EventRecord& r, const core::ImpactModelValues& m) {
  const std::size_t p = r.pair_index;
  for (std::size_t side = 0; side < 2; ++side) r.pair_energy_transfer[side] = m.energy_transfer[p + side];
  r.full_state = true;
  r.bodies = m.positions.size();
  r.positions = m.positions.data();
  r.velocities_before = m.velocities_before.data();
  r.velocities_after = m.velocities_after.data();
  r.energy_transfer = m.energy_transfer.data();
  r.kinetic_energy_after = m.kinetic_energy_after.data();
  r.total_energy = m.total_energy;
  r.total_momentum = m.total_momentum;
  r.predicted_velocities_after = &m.predicted_velocities_after;
  r.predicted_energy_transfer = &m.predicted_energy_transfer;
  r.paper_velocities_after = &m.paper_velocities_after;
  r.paper_energy_transfer = &m.paper_energy_transfer;
}

void SceneEventState::lean(EventRecord& r) {
  r.full_state = false;
  r.uncertified &= core::kPairValues;
  r.predicted_velocities_after = r.predicted_energy_transfer = nullptr;
  r.paper_velocities_after = r.paper_energy_transfer = nullptr;
}

EventRecord SceneEventState::collapse(const core::Collapse& collapse) {
  const std::size_t first = collapse.first_body;
  EventRecord r;
  r.collapse = true;
  r.index = collapse.impacts_before;
  r.pair_index = first;
  r.time = collapse.time;
  r.position = collapse.position;
  r.restitution = scene_.restitutionOf(first);
  r.first_moved = first;
  r.last_moved = collapse.last_body;
  const bool before_uncertified = velocities_uncertified_ > 0;
  replay_.apply(collapse);
  moved(first, collapse.last_body, collapse.uncertified & core::kPairVelocitiesAfter);
  for (std::size_t side = 0; side < 2; ++side) {
    r.pair_velocities_before[side] = replay_.velocityBefore(first + side);
    r.pair_velocities_after[side] = collapse.velocity;
    r.pair_energy_transfer[side] = replay_.energyGained(first + side);
  }
  r.energy_lost = replay_.lastHeat();
  // The limit of infinitely many impacts, from the state at the time and the replay.
  r.uncertified = collapse.uncertified | (before_uncertified ? core::kPairVelocitiesBefore : 0u);
  fill(r, before_uncertified);
  if (full_state_) r.uncertified |= core::kEnergyTransfer;
  return r;
}

namespace {

/// Shortest text that reads back to the same double; 0 for either zero; `non_finite` for
/// NaN and infinities.
std::string exactText(double value, const char* non_finite) {
  if (!std::isfinite(value)) return non_finite;
  if (value == 0) return "0";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

/// Text for CSV cells: inf, -inf and nan spelled out.
std::string csvNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return exactText(value, "nan");
}

using report_text::humanText;
using report_text::number;
using report_text::padLeft;
using report_text::padRight;
using report_text::kTimeBeyondRangeNote;

/// A JSON array of doubles, streamed without building a document (10^6 bodies).
void writeJsonNumbers(std::ostream& out, const std::vector<double>& values) {
  out << '[';
  for (std::size_t i = 0; i < values.size(); ++i) out << (i ? "," : "") << exactText(values[i], "null");
  out << ']';
}

/// A CSV field: quoted when it holds a comma, quote or line break.
std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

Json wallNames(const core::Scene& scene) {
  Json walls = Json::array();
  for (std::size_t i = 0; i < scene.size(); ++i) {
    if (scene.isWall(i)) walls.push_back(core::bodyName(i));
  }
  return walls;
}

std::string restitutionText(const core::Scene& scene) {
  if (scene.isElastic()) return "elastic (e = 1)";
  if (scene.restitution.size() == 1) return "e = " + humanText(scene.restitution[0], 10) + " for every pair";
  return "e per pair, from " + humanText(*std::min_element(scene.restitution.begin(), scene.restitution.end()), 10) +
         " to " + humanText(*std::max_element(scene.restitution.begin(), scene.restitution.end()), 10);
}

/// Why no count formula is printed for a scene without a closed form.
const char* const kNoCountFormula =
    "none: no closed form gives the number of impacts of this scene; the count is the exact event engine's";

/// "A..C": the bodies of a collapse.
std::string collapseBodies(const core::Collapse& c) {
  return core::bodyName(c.first_body) + ".." + core::bodyName(c.last_body);
}

std::string stopReasonText(const core::SceneSimulation& s) {
  return s.simulated ? core::stopReasonName(s.stop) : "NOT_SIMULATED";
}

// ---------------------------------------------------------------------------------------
// Table: for people. The bodies' lists show the first and last kTableBodies entries.

constexpr int kDigits = 10;
constexpr int kEventDigits = 7;
constexpr std::size_t kWidth = 17;

/// The body indices the table shows, with SIZE_MAX marking the gap.
std::vector<std::size_t> shownBodies(std::size_t n) {
  std::vector<std::size_t> shown;
  if (n <= 2 * kTableBodies + 1) {
    for (std::size_t i = 0; i < n; ++i) shown.push_back(i);
    return shown;
  }
  for (std::size_t i = 0; i < kTableBodies; ++i) shown.push_back(i);
  shown.push_back(SIZE_MAX);
  for (std::size_t i = n - kTableBodies; i < n; ++i) shown.push_back(i);
  return shown;
}

/// Rows "body | column 1 | column 2 ..." for the shown bodies; a line for the left-out ones.
void writeBodyRows(std::ostream& out, std::size_t n, const std::vector<std::string>& headers,
                   const std::vector<const std::vector<double>*>& columns) {
  out << padLeft("body", 8);
  for (const std::string& header : headers) out << padLeft(header, kWidth);
  out << "\n";
  for (std::size_t i : shownBodies(n)) {
    if (i == SIZE_MAX) {
      out << padLeft("...", 8) << "  (" << n - 2 * kTableBodies
          << " bodies left out here; JSON and CSV list every body)\n";
      continue;
    }
    out << padLeft(core::bodyName(i), 8);
    for (const auto* column : columns) {
      out << padLeft(i < column->size() ? humanText((*column)[i], kDigits) : "-", kWidth);
    }
    out << "\n";
  }
}

/// The layout of one scene's report in one format (the scene report of every run whose
/// prediction has no rotation values): SceneReportWriter's calls, the model given.
class SceneLayout {
 public:
  virtual ~SceneLayout() = default;
  virtual void begin(const SceneEntry& entry, const core::RunOptions& options, const core::ModelChoice& model) = 0;
  virtual void impact(const core::ImpactRecord& impact) = 0;
  virtual void collapse(const core::Collapse& collapse) = 0;
  virtual void end(const core::SceneRunResult& result) = 0;
};

class SceneTableWriter : public SceneLayout {
 public:
  explicit SceneTableWriter(std::ostream& out) : out_(out) {}

  void begin(const SceneEntry& entry, const core::RunOptions& options, const core::ModelChoice& model) override {
    const core::Scene& scene = entry.scene;
    out_ << "collision_lab: " << (entry.name.empty() ? "scene from the command line" : entry.name);
    if (!entry.description.empty()) out_ << " - " << entry.description;
    const Json walls = wallNames(scene);
    out_ << "\n\n" << scene.size() << (scene.size() == 1 ? " body" : " bodies") << ", right to left; walls: "
         << (walls.empty() ? std::string("none") : jsonText(walls)) << "; " << restitutionText(scene) << "\n";
    writeBodyRows(out_, scene.size(), {"mass [kg]", "position [m]", "velocity [m/s]"},
                  {&scene.masses, &scene.positions, &scene.velocities});
    out_ << "\nmodel: " << core::modelKindName(model.kind) << " - " << model.reason << "\n";
    out_ << "run: mode " << runModeText(options.mode) << ", events " << eventPolicyText(options.events)
         << ", at most " << options.max_collisions << " impacts\n";
  }

  void impact(const core::ImpactRecord& r) override {
    if (!header_written_) writeImpactHeader();
    out_ << padLeft(std::to_string(r.index), 9) << padLeft(core::impactPairName(r.pair_index, r.last_moved), 8);
    for (double value : {r.time, r.position, r.velocities_after[0], r.velocities_after[1], r.energy_lost}) {
      out_ << padLeft(humanText(value, kEventDigits), 15);
    }
    out_ << "\n";
  }

  void collapse(const core::Collapse& c) override {
    if (!header_written_) writeImpactHeader();
    out_ << padLeft("-", 9) << padLeft("-", 8) << "  collapse of bodies " << collapseBodies(c)
         << " at t = " << humanText(c.time, kDigits) << " s, x = " << humanText(c.position, kDigits)
         << " m (the limit of infinitely many impacts, not counted), then all at " << humanText(c.velocity, kDigits)
         << " m/s\n";
  }

  void end(const core::SceneRunResult& result) override {
    const core::SceneSimulation& s = result.simulation;
    const auto& p = result.prediction;
    out_ << "\nSummary\n";
    out_ << "collisions: " << (s.simulated ? "simulated " + std::to_string(s.impact_count) : "not simulated")
         << ", predicted " << predictedCountText(p) << "\n";
    if (!p || (!p->impact_count && !p->infinite)) out_ << "count formula: " << kNoCountFormula << "\n";
    out_ << "truncated: " << (s.truncated ? "yes" : "no") << "; end of run: " << s.stop_message << "\n";
    if (s.time_beyond_range) out_ << "time: " << kTimeBeyondRangeNote << "\n";
    if (!std::isnan(s.energy_lost)) out_ << "energy lost [J]: " << humanText(s.energy_lost, kDigits) << "\n";
    writeRestitution(s, p);
    if (s.simulated) writeChecks(s);
    if (!s.final_velocities.empty()) {
      const std::vector<double>* predicted =
          p && s.simulated && !p->final_velocities.empty() ? &p->final_velocities : nullptr;
      out_ << "\nfinal velocities"
           << (!s.simulated ? " (predicted)" : predicted ? " (simulated; predicted beside them)" : " (simulated)")
           << "\n";
      writeBodyRows(out_, s.final_velocities.size(),
                    predicted ? std::vector<std::string>{"v [m/s]", "predicted [m/s]"}
                              : std::vector<std::string>{"v [m/s]"},
                    predicted ? std::vector<const std::vector<double>*>{&s.final_velocities, predicted}
                              : std::vector<const std::vector<double>*>{&s.final_velocities});
    }
    out_ << "compute time " << humanText(result.compute_time_s, 3) << " s\n";
  }

 private:
  static std::string predictedCountText(const std::optional<core::Prediction>& p) {
    if (!p) return "- (no closed form)";
    if (p->infinite) return "infinitely many";
    return p->impact_count ? std::to_string(*p->impact_count) : "-";
  }

  /// The three-body spiral's constants, a collapse and the cluster rule, when they apply.
  void writeRestitution(const core::SceneSimulation& s, const std::optional<core::Prediction>& p) {
    if (p && p->critical_restitution) {
      out_ << "three-body spiral: critical restitution r_c = tan^2(pi/4 - alpha/2) = "
           << humanText(*p->critical_restitution, kDigits);
      if (p->spiral_angle) out_ << ", spiral angle phi = " << humanText(*p->spiral_angle, kDigits) << " rad";
      out_ << "\n";
    }
    if (s.collapsed && s.collapse_time && s.collapse_position) {
      out_ << "inelastic collapse" << (s.simulated ? "" : " (predicted)") << ": infinitely many impacts before t = "
           << humanText(*s.collapse_time, kDigits) << " s, the bodies meet at x = "
           << humanText(*s.collapse_position, kDigits) << " m and move on as one\n";
    }
    if (s.cluster_impacts > 0) {
      out_ << "cluster rule: " << s.cluster_impacts
           << " impacts hit a cluster (stuck or collapsed) as one body of its total mass\n";
    }
    if (s.rule_elastic_impacts > 0) {
      out_ << "restitution model: " << s.rule_elastic_impacts << " impacts made elastic by the rule\n";
    }
  }

  void writeChecks(const core::SceneSimulation& s) {
    out_ << "checks: relative energy drift " << humanText(s.energy_relative_drift, 3) << ", relative momentum drift "
         << (std::isnan(s.momentum_relative_drift) ? std::string("n/a (a wall does not conserve it)")
                                                   : humanText(s.momentum_relative_drift, 3));
    if (s.matches_prediction) {
      out_ << ", simulation " << (*s.matches_prediction ? "matches" : "DIFFERS FROM") << " the prediction (max |dv| / max |v0| "
           << humanText(s.max_prediction_error, 3) << ")";
    }
    out_ << "\n";
    if (s.multiple_collision) {
      const core::MultipleCollision& m = *s.multiple_collision;
      out_ << "multiple collision: " << core::bodyName(m.first_body) << ", " << core::bodyName(m.first_body + 1)
           << " and " << core::bodyName(m.first_body + 2) << " at t = " << humanText(m.time, kDigits) << " s\n";
    }
  }

  void writeImpactHeader() {
    header_written_ = true;
    out_ << "\nImpacts (velocities of the pair's two bodies after it, right body first; energy turned into heat;"
            " a collapse on a line of its own)\n"
         << padLeft("#", 9) << padLeft("pair", 8);
    for (const char* label : {"t [s]", "x [m]", "v_right [m/s]", "v_left [m/s]", "lost [J]"}) {
      out_ << padLeft(label, 15);
    }
    out_ << "\n";
  }

  std::ostream& out_;
  bool header_written_ = false;
};

// ---------------------------------------------------------------------------------------
// JSON: one document, one impact per line; the bodies' lists are streamed.

/// The restitution model and the ring, only when the scene has them (older outputs unchanged).
Json sceneOptionsJson(const core::Scene& s) {
  Json json = Json::object();
  const core::RestitutionModel& model = s.restitution_model;
  if (model.kind != core::RestitutionModelKind::kConstant) {
    const double parameter = model.kind == core::RestitutionModelKind::kTc
                                 ? model.tc
                                 : (model.kind == core::RestitutionModelKind::kThreshold ? model.elastic_below
                                                                                        : model.viscoelastic_speed);
    const char* key = model.kind == core::RestitutionModelKind::kTc
                          ? "tc"
                          : (model.kind == core::RestitutionModelKind::kThreshold ? "elastic_below" : "viscoelastic_speed");
    json["restitution_model"] = core::restitutionModelName(model.kind);
    json[key] = number(parameter);
  }
  if (s.isRing()) json["ring"] = number(s.ring);
  return json;
}

void writeSceneJson(std::ostream& out, const SceneEntry& entry) {
  const core::Scene& s = entry.scene;
  out << "{\"name\":" << jsonText(Json(entry.name)) << ",\"description\":" << jsonText(Json(entry.description))
      << ",\"bodies\":" << s.size() << ",\"walls\":" << jsonText(wallNames(s)) << ",\"masses\":";
  writeJsonNumbers(out, s.masses);
  out << ",\"positions\":";
  writeJsonNumbers(out, s.positions);
  out << ",\"velocities\":";
  writeJsonNumbers(out, s.velocities);
  out << ",\"restitution\":";
  writeJsonNumbers(out, s.restitution);
  const Json options = sceneOptionsJson(s);
  for (const auto& [key, value] : options.items()) out << "," << jsonText(Json(key)) << ":" << jsonText(value);
  out << "}";
}

/// The summary without its velocity lists (10^6 numbers are streamed, not built).
Json summaryScalars(const core::SceneRunResult& result) {
  const core::SceneSimulation& s = result.simulation;
  const auto& p = result.prediction;
  const bool has_formula = p && (p->impact_count || p->infinite);
  Json json{{"model", core::modelKindName(result.model.kind)},
            {"model_reason", result.model.reason},
            {"collision_count", s.simulated || (p && p->impact_count) ? Json(s.impact_count) : Json(nullptr)},
            {"simulated", s.simulated},
            {"truncated", s.truncated},
            {"stop_reason", stopReasonText(s)},
            {"stop_message", s.stop_message},
            {"predicted_collision_count", p && p->impact_count ? Json(*p->impact_count) : Json(nullptr)},
            {"predicted_infinite", p && p->infinite},
            {"count_formula", has_formula ? Json(core::modelKindName(p->kind)) : Json(kNoCountFormula)},
            {"matches_prediction", s.matches_prediction ? Json(*s.matches_prediction) : Json(nullptr)},
            {"max_prediction_error", number(s.max_prediction_error)},
            {"final_time", number(s.final_time)},
            {"time_beyond_range", s.time_beyond_range},
            {"energy_lost", number(s.energy_lost)},
            {"energy_relative_drift", number(s.energy_relative_drift)},
            {"momentum_relative_drift", number(s.momentum_relative_drift)},
            {"compute_time_s", number(result.compute_time_s)}};
  json["collapsed"] = s.collapsed;
  json["collapse_time"] = s.collapse_time ? number(*s.collapse_time) : Json(nullptr);
  json["collapse_position"] = s.collapse_position ? number(*s.collapse_position) : Json(nullptr);
  json["cluster_impacts"] = s.cluster_impacts;
  json["rule_elastic_impacts"] = s.rule_elastic_impacts;
  json["critical_restitution"] = p && p->critical_restitution ? number(*p->critical_restitution) : Json(nullptr);
  json["spiral_angle"] = p && p->spiral_angle ? number(*p->spiral_angle) : Json(nullptr);
  json["uncertified_values"] = core::uncertifiedValues(result);
  json["multiple_collision"] = nullptr;
  if (s.multiple_collision) {
    const std::size_t b = s.multiple_collision->first_body;
    json["multiple_collision"] = {
        {"bodies", Json::array({core::bodyName(b), core::bodyName(b + 1), core::bodyName(b + 2)})},
        {"first_body_index", b},
        {"time", number(s.multiple_collision->time)}};
  }
  json["escalation"] = {{"refinements", s.escalations.refinements},
                        {"high_precision", s.escalations.high_precision},
                        {"exact_rational", s.escalations.exact_rational},
                        {"replayed_impacts", s.escalations.replayed_impacts}};
  return json;
}

void writeSummaryJson(std::ostream& out, const core::SceneRunResult& result) {
  std::string scalars = jsonText(summaryScalars(result));
  scalars.pop_back();  // the closing brace: the velocity lists follow
  out << scalars << ",\"final_velocities\":";
  writeJsonNumbers(out, result.simulation.final_velocities);
  out << ",\"predicted_final_velocities\":";
  if (result.prediction && !result.prediction->final_velocities.empty()) {
    writeJsonNumbers(out, result.prediction->final_velocities);
  } else {
    out << "null";
  }
  out << "}";
}

class SceneJsonWriter : public SceneLayout {
 public:
  explicit SceneJsonWriter(std::ostream& out) : out_(out), sink_(out) {}

  void begin(const SceneEntry& entry, const core::RunOptions& options, const core::ModelChoice&) override {
    state_.emplace(entry.scene, options.events);
    out_ << "{\"scene\": ";
    writeSceneJson(out_, entry);
    out_ << ",\n\"options\": " << jsonText(optionsJson(options)) << ",\n\"units\": " << jsonText(unitsJson())
         << ",\n\"events\": [";
  }

  void impact(const core::ImpactRecord& r) override { write(state_->impact(r)); }
  void collapse(const core::Collapse& c) override { write(state_->collapse(c)); }

  void end(const core::SceneRunResult& result) override {
    sink_.flush();
    out_ << (any_event_ ? "\n]" : "]") << ",\n\"summary\": ";
    writeSummaryJson(out_, result);
    out_ << "}\n";
  }

 private:
  void write(const EventRecord& record) {
    sink_.put(any_event_ ? ",\n" : "\n");
    any_event_ = true;
    report_text::writeEventRecordJson(sink_, record);
    sink_.flushIfFull();
  }
  std::ostream& out_;
  TextSink sink_;
  std::optional<SceneEventState> state_;  ///< from begin()
  bool any_event_ = false;
};

// ---------------------------------------------------------------------------------------
// CSV: "# key,value..." comment lines for the scene, options and model, a header line, one
// row per event (kind impact or collapse), then "# summary.key,value..." lines (the JSON
// summary's keys). A collapse row leaves the pair, the velocities before and the energies
// empty; its index is the number of impacts before it.

void writeCsvComment(std::ostream& out, const std::string& key, const Json& value) {
  if (value.is_object()) {
    for (const auto& item : value.items()) writeCsvComment(out, key + "." + item.key(), item.value());
    return;
  }
  out << "# " << key;
  const auto scalar = [&](const Json& v) {
    out << ",";
    if (v.is_string()) {
      out << csvField(v.get<std::string>());
    } else if (v.is_number_float()) {
      out << csvNumber(v.get<double>());
    } else if (!v.is_null()) {
      out << jsonText(v);
    }
  };
  if (value.is_array()) {
    for (const Json& element : value) scalar(element);
  } else {
    scalar(value);
  }
  out << "\n";
}

void writeCsvNumbers(std::ostream& out, const char* key, const std::vector<double>& values) {
  out << "# " << key;
  for (double v : values) out << "," << csvNumber(v);
  out << "\n";
}

class SceneCsvWriter : public SceneLayout {
 public:
  explicit SceneCsvWriter(std::ostream& out) : out_(out), sink_(out) {}

  void begin(const SceneEntry& entry, const core::RunOptions& options, const core::ModelChoice& model) override {
    const core::Scene& s = entry.scene;
    out_ << "# scene," << csvField(entry.name) << "\n# bodies," << s.size() << "\n";
    writeCsvNumbers(out_, "masses_kg", s.masses);
    writeCsvNumbers(out_, "positions_m", s.positions);
    writeCsvNumbers(out_, "velocities_m_s", s.velocities);
    writeCsvNumbers(out_, "restitution", s.restitution);
    const Json options_json = optionsJson(options);
    for (const auto& item : options_json.items()) writeCsvComment(out_, item.key(), item.value());
    writeCsvComment(out_, "model", core::modelKindName(model.kind));
    writeCsvComment(out_, "model_reason", model.reason);
    out_ << report_text::kEventCsvHeader << "\n";
    state_.emplace(s, options.events);
  }

  void impact(const core::ImpactRecord& r) override { write(state_->impact(r)); }
  void collapse(const core::Collapse& c) override { write(state_->collapse(c)); }

  void end(const core::SceneRunResult& result) override {
    sink_.flush();
    const Json summary = summaryScalars(result);
    for (const auto& item : summary.items()) {
      writeCsvComment(out_, "summary." + item.key(), item.value());
    }
    writeCsvNumbers(out_, "summary.final_velocities", result.simulation.final_velocities);
    if (result.prediction) writeCsvNumbers(out_, "summary.predicted_final_velocities", result.prediction->final_velocities);
  }

 private:
  void write(const EventRecord& record) {
    report_text::writeEventRecordCsv(sink_, record);
    sink_.flushIfFull();
  }

  std::ostream& out_;
  TextSink sink_;
  std::optional<SceneEventState> state_;  ///< from begin()
};

// ---------------------------------------------------------------------------------------
// The layout of a run with the rotation model's values, with the model stated: the JSON
// summary gets "model" and "model_reason", CSV two "# summary.model..." lines, the table a
// "model:" line.

/// The summary of a run with the rotation model's values (summaryJson) and the model that
/// answered.
Json rotationSummaryJson(const core::SceneRunResult& result, const core::ModelChoice& model) {
  Json summary = summaryJson(result);
  summary["model"] = core::modelKindName(model.kind);
  summary["model_reason"] = model.reason;
  return summary;
}

class ThreeBodyModelWriter : public RunReportWriter {
 public:
  ThreeBodyModelWriter(ReportFormat format, std::ostream& out, const core::ModelChoice& model)
      : format_(format), out_(out), model_(model) {
    if (format == ReportFormat::kJson) {
      events_.emplace(out, report_text::writeEventJsonLine);
    } else {
      inner_ = makeRunReportWriter(format, out);
    }
  }

  void begin(const SceneEntry& scene, const core::RunOptions& options) override {
    policy_ = options.events;
    if (format_ != ReportFormat::kJson) return inner_->begin(scene, options);
    out_ << "{\"scene\": " << jsonText(sceneJson(scene)) << ",\n\"options\": " << jsonText(optionsJson(options))
         << ",\n\"units\": " << jsonText(unitsJson()) << ",\n\"events\": [";
  }

  void event(const core::ImpactRecord& event) override {
    if (format_ != ReportFormat::kJson) return inner_->event(event);
    events_->push(report_text::shownImpact(event, policy_));
    any_event_ = true;
  }

  void end(const core::SceneRunResult& result) override {
    if (format_ == ReportFormat::kJson) {
      events_->finish();
      out_ << (any_event_ ? "\n]" : "]") << ",\n\"summary\": " << jsonText(rotationSummaryJson(result, model_)) << "}\n";
      return;
    }
    inner_->end(result);
    if (format_ == ReportFormat::kCsv) {
      writeCsvComment(out_, "summary.model", core::modelKindName(model_.kind));
      writeCsvComment(out_, "summary.model_reason", model_.reason);
    } else {
      out_ << "model: " << core::modelKindName(model_.kind) << " - " << model_.reason << "\n";
    }
  }

 private:
  ReportFormat format_;
  std::ostream& out_;
  core::ModelChoice model_;
  std::unique_ptr<RunReportWriter> inner_;  ///< table and CSV
  std::optional<EventPipeline> events_;     ///< JSON events
  core::EventPolicy policy_;                ///< from begin(): which events carry the full state
  bool any_event_ = false;
};

// ---------------------------------------------------------------------------------------
// Batches of scenes of any size.

struct BatchRow {
  std::string name, model;
  std::size_t bodies = 0;
  std::string simulated, predicted;
  bool truncated = false;
  double energy_lost = 0.0;
};

BatchRow batchRow(const SceneBatchOutcome& outcome) {
  const core::SceneRunResult& r = outcome.result;
  BatchRow row{outcome.entry.name, core::modelKindName(r.model.kind), outcome.entry.scene.size(), "-", "-", false, 0.0};
  const core::SceneSimulation& s = r.simulation;
  if (s.simulated || (r.prediction && r.prediction->impact_count)) row.simulated = std::to_string(s.impact_count);
  if (r.prediction && r.prediction->infinite) row.predicted = "inf";
  if (r.prediction && r.prediction->impact_count) row.predicted = std::to_string(*r.prediction->impact_count);
  row.truncated = s.truncated;
  row.energy_lost = s.energy_lost;
  return row;
}

void writeSceneBatchTable(const std::vector<SceneBatchOutcome>& outcomes, std::ostream& out) {
  std::size_t name_width = 8;
  for (const auto& outcome : outcomes) name_width = std::max(name_width, outcome.entry.name.size());
  out << padRight("scenario", name_width) << padLeft("bodies", 9) << "  " << padRight("model", 20)
      << padLeft("collisions", 12) << padLeft("predicted", 12) << padLeft("energy lost [J]", 17) << "  truncated\n";
  for (const auto& outcome : outcomes) {
    const BatchRow row = batchRow(outcome);
    out << padRight(row.name, name_width) << padLeft(std::to_string(row.bodies), 9) << "  " << padRight(row.model, 20)
        << padLeft(row.simulated, 12) << padLeft(row.predicted, 12) << padLeft(humanText(row.energy_lost, 6), 17)
        << "  " << (row.truncated ? "yes" : "no") << "\n";
  }
  out << "\ncollisions: the run's answer, simulated or from the model (- when neither gives one); predicted: the "
         "model's closed form "
         "(- when none exists, inf for infinitely many)\n";
}

void writeSceneBatchCsv(const std::vector<SceneBatchOutcome>& outcomes, std::ostream& out) {
  out << "scenario,bodies,model,collision_count,predicted_collision_count,truncated,energy_lost_J\n";
  for (const auto& outcome : outcomes) {
    const BatchRow row = batchRow(outcome);
    out << csvField(row.name) << "," << row.bodies << "," << row.model << ","
        << (row.simulated == "-" ? "" : row.simulated) << "," << (row.predicted == "-" ? "" : row.predicted) << ","
        << (row.truncated ? "true" : "false") << "," << csvNumber(row.energy_lost) << "\n";
  }
}

void writeSceneBatchJson(const std::vector<SceneBatchOutcome>& outcomes, std::ostream& out) {
  out << "{\"units\": " << jsonText(unitsJson()) << ",\n\"scenarios\": [";
  bool first = true;
  for (const auto& outcome : outcomes) {
    const core::SceneRunResult& r = outcome.result;
    Json entry;
    // A run whose prediction carries the rotation model's values has the three-body
    // report's scene and summary.
    const bool rotation = r.prediction && core::hasRotationValues(*r.prediction);
    entry["scene"] = rotation ? sceneJson(outcome.entry) : sceneEntryJson(outcome.entry);
    entry["options"] = optionsJson(outcome.options);
    entry["events"] = Json::array();
    // The kept impacts, each collapse after the impact it follows (as the stream shows
    // them); every collapse before the last kept impact updates the bodies' state.
    SceneEventJson records(outcome.entry.scene, outcome.options.events);
    std::size_t next_collapse = 0;
    const auto collapsesUpTo = [&](std::uint64_t impacts) {
      for (; next_collapse < r.simulation.collapses.size() &&
             r.simulation.collapses[next_collapse].impacts_before <= impacts;
           ++next_collapse) {
        const core::Collapse& c = r.simulation.collapses[next_collapse];
        Json json = records.collapse(c);
        if (outcome.options.events.keepsAfter(c.impacts_before)) entry["events"].push_back(std::move(json));
      }
    };
    for (const core::ImpactRecord& impact : r.simulation.impacts) {
      collapsesUpTo(impact.index - 1);
      entry["events"].push_back(records.impact(impact));
    }
    collapsesUpTo(r.simulation.impact_count);
    if (rotation) {
      entry["summary"] = summaryJson(r);
      entry["summary"]["model"] = core::modelKindName(r.model.kind);
      entry["summary"]["model_reason"] = r.model.reason;
    } else {
      entry["summary"] = sceneSummaryJson(r);
    }
    out << (first ? "\n" : ",\n") << jsonText(entry);
    first = false;
  }
  out << "\n]}\n";
}

}  // namespace

Json sceneEntryJson(const SceneEntry& entry) {
  const core::Scene& s = entry.scene;
  return Json{{"name", entry.name},           {"description", entry.description},
              {"bodies", s.size()},           {"walls", wallNames(s)},
              {"masses", s.masses},           {"positions", s.positions},
              {"velocities", s.velocities},   {"restitution", s.restitution}};
}

namespace {

Json recordJson(const EventRecord& record) {
  std::ostringstream text;
  {
    TextSink sink(text);
    report_text::writeEventRecordJson(sink, record);
  }
  return Json::parse(text.str());
}

}  // namespace

SceneEventJson::SceneEventJson(const core::Scene& scene, const core::EventPolicy& policy)
    : state_(std::make_unique<SceneEventState>(scene, policy)) {}
SceneEventJson::~SceneEventJson() = default;

Json SceneEventJson::impact(const core::ImpactRecord& impact) { return recordJson(state_->impact(impact)); }
Json SceneEventJson::collapse(const core::Collapse& collapse) { return recordJson(state_->collapse(collapse)); }

Json sceneSummaryJson(const core::SceneRunResult& result) {
  Json json = summaryScalars(result);
  const auto& p = result.prediction;
  json["final_velocities"] = result.simulation.final_velocities;
  json["predicted_final_velocities"] =
      p && !p->final_velocities.empty() ? Json(p->final_velocities) : Json(nullptr);
  return json;
}

namespace {

std::unique_ptr<SceneLayout> makeSceneLayout(ReportFormat format, std::ostream& out) {
  switch (format) {
    case ReportFormat::kJson: return std::make_unique<SceneJsonWriter>(out);
    case ReportFormat::kCsv: return std::make_unique<SceneCsvWriter>(out);
    case ReportFormat::kTable: break;
  }
  return std::make_unique<SceneTableWriter>(out);
}

/// The one scene report: the layout chosen in begin() by what the plan's prediction holds.
/// Every event is handed on as it is, its model block with it.
class SceneReport : public SceneReportWriter {
 public:
  SceneReport(ReportFormat format, std::ostream& out) : format_(format), out_(out) {}

  void begin(const SceneEntry& entry, const core::RunOptions& options, const core::ModelChoice& model,
             const std::optional<core::Prediction>& prediction) override {
    if (prediction && core::hasRotationValues(*prediction)) {
      rotation_ = std::make_unique<ThreeBodyModelWriter>(format_, out_, model);
      rotation_->begin(entry, options);
    } else {
      scene_ = makeSceneLayout(format_, out_);
      scene_->begin(entry, options, model);
    }
  }
  void impact(const core::ImpactRecord& impact) override {
    if (rotation_) {
      rotation_->event(impact);
    } else {
      scene_->impact(impact);
    }
  }
  /// Elastic runs (those with rotation values) have none.
  void collapse(const core::Collapse& collapse) override {
    if (scene_) scene_->collapse(collapse);
  }
  void end(const core::SceneRunResult& result) override {
    if (rotation_) {
      rotation_->end(result);
    } else {
      scene_->end(result);
    }
  }

 private:
  ReportFormat format_;
  std::ostream& out_;
  std::unique_ptr<RunReportWriter> rotation_;  ///< from begin(), with rotation values
  std::unique_ptr<SceneLayout> scene_;         ///< from begin(), otherwise
};

}  // namespace

std::unique_ptr<SceneReportWriter> makeSceneReportWriter(ReportFormat format, std::ostream& out) {
  return std::make_unique<SceneReport>(format, out);
}

namespace {

/// The JSON report's values (ReportValues), in its layouts: the rotation model's when the
/// plan's prediction has its values, every scene's otherwise.
class SceneReportValues : public SceneReportWriter {
 public:
  explicit SceneReportValues(ReportValues& values) : values_(values) {}

  void begin(const SceneEntry& entry, const core::RunOptions& options, const core::ModelChoice& model,
             const std::optional<core::Prediction>& prediction) override {
    model_ = model;
    policy_ = options.events;
    if (prediction && core::hasRotationValues(*prediction)) {
      return values_.head(sceneJson(entry), optionsJson(options), unitsJson());
    }
    state_.emplace(entry.scene, options.events);
    Json scene = sceneEntryJson(entry);
    scene.update(sceneOptionsJson(entry.scene));
    values_.head(scene, optionsJson(options), unitsJson());
  }
  void impact(const core::ImpactRecord& impact) override {
    if (state_) return values_.event(state_->impact(impact));
    const core::ImpactRecord shown = report_text::shownImpact(impact, policy_);
    values_.event(report_text::eventRecord(shown));
  }
  void collapse(const core::Collapse& collapse) override {
    if (state_) values_.event(state_->collapse(collapse));  // elastic runs (the rotation's) have none
  }
  void end(const core::SceneRunResult& result) override {
    values_.summary(state_ ? sceneSummaryJson(result) : rotationSummaryJson(result, model_));
  }

 private:
  ReportValues& values_;
  core::ModelChoice model_;
  core::EventPolicy policy_;
  std::optional<SceneEventState> state_;  ///< from begin(), without the rotation model's values
};

}  // namespace

std::unique_ptr<SceneReportWriter> makeSceneReportValues(ReportValues& values) {
  return std::make_unique<SceneReportValues>(values);
}

namespace {

/// The visitors that hand the events that `shown` asks for to the report.
core::SceneVisitors showEvents(const core::RunOptions& shown, SceneReportWriter& report) {
  core::SceneVisitors visitors;
  if (shown.events.kind == core::EventPolicy::Kind::kNone) return visitors;
  const core::EventPolicy policy = shown.events;
  visitors.impact = [&report, policy](const core::ImpactRecord& impact) {
    if (policy.keeps(impact.index)) report.impact(impact);
  };
  visitors.collapse = [&report, policy](const core::Collapse& collapse) {
    if (policy.keepsAfter(collapse.impacts_before)) report.collapse(collapse);
  };
  // The event engine runs to the end even when only the first N impacts are shown.
  return visitors;
}

}  // namespace

core::SceneRunResult runReported(const SceneEntry& entry, const core::ScenePlan& plan, const ReportedRun& run,
                                 SceneReportWriter& report) {
  std::optional<TemperatureCsv> temperature;  // opened before any report: a bad path is bad input
  if (run.temperature_csv) temperature.emplace(*run.temperature_csv, entry.scene);
  report.begin(entry, run.options, plan.model, plan.prediction);
  core::SceneVisitors visitors = showEvents(run.options, report);
  visitors.progress = run.progress;
  core::SceneRunOptions options;
  options.lab = run.options;
  options.simulate_to_cap = run.simulate_to_cap;
  options.keep_events = false;  // handed to the report, not kept
  options.cancel = run.cancel;
  options.progress_interval = run.progress_interval;
  if (temperature) {
    // T(t) needs every impact: the visitors see every event (the report those it shows).
    visitors = temperature->feeding(std::move(visitors));
    options.lab.events = core::EventPolicy::all();
  }
  const core::SceneRunResult result = core::runScene(plan, options, visitors);
  if (temperature) temperature->finish();
  report.end(result);
  return result;
}

void writeSceneBatchReport(ReportFormat format, const std::vector<SceneBatchOutcome>& outcomes, std::ostream& out) {
  switch (format) {
    case ReportFormat::kJson: writeSceneBatchJson(outcomes, out); return;
    case ReportFormat::kCsv: writeSceneBatchCsv(outcomes, out); return;
    case ReportFormat::kTable: writeSceneBatchTable(outcomes, out); return;
  }
}

}  // namespace io
}  // namespace collision_lab
