#include "collision_lab/io/report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "collision_lab/io/number_text.h"

#include "event_pipeline.h"
#include "report_text.h"

namespace collision_lab {
namespace io {

namespace {

const char* const kParticleNames[3] = {"A", "B", "C"};

/// writeCsvNumber's text: shortest round trip, 0 for either zero, nan, inf, -inf.
std::string roundTripText(double value) {
  char buffer[kNumberTextMax];
  return std::string(buffer, writeCsvNumber(buffer, value));
}

using report_text::humanText;
using report_text::number;
using report_text::padLeft;
using report_text::padRight;
using report_text::kTimeBeyondRangeNote;

Json array3(const std::array<double, 3>& values) {
  return Json::array({number(values[0]), number(values[1]), number(values[2])});
}

Json optionalPair(const std::optional<core::Pair>& pair) {
  return pair ? Json(core::pairName(*pair)) : Json(nullptr);
}

double maxAbsDifference(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  double result = 0.0;
  for (int i = 0; i < 3; ++i) result = std::max(result, std::fabs(a[i] - b[i]));
  return result;
}

std::string paperCountText(const core::Prediction& prediction) {
  return prediction.paper_impact_count ? std::to_string(*prediction.paper_impact_count) : std::string("undefined");
}

/// The run's summary in the terms of the three-body reports: its prediction (with the
/// rotation model's values) and simulation.
struct ThreeBodySummary {
  explicit ThreeBodySummary(const core::SceneRunResult& result)
      : p(result.prediction.value()), s(result.simulation), compute_time_s(result.compute_time_s) {}

  const core::Prediction& p;
  const core::SceneSimulation& s;
  double compute_time_s;

  std::uint64_t predictedCount() const { return p.impact_count.value_or(0); }
  bool cancelled() const { return s.stop == core::StopReason::kCancelled; }
  std::string truncationReason() const { return s.truncated ? s.stop_message : std::string(); }
  std::optional<core::Pair> firstPair() const {
    if (!p.first_pair_index) return std::nullopt;
    return *p.first_pair_index == 0 ? core::Pair::AB : core::Pair::BC;
  }
  std::uint64_t decisions() const { return s.simulated ? s.impact_count + 1 : 0; }
  std::uint64_t highPrecision() const { return s.escalations.high_precision + s.escalations.exact_rational; }
};

// ---------------------------------------------------------------------------------------
// Table: for people. Event rows use 7 significant digits, the summary 10; JSON and CSV
// carry the full values.

constexpr int kEventDigits = 7;
constexpr int kSummaryDigits = 10;
constexpr std::size_t kNumberWidth = 15;

class TableWriter : public RunReportWriter {
 public:
  explicit TableWriter(std::ostream& out) : out_(out) {}

  void begin(const SceneEntry& named, const core::RunOptions& options) override {
    out_ << "collision_lab: " << (named.name.empty() ? "scene from the command line" : named.name);
    if (!named.description.empty()) out_ << " - " << named.description;
    out_ << "\n\n" << padRight("", 16);
    for (const char* name : kParticleNames) out_ << padLeft(name, kNumberWidth + 3);
    out_ << "\n";
    writeSceneRow("mass [kg]", core::triple(named.scene.masses));
    writeSceneRow("position [m]", core::triple(named.scene.positions));
    writeSceneRow("velocity [m/s]", core::triple(named.scene.velocities));
    out_ << "\nrun: mode " << runModeText(options.mode) << ", precision double"
         << ", events " << eventPolicyText(options.events) << ", at most " << options.max_collisions
         << " collisions\n";
  }

  void event(const core::ImpactRecord& impact) override {
    if (!header_written_) writeEventHeader();
    const core::ImpactModelValues& m = *impact.model;
    out_ << padLeft(std::to_string(impact.index), 9) << padLeft(core::pairName(impact.pair_index), 5);
    writeNumber(impact.time);
    writeNumber(impact.position);
    for (double v : m.velocities_after) writeNumber(v);
    for (double de : m.energy_transfer) writeNumber(de);
    writeNumber(maxAbsDifference(m.velocities_after, m.predicted_velocities_after));
    writeNumber(maxAbsDifference(m.velocities_after, m.paper_velocities_after));
    out_ << "\n";
  }

