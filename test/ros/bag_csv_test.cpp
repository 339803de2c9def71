// bag_to_csv (no master): a bag written here, exported, and read back as text. The
// expected headers and cells are written out by hand; numbers must round-trip exactly.
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <std_msgs/String.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"
#include "collision_lab/ros/bag_csv.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_ros::bagToCsv;
using collision_lab_ros::csvColumns;
constexpr double kInf = std::numeric_limits<double>::infinity();

using Table = std::vector<std::vector<std::string>>;  // rows of cells, header first

/// RFC 4180: quoted cells may hold commas, doubled quotes and line breaks.
Table readCsv(const std::string& path) {
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Table table(1);
  std::string cell;
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cell += '"', ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cell += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      table.back().push_back(cell), cell.clear();
    } else if (c == '\n') {
      table.back().push_back(cell), cell.clear();
      table.emplace_back();
    } else {
      cell += c;
    }
  }
  if (table.back().empty()) table.pop_back();
  return table;
}

std::vector<std::string> split(const std::string& header) {
  std::vector<std::string> names;
  std::istringstream in(header);
  for (std::string name; std::getline(in, name, ',');) names.push_back(name);
  return names;
}

/// The cell of `column` in data row `row` (1-based: row 0 is the header).
std::string cell(const Table& table, std::size_t row, const std::string& column) {
  const auto& header = table.at(0);
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == column) return table.at(row).at(i);
  }
  ADD_FAILURE() << "no column " << column;
  return {};
}

double number(const Table& table, std::size_t row, const std::string& column) {
  const std::string text = cell(table, row, column);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  EXPECT_EQ(*end, '\0') << column << " = '" << text << "' is not a number";
  return value;
}

class BagCsvTest : public testing::Test {
 protected:
  void SetUp() override {
    ros::Time::init();
    char pattern[] = "/tmp/collision_lab_bag_csv_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
    bag_path_ = dir_ + "/run.bag";
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// One run by hand: input, prediction, two collisions, summary; a rejection; a foreign
  /// topic.
  void writeBag() {
    rosbag::Bag bag(bag_path_, rosbag::bagmode::Write);
    const ros::Time start(1'700'000'000, 5);
    collision_lab::InitialConditions input;
    input.header.stamp = start;
    input.run_id = "csv_run";
    input.mode = collision_lab::InitialConditions::MODE_FULL;
    input.masses = {{1e4, 1, kInf}};
    input.positions = {{2, 1, 0}};
    input.velocities = {{-1, 0, -0.0}};
    bag.write("/collision_lab/initial_conditions", start, input);

    collision_lab::Prediction prediction;
    prediction.header.stamp = start;
    prediction.run_id = "csv_run";
    prediction.collision_count = 314;
    prediction.alpha = 1.0 / 3.0;
    prediction.phi_bc = std::nan("");
    prediction.first_pair_index = collision_lab::Prediction::PAIR_AB;
    prediction.final_velocities = {{0.1, -kInf, 1e-300}};
    prediction.timeline_scale = 1e9;
    bag.write("/collision_lab/predictions", start, prediction);

    for (std::uint64_t k = 1; k <= 2; ++k) {
      collision_lab::CollisionEvent event;
      event.header.stamp = start + ros::Duration(0, 250'000'000 * k);
      event.run_id = "csv_run";
      event.index = k;
      event.pair_index = k == 1 ? collision_lab::CollisionEvent::PAIR_AB : collision_lab::CollisionEvent::PAIR_BC;
      event.time = 0.25 * k;
      event.velocities_after = {{-0.1 * k, 2.0 / 3.0, 0}};
      event.kinetic_energy_after = {{0.005 * k, 2.0 / 9.0, 0}};
      event.total_momentum = -10000;
      bag.write("/collision_lab/collision_events", event.header.stamp, event);
      collision_lab::Velocities velocities;
      velocities.header = event.header;
      velocities.run_id = "csv_run";
      velocities.index = k;
      velocities.time = event.time;
      velocities.v_b = 2.0 / 3.0;
      bag.write("/collision_lab/velocities", event.header.stamp, velocities);
      collision_lab::EnergyTransfer energy;
      energy.header = event.header;
      energy.run_id = "csv_run";
      energy.index = k;
      energy.delta_c = -1.5e-15;
      bag.write("/collision_lab/energy_transfers", event.header.stamp, energy);
    }

    collision_lab::RunSummary summary;
    summary.header.stamp = start + ros::Duration(0, 500'000'000);
    summary.run_id = "csv_run";
    summary.collision_count = 2;
    summary.truncated = true;
    summary.truncation_reason = "stopped at 2, the \"cap\", by request";
    summary.recording_ok = true;
    summary.requested_run_id = "csv";
    bag.write("/collision_lab/run_summaries", summary.header.stamp, summary);

    collision_lab::Rejected rejected;
    rejected.header.stamp = summary.header.stamp;
    rejected.run_id = "bad";
    rejected.reason = collision_lab::Rejected::POSITIONS_NOT_ORDERED;
    rejected.message = "positions (0, 1, 2) m must be strictly decreasing";
    bag.write("/other_ns/rejected", rejected.header.stamp, rejected);

    std_msgs::String note;
    note.data = "not ours";
    bag.write("/note", start, note);
    bag.close();
  }

  std::string dir_, bag_path_;
};

TEST_F(BagCsvTest, OneCsvPerTopicWithUnitsAndExactNumbers) {
  writeBag();
  const auto result = bagToCsv(bag_path_, dir_ + "/csv");
  ASSERT_EQ(result.files.size(), 7u);
  std::set<std::string> names;
  for (const auto& file : result.files) names.insert(fs::path(file.path).filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"initial_conditions.csv", "predictions.csv",
                                           "collision_events.csv", "velocities.csv",
                                           "energy_transfers.csv", "run_summaries.csv",
                                           "rejected.csv"}));
  ASSERT_EQ(result.skipped_topics.size(), 1u);
  EXPECT_EQ(result.skipped_topics.front(), "/note (std_msgs/String)");

