// collision_lab_cli lists each inelastic collapse among the events, in order, in every
// format. Expected values: the exact rational reference of the core's tests
// (test/core/nbody/reference.h, which steps through a collapse's impacts without resolving
// it, so its impact times approach the collapse time) and numbers derived by hand below.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "cli_json.h"
#include "cli_process.h"
#include "reference.h"

namespace {

using namespace collision_lab_test;  // run, runJson, runPreset, doubles, Json, kPresets
using collision_lab::core::reference::Rational;

/// The four-body scene: A, B, C as collapse_equal shifted by 1 m (collapse at 3.5 s), and D
/// far to the left, moving right. Its events: 8 impacts, the collapse, then D meets the
/// cluster (computed by hand in CollapseComesBeforeTheClusterImpact).
const std::vector<std::string> kFourBodies = {"--masses", "1,1,1,1", "--positions", "3,2,1,-10",
                                              "--velocities", "-1,0,0,0.5", "--restitution", "0.05,0.05,0.5"};

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& extra) {
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

/// The event rows of a CSV report (comment lines dropped), each split at the commas.
std::vector<std::vector<std::string>> csvRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells(1);
    for (char c : line) {
      if (c == ',') {
        cells.emplace_back();
      } else {
        cells.back() += c;
      }
    }
    rows.push_back(cells);
  }
  return rows;
}

void expectImpacts(const Json& events, std::size_t count) {
  for (std::size_t k = 0; k < count; ++k) {
    EXPECT_EQ(events.at(k).at("kind"), "impact") << k;
    EXPECT_EQ(events.at(k).at("index"), k + 1) << k;
  }
}

// Three equal masses from x = (2, 1, 0) m, v = (-1, 0, 0) m/s, e = 0.05 < r_c: the reference's
// exact impact times converge geometrically (about a factor 10 per impact) to the collapse
// time. With e = 1/20 exactly the limit is 3.5 s (exact rationals, Python fractions); the
// double 0.05 is a little larger, and the limit for it is 3.5 s + 5.05e-17 s. The bodies meet
// at the centre of mass, x_cm(t) = 1 - t/3 = -1/6 m, and move on at its velocity -1/3 m/s.
TEST(CollapseCli, CollapseEqualListsEightImpactsThenTheCollapseAtTheLimit) {
  const collision_lab::core::reference::Run exact =
      collision_lab::core::reference::simulate(collision_lab::core::Scene{{1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.05}}, 60);
  ASSERT_EQ(exact.events.size(), 60u);
  ASSERT_TRUE(exact.truncated);
  Rational within(1);  // the last step of the exact times: the tail after it is far below a double's ulp
  for (int digit = 0; digit < 25; ++digit) within /= 10;
  EXPECT_LT(exact.events[59].time - exact.events[58].time, within);
  const double limit = static_cast<double>(exact.events.back().time);
  EXPECT_NEAR(limit, 3.5, 1e-15);

  const Json doc = runPreset("collapse_equal", {"--events", "all"});
  const Json& events = doc.at("events");
  ASSERT_EQ(events.size(), 9u);
  expectImpacts(events, 8);
  for (std::size_t k = 0; k < 8; ++k) {
    EXPECT_EQ(events[k].at("pair_index"), exact.events[k].pair) << k;
    const double t = static_cast<double>(exact.events[k].time);
    EXPECT_NEAR(events[k].at("time").get<double>(), t, 4e-16 * t) << k;
  }
  const Json& collapse = events[8];
  EXPECT_EQ(collapse.at("kind"), "collapse");
  EXPECT_EQ(collapse.at("index"), 8);  // not a collision: the number of impacts before it
  EXPECT_EQ(collapse.at("bodies"), (Json{"A", "B", "C"}));
  EXPECT_EQ(collapse.at("first_moved"), 0);
  EXPECT_EQ(collapse.at("last_moved"), 2);
  EXPECT_NEAR(collapse.at("time").get<double>(), limit, 4e-16 * limit);
  EXPECT_NEAR(collapse.at("position").get<double>(), -1.0 / 6, 1e-15);
  for (const Json& v : collapse.at("pair_velocities_after")) EXPECT_NEAR(v.get<double>(), -1.0 / 3, 1e-15);
  // The full state: all three at the centre of mass, moving at -1/3 m/s; 3 (1/2) (1/9) J left.
  for (const Json& v : collapse.at("velocities_after")) EXPECT_NEAR(v.get<double>(), -1.0 / 3, 1e-15);
  for (const Json& x : collapse.at("positions")) EXPECT_NEAR(x.get<double>(), -1.0 / 6, 1e-15);
  EXPECT_NEAR(collapse.at("total_energy").get<double>(), 1.0 / 6, 1e-15);
  EXPECT_TRUE(collapse.at("predicted_velocities_after").is_null());
  EXPECT_EQ(doc.at("summary").at("collision_count"), 8);
  EXPECT_EQ(doc.at("summary").at("collapse_time"), collapse.at("time"));
}