  void end(const core::SceneRunResult& result) override {
    const ThreeBodySummary summary(result);
    const core::Prediction& p = summary.p;
    const core::SceneSimulation& s = summary.s;
    const auto simulated = [&](const std::string& text) { return s.simulated ? text : std::string("-"); };
    out_ << "\n";
    writeSummaryRow("Summary", "simulation", "prediction", "paper, as printed");
    writeSummaryRow("collisions", simulated(std::to_string(s.impact_count)), std::to_string(summary.predictedCount()),
                    "eq. 3.22: " + paperCountText(p));
    writeSummaryRow("most possible collisions", "",
                    std::to_string(p.max_possible_impact_count.value_or(0)) + " = ceil(pi/alpha)", "");
    const std::optional<core::Pair> first = summary.firstPair();
    writeSummaryRow("first pair", "", first ? core::pairName(*first) : "none", "");
    for (int i = 0; i < 3; ++i) {
      writeSummaryRow(std::string("final v_") + kParticleNames[i] + " [m/s]",
                      simulated(humanText(s.final_velocities.at(i), kSummaryDigits)),
                      humanText(p.final_velocities.at(i), kSummaryDigits), "");
    }
    out_ << "\nangles [rad]: alpha " << humanText(p.alpha.value_or(0.0), kSummaryDigits) << ", theta = 2 alpha "
         << humanText(p.theta.value_or(0.0), kSummaryDigits) << ", Omega = pi - alpha "
         << humanText(p.omega.value_or(0.0), kSummaryDigits) << ", psi " << humanText(p.psi.value_or(0.0), kSummaryDigits)
         << ", paper's phi_BC (eq. 3.21) " << humanText(p.phi_bc.value_or(0.0), kSummaryDigits) << "\n";
    if (s.simulated) {
      out_ << "checks: max prediction error " << humanText(s.max_prediction_error, 3)
           << " (|S (v_sim - v_pred)| / |S v0|, S = diag(sqrt m): energy norm), relative energy drift " << humanText(s.energy_relative_drift, 3)
           << ", relative momentum drift "
           << (std::isnan(s.momentum_relative_drift) ? std::string("n/a (a wall does not conserve it)")
                                                     : humanText(s.momentum_relative_drift, 3))
           << "\n";
    }
    if (!s.simulated) {
      out_ << "not simulated: the closed form answers (predict-only, or more collisions predicted than the cap; "
              "--simulate-to-cap simulates up to it)\n";
    }
    out_ << "truncated: " << (s.truncated ? "yes, " + summary.truncationReason() : std::string("no")) << "\n";
    if (s.time_beyond_range) out_ << "time: " << kTimeBeyondRangeNote << "\n";
    out_ << "precision: " << summary.decisions() << " decisions, " << summary.highPrecision()
         << " taken at 100 digits or more, " << s.escalations.exact_rational << " by exact rationals; compute time "
         << humanText(summary.compute_time_s, 3) << " s\n";
  }

 private:
  void writeSceneRow(const char* label, const std::array<double, 3>& values) {
    out_ << padRight(label, 16);
    for (double v : values) out_ << padLeft(humanText(v, kSummaryDigits), kNumberWidth + 3);
    out_ << "\n";
  }

  void writeEventHeader() {
    header_written_ = true;
    out_ << "\nEvents (velocities after each impact; dv pred: max |v - closed form|, dv paper: max |v -"
            " paper's eqs. 2.15/2.16|)\n"
         << padLeft("#", 9) << padLeft("pair", 5);
    for (const char* label : {"t [s]", "x [m]", "v_A [m/s]", "v_B [m/s]", "v_C [m/s]", "dE_A [J]", "dE_B [J]",
                              "dE_C [J]", "dv pred [m/s]", "dv paper [m/s]"}) {
      out_ << padLeft(label, kNumberWidth);
    }
    out_ << "\n";
  }

  void writeNumber(double value) { out_ << padLeft(humanText(value, kEventDigits), kNumberWidth); }

