// bag_to_csv (no master): a bag written here, exported, and read back as text. The
// expected headers and cells are written out by hand; numbers must round-trip exactly.
#include <stdlib.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
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
#include "collision_lab/RunParameters.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"
#include "collision_lab/core/scene_run.h"
#include "collision_lab/ros/bag_csv.h"
#include "collision_lab/ros/msg_conversion.h"
#include "../core/rational_reference.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_ros::bagToClassTable;
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

/// The cells of one unquoted CSV line (a trailing ',' ends with an empty cell).
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells(1);
  for (char c : line) {
    if (c == ',') {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  return cells;
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
    input.student = "ana";
    input.max_run_seconds = 2.5;
    input.max_bag_bytes = 1000000;
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
      event.first_moved = event.pair_index;
      event.last_moved = event.pair_index + 1;
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
    summary.student = "ana";
    bag.write("/collision_lab/run_summaries", summary.header.stamp, summary);

    collision_lab::Rejected rejected;
    rejected.header.stamp = summary.header.stamp;
    rejected.run_id = "bad";
    rejected.student = "ben";
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
  ASSERT_EQ(result.files.size(), 9u);
  std::set<std::string> names;
  for (const auto& file : result.files) names.insert(fs::path(file.path).filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"initial_conditions.csv", "predictions.csv",
                                           "collision_events.csv", "velocities.csv",
                                           "energy_transfers.csv", "run_summaries.csv",
                                           "rejected.csv", "bodies.csv", "final_velocities.csv"}));
  ASSERT_EQ(result.skipped_topics.size(), 1u);
  EXPECT_EQ(result.skipped_topics.front(), "/note (std_msgs/String)");
  EXPECT_TRUE(result.warnings.empty());
  EXPECT_EQ(result.files.at(7).topic, "/collision_lab/initial_conditions + /collision_lab/collision_events");
  EXPECT_EQ(result.files.at(7).rows, 3u + 2 * 3u);  // the start and two events, three bodies each

  const Table velocities = readCsv(dir_ + "/csv/velocities.csv");
  ASSERT_EQ(velocities.size(), 3u);
  EXPECT_EQ(velocities[0], split("stamp_s,run_id,index,time_s,v_m_s,v_a_m_s,v_b_m_s,v_c_m_s"));
  EXPECT_EQ(cell(velocities, 1, "stamp_s"), "1700000000.250000005");
  EXPECT_EQ(cell(velocities, 2, "stamp_s"), "1700000000.500000005");
  EXPECT_EQ(number(velocities, 2, "time_s"), 0.5);
  EXPECT_EQ(number(velocities, 1, "v_b_m_s"), 2.0 / 3.0);

  const Table input = readCsv(dir_ + "/csv/initial_conditions.csv");
  ASSERT_EQ(input.size(), 2u);
  EXPECT_EQ(input[0], split("stamp_s,run_id,time_s,mode,masses_kg,positions_m,velocities_m_s,restitution,"
                            "restitution_model,tc_s,elastic_below_m_s,viscoelastic_speed_m_s,ring_m,"
                            "max_collisions,max_run_seconds_s,max_bag_bytes_bytes,student"));
  EXPECT_EQ(input[1], (std::vector<std::string>{"1700000000.000000005", "csv_run", "0", "full", "10000;1;inf",
                                                 "2;1;0", "-1;0;0", "", "0", "0", "0", "0", "0", "0", "2.5",
                                                 "1000000", "ana"}));

  // The masses, positions and velocities of the input are the start's rows (index 0).
  const Table bodies = readCsv(dir_ + "/csv/bodies.csv");
  ASSERT_EQ(bodies.size(), 10u);
  EXPECT_EQ(bodies[0], split("run_id,index,time_s,body,body_name,moved,mass_kg,x_m,v_before_m_s,v_m_s,"
                             "energy_transfer_J,kinetic_J,predicted_v_m_s,paper_v_m_s,"
                             "predicted_energy_transfer_J,paper_energy_transfer_J,kind"));
  EXPECT_EQ(bodies[1], split("csv_run,0,0,0,A,false,10000,2,,-1,,5000,,,,,start"));
  EXPECT_EQ(bodies[3], split("csv_run,0,0,2,C,false,inf,0,,0,,0,,,,,start"));  // -0.0 as 0; a wall has no kinetic energy

  const Table prediction = readCsv(dir_ + "/csv/predictions.csv");
  EXPECT_EQ(number(prediction, 1, "alpha_rad"), 1.0 / 3.0);
  EXPECT_EQ(cell(prediction, 1, "phi_bc_rad"), "nan");
  EXPECT_EQ(cell(prediction, 1, "first_pair_index"), "0");
  EXPECT_EQ(cell(prediction, 1, "first_pair"), "AB");
  EXPECT_EQ(number(prediction, 1, "timeline_scale_bag_s_per_s"), 1e9);
  EXPECT_EQ(cell(prediction, 1, "paper_collision_count_defined"), "false");
  const Table finals = readCsv(dir_ + "/csv/final_velocities.csv");
  ASSERT_EQ(finals.size(), 4u);  // the prediction's three; the summary has none
  EXPECT_EQ(finals[0], split("run_id,source,body,body_name,v_m_s"));
  EXPECT_EQ(finals[2], split("csv_run,prediction,1,B,-inf"));
  EXPECT_EQ(number(finals, 3, "v_m_s"), 1e-300);

  const Table events = readCsv(dir_ + "/csv/collision_events.csv");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(cell(events, 2, "pair"), "BC");
  EXPECT_EQ(cell(events, 2, "pair_index"), "1");
  EXPECT_EQ(cell(events, 2, "kind"), "impact");
  EXPECT_EQ(number(events, 1, "total_momentum_kg_m_s"), -10000);
  // Event k's bodies: rows 1 + 3k .. 3 + 3k.
  EXPECT_EQ(number(bodies, 7, "kinetic_J"), 0.005 * 2);
  EXPECT_EQ(number(bodies, 5, "kinetic_J"), 2.0 / 9.0);
  EXPECT_EQ(number(bodies, 7, "v_m_s"), -0.1 * 2);
  EXPECT_EQ(cell(bodies, 7, "moved"), "false");  // event 2 is pair BC: bodies 1 and 2
  EXPECT_EQ(cell(bodies, 8, "moved"), "true");
  EXPECT_EQ(cell(bodies, 7, "x_m"), "");  // not in the event
  const Table energy = readCsv(dir_ + "/csv/energy_transfers.csv");
  EXPECT_EQ(number(energy, 1, "delta_c_J"), -1.5e-15);

  const Table summary = readCsv(dir_ + "/csv/run_summaries.csv");
  ASSERT_EQ(summary.size(), 2u);
  EXPECT_EQ(cell(summary, 1, "truncation_reason"), "stopped at 2, the \"cap\", by request");
  EXPECT_EQ(cell(summary, 1, "truncated"), "true");
  EXPECT_EQ(cell(summary, 1, "requested_run_id"), "csv");
  EXPECT_EQ(cell(summary, 1, "student"), "ana");
  const Table rejected = readCsv(dir_ + "/csv/rejected.csv");
  EXPECT_EQ(cell(rejected, 1, "message"), "positions (0, 1, 2) m must be strictly decreasing");
  EXPECT_EQ(cell(rejected, 1, "reason"), "5");
  EXPECT_EQ(cell(rejected, 1, "student"), "ben");
}

