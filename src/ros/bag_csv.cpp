#include "collision_lab/ros/bag_csv.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <utility>

#include <boost/array.hpp>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <rosbag/query.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunParameters.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"
#include "collision_lab/core/nbody/body_state_replay.h"
#include "collision_lab/core/nbody/scene.h"
#include "collision_lab/core/totals.h"
#include "collision_lab/io/number_text.h"
#include "collision_lab/ros/bag_reading.h"
#include "collision_lab/ros/msg_conversion.h"

namespace collision_lab_ros {

namespace {

namespace fs = std::filesystem;
namespace core = collision_lab::core;

// ---- Cell formats ----

/// The shortest text that reads back to the same double; "0" for either zero, "nan", "inf".
void writeCell(std::ostream& out, double value) {
  char buffer[collision_lab::io::kNumberTextMax];
  out.write(buffer, collision_lab::io::writeCsvNumber(buffer, value) - buffer);
}
void writeCell(std::ostream& out, std::uint64_t value) { out << value; }
void writeCell(std::ostream& out, std::int64_t value) { out << value; }
void writeCell(std::ostream& out, const std::string& value) {
  if (value.find_first_of(",\"\n\r") == std::string::npos) {
    out << value;
    return;
  }
  out << '"';
  for (char c : value) out << (c == '"' ? "\"\"" : std::string(1, c));
  out << '"';
}
void writeStamp(std::ostream& out, const ros::Time& stamp) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%" PRIu32 ".%09" PRIu32, stamp.sec, stamp.nsec);
  out << buffer;
}
void writeBool(std::ostream& out, std::uint8_t value) { out << (value ? "true" : "false"); }
static_assert(std::uint32_t{collision_lab::CollisionEvent::PAIR_AB} == collision_lab::Prediction::PAIR_AB &&
                  std::uint32_t{collision_lab::CollisionEvent::PAIR_BC} == collision_lab::Prediction::PAIR_BC,
              "one pair code for every message");
void writePairIndex(std::ostream& out, std::uint32_t pair) {
  if (pair == collision_lab::Prediction::PAIR_NONE) {
    out << "none";
  } else {
    out << pair;
  }
}
void writePairName(std::ostream& out, std::uint32_t pair) {
  out << (pair == collision_lab::Prediction::PAIR_NONE ? std::string("none") : core::pairName(pair));
}
void writeKind(std::ostream& out, std::uint8_t kind) {
  switch (kind) {
    case collision_lab::CollisionEvent::KIND_IMPACT: out << "impact"; return;
    case collision_lab::CollisionEvent::KIND_COLLAPSE: out << "collapse"; return;
    default: out << static_cast<int>(kind);
  }
}
void writeMode(std::ostream& out, std::uint8_t mode) {
  switch (mode) {
    case collision_lab::InitialConditions::MODE_FULL: out << "full"; return;
    case collision_lab::InitialConditions::MODE_PREDICT_ONLY: out << "predict_only"; return;
    case collision_lab::InitialConditions::MODE_SUMMARY_ONLY: out << "summary_only"; return;
    default: out << static_cast<int>(mode);
  }
}

// ---- Column tables ----

template <class M>
struct Column {
  CsvColumn name;
  std::function<void(std::ostream&, const M&)> write;
};

/// The columns of one topic's CSV: the scalar fields of M.
template <class M>
class Table {
 public:
  Table() {
    add("stamp_s", "header", [](std::ostream& o, const M& m) { writeStamp(o, m.header.stamp); });
    add("run_id", "run_id", [](std::ostream& o, const M& m) { writeCell(o, m.run_id); });
  }
  /// A number or string field, written as it is; its column is the field's name and unit
  /// (e.g. "_s"; empty for [1] and strings).
  template <class T>
  Table& field(const std::string& field, T M::*member, const std::string& unit = "") {
    return add(field + unit, field, [member](std::ostream& o, const M& m) {
      if constexpr (std::is_same_v<T, std::uint8_t>) {
        o << static_cast<int>(m.*member);
      } else if constexpr (std::is_integral_v<T> && std::is_unsigned_v<T>) {
        writeCell(o, static_cast<std::uint64_t>(m.*member));
      } else if constexpr (std::is_integral_v<T>) {
        writeCell(o, static_cast<std::int64_t>(m.*member));
      } else {
        writeCell(o, m.*member);
      }
    });
  }
  /// The column time_s of a message that the node stamps at the run's start: simulated
  /// time 0 [s] (run_timeline.h: stamp = start + scale * t).
  Table& atRunStart() {
    return add("time_s", "header", [](std::ostream& o, const M&) { o << '0'; });
  }
  Table& flag(const std::string& field, std::uint8_t M::*member) {
    return add(field, field, [member](std::ostream& o, const M& m) { writeBool(o, m.*member); });
  }
  /// Two columns: the pair's number (pair_index; "none" for PAIR_NONE) and its name
  /// (name_column: "AB", "BC", ..., core::pairName).
  Table& pair(const std::string& field, const std::string& name_column, std::uint32_t M::*member) {
    add(field, field, [member](std::ostream& o, const M& m) { writePairIndex(o, m.*member); });
    return add(name_column, field, [member](std::ostream& o, const M& m) { writePairName(o, m.*member); });
  }
  /// A uint8 enum field written by its name (write: e.g. writeMode).
  Table& named(const std::string& field, std::uint8_t M::*member, void (*write)(std::ostream&, std::uint8_t)) {
    return add(field, field, [member, write](std::ostream& o, const M& m) { write(o, m.*member); });
  }
  /// A fixed pair array [2] as columns <prefix>_0<unit> and <prefix>_1<unit>: bodies
  /// pair_index and pair_index + 1.
  Table& pairArray(const std::string& prefix, const std::string& field, const std::string& unit,
                   boost::array<double, 2> M::*member) {
    for (std::size_t i = 0; i < 2; ++i) {
      add(prefix + "_" + std::to_string(i) + unit, field,
          [member, i](std::ostream& o, const M& m) { writeCell(o, (m.*member)[i]); });
    }
    return *this;
  }
  /// A list in one cell, values separated by ';' (empty cell: an empty list).
  Table& list(const std::string& field, const std::string& unit, std::vector<double> M::*member) {
    return add(field + unit, field, [member](std::ostream& o, const M& m) {
      const char* separator = "";
      for (double value : m.*member) {
        o << separator;
        writeCell(o, value);
        separator = ";";
      }
    });
  }
  /// A list of names in one cell, separated by ';' (empty cell: none).
  Table& names(const std::string& field, std::vector<std::string> M::*member) {
    return add(field, field, [member](std::ostream& o, const M& m) {
      std::string joined;
      for (const std::string& name : m.*member) joined += (joined.empty() ? "" : ";") + name;
      writeCell(o, joined);
    });
  }
  /// A field that is exported to a tidy table (file), not to this topic's CSV: listed by
  /// columns() so that every field has a column.
  Table& elsewhere(const std::string& file, const std::vector<std::pair<std::string, std::string>>& columns) {
    for (const auto& [name, field] : columns) elsewhere_.push_back({name, field, file});
    return *this;
  }
  const std::vector<Column<M>>& columns() const { return columns_; }
  const std::vector<CsvColumn>& elsewhereColumns() const { return elsewhere_; }