  void writeSummaryRow(const std::string& label, const std::string& simulation, const std::string& prediction,
                       const std::string& paper) {
    constexpr std::size_t kLabelWidth = 26;
    constexpr std::size_t kColumnWidth = 22;
    std::string row = padRight(label, kLabelWidth) + padLeft(simulation, kColumnWidth) +
                      padLeft(prediction, kColumnWidth) + padLeft(paper, kColumnWidth);
    row.erase(row.find_last_not_of(' ') + 1);
    out_ << row << "\n";
  }

  std::ostream& out_;
  bool header_written_ = false;
};

// ---------------------------------------------------------------------------------------
// JSON: one document, one event per line.

class JsonWriter : public RunReportWriter {
 public:
  explicit JsonWriter(std::ostream& out) : out_(out), events_(out, report_text::writeEventJsonLine) {}

  void begin(const SceneEntry& named, const core::RunOptions& options) override {
    policy_ = options.events;
    out_ << "{\"scene\": " << jsonText(sceneJson(named)) << ",\n\"options\": " << jsonText(optionsJson(options))
         << ",\n\"units\": " << jsonText(unitsJson()) << ",\n\"events\": [";
  }

  void event(const core::ImpactRecord& impact) override {
    events_.push(report_text::shownImpact(impact, policy_));
    any_event_ = true;
  }

  void end(const core::SceneRunResult& result) override {
    events_.finish();
    out_ << (any_event_ ? "\n]" : "]") << ",\n\"summary\": " << jsonText(summaryJson(result)) << "}\n";
  }

 private:
  std::ostream& out_;
  EventPipeline events_;
  core::EventPolicy policy_;  ///< from begin(): which events carry the full state
  bool any_event_ = false;
};

// ---------------------------------------------------------------------------------------
// CSV: "# key,value..." comment lines for the scene and options, a header line, one row
// per event, then "# key,value..." comment lines for the summary (the JSON summary keys,
// nested keys joined by '.', doubles as in the rows, an absent value as an empty field).

void writeCsvComments(std::ostream& out, const std::string& prefix, const Json& object) {
  for (const auto& item : object.items()) {
    const std::string key = prefix + item.key();
    const Json& value = item.value();
    if (value.is_object()) {
      writeCsvComments(out, key + ".", value);
      continue;
    }
    out << "# " << key;
    const auto write_scalar = [&](const Json& scalar) {
      out << ",";
      if (scalar.is_string()) {
        out << scalar.get<std::string>();
      } else if (scalar.is_number_float()) {
        out << roundTripText(scalar.get<double>());
      } else if (!scalar.is_null()) {
        out << jsonText(scalar);
      }
    };
    if (value.is_array()) {
      for (const Json& element : value) write_scalar(element);
    } else {
      write_scalar(value);
    }
    out << "\n";
  }
}

/// One event row, in the columns of kEventCsvHeader.
void writeEventCsv(TextSink& sink, const core::ImpactRecord& impact, bool /*first*/) {
  report_text::writeEventRecordCsv(sink, report_text::eventRecord(impact));
}

class CsvWriter : public RunReportWriter {
 public:
  explicit CsvWriter(std::ostream& out) : out_(out), events_(out, writeEventCsv) {}

  void begin(const SceneEntry& named, const core::RunOptions& options) override {
    out_ << "# scene," << named.name << "\n";
    const std::pair<const char*, const std::vector<double>*> vectors[] = {
        {"masses_kg", &named.scene.masses},
        {"positions_m", &named.scene.positions},
        {"velocities_m_s", &named.scene.velocities}};
    for (const auto& [label, values] : vectors) {
      out_ << "# " << label;
      for (double v : *values) out_ << "," << roundTripText(v);
      out_ << "\n";
    }
    writeCsvComments(out_, "", optionsJson(options));
    out_ << report_text::kEventCsvHeader << "\n";
    policy_ = options.events;
  }

  void event(const core::ImpactRecord& impact) override { events_.push(report_text::shownImpact(impact, policy_)); }

  void end(const core::SceneRunResult& result) override {
    events_.finish();
    writeCsvComments(out_, "summary.", summaryJson(result));
  }