TEST(CollapseCli, TableAndCsvShowTheCollapseAfterTheEighthImpact) {
  const CliOutput table = run({"--name", "collapse_equal", "--events", "all"});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  const std::size_t eighth = table.out.find("\n        8      BC ");
  const std::size_t row = table.out.find(
      "\n        -       -  collapse of bodies A..C at t = 3.5 s, x = -0.1666666667 m (the limit of infinitely many "
      "impacts, not counted), then all at -0.3333333333 m/s\n");
  const std::size_t summary = table.out.find("\nSummary\n");
  ASSERT_NE(eighth, std::string::npos) << table.out;
  ASSERT_NE(row, std::string::npos) << table.out;
  EXPECT_LT(eighth, row);
  EXPECT_EQ(table.out.find('\n', eighth + 1), row);  // the very next line
  EXPECT_LT(row, summary);

  const CliOutput csv = run({"--name", "collapse_equal", "--events", "all", "--format", "csv"});
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  const auto rows = csvRows(csv.out);
  ASSERT_EQ(rows.size(), 10u);  // the header, 8 impacts, the collapse
  const std::vector<std::string>& header = rows[0];
  ASSERT_EQ(header.size(), 29u);
  EXPECT_EQ(header[0], "kind");
  EXPECT_EQ(header[17], "energy_lost_J");
  for (std::size_t k = 1; k <= 8; ++k) {
    ASSERT_EQ(rows[k].size(), header.size()) << k;
    EXPECT_EQ(rows[k][0], "impact");
    EXPECT_EQ(rows[k][1], std::to_string(k));
  }
  const std::vector<std::string>& collapse = rows[9];
  ASSERT_EQ(collapse.size(), header.size());
  EXPECT_EQ(collapse[0], "collapse");
  EXPECT_EQ(collapse[1], "8");
  EXPECT_EQ(collapse[4], "A;B;C");
  EXPECT_EQ(collapse[5], "3.5");
  // The exact meeting point: e = 0.05 as a double is a little above 1/20, so the bodies meet
  // 5.0e-17 s after 3.5 s, at x = -0.1666666666666666835 m (exact rationals), whose nearest
  // double is this one (the engine's point, 1 - 3.5 / 3 in double, was an ulp away).
  EXPECT_EQ(collapse[6], "-0.16666666666666669");
  EXPECT_EQ(collapse[8], "0");
  EXPECT_EQ(collapse[9], "2");
  EXPECT_EQ(collapse[13], "-0.3333333333333333");
  EXPECT_EQ(collapse[14], "-0.3333333333333333");
  EXPECT_EQ(header[20], "velocities_after_m_s");
  EXPECT_EQ(collapse[20], "-0.3333333333333333;-0.3333333333333333;-0.3333333333333333");
  for (std::size_t c = 25; c < 29; ++c) EXPECT_EQ(collapse[c], "") << header[c];  // no model values
}