 private:
  Table& add(std::string name, std::string field, std::function<void(std::ostream&, const M&)> write) {
    columns_.push_back({CsvColumn{std::move(name), std::move(field), ""}, std::move(write)});
    return *this;
  }
  std::vector<Column<M>> columns_;
  std::vector<CsvColumn> elsewhere_;
};

constexpr const char* kBodiesFile = "bodies.csv";
constexpr const char* kFinalVelocitiesFile = "final_velocities.csv";

Table<collision_lab::InitialConditions> initialConditionsTable() {
  using M = collision_lab::InitialConditions;
  Table<M> t;
  t.atRunStart()
      .named("mode", &M::mode, writeMode)
      .list("masses", "_kg", &M::masses)
      .list("positions", "_m", &M::positions)
      .list("velocities", "_m_s", &M::velocities)
      .list("restitution", "", &M::restitution)
      .field("restitution_model", &M::restitution_model)
      .field("tc", &M::tc, "_s")
      .field("elastic_below", &M::elastic_below, "_m_s")
      .field("viscoelastic_speed", &M::viscoelastic_speed, "_m_s")
      .field("ring", &M::ring, "_m")
      .field("max_collisions", &M::max_collisions)
      .field("max_run_seconds", &M::max_run_seconds, "_s")
      .field("max_bag_bytes", &M::max_bag_bytes, "_bytes")
      .field("student", &M::student)
      .elsewhere(kBodiesFile, {{"mass_kg", "masses"}, {"x_m", "positions"}, {"v_m_s", "velocities"}});
  return t;
}

Table<collision_lab::Prediction> predictionTable() {
  using M = collision_lab::Prediction;
  Table<M> t;
  t.atRunStart()
      .field("model", &M::model)
      .field("model_name", &M::model_name)
      .field("model_reason", &M::model_reason)
      .field("body_count", &M::body_count)
      .field("collision_count", &M::collision_count)
      .flag("collision_count_defined", &M::collision_count_defined)
      .flag("infinite_collisions", &M::infinite_collisions)
      .field("paper_collision_count", &M::paper_collision_count)
      .flag("paper_collision_count_defined", &M::paper_collision_count_defined)
      .field("max_possible_collision_count", &M::max_possible_collision_count)
      .field("alpha", &M::alpha, "_rad")
      .field("theta", &M::theta, "_rad")
      .field("omega", &M::omega, "_rad")
      .field("phi_bc", &M::phi_bc, "_rad")
      .field("psi", &M::psi, "_rad")
      .pair("first_pair_index", "first_pair", &M::first_pair_index)
      .field("energy_lost", &M::energy_lost, "_J")
      .flag("collapsed", &M::collapsed)
      .field("collapse_time", &M::collapse_time, "_s")
      .field("collapse_position", &M::collapse_position, "_m")
      .field("critical_restitution", &M::critical_restitution)
      .field("spiral_angle", &M::spiral_angle, "_rad")
      .field("timeline_scale", &M::timeline_scale, "_bag_s_per_s")
      .elsewhere(kFinalVelocitiesFile, {{"v_m_s", "final_velocities"}});
  return t;
}

Table<collision_lab::CollisionEvent> collisionEventTable() {
  using M = collision_lab::CollisionEvent;
  Table<M> t;
  t.named("kind", &M::kind, writeKind)
      .field("index", &M::index)
      .pair("pair_index", "pair", &M::pair_index)
      .field("time", &M::time, "_s")
      .field("position", &M::position, "_m")
      .field("restitution", &M::restitution)
      .field("first_moved", &M::first_moved)
      .field("last_moved", &M::last_moved)
      .flag("cluster_impact", &M::cluster_impact)
      .pairArray("pair_v_before", "pair_velocities_before", "_m_s", &M::pair_velocities_before)
      .pairArray("pair_v_after", "pair_velocities_after", "_m_s", &M::pair_velocities_after)
      .pairArray("pair_energy_transfer", "pair_energy_transfer", "_J", &M::pair_energy_transfer)
      .field("energy_lost", &M::energy_lost, "_J")
      .field("total_energy", &M::total_energy, "_J")
      .field("total_momentum", &M::total_momentum, "_kg_m_s")
      .names("uncertified", &M::uncertified)
      .elsewhere(kBodiesFile, {{"x_m", "positions"},
                               {"v_before_m_s", "velocities_before"},
                               {"v_m_s", "velocities_after"},
                               {"energy_transfer_J", "energy_transfer"},
                               {"kinetic_J", "kinetic_energy_after"},
                               {"predicted_v_m_s", "predicted_velocities_after"},
                               {"paper_v_m_s", "paper_velocities_after"},
                               {"predicted_energy_transfer_J", "predicted_energy_transfer"},
                               {"paper_energy_transfer_J", "paper_energy_transfer"}});
  return t;
}

Table<collision_lab::Velocities> velocitiesTable() {
  using M = collision_lab::Velocities;
  Table<M> t;
  t.field("index", &M::index)
      .field("time", &M::time, "_s")
      .list("v", "_m_s", &M::v)
      .field("v_a", &M::v_a, "_m_s")
      .field("v_b", &M::v_b, "_m_s")
      .field("v_c", &M::v_c, "_m_s");
  return t;
}

Table<collision_lab::EnergyTransfer> energyTransferTable() {
  using M = collision_lab::EnergyTransfer;
  Table<M> t;
  t.field("index", &M::index)
      .field("time", &M::time, "_s")
      .list("delta", "_J", &M::delta)
      .list("kinetic", "_J", &M::kinetic)
      .field("energy_lost", &M::energy_lost, "_J")
      .field("cumulative_energy_lost", &M::cumulative_energy_lost, "_J");
  t.field("delta_a", &M::delta_a, "_J")
      .field("delta_b", &M::delta_b, "_J")
      .field("delta_c", &M::delta_c, "_J")
      .field("kinetic_a", &M::kinetic_a, "_J")
      .field("kinetic_b", &M::kinetic_b, "_J")
      .field("kinetic_c", &M::kinetic_c, "_J");
  return t;
}

Table<collision_lab::RunSummary> runSummaryTable() {
  using M = collision_lab::RunSummary;
  Table<M> t;
  t.named("mode", &M::mode, writeMode)
      .field("model", &M::model)
      .field("model_name", &M::model_name)
      .field("model_reason", &M::model_reason)
      .field("body_count", &M::body_count)
      .field("collision_count", &M::collision_count)
      .flag("truncated", &M::truncated)
      .field("truncation_reason", &M::truncation_reason)
      .flag("cancelled", &M::cancelled)
      .field("stop_reason", &M::stop_reason)
      .flag("simulated", &M::simulated)
      .field("predicted_collision_count", &M::predicted_collision_count)
      .flag("predicted_collision_count_defined", &M::predicted_collision_count_defined)
      .flag("infinite_collisions", &M::infinite_collisions)
      .field("paper_predicted_collision_count", &M::paper_predicted_collision_count)
      .flag("paper_predicted_collision_count_defined", &M::paper_predicted_collision_count_defined)
      .field("energy_lost", &M::energy_lost, "_J")
      .flag("collapsed", &M::collapsed)
      .field("collapse_time", &M::collapse_time, "_s")
      .field("collapse_position", &M::collapse_position, "_m")
      .field("collapse_count", &M::collapse_count)
      .field("cluster_impacts", &M::cluster_impacts)
      .field("rule_elastic_impacts", &M::rule_elastic_impacts)
      .field("critical_restitution", &M::critical_restitution)
      .field("spiral_angle", &M::spiral_angle, "_rad")
      .field("max_prediction_error", &M::max_prediction_error)
      .field("energy_relative_drift", &M::energy_relative_drift)
      .field("momentum_relative_drift", &M::momentum_relative_drift)
      .field("compute_time", &M::compute_time, "_s")
      .field("published_events", &M::published_events)
      .flag("events_not_published", &M::events_not_published)
      .field("bag_path", &M::bag_path)
      .flag("recording_ok", &M::recording_ok)
      .field("recording_error", &M::recording_error)
      .field("timeline_scale", &M::timeline_scale, "_bag_s_per_s")
      .flag("timeline_saturated", &M::timeline_saturated)
      .field("requested_run_id", &M::requested_run_id)
      .field("student", &M::student)
      .names("uncertified_values", &M::uncertified_values)
      .flag("time_beyond_range", &M::time_beyond_range)
      .elsewhere(kFinalVelocitiesFile, {{"v_m_s", "final_velocities"}});
  return t;
}

Table<collision_lab::Rejected> rejectedTable() {
  using M = collision_lab::Rejected;
  Table<M> t;
  t.field("reason", &M::reason)
      .field("reason_name", &M::reason_name)
      .field("field", &M::field)
      .field("message", &M::message)
      .field("student", &M::student);
  return t;
}

Table<collision_lab::RunParameters> runParametersTable() {
  using M = collision_lab::RunParameters;
  Table<M> t;
  t.field("package_version", &M::package_version)
      .field("node_name", &M::node_name)
      .field("max_collisions", &M::max_collisions)
      .field("max_published_events", &M::max_published_events)
      .field("max_bodies", &M::max_bodies)
      .field("max_run_seconds", &M::max_run_seconds, "_s")
      .field("max_bag_bytes", &M::max_bag_bytes, "_bytes");
  return t;
}

// ---- Tidy tables: one row per body ----

void writeCell(std::ostream& out, const std::optional<double>& value) {
  if (value) writeCell(out, *value);  // empty cell: not given
}
void writeHeader(std::ostream& out, const std::vector<std::string>& names) {
  const char* separator = "";
  for (const auto& name : names) out << std::exchange(separator, ",") << name;
  out << '\n';
}
template <class T>
std::optional<T> at(const std::vector<T>& values, std::size_t i) {
  return i < values.size() ? std::optional<T>(values[i]) : std::nullopt;
}

/// A tidy CSV file, opened by the first row.
class TidyFile {
 public:
  TidyFile(std::string path, std::vector<std::string> header) : path_(std::move(path)), header_(std::move(header)) {}
  /// The stream of a new row; throws BagCsvError when the file cannot be written.
  std::ostream& row() {
    if (!out_.is_open()) {
      out_.open(path_);
      if (!out_) throw BagCsvError("cannot write " + path_);
      writeHeader(out_, header_);
    }
    ++rows_;
    return out_;
  }
  /// The file written, or nothing when it has no rows.
  std::optional<CsvFile> close(const std::string& topics) {
    if (!out_.is_open()) return std::nullopt;
    out_.close();
    if (!out_) throw BagCsvError("writing " + path_ + " failed");
    return CsvFile{topics, path_, rows_};
  }