 private:
  std::ostream& out_;
  EventPipeline events_;
  core::EventPolicy policy_;  ///< from begin(): which events carry the full state
};

}  // namespace

std::optional<ReportFormat> parseReportFormat(const std::string& text) {
  if (text == "table") return ReportFormat::kTable;
  if (text == "json") return ReportFormat::kJson;
  if (text == "csv") return ReportFormat::kCsv;
  return std::nullopt;
}

std::optional<core::RunMode> parseRunMode(const std::string& text) {
  if (text == "full") return core::RunMode::kFull;
  if (text == "predict") return core::RunMode::kPredictOnly;
  if (text == "summary") return core::RunMode::kSummaryOnly;
  return std::nullopt;
}

std::optional<core::EventPolicy> parseEventPolicy(const std::string& text) {
  if (text == "all") return core::EventPolicy::all();
  if (text == "none") return core::EventPolicy::none();
  const std::string prefix = "first:";
  if (text.compare(0, prefix.size(), prefix) == 0) {
    const ParsedCount n = parseCount(std::string_view(text).substr(prefix.size()));
    if (n.problem.empty()) return core::EventPolicy::firstN(n.value);
  }
  return std::nullopt;
}

std::string runModeText(core::RunMode mode) {
  switch (mode) {
    case core::RunMode::kFull: return "full";
    case core::RunMode::kPredictOnly: return "predict";
    case core::RunMode::kSummaryOnly: return "summary";
  }
  return "unknown";
}

std::string eventPolicyText(const core::EventPolicy& policy) {
  switch (policy.kind) {
    case core::EventPolicy::Kind::kAll: return "all";
    case core::EventPolicy::Kind::kNone: return "none";
    case core::EventPolicy::Kind::kFirstN: return "first:" + std::to_string(policy.first_n);
  }
  return "unknown";
}

std::string jsonText(const Json& json) {
  return json.dump(-1, ' ', false, Json::error_handler_t::replace);
}

Json unitsJson() {
  return Json{{"mass", "kg"},         {"position", "m"}, {"velocity", "m/s"},
              {"time", "s"},          {"energy", "J"},   {"momentum", "kg m/s"},
              {"angle", "rad"},       {"drift", "relative (dimensionless)"},
              {"prediction_error", "energy norm |S (v_sim - v_pred)| / |S v0|, S = diag(sqrt m) (dimensionless)"}};
}

Json sceneJson(const SceneEntry& named) {
  Json walls = Json::array();
  const int wall = core::wallIndex(named.scene);
  if (wall >= 0) walls.push_back(kParticleNames[wall]);
  return Json{{"name", named.name},
              {"description", named.description},
              {"masses", array3(core::triple(named.scene.masses))},
              {"walls", std::move(walls)},
              {"positions", array3(core::triple(named.scene.positions))},
              {"velocities", array3(core::triple(named.scene.velocities))}};
}

Json optionsJson(const core::RunOptions& options) {
  Json json{{"max_collisions", options.max_collisions},
            {"events", eventPolicyText(options.events)},
            {"mode", runModeText(options.mode)},
            {"precision", "double"}};  // kept for readers of the format: every run is exact
  if (options.events.full_state_every > 1) json["full_state_every"] = options.events.full_state_every;
  return json;
}

Json eventJson(const core::ImpactRecord& impact) {
  std::ostringstream text;
  {
    TextSink sink(text);
    report_text::writeEventJson(sink, impact);
  }
  return Json::parse(text.str());
}

std::string eventPairName(const EventRecord& r) {
  return r.collapse ? core::pairName(r.pair_index) : core::impactPairName(r.pair_index, r.last_moved);
}

namespace report_text {

EventRecord eventRecord(const core::ImpactRecord& impact) {
  const std::size_t p = impact.pair_index;
  if (!impact.model) {  // the lean record (leanImpact): the pair's values only
    EventRecord r;
    r.index = impact.index;
    r.pair_index = p;
    r.time = impact.time;
    r.position = impact.position;
    r.first_moved = impact.first_moved;
    r.last_moved = impact.last_moved;
    r.pair_velocities_before = impact.velocities_before;
    r.pair_velocities_after = impact.velocities_after;
    r.pair_energy_transfer = impact.energy_gained;
    r.energy_lost = impact.energy_lost;
    r.uncertified = impact.uncertified & core::kPairValues;
    return r;
  }
  const core::ImpactModelValues& m = *impact.model;
  EventRecord r;
  r.index = impact.index;
  r.pair_index = p;
  r.time = impact.time;
  r.position = impact.position;
  r.restitution = 1.0;  // the three-body path answers elastic scenes only
  r.first_moved = impact.first_moved;
  r.last_moved = impact.last_moved;
  for (std::size_t side = 0; side < 2; ++side) {
    r.pair_velocities_before[side] = m.velocities_before[p + side];
    r.pair_velocities_after[side] = m.velocities_after[p + side];
  }
  r.energy_lost = impact.energy_lost;
  r.uncertified = impact.uncertified;
  fillFromModelBlock(r, m);
  return r;
}

namespace {

void jsonValues(TextSink& sink, std::string_view key, const double* values, std::size_t n) {
  sink.put(key);
  if (!values) return sink.put("null");
  sink.put('[');
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) sink.put(',');
    sink.jsonNumber(values[i]);
  }
  sink.put(']');
}

void jsonModel(TextSink& sink, std::string_view key, const std::array<double, 3>* values) {
  jsonValues(sink, key, values ? values->data() : nullptr, 3);
}

/// The JSON strings of the names of the record's uncertified values (core::impactValueName),
/// separated by commas.
void putUncertified(TextSink& sink, std::uint32_t bits) {
  bool first = true;
  for (int k = 0; k < core::kImpactValueCount; ++k) {
    if (!(bits & (1u << k))) continue;
    sink.put(first ? "\"" : ",\"");
    sink.put(core::impactValueName(k));
    sink.put('"');
    first = false;
  }
}

/// One CSV cell of n values separated by ';' (empty for none).
void csvValues(TextSink& sink, const double* values, std::size_t n) {
  sink.put(',');
  if (!values) return;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) sink.put(';');
    sink.csvNumber(values[i]);
  }
}