/// An impact of a CollisionEvent of run run_id, pair fields only.
collision_lab::CollisionEvent impact(const std::string& run_id, std::uint64_t index, std::uint32_t pair,
                                     double time, double position, double restitution) {
  collision_lab::CollisionEvent event;
  event.header.stamp = ros::Time(1'700'000'000) + ros::Duration(time);
  event.run_id = run_id;
  event.index = index;
  event.pair_index = pair;
  event.time = time;
  event.position = position;
  event.restitution = restitution;
  event.first_moved = pair;
  event.last_moved = pair + 1;
  event.total_energy = event.total_momentum = std::nan("");
  return event;
}

collision_lab::InitialConditions scene(const std::string& run_id, std::vector<double> masses,
                                       std::vector<double> positions, std::vector<double> velocities,
                                       std::vector<double> restitution) {
  collision_lab::InitialConditions input;
  input.header.stamp = ros::Time(1'700'000'000);
  input.run_id = run_id;
  input.masses = std::move(masses);
  input.positions = std::move(positions);
  input.velocities = std::move(velocities);
  input.restitution = std::move(restitution);
  return input;
}

// Newton's cradle with gaps and e = 0.5: five 1 kg bodies at 4, 3, 2, 1, 0 m, body 0 at
// -1 m/s. By hand (v' = V -+ e (v_i - v_j) / 2 for equal masses):
//  impact 1, pair 0 at t = 1 s, x = 3 m: V = -0.5, (-1, 0) -> (-0.25, -0.75); heat
//    (1 - e^2) mu v_rel^2 / 2 = 0.75 * 0.5 * 1 / 2 = 0.1875 J.
//  impact 2, pair 1 at t = 1 + 1/0.75 = 7/3 s, x = 2 m: V = -0.375, (-0.75, 0) ->
//    (-0.1875, -0.5625); heat 0.75 * 0.5 * 0.5625 / 2 = 0.10546875 J. Body 0 is then at
//    3 - 0.25 * 4/3 = 8/3 m.
TEST_F(BagCsvTest, FiveBodiesWithRestitutionEveryBodyAfterEveryImpact) {
  {
    rosbag::Bag bag(bag_path_, rosbag::bagmode::Write);
    const auto input = scene("cradle", {1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}, {0.5});
    bag.write("/collision_lab/initial_conditions", input.header.stamp, input);
    auto first = impact("cradle", 1, 0, 1.0, 3.0, 0.5);
    first.pair_velocities_before = {{-1, 0}};
    first.pair_velocities_after = {{-0.25, -0.75}};
    first.energy_lost = 0.1875;
    first.positions = {3, 3, 2, 1, 0};
    first.velocities_before = {-1, 0, 0, 0, 0};
    first.velocities_after = {-0.25, -0.75, 0, 0, 0};
    first.energy_transfer = {0.03125 - 0.5, 0.28125, 0, 0, 0};
    first.kinetic_energy_after = {0.03125, 0.28125, 0, 0, 0};
    bag.write("/collision_lab/collision_events", first.header.stamp, first);
    auto second = impact("cradle", 2, 1, 7.0 / 3.0, 2.0, 0.5);
    second.pair_velocities_before = {{-0.75, 0}};
    second.pair_velocities_after = {{-0.1875, -0.5625}};
    second.energy_lost = 0.10546875;
    second.positions = {8.0 / 3.0, 2, 2, 1, 0};
    second.velocities_before = first.velocities_after;
    second.velocities_after = {-0.25, -0.1875, -0.5625, 0, 0};
    second.energy_transfer = {0, 0.017578125 - 0.28125, 0.158203125, 0, 0};
    second.kinetic_energy_after = {0.03125, 0.017578125, 0.158203125, 0, 0};
    bag.write("/collision_lab/collision_events", second.header.stamp, second);
  }
  bagToCsv(bag_path_, dir_ + "/csv");
  const Table input = readCsv(dir_ + "/csv/initial_conditions.csv");
  EXPECT_EQ(cell(input, 1, "restitution"), "0.5");
  const Table events = readCsv(dir_ + "/csv/collision_events.csv");
  EXPECT_EQ(number(events, 2, "restitution"), 0.5);
  EXPECT_EQ(number(events, 2, "pair_v_before_0_m_s"), -0.75);
  EXPECT_EQ(number(events, 2, "pair_v_after_1_m_s"), -0.5625);
  EXPECT_EQ(number(events, 1, "energy_lost_J"), 0.1875);
  EXPECT_EQ(cell(events, 1, "total_energy_J"), "nan");
  EXPECT_EQ(cell(events, 2, "first_moved") + cell(events, 2, "last_moved"), "12");

  const Table bodies = readCsv(dir_ + "/csv/bodies.csv");
  ASSERT_EQ(bodies.size(), 1u + 3 * 5);
  // Impact 2: rows 11..15 (bodies 0..4).
  EXPECT_EQ(bodies[11], split("cradle,2,2.3333333333333335,0,A,false,1,2.6666666666666665,-0.25,-0.25,0,0.03125,,,,,impact"));
  EXPECT_EQ(bodies[13], split("cradle,2,2.3333333333333335,2,C,true,1,2,0,-0.5625,0.158203125,0.158203125,,,,,impact"));
  EXPECT_EQ(cell(bodies, 15, "body_name"), "E");
  // Each impact's heat is what the bodies lost together.
  for (std::size_t event = 1; event <= 2; ++event) {
    double gained = 0.0;
    for (std::size_t row = 1 + 5 * event; row <= 5 + 5 * event; ++row) gained += number(bodies, row, "energy_transfer_J");
    EXPECT_EQ(-gained, number(events, event, "energy_lost_J")) << event;
  }
}

// 70 bodies (over FULL_STATE_MAX_BODIES): the events carry the pair fields only, and
// bodies.csv rebuilds the bodies each one moved. 1 kg each, 1 m apart (body i at 69 - i m),
// e = 0 everywhere, body 0 at -1 m/s. By hand:
//  impact 1, pair 0 at t = 1 s, x = 68 m: 0 and 1 stick at -0.5 m/s (heat 0.25 J).
//  impact 2, pair 1 at t = 1 + 1/0.5 = 3 s, x = 67 m: the cluster {0, 1} (2 kg) hits body
//    2: all three at -1/3 m/s (heat 1/12 J); a cluster impact, bodies 0 .. 2 moved.
// A second run, "collapse" (65 bodies), stands for a run whose engine resolved a collapse
// right after its first impact: three 1 kg bodies at 2, 1, 0 m (body 0 at -1 m/s, e = 0.05),
// the rest at rest far left. Impact 1, pair 0 at t = 1 s, x = 1 m: (-1, 0) -> (-0.475,
// -0.525); then the collapse of bodies 0 .. 2 moves all three at -1/3 m/s.
TEST_F(BagCsvTest, OverSixtyFourBodiesTheMovedBodiesAreRebuiltFromThePairFields) {
  {
    rosbag::Bag bag(bag_path_, rosbag::bagmode::Write);
    std::vector<double> ones(70, 1.0), positions(70), velocities(70, 0.0);
    for (std::size_t i = 0; i < 70; ++i) positions[i] = 69.0 - static_cast<double>(i);
    velocities[0] = -1;
    const auto gas = scene("big", ones, positions, velocities, {0});
    bag.write("/collision_lab/initial_conditions", gas.header.stamp, gas);
    auto first = impact("big", 1, 0, 1.0, 68.0, 0.0);
    first.pair_velocities_before = {{-1, 0}};
    first.pair_velocities_after = {{-0.5, -0.5}};
    bag.write("/collision_lab/collision_events", first.header.stamp, first);
    auto second = impact("big", 2, 1, 3.0, 67.0, 0.0);
    second.first_moved = 0;
    second.cluster_impact = true;
    second.pair_velocities_before = {{-0.5, 0}};
    second.pair_velocities_after = {{-1.0 / 3.0, -1.0 / 3.0}};
    bag.write("/collision_lab/collision_events", second.header.stamp, second);

    std::vector<double> far(65, 1.0), far_x(65), far_v(65, 0.0);
    for (std::size_t i = 0; i < 65; ++i) far_x[i] = i < 3 ? 2.0 - static_cast<double>(i) : -10.0 - static_cast<double>(i);
    far_v[0] = -1;
    const ros::Duration later(100.0);  // after the run "big" in the bag
    const auto three = scene("collapse", far, far_x, far_v, {0.05});
    bag.write("/collision_lab/initial_conditions", three.header.stamp + later, three);
    auto hit = impact("collapse", 1, 0, 1.0, 1.0, 0.05);
    hit.pair_velocities_after = {{-0.475, -0.525}};
    bag.write("/collision_lab/collision_events", hit.header.stamp + later, hit);
    auto collapse = impact("collapse", 1, 1, 1.5, 0.25, 0.05);
    collapse.kind = collision_lab::CollisionEvent::KIND_COLLAPSE;
    collapse.first_moved = 0;
    collapse.last_moved = 2;
    collapse.pair_velocities_after = {{-1.0 / 3.0, -1.0 / 3.0}};
    bag.write("/collision_lab/collision_events", collapse.header.stamp + later, collapse);
  }
  const auto result = bagToCsv(bag_path_, dir_ + "/csv");
  EXPECT_TRUE(result.warnings.empty());
  const Table bodies = readCsv(dir_ + "/csv/bodies.csv");
  // The starts (70 and 65 rows) and the moved bodies: 2 + 3, then 2 + 3.
  ASSERT_EQ(bodies.size(), 1u + 70 + 5 + 65 + 5);
  const std::size_t big = 1 + 70;  // impact 1 of "big"
  EXPECT_EQ(bodies[big], split("big,1,1,0,A,true,1,68,-1,-0.5,-0.375,0.125,,,,,impact"));
  EXPECT_EQ(bodies[big + 1], split("big,1,1,1,B,true,1,68,0,-0.5,0.125,0.125,,,,,impact"));
  const double third = 1.0 / 3.0, kinetic = 0.5 * third * third;
  for (std::size_t body = 0; body < 3; ++body) {
    const std::size_t row = big + 2 + body;
    EXPECT_EQ(cell(bodies, row, "index") + cell(bodies, row, "body"), "2" + std::to_string(body));
    EXPECT_EQ(number(bodies, row, "x_m"), 67.0);
    EXPECT_EQ(number(bodies, row, "v_before_m_s"), body < 2 ? -0.5 : 0.0);
    EXPECT_EQ(number(bodies, row, "v_m_s"), -third);
    EXPECT_EQ(number(bodies, row, "kinetic_J"), kinetic);
    EXPECT_EQ(number(bodies, row, "energy_transfer_J"), kinetic - (body < 2 ? 0.125 : 0.0));
  }
  const std::size_t collapse = big + 5 + 65 + 2;  // the collapse's rows, after impact 1 of "collapse"
  EXPECT_EQ(number(bodies, collapse - 1, "v_m_s"), -0.525);  // impact 1's body B
  // The impact and the collapse share index 1; the column kind tells them apart.
  EXPECT_EQ(cell(bodies, collapse - 1, "index") + " " + cell(bodies, collapse - 1, "kind"), "1 impact");
  EXPECT_EQ(cell(bodies, collapse, "index") + " " + cell(bodies, collapse, "kind"), "1 collapse");
  EXPECT_EQ(number(bodies, collapse - 1, "energy_transfer_J"), 0.5 * 0.525 * 0.525);
  for (std::size_t body = 0; body < 3; ++body) {
    EXPECT_EQ(cell(bodies, collapse + body, "body"), std::to_string(body));
    EXPECT_EQ(number(bodies, collapse + body, "x_m"), 0.25);
    EXPECT_EQ(number(bodies, collapse + body, "v_before_m_s"), std::vector<double>({-0.475, -0.525, 0.0})[body]);
    EXPECT_EQ(number(bodies, collapse + body, "v_m_s"), -third);
  }
}

TEST_F(BagCsvTest, EventsWithoutArraysAndWithoutTheirInputHaveNoBodyRowsAndAWarning) {
  {
    rosbag::Bag bag(bag_path_, rosbag::bagmode::Write);
    auto first = impact("lost_input", 1, 0, 1.0, 68.0, 1.0);
    bag.write("/collision_lab/collision_events", first.header.stamp, first);
  }
  const auto result = bagToCsv(bag_path_, dir_ + "/csv");
  ASSERT_EQ(result.files.size(), 1u);  // no bodies.csv
  ASSERT_EQ(result.warnings.size(), 1u);
  EXPECT_NE(result.warnings.front().find("run 'lost_input'"), std::string::npos) << result.warnings.front();
  EXPECT_FALSE(fs::exists(dir_ + "/csv/bodies.csv"));
}

/// Whether `text` has more significant digits than the shortest decimal that reads back to
/// `value`: some rounding of `value` to fewer digits reads back to it too.
bool longerThanNeeded(const std::string& text, double value) {
  std::string significant;
  for (char c : text.substr(0, text.find_first_of("eE"))) {
    if (c >= '0' && c <= '9') significant += c;
  }
  significant.erase(0, significant.find_first_not_of('0'));
  significant.erase(significant.find_last_not_of('0') + 1);
  const std::size_t digits = significant.size();
  for (int fewer = 1; fewer < static_cast<int>(digits); ++fewer) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*e", fewer - 1, value);
    if (std::strtod(buffer, nullptr) == value) return true;
  }
  return false;
}

// Numbers as people and Python write them: the shortest digits that read back to the same
// double (Python's repr gives 0.9, 0.1, 0.6666666666666666, 1e-300), never 17 digits
// (0.90000000000000002); the simulated time beside the epoch stamp in every topic's file
// that has a time; the start's masses, positions and velocities in initial_conditions.csv.
TEST_F(BagCsvTest, ShortestDigitsSimulatedTimeAndTheStartInInitialConditions) {
  rosbag::Bag bag(bag_path_, rosbag::bagmode::Write);
  const ros::Time start(1'700'000'000);
  collision_lab::InitialConditions input = scene("digits", {0.9, 0.1, 3}, {2.5, 0.3, -7}, {-0.9, 0.1, 0}, {});
  input.header.stamp = start;
  bag.write("/collision_lab/initial_conditions", start, input);
  collision_lab::Prediction prediction;
  prediction.header.stamp = start;
  prediction.run_id = "digits";
  prediction.alpha = 2.0 / 3.0;
  prediction.final_velocities = {{0.9, 1e-300}};
  bag.write("/collision_lab/predictions", start, prediction);
  collision_lab::CollisionEvent event = impact("digits", 1, 0, 0.3, 0.1, 1);
  event.header.stamp = start + ros::Duration(0, 300'000'000);
  event.energy_lost = 0.9;
  bag.write("/collision_lab/collision_events", event.header.stamp, event);
  bag.close();
  bagToCsv(bag_path_, dir_ + "/csv");

  const Table input_csv = readCsv(dir_ + "/csv/initial_conditions.csv");
  ASSERT_EQ(input_csv.size(), 2u);
  EXPECT_EQ(cell(input_csv, 1, "time_s"), "0");
  EXPECT_EQ(cell(input_csv, 1, "masses_kg"), "0.9;0.1;3");
  EXPECT_EQ(cell(input_csv, 1, "positions_m"), "2.5;0.3;-7");
  EXPECT_EQ(cell(input_csv, 1, "velocities_m_s"), "-0.9;0.1;0");
  const Table prediction_csv = readCsv(dir_ + "/csv/predictions.csv");
  EXPECT_EQ(cell(prediction_csv, 1, "time_s"), "0");
  EXPECT_EQ(cell(prediction_csv, 1, "alpha_rad"), "0.6666666666666666");
  const Table events = readCsv(dir_ + "/csv/collision_events.csv");
  EXPECT_EQ(cell(events, 1, "stamp_s"), "1700000000.300000000");
  EXPECT_EQ(cell(events, 1, "time_s"), "0.3");
  EXPECT_EQ(cell(events, 1, "energy_lost_J"), "0.9");
  const Table finals = readCsv(dir_ + "/csv/final_velocities.csv");
  EXPECT_EQ(cell(finals, 1, "v_m_s"), "0.9");
  EXPECT_EQ(cell(finals, 2, "v_m_s"), "1e-300");

  // Every number cell of every file reads back exactly and is no longer than needed.
  std::size_t numbers = 0;
  for (const auto& entry : fs::directory_iterator(dir_ + "/csv")) {
    const Table table = readCsv(entry.path().string());
    for (std::size_t row = 1; row < table.size(); ++row) {
      for (std::size_t col = 0; col < table[row].size(); ++col) {
        if (table[0][col] == "stamp_s") continue;  // exact nanoseconds, not a double
        std::istringstream items(table[row][col]);
        for (std::string item; std::getline(items, item, ';');) {
          char* end = nullptr;
          const double value = std::strtod(item.c_str(), &end);
          if (item.empty() || *end != '\0' || !std::isfinite(value)) continue;
          ++numbers;
          EXPECT_FALSE(longerThanNeeded(item, value)) << entry.path() << " " << table[0][col] << " = " << item;
        }
      }
    }
  }
  EXPECT_GT(numbers, 30u);
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
  for (const auto& column : csvColumns(datatype)) {
    exported.insert(column.field);
    EXPECT_TRUE(column.file.empty() || column.file == "bodies.csv" || column.file == "final_velocities.csv")
        << column.file;
  }
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
  expectEveryFieldExported<collision_lab::RunParameters>();
}

// Without OUTDIR the CSVs go to RUN_csv in the current folder, not into the bag's folder
// (the node's runs folder holds bags only).
TEST_F(BagCsvTest, CommandLineWritesIntoTheCurrentFolderAndFailsClearly) {
  writeBag();
  fs::create_directory(dir_ + "/work");
  EXPECT_EQ(std::system(("cd " + dir_ + "/work && " + COLLISION_LAB_BAG_TO_CSV + " ../run.bag > /dev/null 2>&1").c_str()),
            0);
  EXPECT_EQ(readCsv(dir_ + "/work/run_csv/collision_events.csv").size(), 3u);
  EXPECT_FALSE(fs::exists(dir_ + "/run_csv"));
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

namespace class_table {

namespace core = collision_lab::core;
using core::reference::Q;

/// A bag of the engine's run of `scene`, as the node records it: InitialConditions, every
/// event, RunSummary.
void recordRun(const std::string& bag_path, const core::Scene& scene) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
  const ros::Time start(1'700'000'000, 0);
  collision_lab::InitialConditions input =
      collision_lab_ros::toInitialConditions(scene, core::RunMode::kFull, 1000);
  input.run_id = "table";
  bag.write("/collision_lab/initial_conditions", start, input);
  const core::ScenePlan plan = core::planScene(scene);
  core::SceneRunOptions options;
  options.lab.max_collisions = 1000;
  options.lab.events = core::EventPolicy::none();
  core::SceneVisitors visitors;
  collision_lab_ros::SceneEventConverter converter(plan.scene);
  ros::Time stamp = start;
  visitors.impact = [&](const core::ImpactRecord& e) {
    auto msg = converter.impact(e);
    msg.run_id = "table";
    stamp += ros::Duration(0, 1000);
    bag.write("/collision_lab/collision_events", stamp, msg);
  };
  auto summary = collision_lab_ros::toRunSummaryMsg(core::runScene(plan, options, visitors), scene.size(),
                                                    core::RunMode::kFull);
  summary.run_id = "table";
  bag.write("/collision_lab/run_summaries", stamp + ros::Duration(0, 1000), summary);
}

/// The exact momentum and kinetic energy of the finite masses at the given doubles.
std::pair<Q, Q> exactTotals(const std::vector<double>& masses, const std::vector<double>& velocities) {
  Q momentum = 0, energy = 0;
  for (std::size_t i = 0; i < masses.size(); ++i) {
    if (std::isinf(masses[i])) continue;
    momentum += Q(masses[i]) * Q(velocities[i]);
    energy += Q(masses[i]) * Q(velocities[i]) * Q(velocities[i]) / 2;
  }
  return {momentum, energy};
}

}  // namespace class_table

// The class table of the pi billiard (100 kg and 1 kg against a wall, 31 impacts), row by
// row against test/core's exact rational run, which shares no code with the engine: the
// start, then every impact's time, pair, positions and velocities; the totals are the
// exact sums of the row's own doubles, rounded once.
TEST_F(BagCsvTest, ClassTableIsTheExactRunAtTheStartAndAfterEveryImpact) {
  using namespace class_table;
  const core::Scene scene = core::threeBodies({100, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  recordRun(bag_path_, scene);
  const auto table = bagToClassTable(bag_path_, dir_ + "/table.csv", 64);
  const auto exact = core::reference::simulate(scene, 1000);
  ASSERT_EQ(exact.impacts.size(), 31u);
  EXPECT_EQ(table.bodies, 3u);
  EXPECT_EQ(table.rows, 32u);
  EXPECT_FALSE(table.events_missing);
  EXPECT_FALSE(table.too_many_bodies);

  const Table csv = readCsv(dir_ + "/table.csv");
  ASSERT_EQ(csv.size(), 33u);
  EXPECT_EQ(csv[0], split("t_s,collision,event,pair,x_A_m,x_B_m,x_C_m,v_A_m_s,v_B_m_s,v_C_m_s,p_total_kg_m_s,"
                          "kinetic_total_J"));
  EXPECT_EQ(csv[1], split("0,0,start,,2,1,0,-1,0,0,-100,50"));
  for (std::size_t k = 1; k <= 31; ++k) {
    const auto& impact = exact.impacts[k - 1];
    SCOPED_TRACE("impact " + std::to_string(k));
    EXPECT_EQ(cell(csv, k + 1, "collision"), std::to_string(k));
    EXPECT_EQ(cell(csv, k + 1, "event"), "impact");
    EXPECT_EQ(cell(csv, k + 1, "pair"), core::pairName(impact.pair));
    EXPECT_TRUE(core::testing_support::correctlyRounded(number(csv, k + 1, "t_s"), impact.time));
    std::vector<double> v;
    for (int i = 0; i < 3; ++i) {
      const std::string name = std::string(1, static_cast<char>('A' + i));
      const double x = number(csv, k + 1, "x_" + name + "_m");
      v.push_back(number(csv, k + 1, "v_" + name + "_m_s"));
      EXPECT_TRUE(core::testing_support::correctlyRounded(v.back(), impact.velocities[i])) << name;
      EXPECT_TRUE(core::reference::closeOnScale(x, impact.positions[i], 2, 1e-15)) << name << " at " << x;
    }
    const auto [momentum, energy] = exactTotals({100, 1, kInf}, v);
    EXPECT_TRUE(core::testing_support::correctlyRounded(number(csv, k + 1, "p_total_kg_m_s"), momentum));
    EXPECT_TRUE(core::testing_support::correctlyRounded(number(csv, k + 1, "kinetic_total_J"), energy));
    EXPECT_NEAR(number(csv, k + 1, "kinetic_total_J"), 50.0, 1e-12);  // elastic, the wall at rest
  }
}

// A ring's impact across its seam (bodies D and A of four) is named as the reports name it,
// "DA", never after a fifth body; every other impact after its two neighbours. The bodies
// of each row's pair are the two whose velocities the row changes.
TEST_F(BagCsvTest, ClassTableNamesARingsSeamPairAsTheReportsDo) {
  using namespace class_table;
  core::Scene scene;
  scene.masses = {1, 2, 3, 4};
  scene.positions = {3.5, 2.5, 1.5, 0.5};
  scene.velocities = {1, -1, 0.5, -0.5};
  scene.ring = 4;
  recordRun(bag_path_, scene);
  const auto table = bagToClassTable(bag_path_, dir_ + "/ring.csv", 64);
  ASSERT_GT(table.rows, 20u);
  const Table csv = readCsv(dir_ + "/ring.csv");
  const std::set<std::string> pairs = {"AB", "BC", "CD", "DA"};
  const char* const names[] = {"A", "B", "C", "D"};
  int seams = 0;
  for (std::size_t row = 2; row < csv.size(); ++row) {
    SCOPED_TRACE("row " + std::to_string(row));
    const std::string pair = cell(csv, row, "pair");
    ASSERT_EQ(pairs.count(pair), 1u) << pair;
    seams += pair == "DA";
    for (int i = 0; i < 4; ++i) {  // the row changes the velocities of its pair's bodies only
      const std::string v = "v_" + std::string(names[i]) + "_m_s";
      const bool in_pair = pair.find(names[i]) != std::string::npos;
      EXPECT_EQ(number(csv, row, v) != number(csv, row - 1, v), in_pair) << v;
    }
  }
  EXPECT_GT(seams, 0);
}

// A table with a column per body is refused past max_bodies, and a bag whose summary counts
// impacts it has no events for says so; neither writes anything.
TEST_F(BagCsvTest, ClassTableRefusesTooManyBodiesAndSaysWhenEventsAreMissing) {
  using namespace class_table;
  {
    rosbag::Bag bag(bag_path_, rosbag::bagmode::Write);
    collision_lab::InitialConditions input;
    input.run_id = "wide";
    input.masses.assign(5, 1.0);
    input.positions = {4, 3, 2, 1, 0};
    input.velocities = {-1, 0, 0, 0, 0};
    bag.write("/collision_lab/initial_conditions", ros::Time(1, 0), input);
    collision_lab::RunSummary summary;
    summary.run_id = "wide";
    summary.collision_count = 4;
    bag.write("/collision_lab/run_summaries", ros::Time(1, 0), summary);
  }
  const auto refused = bagToClassTable(bag_path_, dir_ + "/wide.csv", 4);
  EXPECT_TRUE(refused.too_many_bodies);
  EXPECT_EQ(refused.bodies, 5u);
  EXPECT_FALSE(fs::exists(dir_ + "/wide.csv"));
  const auto start_only = bagToClassTable(bag_path_, dir_ + "/start.csv", 64);
  EXPECT_TRUE(start_only.events_missing);
  EXPECT_EQ(start_only.rows, 0u);
  EXPECT_FALSE(fs::exists(dir_ + "/start.csv")) << "refused before anything is written";
  EXPECT_THROW(bagToClassTable(dir_ + "/missing.bag", dir_ + "/x.csv", 64), collision_lab_ros::BagCsvError);
}