 private:
  std::string path_;
  std::vector<std::string> header_;
  std::ofstream out_;
  std::size_t rows_ = 0;
};

/// bodies.csv (bag_csv.h): the start and the bodies after each event, per run_id.
class BodiesCsv {
 public:
  explicit BodiesCsv(const std::string& out_dir)
      : file_((fs::path(out_dir) / kBodiesFile).string(),
              {"run_id", "index", "time_s", "body", "body_name", "moved", "mass_kg", "x_m", "v_before_m_s", "v_m_s",
               "energy_transfer_J", "kinetic_J", "predicted_v_m_s", "paper_v_m_s", "predicted_energy_transfer_J",
               "paper_energy_transfer_J", "kind"}) {}

  void add(const collision_lab::InitialConditions& m) {
    const std::size_t n = std::min({m.masses.size(), m.positions.size(), m.velocities.size()});
    const core::BodyStateReplay& replay =
        runs_.insert_or_assign(m.run_id, core::BodyStateReplay(m.masses, m.positions, m.velocities, m.ring)).first->second;
    for (std::size_t i = 0; i < n; ++i) {
      BodyRow r(0, 0.0, std::nullopt, i, false);
      r.mass = m.masses[i], r.x = m.positions[i], r.v = m.velocities[i];
      r.kinetic = replay.kinetic(i);
      write(m.run_id, r);
    }
  }

