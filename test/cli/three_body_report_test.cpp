// The three-body report keeps every key and value it printed before the rotation model
// became a model like the others (issue 32): the pi billiard (100, 1, inf), positions
// (2, 1, 0), velocities (-1, 0, 0), in JSON (full with first:3 events, predict, summary),
// CSV and the table. The expected keys are written out here, from the report before the
// change; keys may be added, none removed. The values are the physics' (shared/physics.md):
// 31 impacts, at most ceil(pi / alpha) = 32 with alpha = atan(1/10); the first impact at
// t = 1 s, x = 1 m gives A -99/101 and B -200/101 m/s; B then meets the wall at t = 1.505 s.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_process.h"

namespace {

using collision_lab_test::CliOutput;
using collision_lab_test::runCli;
using Json = nlohmann::json;

const std::vector<std::string> kPiBilliard = {"--masses", "100,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0"};

Json runJson(std::vector<std::string> extra) {
  std::vector<std::string> args = kPiBilliard;
  args.push_back("--format");
  args.push_back("json");
  args.insert(args.end(), extra.begin(), extra.end());
  const CliOutput out = runCli(args, COLLISION_LAB_SOURCE_DIR);
  EXPECT_EQ(out.exit_code, 0) << out.err;
  return Json::parse(out.out);
}

void expectKeys(const Json& object, const std::vector<std::string>& keys, const std::string& where) {
  ASSERT_TRUE(object.is_object()) << where;
  for (const std::string& key : keys) EXPECT_TRUE(object.contains(key)) << where << " lost the key " << key;
}

const std::vector<std::string> kSummaryKeys = {
    "collision_count", "truncated", "cancelled", "truncation_reason", "simulated", "final_velocities",
    "predicted_collision_count", "paper_predicted_collision_count", "max_possible_collision_count",
    "predicted_first_pair", "predicted_final_velocities", "theta", "alpha", "omega", "psi", "paper_phi_bc",
    "max_prediction_error", "energy_relative_drift", "momentum_relative_drift", "compute_time_s", "escalation",
    "model", "model_reason"};

const std::vector<std::string> kEventKeys = {
    "kind", "index", "pair", "pair_index", "bodies", "time", "position", "restitution", "first_moved", "last_moved",
    "cluster_impact", "pair_velocities_before", "pair_velocities_after", "pair_energy_transfer", "energy_lost",
    "positions", "velocities_before", "velocities_after", "energy_transfer", "kinetic_energy_after", "total_energy",
    "total_momentum", "predicted_velocities_after", "predicted_energy_transfer", "paper_velocities_after",
    "paper_energy_transfer"};

void expectRotationPrediction(const Json& summary) {
  EXPECT_EQ(summary["predicted_collision_count"], 31);
  EXPECT_TRUE(summary["paper_predicted_collision_count"].is_null());  // eq. (3.22) undefined with a wall
  EXPECT_EQ(summary["max_possible_collision_count"], 32);
  EXPECT_EQ(summary["predicted_first_pair"], "AB");
  const double alpha = std::atan(0.1);
  EXPECT_NEAR(summary["alpha"].get<double>(), alpha, 1e-15);
  EXPECT_NEAR(summary["theta"].get<double>(), 2 * alpha, 1e-15);
  EXPECT_NEAR(summary["omega"].get<double>(), M_PI - alpha, 1e-15);
  EXPECT_NEAR(summary["psi"].get<double>(), M_PI, 1e-15);
  EXPECT_TRUE(summary["paper_phi_bc"].is_null());
  EXPECT_EQ(summary["model"], "three_body_rotation");
  expectKeys(summary["escalation"], {"decisions", "high_precision", "exact_rational"}, "summary.escalation");
}

TEST(ThreeBodyReport, JsonWithEventsKeepsEveryKeyAndValue) {
  const Json report = runJson({"--events", "first:3"});
  expectKeys(report, {"scene", "options", "units", "events", "summary"}, "report");
  expectKeys(report["scene"], {"name", "description", "masses", "walls", "positions", "velocities"}, "scene");
  EXPECT_EQ(report["scene"]["walls"], Json::array({"C"}));
  expectKeys(report["options"], {"max_collisions", "events", "mode"}, "options");
  ASSERT_EQ(report["events"].size(), 3u);
  for (const Json& event : report["events"]) expectKeys(event, kEventKeys, "event");
  const Json& first = report["events"][0];
  EXPECT_EQ(first["pair"], "AB");
  EXPECT_EQ(first["time"], 1.0);
  EXPECT_EQ(first["position"], 1.0);
  EXPECT_DOUBLE_EQ(first["pair_velocities_after"][0].get<double>(), -99.0 / 101);
  EXPECT_DOUBLE_EQ(first["pair_velocities_after"][1].get<double>(), -200.0 / 101);
  EXPECT_DOUBLE_EQ(first["predicted_velocities_after"][1].get<double>(), -200.0 / 101);
  EXPECT_EQ(first["total_energy"], 50.0);
  EXPECT_EQ(first["total_momentum"], -100.0);
  const Json& second = report["events"][1];
  EXPECT_EQ(second["pair"], "BC");
  EXPECT_DOUBLE_EQ(second["time"].get<double>(), 1.505);
  EXPECT_DOUBLE_EQ(second["velocities_after"][1].get<double>(), 200.0 / 101);
  const Json& summary = report["summary"];
  expectKeys(summary, kSummaryKeys, "summary");
  EXPECT_EQ(summary["collision_count"], 31);
  EXPECT_EQ(summary["simulated"], true);
  EXPECT_EQ(summary["truncated"], false);
  EXPECT_EQ(summary["escalation"]["decisions"], 32);  // one per impact and the final one
  expectRotationPrediction(summary);
}

TEST(ThreeBodyReport, JsonPredictAndSummaryModesKeepEveryKey) {
  for (const char* mode : {"predict", "summary"}) {
    const Json report = runJson({"--mode", mode});
    SCOPED_TRACE(mode);
    EXPECT_TRUE(report["events"].empty());
    expectKeys(report["summary"], kSummaryKeys, "summary");
    EXPECT_EQ(report["summary"]["collision_count"], 31);
    EXPECT_EQ(report["summary"]["simulated"], std::string(mode) == "summary");
    expectRotationPrediction(report["summary"]);
  }
}

TEST(ThreeBodyReport, CsvAndTableKeepTheirFields) {
  std::vector<std::string> args = kPiBilliard;
  for (const char* extra : {"--format", "csv", "--events", "first:3"}) args.push_back(extra);
  const CliOutput csv = runCli(args, COLLISION_LAB_SOURCE_DIR);
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  EXPECT_NE(csv.out.find("kind,index,pair,pair_index,bodies,time_s,position_m,restitution,first_moved,last_moved,"
                         "cluster_impact,pair_v_before_right_m_s,pair_v_before_left_m_s,pair_v_after_right_m_s,"
                         "pair_v_after_left_m_s,pair_energy_transfer_right_J,pair_energy_transfer_left_J,energy_lost_J,"
                         "positions_m,velocities_before_m_s,velocities_after_m_s,energy_transfer_J,"
                         "kinetic_energy_after_J,total_energy_J,total_momentum_kg_m_s,predicted_velocities_after_m_s,"
                         "predicted_energy_transfer_J,paper_velocities_after_m_s,paper_energy_transfer_J\n"),
            std::string::npos);
  for (const char* line : {"# summary.collision_count,31\n", "# summary.predicted_collision_count,31\n",
                           "# summary.max_possible_collision_count,32\n", "# summary.predicted_first_pair,AB\n",
                           "# summary.paper_predicted_collision_count,\n", "# summary.escalation.decisions,32\n",
                           "# summary.model,three_body_rotation\n"}) {
    EXPECT_NE(csv.out.find(line), std::string::npos) << line;
  }
  args = kPiBilliard;
  for (const char* extra : {"--mode", "summary"}) args.push_back(extra);
  const CliOutput table = runCli(args, COLLISION_LAB_SOURCE_DIR);
  ASSERT_EQ(table.exit_code, 0) << table.err;
  for (const char* text : {"collisions                                    31                    31   eq. 3.22: undefined",
                           "most possible collisions                           32 = ceil(pi/alpha)",
                           "first pair                                                          AB",
                           "angles [rad]: alpha 0.09966865249, theta = 2 alpha 0.199337305",
                           "model: three_body_rotation - "}) {
    EXPECT_NE(table.out.find(text), std::string::npos) << text << "\nin\n" << table.out;
  }
}

}  // namespace