  const Table velocities = readCsv(dir_ + "/csv/velocities.csv");
  ASSERT_EQ(velocities.size(), 3u);
  EXPECT_EQ(velocities[0], split("stamp_s,run_id,index,time_s,v_a_m_s,v_b_m_s,v_c_m_s"));
  EXPECT_EQ(cell(velocities, 1, "stamp_s"), "1700000000.250000005");
  EXPECT_EQ(cell(velocities, 2, "stamp_s"), "1700000000.500000005");
  EXPECT_EQ(number(velocities, 2, "time_s"), 0.5);
  EXPECT_EQ(number(velocities, 1, "v_b_m_s"), 2.0 / 3.0);

  const Table input = readCsv(dir_ + "/csv/initial_conditions.csv");
  ASSERT_EQ(input.size(), 2u);
  EXPECT_EQ(input[0], split("stamp_s,run_id,mode,m_a_kg,m_b_kg,m_c_kg,x_a_m,x_b_m,x_c_m,"
                            "v_a_m_s,v_b_m_s,v_c_m_s,max_collisions"));
  EXPECT_EQ(input[1], split("1700000000.000000005,csv_run,full,10000,1,inf,2,1,0,-1,0,0,0"));

  const Table prediction = readCsv(dir_ + "/csv/predictions.csv");
  EXPECT_EQ(number(prediction, 1, "alpha_rad"), 1.0 / 3.0);
  EXPECT_EQ(cell(prediction, 1, "phi_bc_rad"), "nan");
  EXPECT_EQ(cell(prediction, 1, "first_pair_index"), "AB");
  EXPECT_EQ(cell(prediction, 1, "v_b_final_m_s"), "-inf");
  EXPECT_EQ(number(prediction, 1, "v_c_final_m_s"), 1e-300);
  EXPECT_EQ(number(prediction, 1, "timeline_scale_bag_s_per_s"), 1e9);
  EXPECT_EQ(cell(prediction, 1, "paper_collision_count_defined"), "false");