  void add(const collision_lab::CollisionEvent& m) {
    const auto run = runs_.find(m.run_id);
    core::BodyStateReplay* state = run == runs_.end() ? nullptr : &run->second;
    if (!m.velocities_after.empty()) {
      addFullState(m, state);
    } else if (state) {
      addMoved(m, *state);
    } else if (unknown_runs_.insert(m.run_id).second) {
      warnings.push_back("bodies.csv: run '" + m.run_id + "' has events without per-body arrays (more than " +
                         std::to_string(collision_lab::CollisionEvent::FULL_STATE_MAX_BODIES) +
                         " bodies) and no InitialConditions in the bag to rebuild them from: no body rows");
    }
  }

  std::optional<CsvFile> close(const std::string& topics) { return file_.close(topics); }
  std::vector<std::string> warnings;

 private:
  struct BodyRow {
    BodyRow(std::uint64_t index, double time, std::optional<std::uint8_t> kind, std::size_t body, bool moved)
        : index(index), time(time), kind(kind), body(body), moved(moved) {}
    std::uint64_t index;
    double time;
    /// The event's CollisionEvent::kind (impact, collapse); none for the start's rows.
    std::optional<std::uint8_t> kind;
    std::size_t body;
    bool moved;
    std::optional<double> mass, x, v_before, v, energy_transfer, kinetic, predicted_v, paper_v, predicted_energy,
        paper_energy;
  };