/// The bodies a record names, in order: the pair's two for an impact (body 0 second across a
/// ring's seam, the only impact whose last_moved is below its pair_index: a ring has no
/// clusters), the cluster's for a collapse.
std::vector<std::size_t> namedBodies(const EventRecord& r) {
  if (!r.collapse) return {r.pair_index, r.last_moved < r.pair_index ? std::size_t{0} : r.pair_index + 1};
  std::vector<std::size_t> bodies;
  for (std::size_t i = r.first_moved; i <= r.last_moved; ++i) bodies.push_back(i);
  return bodies;
}

/// core::bodyName(body), written without building a string.
void putBodyName(TextSink& sink, std::size_t body) {
  if (body < 26) return sink.put(static_cast<char>('A' + body));
  sink.put('#');
  sink.count(body);
}

/// The CSV cells pair (eventPairName), pair_index and bodies (namedBodies, separated by
/// ';') of a record, written without building strings.
void putCsvPairAndBodies(TextSink& sink, const EventRecord& r) {
  const std::size_t first = r.pair_index;
  const std::size_t second = r.collapse || r.last_moved >= r.pair_index ? r.pair_index + 1 : 0;
  putBodyName(sink, first);
  if (second >= 26 || (second == 0 && first >= 26)) sink.put('-');  // as core::pairName
  putBodyName(sink, second);
  sink.put(',');
  sink.count(r.pair_index);
  sink.put(',');
  if (!r.collapse) {
    putBodyName(sink, first);
    sink.put(';');
    return putBodyName(sink, second);
  }
  for (std::size_t i = r.first_moved; i <= r.last_moved; ++i) {
    if (i > r.first_moved) sink.put(';');
    putBodyName(sink, i);
  }
}

}  // namespace

