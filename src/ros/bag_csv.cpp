#include "collision_lab/ros/bag_csv.h"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <ostream>

#include <boost/array.hpp>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"

namespace collision_lab_ros {

namespace {

namespace fs = std::filesystem;

// ---- Cell formats ----

void writeCell(std::ostream& out, double value) {
  if (std::isnan(value)) {
    out << "nan";
  } else if (value == 0.0) {
    out << "0";  // no "-0"
  } else {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", value);
    out << buffer;
  }
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
void writePair(std::ostream& out, std::uint32_t pair) {
  static_assert(collision_lab::CollisionEvent::PAIR_AB == collision_lab::Prediction::PAIR_AB &&
                    collision_lab::CollisionEvent::PAIR_BC == collision_lab::Prediction::PAIR_BC,
                "one pair code for every message");
  switch (pair) {
    case collision_lab::Prediction::PAIR_AB: out << "AB"; return;
    case collision_lab::Prediction::PAIR_BC: out << "BC"; return;
    case collision_lab::Prediction::PAIR_NONE: out << "none"; return;
    default: out << pair;
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

template <class M>
class Table {
 public:
  Table() {
    add({"stamp_s", "header"}, [](std::ostream& o, const M& m) { writeStamp(o, m.header.stamp); });
    add({"run_id", "run_id"}, [](std::ostream& o, const M& m) { writeCell(o, m.run_id); });
  }
  /// A number or string field, written as it is; its column is the field's name and unit
  /// (e.g. "_s"; empty for [1] and strings).
  template <class T>
  Table& field(const std::string& field, T M::*member, const std::string& unit = "") {
    return add({field + unit, field}, [member](std::ostream& o, const M& m) {
      if constexpr (std::is_same_v<T, std::uint8_t>) {
        o << static_cast<int>(m.*member);
      } else {
        writeCell(o, m.*member);
      }
    });
  }
  Table& flag(const std::string& field, std::uint8_t M::*member) {
    return add({field, field}, [member](std::ostream& o, const M& m) { writeBool(o, m.*member); });
  }
  Table& pair(const std::string& field, std::uint32_t M::*member) {
    return add({field, field}, [member](std::ostream& o, const M& m) { writePair(o, m.*member); });
  }
  Table& mode(std::uint8_t M::*member) {
    return add({"mode", "mode"}, [member](std::ostream& o, const M& m) { writeMode(o, m.*member); });
  }
  /// Three columns for A, B, C (bodies 0, 1, 2): pattern with "{}" replaced by a, b, c;
  /// an empty cell for a body the array does not have.
  Table& triple(const std::string& pattern, const std::string& field,
                std::vector<double> M::*member) {
    for (std::size_t i = 0; i < 3; ++i) {
      add({abc(pattern, i), field}, [member, i](std::ostream& o, const M& m) {
        if (i < (m.*member).size()) writeCell(o, (m.*member)[i]);
      });
    }
    return *this;
  }
  /// Three scalar fields for A, B, C named pattern with "{}" replaced by a, b, c; the
  /// column adds unit.
  Table& scalars(const std::string& pattern, const std::string& unit,
                 const std::array<double M::*, 3>& members) {
    for (int i = 0; i < 3; ++i) {
      const std::string name = abc(pattern, i);
      field(name, members[i], unit);
    }
    return *this;
  }
  const std::vector<Column<M>>& columns() const { return columns_; }

 private:
  static std::string abc(const std::string& pattern, int i) {
    const auto at = pattern.find("{}");
    return pattern.substr(0, at) + static_cast<char>('a' + i) + pattern.substr(at + 2);
  }
  Table& add(CsvColumn name, std::function<void(std::ostream&, const M&)> write) {
    columns_.push_back({std::move(name), std::move(write)});
    return *this;
  }
  std::vector<Column<M>> columns_;
};

Table<collision_lab::InitialConditions> initialConditionsTable() {
  using M = collision_lab::InitialConditions;
  Table<M> t;
  t.mode(&M::mode)
      .triple("m_{}_kg", "masses", &M::masses)
      .triple("x_{}_m", "positions", &M::positions)
      .triple("v_{}_m_s", "velocities", &M::velocities)
      .field("max_collisions", &M::max_collisions);
  return t;
}

Table<collision_lab::Prediction> predictionTable() {
  using M = collision_lab::Prediction;
  Table<M> t;
  t.field("collision_count", &M::collision_count)
      .field("paper_collision_count", &M::paper_collision_count)
      .flag("paper_collision_count_defined", &M::paper_collision_count_defined)
      .field("max_possible_collision_count", &M::max_possible_collision_count)
      .field("alpha", &M::alpha, "_rad")
      .field("theta", &M::theta, "_rad")
      .field("omega", &M::omega, "_rad")
      .field("phi_bc", &M::phi_bc, "_rad")
      .field("psi", &M::psi, "_rad")
      .pair("first_pair_index", &M::first_pair_index)
      .triple("v_{}_final_m_s", "final_velocities", &M::final_velocities)
      .field("timeline_scale", &M::timeline_scale, "_bag_s_per_s");
  return t;
}

Table<collision_lab::CollisionEvent> collisionEventTable() {
  using M = collision_lab::CollisionEvent;
  Table<M> t;
  t.field("index", &M::index)
      .pair("pair_index", &M::pair_index)
      .field("time", &M::time, "_s")
      .field("position", &M::position, "_m")
      .triple("x_{}_m", "positions", &M::positions)
      .triple("v_{}_before_m_s", "velocities_before", &M::velocities_before)
      .triple("v_{}_after_m_s", "velocities_after", &M::velocities_after)
      .triple("predicted_v_{}_after_m_s", "predicted_velocities_after", &M::predicted_velocities_after)
      .triple("paper_v_{}_after_m_s", "paper_velocities_after", &M::paper_velocities_after)
      .triple("energy_transfer_{}_J", "energy_transfer", &M::energy_transfer)
      .triple("predicted_energy_transfer_{}_J", "predicted_energy_transfer",
              &M::predicted_energy_transfer)
      .triple("paper_energy_transfer_{}_J", "paper_energy_transfer", &M::paper_energy_transfer)
      .triple("kinetic_energy_{}_after_J", "kinetic_energy_after", &M::kinetic_energy_after)
      .field("total_energy", &M::total_energy, "_J")
      .field("total_momentum", &M::total_momentum, "_kg_m_s");
  return t;
}

Table<collision_lab::Velocities> velocitiesTable() {
  using M = collision_lab::Velocities;
  Table<M> t;
  t.field("index", &M::index)
      .field("time", &M::time, "_s")
      .scalars("v_{}", "_m_s", {&M::v_a, &M::v_b, &M::v_c});
  return t;
}

Table<collision_lab::EnergyTransfer> energyTransferTable() {
  using M = collision_lab::EnergyTransfer;
  Table<M> t;
  t.field("index", &M::index)
      .field("time", &M::time, "_s")
      .scalars("delta_{}", "_J", {&M::delta_a, &M::delta_b, &M::delta_c})
      .scalars("kinetic_{}", "_J", {&M::kinetic_a, &M::kinetic_b, &M::kinetic_c});
  return t;
}

Table<collision_lab::RunSummary> runSummaryTable() {
  using M = collision_lab::RunSummary;
  Table<M> t;
  t.mode(&M::mode)
      .field("collision_count", &M::collision_count)
      .flag("truncated", &M::truncated)
      .field("truncation_reason", &M::truncation_reason)
      .flag("simulated", &M::simulated)
      .field("predicted_collision_count", &M::predicted_collision_count)
      .field("paper_predicted_collision_count", &M::paper_predicted_collision_count)
      .flag("paper_predicted_collision_count_defined", &M::paper_predicted_collision_count_defined)
      .triple("v_{}_final_m_s", "final_velocities", &M::final_velocities)
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
      .field("requested_run_id", &M::requested_run_id);
  return t;
}

Table<collision_lab::Rejected> rejectedTable() {
  using M = collision_lab::Rejected;
  Table<M> t;
  t.field("reason", &M::reason)
      .field("reason_name", &M::reason_name)
      .field("field", &M::field)
      .field("message", &M::message);
  return t;
}

// ---- Export ----

class Exporter {
 public:
  virtual ~Exporter() = default;
  virtual std::string md5sum() const = 0;
  virtual std::vector<CsvColumn> columns() const = 0;
  /// False when the message cannot be read as this type.
  virtual bool writeRow(const rosbag::MessageInstance& m, std::ostream& out) const = 0;
};

template <class M>
class TableExporter : public Exporter {
 public:
  explicit TableExporter(Table<M> table) : table_(std::move(table)) {}
  std::string md5sum() const override { return ros::message_traits::MD5Sum<M>::value(); }
  std::vector<CsvColumn> columns() const override {
    std::vector<CsvColumn> names;
    for (const auto& c : table_.columns()) names.push_back(c.name);
    return names;
  }
  bool writeRow(const rosbag::MessageInstance& m, std::ostream& out) const override {
    const auto msg = m.instantiate<M>();
    if (!msg) return false;
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
  std::ofstream out;
};

}  // namespace

std::vector<CsvColumn> csvColumns(const std::string& datatype) {
  const Exporter* exporter = exporterFor(datatype);
  return exporter ? exporter->columns() : std::vector<CsvColumn>{};
}

CsvExport bagToCsv(const std::string& bag_path, const std::string& out_dir) {
  rosbag::Bag bag;
  try {
    bag.open(bag_path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw BagCsvError("cannot read bag " + bag_path + ": " + e.what());
  }
  rosbag::View view(bag);

  CsvExport result;
  std::vector<std::string> topics;  // exported, in the order of first appearance
  std::map<std::string, std::string> datatypes;  // of every topic
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    if (!datatypes.emplace(c->topic, c->datatype).second) continue;
    const Exporter* exporter = exporterFor(c->datatype);
    if (!exporter) {
      result.skipped_topics.push_back(c->topic + " (" + c->datatype + ")");
    } else if (exporter->md5sum() != c->md5sum) {
      result.skipped_topics.push_back(c->topic + " (" + c->datatype +
                                      " of another definition: recorded by another version)");
    } else {
      topics.push_back(c->topic);
    }
  }

  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw BagCsvError("cannot create " + out_dir + ": " + ec.message());
  const auto names = fileNames(topics);
  std::map<std::string, OpenFile> files;
  for (const auto& topic : topics) {
    OpenFile& file = files[topic];
    file.info = CsvFile{topic, (fs::path(out_dir) / names.at(topic)).string(), 0};
    file.out.open(file.info.path);
    if (!file.out) throw BagCsvError("cannot write " + file.info.path);
    const char* separator = "";
    for (const auto& c : exporterFor(datatypes.at(topic))->columns()) {
      file.out << separator << c.name;
      separator = ",";
    }
    file.out << '\n';
  }
  for (const rosbag::MessageInstance& m : view) {
    const auto file = files.find(m.getTopic());
    if (file == files.end()) continue;
    OpenFile& f = file->second;
    if (exporterFor(datatypes.at(m.getTopic()))->writeRow(m, f.out)) ++f.info.rows;
  }
  for (const auto& topic : topics) {
    OpenFile& f = files.at(topic);
    f.out.close();
    if (!f.out) throw BagCsvError("writing " + f.info.path + " failed");
    result.files.push_back(f.info);
  }
  return result;
}

}  // namespace collision_lab_ros