  /// An event that carries every body: the arrays as they are.
  void addFullState(const collision_lab::CollisionEvent& m, core::BodyStateReplay* state) {
    const std::size_t n = m.velocities_after.size();
    const bool known = state && state->size() == n;
    for (std::size_t i = 0; i < n; ++i) {
      // A ring's seam event wraps: first_moved..N-1, then 0..last_moved.
      const bool moved = m.first_moved <= m.last_moved ? m.first_moved <= i && i <= m.last_moved
                                                       : i >= m.first_moved || i <= m.last_moved;
      BodyRow r(m.index, m.time, m.kind, i, moved);
      if (known) r.mass = state->mass(i);
      r.x = at(m.positions, i), r.v_before = at(m.velocities_before, i), r.v = m.velocities_after[i];
      r.energy_transfer = at(m.energy_transfer, i), r.kinetic = at(m.kinetic_energy_after, i);
      r.predicted_v = at(m.predicted_velocities_after, i), r.paper_v = at(m.paper_velocities_after, i);
      r.predicted_energy = at(m.predicted_energy_transfer, i), r.paper_energy = at(m.paper_energy_transfer, i);
      write(m.run_id, r);
    }
    if (known) replayEvent(*state, m);
  }

  /// An event with the pair fields only: the bodies it moved, from the core's replay of the
  /// run (bag_csv.h says how). An event that does not fit the run's bodies has no rows.
  void addMoved(const collision_lab::CollisionEvent& m, core::BodyStateReplay& state) {
    if (!replayEvent(state, m)) return;
    for (std::size_t k = 0; k < state.movedCount(); ++k) {
      const std::size_t i = (state.firstMoved() + k) % state.size();  // a ring's seam wraps
      BodyRow r(m.index, m.time, m.kind, i, true);
      r.mass = state.mass(i), r.x = state.position(i, m.time), r.v_before = state.velocityBefore(i);
      r.v = state.velocities()[i], r.kinetic = state.kinetic(i), r.energy_transfer = state.energyGained(i);
      write(m.run_id, r);
    }
  }