const char* const kEventCsvHeader =
    "kind,index,pair,pair_index,bodies,time_s,position_m,restitution,first_moved,last_moved,cluster_impact,"
    "pair_v_before_right_m_s,pair_v_before_left_m_s,pair_v_after_right_m_s,pair_v_after_left_m_s,"
    "pair_energy_transfer_right_J,pair_energy_transfer_left_J,energy_lost_J,positions_m,velocities_before_m_s,"
    "velocities_after_m_s,energy_transfer_J,kinetic_energy_after_J,total_energy_J,total_momentum_kg_m_s,"
    "predicted_velocities_after_m_s,predicted_energy_transfer_J,paper_velocities_after_m_s,"
    "paper_energy_transfer_J";

void writeEventRecordJson(TextSink& sink, const EventRecord& r) {
  // Names are letters, digits, '#' and '-': no escapes.
  sink.put(r.collapse ? "{\"kind\":\"collapse\",\"index\":" : "{\"kind\":\"impact\",\"index\":");
  sink.count(r.index);
  sink.put(",\"pair\":\"");
  sink.put(eventPairName(r));
  sink.put("\",\"pair_index\":");
  sink.count(r.pair_index);
  sink.put(",\"bodies\":[");
  bool first = true;
  for (std::size_t i : namedBodies(r)) {
    sink.put(first ? "\"" : ",\"");
    sink.put(core::bodyName(i));
    sink.put('"');
    first = false;
  }
  sink.put(']');
  sink.jsonField(",\"time\":", r.time);
  sink.jsonField(",\"position\":", r.position);
  sink.jsonField(",\"restitution\":", r.restitution);
  sink.put(",\"first_moved\":");
  sink.count(r.first_moved);
  sink.put(",\"last_moved\":");
  sink.count(r.last_moved);
  sink.put(r.cluster_impact ? ",\"cluster_impact\":true" : ",\"cluster_impact\":false");
  sink.jsonArray(",\"pair_velocities_before\":", r.pair_velocities_before);
  sink.jsonArray(",\"pair_velocities_after\":", r.pair_velocities_after);
  sink.jsonArray(",\"pair_energy_transfer\":", r.pair_energy_transfer);
  sink.jsonField(",\"energy_lost\":", r.energy_lost);
  // An event without the full state (the lean record, or a scene of more than
  // kFullStateMaxBodies bodies) leaves out the per-body, total and model keys: absent, not
  // null, so that the lean record is the pair's values alone.
  if (r.full_state) {
    const std::size_t n = r.bodies;
    jsonValues(sink, ",\"positions\":", r.positions, n);
    jsonValues(sink, ",\"velocities_before\":", r.velocities_before, n);
    jsonValues(sink, ",\"velocities_after\":", r.velocities_after, n);
    jsonValues(sink, ",\"energy_transfer\":", r.energy_transfer, n);
    jsonValues(sink, ",\"kinetic_energy_after\":", r.kinetic_energy_after, n);
    sink.jsonField(",\"total_energy\":", r.total_energy);
    sink.jsonField(",\"total_momentum\":", r.total_momentum);
    jsonModel(sink, ",\"predicted_velocities_after\":", r.predicted_velocities_after);
    jsonModel(sink, ",\"predicted_energy_transfer\":", r.predicted_energy_transfer);
    jsonModel(sink, ",\"paper_velocities_after\":", r.paper_velocities_after);
    jsonModel(sink, ",\"paper_energy_transfer\":", r.paper_energy_transfer);
  }
  sink.put(",\"uncertified\":[");
  putUncertified(sink, r.uncertified);
  sink.put("]}");
}

void writeEventRecordCsv(TextSink& sink, const EventRecord& r) {
  const auto cell = [&sink](double value) {
    sink.put(',');
    sink.csvNumber(value);
  };
  const auto count = [&sink](std::uint64_t value) {
    sink.put(',');
    sink.count(value);
  };
  sink.put(r.collapse ? "collapse" : "impact");
  count(r.index);
  sink.put(',');
  putCsvPairAndBodies(sink, r);
  cell(r.time);
  cell(r.position);
  cell(r.restitution);
  count(r.first_moved);
  count(r.last_moved);
  sink.put(r.cluster_impact ? ",true" : ",false");
  for (const auto* pair : {&r.pair_velocities_before, &r.pair_velocities_after, &r.pair_energy_transfer}) {
    for (double v : *pair) cell(v);
  }
  cell(r.energy_lost);
  const std::size_t n = r.full_state ? r.bodies : 0;
  for (const double* values :
       {r.positions, r.velocities_before, r.velocities_after, r.energy_transfer, r.kinetic_energy_after}) {
    csvValues(sink, r.full_state ? values : nullptr, n);
  }
  if (r.full_state) {
    cell(r.total_energy);
    cell(r.total_momentum);
  } else {
    sink.put(",,");
  }
  for (const auto* values : {r.predicted_velocities_after, r.predicted_energy_transfer, r.paper_velocities_after,
                             r.paper_energy_transfer}) {
    csvValues(sink, values ? values->data() : nullptr, 3);
  }
  sink.put('\n');
}