  const Table events = readCsv(dir_ + "/csv/collision_events.csv");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(cell(events, 2, "pair_index"), "BC");
  EXPECT_EQ(number(events, 2, "kinetic_energy_a_after_J"), 0.005 * 2);
  EXPECT_EQ(number(events, 1, "kinetic_energy_b_after_J"), 2.0 / 9.0);
  EXPECT_EQ(number(events, 2, "v_a_after_m_s"), -0.1 * 2);
  EXPECT_EQ(number(events, 1, "total_momentum_kg_m_s"), -10000);
  const Table energy = readCsv(dir_ + "/csv/energy_transfers.csv");
  EXPECT_EQ(number(energy, 1, "delta_c_J"), -1.5e-15);

  const Table summary = readCsv(dir_ + "/csv/run_summaries.csv");
  ASSERT_EQ(summary.size(), 2u);
  EXPECT_EQ(cell(summary, 1, "truncation_reason"), "stopped at 2, the \"cap\", by request");
  EXPECT_EQ(cell(summary, 1, "truncated"), "true");
  EXPECT_EQ(cell(summary, 1, "requested_run_id"), "csv");
  const Table rejected = readCsv(dir_ + "/csv/rejected.csv");
  EXPECT_EQ(cell(rejected, 1, "message"), "positions (0, 1, 2) m must be strictly decreasing");
  EXPECT_EQ(cell(rejected, 1, "reason"), "5");
}

/// The top-level field names of a message definition (constants and nested types left out).
std::set<std::string> fieldsOf(const std::string& definition) {
  std::set<std::string> fields;
  std::istringstream in(definition);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("=====", 0) == 0) break;
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string type, name;
    if (!(words >> type >> name) || line.find('=') != std::string::npos) continue;
    fields.insert(name);
  }
  return fields;
}

template <class M>
void expectEveryFieldExported() {
  const std::string datatype = ros::message_traits::DataType<M>::value();
  std::set<std::string> exported;
  for (const auto& column : csvColumns(datatype)) exported.insert(column.field);
  EXPECT_EQ(exported, fieldsOf(ros::message_traits::Definition<M>::value())) << datatype;
}

TEST(BagCsvColumns, EveryFieldOfEveryMessageHasAColumn) {
  expectEveryFieldExported<collision_lab::InitialConditions>();
  expectEveryFieldExported<collision_lab::Prediction>();
  expectEveryFieldExported<collision_lab::CollisionEvent>();
  expectEveryFieldExported<collision_lab::Velocities>();
  expectEveryFieldExported<collision_lab::EnergyTransfer>();
  expectEveryFieldExported<collision_lab::RunSummary>();
  expectEveryFieldExported<collision_lab::Rejected>();
}

TEST_F(BagCsvTest, CommandLineWritesBesideTheBagAndFailsClearly) {
  writeBag();
  EXPECT_EQ(std::system((std::string(COLLISION_LAB_BAG_TO_CSV) + " " + bag_path_ + " > /dev/null 2>&1").c_str()), 0);
  EXPECT_EQ(readCsv(dir_ + "/run_csv/collision_events.csv").size(), 3u);
  const std::string missing = dir_ + "/missing.bag";
  const std::string log = dir_ + "/stderr.txt";
  const int status = std::system(
      (std::string(COLLISION_LAB_BAG_TO_CSV) + " " + missing + " 2> " + log).c_str());
  EXPECT_NE(status, 0);
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("cannot read bag " + missing), std::string::npos) << text;
}

TEST_F(BagCsvTest, AnUnreadableBagIsAClearError) {
  std::ofstream(bag_path_) << "not a bag";
  try {
    bagToCsv(bag_path_, dir_ + "/csv");
    FAIL() << "no error";
  } catch (const collision_lab_ros::BagCsvError& e) {
    EXPECT_NE(std::string(e.what()).find(bag_path_), std::string::npos) << e.what();
  }
}

}  // namespace