  void write(const std::string& run_id, const BodyRow& r) {
    std::ostream& o = file_.row();
    writeCell(o, run_id);
    o << ',' << r.index << ',';
    writeCell(o, r.time);
    o << ',' << r.body << ',' << core::bodyName(r.body) << ',';
    writeBool(o, r.moved);
    for (const auto* value : {&r.mass, &r.x, &r.v_before, &r.v, &r.energy_transfer, &r.kinetic, &r.predicted_v,
                              &r.paper_v, &r.predicted_energy, &r.paper_energy}) {
      o << ',';
      writeCell(o, *value);
    }
    o << ',';
    if (r.kind) {
      writeKind(o, *r.kind);
    } else {
      o << "start";
    }
    o << '\n';
  }

  TidyFile file_;
  std::map<std::string, core::BodyStateReplay> runs_;  ///< each run's bodies after the last event read
  std::set<std::string> unknown_runs_;
};

/// final_velocities.csv: the final velocities of Prediction (source "prediction", the
/// closed form) and RunSummary (source "summary"), one row per body.
class FinalVelocitiesCsv {
 public:
  explicit FinalVelocitiesCsv(const std::string& out_dir)
      : file_((fs::path(out_dir) / kFinalVelocitiesFile).string(), {"run_id", "source", "body", "body_name", "v_m_s"}) {}
  void add(const collision_lab::Prediction& m) { write(m.run_id, "prediction", m.final_velocities); }
  void add(const collision_lab::RunSummary& m) { write(m.run_id, "summary", m.final_velocities); }
  std::optional<CsvFile> close(const std::string& topics) { return file_.close(topics); }

 private:
  void write(const std::string& run_id, const char* source, const std::vector<double>& v) {
    for (std::size_t i = 0; i < v.size(); ++i) {
      std::ostream& o = file_.row();
      writeCell(o, run_id);
      o << ',' << source << ',' << i << ',' << core::bodyName(i) << ',';
      writeCell(o, v[i]);
      o << '\n';
    }
  }
  TidyFile file_;
};

/// Both tidy tables; add() takes every exported message and keeps what they need.
struct TidyTables {
  explicit TidyTables(const std::string& out_dir) : bodies(out_dir), final_velocities(out_dir) {}
  void add(const collision_lab::InitialConditions& m) { bodies.add(m); }
  void add(const collision_lab::CollisionEvent& m) { bodies.add(m); }
  void add(const collision_lab::Prediction& m) { final_velocities.add(m); }
  void add(const collision_lab::RunSummary& m) { final_velocities.add(m); }
  template <class M>
  void add(const M&) {}
  BodiesCsv bodies;
  FinalVelocitiesCsv final_velocities;
};

// ---- Export ----

class Exporter {
 public:
  virtual ~Exporter() = default;
  virtual std::string md5sum() const = 0;
  virtual std::vector<CsvColumn> columns() const = 0;
  /// Writes the message's row to out and its per-body rows to tidy; false when the
  /// message cannot be read as this type.
  virtual bool writeRow(const rosbag::MessageInstance& m, std::ostream& out, TidyTables& tidy) const = 0;
};

template <class M>
class TableExporter : public Exporter {
 public:
  explicit TableExporter(Table<M> table) : table_(std::move(table)) {}
  std::string md5sum() const override { return ros::message_traits::MD5Sum<M>::value(); }
  std::vector<CsvColumn> columns() const override {
    std::vector<CsvColumn> names;
    for (const auto& c : table_.columns()) names.push_back(c.name);
    names.insert(names.end(), table_.elsewhereColumns().begin(), table_.elsewhereColumns().end());
    return names;
  }
  bool writeRow(const rosbag::MessageInstance& m, std::ostream& out, TidyTables& tidy) const override {
    const auto msg = m.instantiate<M>();
    if (!msg) return false;
    tidy.add(*msg);
    const char* separator = "";
    for (const auto& c : table_.columns()) {
      out << separator;
      c.write(out, *msg);
      separator = ",";
    }
    out << '\n';
    return true;
  }