void writeEventJson(TextSink& sink, const core::ImpactRecord& impact) { writeEventRecordJson(sink, eventRecord(impact)); }

core::ImpactRecord shownImpact(const core::ImpactRecord& impact, const core::EventPolicy& policy) {
  if (!impact.model || policy.fullStateAt(impact.index)) return impact;
  core::ImpactRecord lean = impact;
  const core::ImpactModelValues& m = *impact.model;
  const std::size_t p = impact.pair_index;
  for (std::size_t side = 0; side < 2; ++side) {
    lean.velocities_before[side] = m.velocities_before[p + side];
    lean.velocities_after[side] = m.velocities_after[p + side];
    lean.energy_gained[side] = m.energy_transfer[p + side];
  }
  lean.model.reset();
  return lean;
}

void writeEventJsonLine(TextSink& sink, const core::ImpactRecord& impact, bool first) {
  sink.put(first ? "\n" : ",\n");
  writeEventJson(sink, impact);
}

}  // namespace report_text

Json summaryJson(const core::SceneRunResult& result) {
  const ThreeBodySummary summary(result);
  const core::Prediction& p = summary.p;
  const core::SceneSimulation& s = summary.s;
  return Json{{"collision_count", s.impact_count},
              {"truncated", s.truncated},
              {"cancelled", summary.cancelled()},
              {"truncation_reason", summary.truncationReason()},
              {"time_beyond_range", s.time_beyond_range},
              {"simulated", s.simulated},
              {"final_velocities", array3(core::triple(s.final_velocities))},
              {"predicted_collision_count", summary.predictedCount()},
              {"paper_predicted_collision_count", p.paper_impact_count ? Json(*p.paper_impact_count) : Json(nullptr)},
              {"max_possible_collision_count", p.max_possible_impact_count.value_or(0)},
              {"predicted_first_pair", optionalPair(summary.firstPair())},
              {"predicted_final_velocities", array3(core::triple(p.final_velocities))},
              {"theta", number(p.theta.value_or(0.0))},
              {"alpha", number(p.alpha.value_or(0.0))},
              {"omega", number(p.omega.value_or(0.0))},
              {"psi", number(p.psi.value_or(0.0))},
              {"paper_phi_bc", number(p.phi_bc.value_or(0.0))},
              {"max_prediction_error", number(s.max_prediction_error)},
              {"uncertified_values", core::uncertifiedValues(result)},
              {"energy_relative_drift", number(s.energy_relative_drift)},
              {"momentum_relative_drift", number(s.momentum_relative_drift)},
              {"compute_time_s", number(summary.compute_time_s)},
              {"escalation",
               {{"decisions", summary.decisions()},
                {"high_precision", summary.highPrecision()},
                {"exact_rational", s.escalations.exact_rational}}}};
}

Json errorJson(const std::string& reason, int code, const std::string& field, const std::string& message) {
  return Json{{"error", {{"reason", reason}, {"code", code}, {"field", field}, {"message", message}}}};
}

std::unique_ptr<RunReportWriter> makeRunReportWriter(ReportFormat format, std::ostream& out) {
  switch (format) {
    case ReportFormat::kJson: return std::make_unique<JsonWriter>(out);
    case ReportFormat::kCsv: return std::make_unique<CsvWriter>(out);
    case ReportFormat::kTable: break;
  }
  return std::make_unique<TableWriter>(out);
}

}  // namespace io
}  // namespace collision_lab
