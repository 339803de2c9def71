// collision_lab_cli --temperature-csv (issue 21), run as a user runs it. Expected values are
// derived by hand (in the comments) or from conservation laws computed here with the test's
// own sums; none shares code with the program.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_json.h"
#include "cli_process.h"

namespace {

using namespace collision_lab_test;  // run, runJson, kPresets, Json

/// A unique temporary folder, removed with what it holds when the object goes.
class TempDir {
 public:
  TempDir() {
    char pattern[] = "/tmp/collision_lab_temperature_XXXXXX";
    if (mkdtemp(pattern) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

struct Row {
  std::uint64_t impacts = 0;
  double time = 0.0, temperature = 0.0;
};

/// The CSV's header, rows and `#` lines.
struct TemperatureCsv {
  std::vector<std::string> comments;
  std::string header;
  std::vector<Row> rows;
};

TemperatureCsv readCsv(const std::string& path) {
  TemperatureCsv csv;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) {
      csv.comments.push_back(line);
    } else if (csv.header.empty()) {
      csv.header = line;
    } else {
      Row row;
      char comma1 = 0, comma2 = 0;
      std::istringstream(line) >> row.impacts >> comma1 >> row.time >> comma2 >> row.temperature;
      EXPECT_EQ(comma1, ',');
      EXPECT_EQ(comma2, ',');
      csv.rows.push_back(row);
    }
  }
  return csv;
}

bool hasComment(const TemperatureCsv& csv, const std::string& start) {
  for (const std::string& c : csv.comments) {
    if (c.rfind(start, 0) == 0) return true;
  }
  return false;
}

TEST(TemperatureCsv, ASmallRunByHand) {
  // Equal masses of 1 kg at x = (2, 1, 0) m, v = (0, 0, 1) m/s, e = 1/2. Impact 1 (CB) at
  // t = 1 s leaves v = (0, 3/4, 1/4); impact 2 (BA) at t = 7/3 s leaves (9/16, 3/16, 1/4).
  // V = 1/3 m/s; T = sum (v - V)^2 / 3: 2/9 J, 7/72 J, 31/1152 J.
  const TempDir dir;
  const std::string path = dir.file("t.csv");
  const Json report = runJson({"--masses", "1,1,1", "--positions", "2,1,0", "--velocities", "0,0,1",
                               "--restitution", "0.5", "--events", "none", "--temperature-csv", path});
  const TemperatureCsv csv = readCsv(path);
  EXPECT_EQ(csv.header, "impacts,time_s,temperature_J");
  EXPECT_TRUE(hasComment(csv, "# granular temperature T = (1/N) sum m_i (v_i - V)^2"));
  const std::uint64_t impacts = report.at("summary").at("collision_count");
  ASSERT_EQ(csv.rows.size(), impacts + 1);  // N = 3: every impact, and the start
  ASSERT_GE(csv.rows.size(), 3u);
  EXPECT_EQ(csv.rows[0].impacts, 0u);
  EXPECT_NEAR(csv.rows[0].temperature, 2.0 / 9, 1e-15);
  EXPECT_NEAR(csv.rows[1].time, 1.0, 1e-15);
  EXPECT_NEAR(csv.rows[1].temperature, 7.0 / 72, 1e-15);
  EXPECT_EQ(csv.rows[2].impacts, 2u);
  EXPECT_NEAR(csv.rows[2].time, 7.0 / 3, 1e-15);
  EXPECT_NEAR(csv.rows[2].temperature, 31.0 / 1152, 1e-15);
  EXPECT_TRUE(hasComment(csv, "# haff_fit,tau_s,"));
  EXPECT_TRUE(report.at("events").empty());  // --events none still holds for the report
}

TEST(TemperatureCsv, ThreeElasticBodiesKeepTheirTemperature) {
  // The paper's path (equal_masses: m = 1 kg, v = (-1, 0, 1) m/s, 3 collisions): V = 0 and
  // T = (1 + 0 + 1)/3 = 2/3 J before and after each elastic collision of equal masses.
  const TempDir dir;
  const std::string path = dir.file("t.csv");
  runJson({"--name", "equal_masses", "--events", "none", "--temperature-csv", path});
  const TemperatureCsv csv = readCsv(path);
  ASSERT_EQ(csv.rows.size(), 4u);
  for (const Row& row : csv.rows) EXPECT_NEAR(row.temperature, 2.0 / 3, 1e-15);
  EXPECT_EQ(csv.rows.back().impacts, 3u);
  EXPECT_DOUBLE_EQ(csv.rows.back().time, 2.0);
}

TEST(TemperatureCsv, AnElasticGasWithoutWallsKeepsTAndIsDecimated) {
  // gas_1000 is elastic and has no wall: kinetic energy E and momentum P are conserved, so
  // T = (2E - P^2/M)/N is too. The start's T from config/gas_1000.csv by this test's own sums;
  // N = 1000 bodies: a row every 1000/8 = 125 impacts, and the last impact's.
  std::ifstream bodies(COLLISION_LAB_SOURCE_DIR "/config/gas_1000.csv");
  std::string line;
  std::getline(bodies, line);
  std::vector<double> m, v;
  while (std::getline(bodies, line)) {
    double mass = 0, x = 0, vel = 0;
    char c1 = 0, c2 = 0;
    std::istringstream(line) >> mass >> c1 >> x >> c2 >> vel;
    m.push_back(mass);
    v.push_back(vel);
  }
  ASSERT_EQ(m.size(), 1000u);
  const auto temperatureOf = [&m](const std::vector<double>& vel) {
    double mass = 0, p = 0;
    for (std::size_t i = 0; i < m.size(); ++i) mass += m[i], p += m[i] * vel[i];
    double sum = 0;
    for (std::size_t i = 0; i < m.size(); ++i) sum += m[i] * (vel[i] - p / mass) * (vel[i] - p / mass);
    return sum / static_cast<double>(m.size());
  };
  const double t0 = temperatureOf(v);
  const TempDir dir;
  const std::string path = dir.file("t.csv");
  const Json report = runJson({"--name", "gas_1000", "--events", "none", "--temperature-csv", path});
  const TemperatureCsv csv = readCsv(path);
  const std::uint64_t impacts = report.at("summary").at("collision_count");
  ASSERT_GT(impacts, 1000u);
  EXPECT_EQ(csv.rows.size(), 1 + impacts / 125 + (impacts % 125 != 0));
  for (std::size_t k = 1; k + 1 < csv.rows.size(); ++k) ASSERT_EQ(csv.rows[k].impacts, 125 * k);
  EXPECT_EQ(csv.rows.back().impacts, impacts);
  for (const Row& row : csv.rows) ASSERT_NEAR(row.temperature, t0, 1e-12 * t0);
  EXPECT_NEAR(csv.rows.back().temperature, temperatureOf(doubles(report.at("summary").at("final_velocities"))),
              1e-13 * t0);
}

TEST(TemperatureCsv, RejectsWhatItCannotWrite) {
  const TempDir dir;
  const CliOutput all = run({"--scenario", kPresets, "--temperature-csv", dir.file("t.csv")});
  EXPECT_EQ(all.exit_code, 2);
  EXPECT_NE(all.err.find("invalid temperature-csv (USAGE)"), std::string::npos) << all.err;
  const CliOutput summary = run({"--name", "equal_masses", "--mode", "summary", "--temperature-csv", dir.file("t.csv")});
  EXPECT_EQ(summary.exit_code, 2);
  EXPECT_NE(summary.err.find("invalid temperature-csv (INVALID_OPTION)"), std::string::npos) << summary.err;
  const CliOutput folder = run({"--name", "equal_masses", "--temperature-csv", dir.file("no/such/folder.csv")});
  EXPECT_EQ(folder.exit_code, 2);
  EXPECT_NE(folder.err.find("cannot open"), std::string::npos) << folder.err;
  EXPECT_EQ(folder.out, "");  // rejected before any report
}

}  // namespace