 private:
  Table<M> table_;
};

template <class M>
void addExporter(std::map<std::string, std::unique_ptr<Exporter>>& exporters, Table<M> table) {
  exporters[ros::message_traits::DataType<M>::value()] =
      std::make_unique<TableExporter<M>>(std::move(table));
}

const std::map<std::string, std::unique_ptr<Exporter>>& exporters() {
  static const auto all = [] {
    std::map<std::string, std::unique_ptr<Exporter>> e;
    addExporter(e, initialConditionsTable());
    addExporter(e, predictionTable());
    addExporter(e, collisionEventTable());
    addExporter(e, velocitiesTable());
    addExporter(e, energyTransferTable());
    addExporter(e, runSummaryTable());
    addExporter(e, rejectedTable());
    addExporter(e, runParametersTable());
    return e;
  }();
  return all;
}

const Exporter* exporterFor(const std::string& datatype) {
  const auto it = exporters().find(datatype);
  return it == exporters().end() ? nullptr : it->second.get();
}

/// <out_dir>/<file name> per exported topic: the topic's last part, or the whole topic
/// ('/' as '_') when two topics share a last part.
std::map<std::string, std::string> fileNames(const std::vector<std::string>& topics) {
  std::map<std::string, int> uses;
  const auto lastPart = [](const std::string& topic) { return topic.substr(topic.rfind('/') + 1); };
  for (const auto& topic : topics) ++uses[lastPart(topic)];
  std::map<std::string, std::string> names;
  for (const auto& topic : topics) {
    std::string name = lastPart(topic);
    if (uses[name] > 1) {
      name = topic.substr(topic.find_first_not_of('/'));
      for (char& c : name) c = c == '/' ? '_' : c;
    }
    names[topic] = name + ".csv";
  }
  return names;
}

struct OpenFile {
  CsvFile info;
  const Exporter* exporter = nullptr;
  std::ofstream out;
};

struct ExportedTopic {
  std::string name;
  std::string datatype;
};

/// The bag's topics that hold a collision_lab type of this version, in the order of first
/// appearance; every other topic goes to skipped as "topic (type...)".
std::vector<ExportedTopic> exportedTopics(rosbag::View& view, std::vector<std::string>& skipped) {
  std::vector<ExportedTopic> topics;
  std::set<std::string> seen;
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    if (!seen.insert(c->topic).second) continue;
    const Exporter* exporter = exporterFor(c->datatype);
    if (!exporter) {
      skipped.push_back(c->topic + " (" + c->datatype + ")");
    } else if (exporter->md5sum() != c->md5sum) {
      skipped.push_back(c->topic + " (" + c->datatype + " of another definition: recorded by another version)");
    } else {
      topics.push_back({c->topic, c->datatype});
    }
  }
  return topics;
}

/// One CSV per topic, its header written; throws BagCsvError.
std::map<std::string, OpenFile> openTopicFiles(const std::vector<ExportedTopic>& topics, const std::string& out_dir) {
  std::vector<std::string> names;
  for (const auto& topic : topics) names.push_back(topic.name);
  const auto file_names = fileNames(names);
  std::map<std::string, OpenFile> files;
  for (const auto& topic : topics) {
    OpenFile& file = files[topic.name];
    file.info = CsvFile{topic.name, (fs::path(out_dir) / file_names.at(topic.name)).string(), 0};
    file.exporter = exporterFor(topic.datatype);
    file.out.open(file.info.path);
    if (!file.out) throw BagCsvError("cannot write " + file.info.path);
    std::vector<std::string> header;
    for (const auto& c : file.exporter->columns()) {
      if (c.file.empty()) header.push_back(c.name);
    }
    writeHeader(file.out, header);
  }
  return files;
}

/// The topics of types A and B, joined by " + " (a tidy table's sources).
template <class A, class B>
std::string topicsOf(const std::vector<ExportedTopic>& topics) {
  std::string joined;
  for (const auto& topic : topics) {
    if (topic.datatype == ros::message_traits::DataType<A>::value() ||
        topic.datatype == ros::message_traits::DataType<B>::value()) {
      joined += (joined.empty() ? "" : " + ") + topic.name;
    }
  }
  return joined;
}

}  // namespace

std::vector<CsvColumn> csvColumns(const std::string& datatype) {
  const Exporter* exporter = exporterFor(datatype);
  return exporter ? exporter->columns() : std::vector<CsvColumn>{};
}

CsvExport bagToCsv(const std::string& bag_path, const std::string& out_dir) {
  ReadableBag bag;
  try {
    bag = openBagForReading(bag_path);
  } catch (const std::exception& e) {
    throw BagCsvError("cannot read bag " + bag_path + ": " + e.what());
  }
  rosbag::View view(*bag);
  CsvExport result;
  const std::vector<ExportedTopic> topics = exportedTopics(view, result.skipped_topics);

  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw BagCsvError("cannot create " + out_dir + ": " + ec.message());
  std::map<std::string, OpenFile> files = openTopicFiles(topics, out_dir);
  TidyTables tidy(out_dir);
  for (const rosbag::MessageInstance& m : view) {
    const auto file = files.find(m.getTopic());
    if (file == files.end()) continue;
    OpenFile& f = file->second;
    if (f.exporter->writeRow(m, f.out, tidy)) ++f.info.rows;
  }
  for (const auto& topic : topics) {
    OpenFile& f = files.at(topic.name);
    f.out.close();
    if (!f.out) throw BagCsvError("writing " + f.info.path + " failed");
    result.files.push_back(f.info);
  }
  using collision_lab::InitialConditions, collision_lab::CollisionEvent;
  using collision_lab::Prediction, collision_lab::RunSummary;
  if (auto f = tidy.bodies.close(topicsOf<InitialConditions, CollisionEvent>(topics))) result.files.push_back(*f);
  if (auto f = tidy.final_velocities.close(topicsOf<Prediction, RunSummary>(topics))) result.files.push_back(*f);
  result.warnings = tidy.bodies.warnings;
  return result;
}