// By hand: A, B, C collapse as in collapse_equal, 1 m to the right: at t = 3.5 s at x_cm =
// 2 - 3.5/3 = 5/6 m, then the cluster (3 kg) moves at -1/3 m/s, x = 2 - t/3. D (1 kg) is at
// -10 + t/2; they meet when (1/2 + 1/3) t = 12: t = 14.4 s, x = -2.8 m. With e = 0.5:
// V = (3 (-1/3) + 1/2)/4 = -1/8 m/s, relative velocity -1/3 - 1/2 = -5/6 m/s; the cluster
// leaves at V + e (5/6) / 4 = -1/48 m/s and D at V - 3 e (5/6) / 4 = -7/16 m/s.
TEST(CollapseCli, CollapseComesBeforeTheClusterImpact) {
  const Json doc = runJson(kFourBodies);
  const Json& events = doc.at("events");
  ASSERT_EQ(events.size(), 10u);
  expectImpacts(events, 8);
  const Json& collapse = events[8];
  EXPECT_EQ(collapse.at("kind"), "collapse");
  EXPECT_EQ(collapse.at("index"), 8);
  EXPECT_EQ(collapse.at("first_moved"), 0);
  EXPECT_EQ(collapse.at("last_moved"), 2);
  EXPECT_NEAR(collapse.at("time").get<double>(), 3.5, 4e-16 * 3.5);
  EXPECT_NEAR(collapse.at("position").get<double>(), 5.0 / 6, 1e-15);
  const Json& cluster = events[9];
  EXPECT_EQ(cluster.at("kind"), "impact");
  EXPECT_EQ(cluster.at("index"), 9);
  EXPECT_EQ(cluster.at("pair"), "CD");
  EXPECT_NEAR(cluster.at("time").get<double>(), 14.4, 1e-14);
  EXPECT_NEAR(cluster.at("position").get<double>(), -2.8, 1e-14);
  EXPECT_NEAR(cluster.at("pair_velocities_after")[0].get<double>(), -1.0 / 48, 1e-15);
  EXPECT_NEAR(cluster.at("pair_velocities_after")[1].get<double>(), -7.0 / 16, 1e-15);
  EXPECT_EQ(cluster.at("cluster_impact"), true);
  // The full state: the cluster A..C moved as one, D on its own.
  const std::vector<double> after = doubles(cluster.at("velocities_after"));
  ASSERT_EQ(after.size(), 4u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(after[i], -1.0 / 48, 1e-15) << i;
  EXPECT_NEAR(after[3], -7.0 / 16, 1e-15);
  EXPECT_EQ(doc.at("summary").at("collision_count"), 9);

  const CliOutput csv = run(with(kFourBodies, {"--format", "csv"}));
  const auto rows = csvRows(csv.out);
  ASSERT_EQ(rows.size(), 11u);
  EXPECT_EQ(rows[9][0], "collapse");
  EXPECT_EQ(rows[10][0], "impact");
  EXPECT_EQ((std::vector<std::string>(rows[10].begin() + 8, rows[10].begin() + 11)),
            (std::vector<std::string>{"0", "3", "true"}));  // the cluster A..C and D moved
}

// --events first:N counts impacts; a collapse is shown when it comes before impact N + 1.
TEST(CollapseCli, FirstNShowsACollapseThatComesBeforeImpactNPlusOne) {
  const auto kinds = [](const Json& doc) {
    std::vector<std::string> out;
    for (const Json& event : doc.at("events")) out.push_back(event.at("kind"));
    return out;
  };
  const std::vector<std::string> eight(8, "impact");
  std::vector<std::string> eight_then_collapse = eight;
  eight_then_collapse.push_back("collapse");
  EXPECT_EQ(kinds(runJson(with(kFourBodies, {"--events", "first:7"}))), std::vector<std::string>(7, "impact"));
  EXPECT_EQ(kinds(runJson(with(kFourBodies, {"--events", "first:8"}))), eight_then_collapse);
  std::vector<std::string> nine = eight_then_collapse;
  nine.push_back("impact");
  EXPECT_EQ(kinds(runJson(with(kFourBodies, {"--events", "first:9"}))), nine);
  EXPECT_TRUE(runJson(with(kFourBodies, {"--events", "none"})).at("events").empty());
  EXPECT_TRUE(runJson(with(kFourBodies, {"--events", "first:0"})).at("events").empty());
}

// The preset cluster_collapse_5 (issue 21), by hand: A, B, C collapse as in collapse_equal,
// 2 m to the right (t = 3.5 s, x = 3 - 3.5/3 = 11/6 m), then move on as one cluster of 3 kg at
// -1/3 m/s, x = 11/6 - (t - 3.5)/3, and meet D (at rest at 1 m) at t = 6 s. From there the
// cluster, D and E are the three-body scene masses (3, 1, 1), x = (2, 1, 0) m,
// v = (-1/3, 0, 0) m/s shifted by 3 s, whose collapse time the exact reference gives. All five
// end at the centre-of-mass velocity -1/5 m/s; heat 1/2 - 5 (1/5)^2 / 2 = 0.4 J.
TEST(CollapseCli, ClusterCollapse5CollapsesTwiceIntoOneCluster) {
  const Json doc = runPreset("cluster_collapse_5", {"--events", "all"});
  std::vector<Json> collapses;
  for (const Json& event : doc.at("events")) {
    if (event.at("kind") == "collapse") collapses.push_back(event);
  }
  ASSERT_EQ(collapses.size(), 2u);
  EXPECT_EQ(collapses[0].at("first_moved"), 0);
  EXPECT_EQ(collapses[0].at("last_moved"), 2);
  EXPECT_EQ(collapses[0].at("bodies"), (Json{"A", "B", "C"}));
  EXPECT_NEAR(collapses[0].at("time").get<double>(), 3.5, 1e-15);
  EXPECT_NEAR(collapses[0].at("position").get<double>(), 11.0 / 6, 1e-15);
  EXPECT_EQ(collapses[1].at("first_moved"), 0);
  EXPECT_EQ(collapses[1].at("last_moved"), 4);
  EXPECT_EQ(collapses[1].at("bodies"), (Json{"A", "B", "C", "D", "E"}));
  const double second = 3 + collision_lab::core::reference::collapseTime(
                                collision_lab::core::Scene{{3, 1, 1}, {2, 1, 0}, {-1.0 / 3, 0, 0}, {0.05}});
  EXPECT_NEAR(collapses[1].at("time").get<double>(), second, 1e-12);
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("stop_reason"), "FINISHED");
  for (double v : doubles(summary.at("final_velocities"))) EXPECT_NEAR(v, -0.2, 1e-15);
  EXPECT_NEAR(summary.at("energy_lost").get<double>(), 0.4, 1e-15);
}

}  // namespace