namespace {

void writeClassTableRow(std::ostream& out, double time, std::uint64_t impacts, const char* event,
                        const std::string& pair, const std::vector<double>& x, const core::BodyStateReplay& state) {
  writeCell(out, time);
  out << ',' << impacts << ',' << event << ',' << pair;
  for (double value : x) {
    out << ',';
    writeCell(out, value);
  }
  for (double value : state.velocities()) {
    out << ',';
    writeCell(out, value);
  }
  const core::Totals totals = core::totalsOf(state.masses(), state.velocities());
  out << ',';
  writeCell(out, totals.momentum);
  out << ',';
  writeCell(out, totals.kinetic_energy);
  out << '\n';
}

}  // namespace

ClassTable bagToClassTable(const std::string& bag_path, const std::string& csv_path, std::size_t max_bodies) {
  using collision_lab::CollisionEvent, collision_lab::InitialConditions, collision_lab::RunSummary;
  ReadableBag bag;
  try {
    bag = openBagForReading(bag_path);
  } catch (const std::exception& e) {
    throw BagCsvError("cannot read bag " + bag_path + ": " + e.what());
  }
  // The start first, whatever its stamp; then the events in the bag's order.
  rosbag::View starts(*bag, rosbag::TypeQuery(ros::message_traits::datatype<InitialConditions>()));
  std::optional<core::BodyStateReplay> state;
  for (const rosbag::MessageInstance& m : starts) {
    if (const auto initial = m.instantiate<InitialConditions>()) {
      state.emplace(initial->masses, initial->positions, initial->velocities, initial->ring);
      break;
    }
  }
  if (!state) throw BagCsvError(bag_path + " has no InitialConditions: not a run of collision_lab_node");
  ClassTable table;
  table.bodies = state->size();
  if (table.bodies > max_bodies) {
    table.too_many_bodies = true;
    return table;
  }
  // A run recorded without all its events is known before anything is written: its summary
  // counts more impacts than the bag has events.
  std::uint64_t summary_impacts = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(*bag, rosbag::TypeQuery(ros::message_traits::datatype<RunSummary>()))) {
    if (const auto summary = m.instantiate<RunSummary>()) summary_impacts = summary->collision_count;
  }
  if (summary_impacts > rosbag::View(*bag, rosbag::TypeQuery(ros::message_traits::datatype<CollisionEvent>())).size()) {
    table.events_missing = true;
    return table;
  }
  std::ofstream out(csv_path);
  if (!out) throw BagCsvError("cannot write " + csv_path);
  out << "t_s,collision,event,pair";
  for (std::size_t i = 0; i < table.bodies; ++i) out << ",x_" << core::bodyName(i) << "_m";
  for (std::size_t i = 0; i < table.bodies; ++i) out << ",v_" << core::bodyName(i) << "_m_s";
  out << ",p_total_kg_m_s,kinetic_total_J\n";
  writeClassTableRow(out, 0.0, 0, "start", "", state->positions(0.0), *state);
  ++table.rows;
  std::uint64_t impacts = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(*bag, rosbag::TypeQuery(ros::message_traits::datatype<CollisionEvent>()))) {
    if (const auto event = m.instantiate<CollisionEvent>()) {
      if (!replayEvent(*state, *event)) continue;
      const bool collapse = event->kind == CollisionEvent::KIND_COLLAPSE;
      if (!collapse) impacts = event->index;
      const std::string pair = collapse ? core::bodyName(event->first_moved) + ".." + core::bodyName(event->last_moved)
                                        : core::impactPairName(event->pair_index, event->last_moved);
      const bool every_body = event->positions.size() == state->size();
      writeClassTableRow(out, event->time, impacts, collapse ? "collapse" : "impact", pair,
                         every_body ? std::vector<double>(event->positions.begin(), event->positions.end())
                                    : state->positions(event->time),
                         *state);
      ++table.rows;
    }
  }
  out.close();
  if (!out) throw BagCsvError("writing " + csv_path + " failed");
  table.events_missing = summary_impacts > impacts;
  return table;
}

}  // namespace collision_lab_ros
