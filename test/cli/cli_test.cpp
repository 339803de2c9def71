// collision_lab_cli, run as a user runs it: a child process, its exit code and output.
// Expected counts and velocities are exact (shared/physics.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_json.h"
#include "cli_process.h"
#include "collision_lab/core/exact.h"

namespace {

using namespace collision_lab_test;  // run, runJson, runPreset, doubles, Json, kPresets

TEST(CliJson, EqualMassesGiveThreeCollisionsAndSwapOuterVelocities) {
  const Json doc = runJson({"--masses", "1,1,1", "--positions", "2,1,-1", "--velocities", "-1,0,1"});

  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("collision_count"), 3);
  EXPECT_EQ(summary.at("predicted_collision_count"), 3);
  EXPECT_EQ(summary.at("max_possible_collision_count"), 3);
  EXPECT_EQ(summary.at("truncated"), false);
  // Equal masses exchange velocities: exact in double.
  EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>{1, 0, -1}));
  EXPECT_NEAR(summary.at("alpha").get<double>(), M_PI / 3, 1e-15);
  EXPECT_NEAR(summary.at("theta").get<double>(), 2 * M_PI / 3, 1e-15);
  EXPECT_NEAR(summary.at("omega").get<double>(), 2 * M_PI / 3, 1e-15);
  for (const char* key : {"paper_predicted_collision_count", "max_prediction_error", "energy_relative_drift",
                          "momentum_relative_drift"}) {
    EXPECT_TRUE(summary.contains(key)) << key;
  }
  EXPECT_LE(summary.at("max_prediction_error").get<double>(), 1e-12);

  const Json& events = doc.at("events");
  ASSERT_EQ(events.size(), 3u);
  const std::vector<std::string> pairs = {"AB", "BC", "AB"};
  const std::vector<std::vector<double>> after = {{0, -1, 1}, {0, 1, -1}, {1, 0, -1}};
  for (std::size_t i = 0; i < 3; ++i) {
    const Json& event = events[i];
    EXPECT_EQ(event.at("index"), i + 1);
    EXPECT_EQ(event.at("pair"), pairs[i]);
    EXPECT_EQ(doubles(event.at("velocities_after")), after[i]);
    EXPECT_EQ(event.at("velocities_before").size(), 3u);
    EXPECT_EQ(event.at("positions").size(), 3u);
    EXPECT_EQ(event.at("energy_transfer").size(), 3u);
    EXPECT_EQ(event.at("paper_velocities_after").size(), 3u);
    EXPECT_EQ(event.at("paper_energy_transfer").size(), 3u);
    const std::vector<double> predicted = doubles(event.at("predicted_velocities_after"));
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(predicted[k], after[i][k], 1e-12);
  }
  // First impact: A (at rest after) hands its 0.5 J to B at t = 1 s, x = 1 m.
  EXPECT_EQ(events[0].at("time"), 1.0);
  EXPECT_EQ(events[0].at("position"), 1.0);
  EXPECT_EQ(doubles(events[0].at("energy_transfer")), (std::vector<double>{-0.5, 0.5, 0}));

  EXPECT_EQ(doc.at("units").at("energy"), "J");
  EXPECT_EQ(doc.at("units").at("velocity"), "m/s");
}

TEST(CliJson, PiDigitsByPresets) {
  EXPECT_EQ(runPreset("pi_digits_2", {"--events", "none"}).at("summary").at("collision_count"), 31);
  EXPECT_EQ(runPreset("pi_digits_3", {"--events", "none"}).at("summary").at("collision_count"), 314);
  const Json four = runPreset("pi_digits_4", {"--mode", "summary"}).at("summary");
  EXPECT_EQ(four.at("collision_count"), 3141);
  EXPECT_EQ(four.at("predicted_collision_count"), 3141);
}

TEST(CliJson, PiDigitsFromTheCommandLineWithAnInfiniteMass) {
  const Json doc = runJson({"--masses", "100,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0"});
  EXPECT_EQ(doc.at("summary").at("collision_count"), 31);
  EXPECT_EQ(doc.at("events").size(), 31u);
  // Infinities and NaN are null in JSON; the wall is named instead.
  EXPECT_TRUE(doc.at("scene").at("masses")[2].is_null());
  EXPECT_EQ(doc.at("scene").at("walls"), Json::array({"C"}));
  EXPECT_TRUE(doc.at("summary").at("momentum_relative_drift").is_null());
}

TEST(CliJson, TheRemovedPrecisionOptionFailsClearly) {
  // Every run is exact: --precision, which chose the working precision of the old
  // three-body simulator, was removed, and says so in one line (exit 2).
  for (const char* precision : {"double", "long_double", "high"}) {
    const CliOutput result = run({"--name", "pi_digits_3", "--events", "none", "--precision", precision});
    EXPECT_EQ(result.exit_code, 2) << precision;
    EXPECT_TRUE(result.out.empty()) << result.out;
    EXPECT_EQ(linesOf(result.err).size(), 1u) << result.err;
    EXPECT_NE(result.err.find("--precision was removed: every run is exact"), std::string::npos) << result.err;
  }
  // The JSON keeps its "precision" key, with the value it always had.
  const Json doc = runPreset("pi_digits_3", {"--events", "none"});
  EXPECT_EQ(doc.at("summary").at("collision_count"), 314);
  EXPECT_EQ(doc.at("options").at("precision"), "double");
}

TEST(CliJson, HardPresetsMatchExactArithmetic) {
  EXPECT_EQ(runPreset("kaleidoscopic").at("summary").at("collision_count"), 3);
  const Json grazing = runPreset("grazing").at("summary");
  EXPECT_EQ(grazing.at("collision_count"), 2);
  EXPECT_EQ(grazing.at("predicted_collision_count"), 2);
  const std::vector<double> v = doubles(grazing.at("final_velocities"));
  EXPECT_EQ(v[0], v[1]);  // ends with v_A = v_B exactly: the third contact grazes
  EXPECT_EQ(runPreset("no_collision").at("summary").at("collision_count"), 0);
  const Json bc_first = runPreset("bc_first");
  EXPECT_EQ(bc_first.at("summary").at("predicted_first_pair"), "BC");
  EXPECT_EQ(bc_first.at("events").at(0).at("pair"), "BC");
}

/// Hard scenes not in the presets: counts, pair sequences and final velocities printed by
/// the CLI must be those of exact rational arithmetic on the same doubles.
TEST(CliJson, AgreesWithExactArithmetic) {
  struct Case {
    std::string masses, positions, velocities;
  };
  const std::vector<Case> cases = {
      {"5,1,9", "2,1,0", "-1,0,0"},                              // kaleidoscopic, last contact grazes
      {"1,1,1", "1,0,-0.9999999999999999", "-1,0,1"},            // near-triple: BC first by one ulp
      {"0.3,0.7,0.11", "0.9,0.2,-0.4", "-0.3,0.1,0.25"},         // general
      {"inf,1,2", "3,1,0", "-0.7,0.1,0"},                        // moving wall at A
      {"1e-100,2e-100,3e-100", "2e-100,0,-1e-100", "-1e100,0,1e100"},  // extreme scale
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.masses + " / " + c.positions + " / " + c.velocities);
    const Json doc = runJson({"--masses", c.masses, "--positions", c.positions, "--velocities", c.velocities});
    collision_lab::core::Scene scene = collision_lab::core::threeBodies();
    for (int i = 0; i < 3; ++i) {
      scene.masses[i] = doc.at("scene").at("masses")[i].is_null() ? std::numeric_limits<double>::infinity()
                                                                  : doc.at("scene").at("masses")[i].get<double>();
      scene.positions[i] = doc.at("scene").at("positions")[i].get<double>();
      scene.velocities[i] = doc.at("scene").at("velocities")[i].get<double>();
    }
    const collision_lab::core::exact::MapWalk truth = collision_lab::core::exact::walkVelocityMaps(scene, 100000);
    ASSERT_FALSE(truth.truncated);
    EXPECT_EQ(doc.at("summary").at("collision_count"), truth.impact_count);
    EXPECT_EQ(doc.at("summary").at("predicted_collision_count"), truth.impact_count);
    const Json& events = doc.at("events");
    ASSERT_EQ(events.size(), truth.pairs.size());
    for (std::size_t i = 0; i < events.size(); ++i) {
      EXPECT_EQ(events[i].at("pair"), collision_lab::core::pairName(truth.pairs[i])) << "event " << i + 1;
    }
    const std::vector<double> final_velocities = doubles(doc.at("summary").at("final_velocities"));
    double scale = 0.0;
    for (double v : scene.velocities) scale = std::max(scale, std::fabs(v));
    for (int i = 0; i < 3; ++i) {
      const double exact = truth.final_velocities[i].convert_to<double>();
      EXPECT_NEAR(final_velocities[i], exact, 1e-12 * scale) << "particle " << i;
    }
  }
}

TEST(CliArguments, NegativeValuesRightAfterAFlag) {
  const Json doc = runJson({"--masses", "1,1,1", "--positions", "0,-1,-2.5", "--velocities", "-1,-.5,-0"});
  EXPECT_EQ(doubles(doc.at("scene").at("positions")), (std::vector<double>{0, -1, -2.5}));
  EXPECT_EQ(doubles(doc.at("scene").at("velocities")), (std::vector<double>{-1, -0.5, 0}));
  const Json with_equals = runJson({"--masses", "1,1,1", "--positions", "2,1,0", "--velocities=-1e-3,0,0"});
  EXPECT_EQ(with_equals.at("scene").at("velocities")[0], -1e-3);
  const Json scientific = runJson({"--velocities", "-2e+0,0,0", "--masses", "1,1,1", "--positions", "2,1,0"});
  EXPECT_EQ(scientific.at("scene").at("velocities")[0], -2.0);
}

TEST(CliJson, DoublesReadBackExactly) {
  const std::string text = "-0.30000000000000004";
  const Json doc = runJson({"--masses", "1,2,3", "--positions", "2,0,-2", "--velocities", text + ",0.1,0.7"});
  EXPECT_EQ(doc.at("scene").at("velocities")[0].get<double>(), std::strtod(text.c_str(), nullptr));
  EXPECT_EQ(doc.at("scene").at("velocities")[1].get<double>(), 0.1);
  // The last event's velocities are the summary's final velocities, bit for bit.
  EXPECT_EQ(doc.at("events").back().at("velocities_after"), doc.at("summary").at("final_velocities"));
}

TEST(CliEvents, NoneStillReportsThePrediction) {
  const Json doc = runPreset("pi_digits_3", {"--events", "none"});
  EXPECT_TRUE(doc.at("events").empty());
  EXPECT_EQ(doc.at("summary").at("predicted_collision_count"), 314);
}

TEST(CliEvents, FirstNKeepsTheFirstN) {
  const Json doc = runPreset("pi_digits_2", {"--events", "first:4"});
  ASSERT_EQ(doc.at("events").size(), 4u);
  EXPECT_EQ(doc.at("events")[3].at("index"), 4);
  EXPECT_EQ(doc.at("summary").at("collision_count"), 31);
}

TEST(CliEvents, CapTruncatesTheRunButNotThePrediction) {
  const Json doc = runPreset("pi_digits_3", {"--max-collisions", "100", "--simulate-to-cap", "--events", "none"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("collision_count"), 100);
  EXPECT_EQ(summary.at("truncated"), true);
  EXPECT_NE(summary.at("truncation_reason"), "");
  EXPECT_EQ(summary.at("predicted_collision_count"), 314);
}

TEST(CliModes, PredictOnlyDoesNotSimulate) {
  const Json doc = runPreset("pi_digits_5", {"--mode", "predict"});
  EXPECT_EQ(doc.at("summary").at("simulated"), false);
  EXPECT_EQ(doc.at("summary").at("predicted_collision_count"), 31415);
  EXPECT_TRUE(doc.at("events").empty());
}

TEST(CliTable, AlignedColumnsWithUnitsAndThePapersValuesLabelled) {
  const CliOutput result =
      run({"--masses", "1,1,1", "--positions", "2,1,-1", "--velocities", "-1,0,1"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* text : {"mass [kg]", "velocity [m/s]", "t [s]", "dE_A [J]", "dv paper [m/s]",
                           "paper, as printed", "eq. 3.22: 4", "3 = ceil(pi/alpha)"}) {
    EXPECT_NE(result.out.find(text), std::string::npos) << text;
  }
  // Event rows line up under the header: every row is as long as the header row.
  const std::vector<std::string> lines = linesOf(result.out);
  std::size_t header = 0;
  while (header < lines.size() && lines[header].find("pair") == std::string::npos) ++header;
  ASSERT_LT(header + 3, lines.size());
  for (std::size_t i = 1; i <= 3; ++i) EXPECT_EQ(lines[header + i].size(), lines[header].size());
  // The summary row puts the simulated count beside the prediction and the paper's.
  const auto row = std::find_if(lines.begin(), lines.end(),
                                [](const std::string& line) { return line.rfind("collisions ", 0) == 0; });
  ASSERT_NE(row, lines.end());
  std::istringstream words(*row);
  std::string label, simulated, predicted;
  words >> label >> simulated >> predicted;
  EXPECT_EQ(simulated, "3");
  EXPECT_EQ(predicted, "3");
  // Eq. (3.22) is even for every non-integer argument (physics.md, Errata 4).
  EXPECT_NE(row->find("eq. 3.22: 4"), std::string::npos);
}

TEST(CliTable, NamesTheTierItsEscalatedDecisionsAreTakenAt) {
  // Masses (3, 1, 0.5), v = (-1, 0, 0): psi / alpha is exactly 3, so after 2 collisions the
  // pair AB touches at exactly zero approach speed (physics.md). The summary comes from the
  // known count, which needs no decision (the engine that publishes the events would take
  // that one at 100 digits): the table names the tier with its count, 0.
  const std::vector<std::string> scene = {"--masses", "3,1,0.5", "--positions", "2,1,0", "--velocities", "-1,0,0"};
  const Json json = runJson(scene);
  ASSERT_EQ(json["summary"]["collision_count"], 2);
  ASSERT_EQ(json["summary"]["escalation"]["high_precision"].get<int>(), 0);
  const CliOutput table = run(scene);
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find(" taken at 100 digits or more, "), std::string::npos) << table.out;
  EXPECT_EQ(table.out.find("50 digits"), std::string::npos) << table.out;
}

TEST(CliJson, ARunGivesTheSameSummaryWithAndWithoutEvents) {
  // Events only watch: the summary, escalations included, is the same whether the run
  // publishes its events or not. (3, 1, 0.5) used to take 1 decision at 100 digits with
  // events (the engine decides the grazing contact) and none without (the known count).
  const std::vector<std::vector<std::string>> scenes = {
      {"--masses", "100,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0"},      // 31
      {"--masses", "10000,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0"},    // 314
      {"--masses", "3,1,0.5", "--positions", "2,1,0", "--velocities", "-1,0,0"},        // grazing
      {"--masses", "inf,1,3", "--positions", "2,1,0", "--velocities", "0.25,0,1"},      // a moving wall
      {"--masses", "1,1,1", "--positions", "2,1,0", "--velocities=-1,-5e-324,0"},       // stops out of range
  };
  for (const auto& scene : scenes) {
    std::vector<std::string> with_events = scene, without = scene;
    with_events.insert(with_events.end(), {"--events", "all"});
    without.insert(without.end(), {"--events", "none"});
    Json all = runJson(with_events), none = runJson(without);
    for (Json* doc : {&all, &none}) doc->at("summary").erase("compute_time_s");  // wall time
    EXPECT_EQ(all.at("summary").dump(), none.at("summary").dump()) << scene[1];
    EXPECT_EQ(all.at("events").size(), all.at("summary").at("collision_count").get<std::size_t>()) << scene[1];
  }
}

TEST(CliTerminal, ARunTakesTheSamePathInATerminalAsInAPipe) {
  // As above, AB touches at exactly zero approach speed after 2 collisions: the event
  // engine takes that decision at 100 digits, while a run that shows no event needs no
  // decision (the count is known). A terminal on stderr (the progress line) must not change
  // which: the run, its numbers and its escalations are the same in a terminal and a pipe.
  const std::vector<std::string> args = {"--masses", "3,1,0.5", "--positions", "2,1,0", "--velocities", "-1,0,0",
                                         "--events", "none", "--format", "json"};
  const CliOutput pipe = run(args);
  CliOutput terminal;
  try {
    terminal = runCliOnTerminal(args, COLLISION_LAB_SOURCE_DIR);
  } catch (const NoPseudoTerminal& e) {
    GTEST_SKIP() << e.what() << ": a real machine has them; a chroot may not";
  }
  ASSERT_EQ(pipe.exit_code, 0) << pipe.err;
  ASSERT_EQ(terminal.exit_code, 0) << terminal.err;
  Json in_pipe = Json::parse(pipe.out), in_terminal = Json::parse(terminal.out);
  EXPECT_EQ(in_pipe.at("summary").at("escalation").at("high_precision"), 0);
  for (Json* doc : {&in_pipe, &in_terminal}) doc->at("summary").erase("compute_time_s");  // wall time
  EXPECT_EQ(in_terminal.dump(2), in_pipe.dump(2));
}

TEST(CliCsv, HeaderOneRowPerEventAndSummaryComments) {
  const CliOutput result =
      run({"--masses", "1,1,1", "--positions", "2,1,-1", "--velocities", "-1,0,1", "--format", "csv"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  std::vector<std::string> rows;
  std::vector<std::string> comments;
  for (const std::string& line : linesOf(result.out)) (line.rfind("# ", 0) == 0 ? comments : rows).push_back(line);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].rfind("kind,index,pair,pair_index,bodies,time_s,position_m,", 0), 0u);
  EXPECT_EQ(rows[1].rfind("impact,1,AB,0,A;B,1,1,", 0), 0u);
  EXPECT_EQ(rows[3].rfind("impact,3,AB,0,A;B,2,1,", 0), 0u);
  const auto count_columns = [](const std::string& row) { return std::count(row.begin(), row.end(), ','); };
  for (const std::string& row : rows) EXPECT_EQ(count_columns(row), count_columns(rows[0]));
  EXPECT_NE(std::find(comments.begin(), comments.end(), "# summary.collision_count,3"), comments.end());
  EXPECT_NE(std::find(comments.begin(), comments.end(), "# summary.final_velocities,1,0,-1"), comments.end());
}

TEST(CliScenarioFile, ListNamesEveryPreset) {
  const CliOutput result = run({"--scenario", kPresets, "--list"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::vector<std::string> lines = linesOf(result.out);
  ASSERT_EQ(lines.size(), 24u);
  EXPECT_EQ(lines[0].rfind("equal_masses ", 0), 0u);
  EXPECT_EQ(lines[11].rfind("moving_wall ", 0), 0u);
  EXPECT_EQ(lines[20].rfind("gas_1000 ", 0), 0u);
  EXPECT_EQ(lines[22].rfind("granular_ring ", 0), 0u);
  EXPECT_EQ(lines[23].rfind("cluster_collapse_5 ", 0), 0u);
}

TEST(CliScenarioFile, WithoutANameRunsEveryScene) {
  const Json doc = runJson({"--scenario", kPresets});
  const Json& scenarios = doc.at("scenarios");
  ASSERT_EQ(scenarios.size(), 24u);
  const std::vector<std::pair<std::string, int>> expected = {
      {"equal_masses", 3}, {"no_collision", 0}, {"pi_digits_2", 31},  {"pi_digits_3", 314},
      {"pi_digits_4", 3141}, {"pi_digits_5", 31415}, {"kaleidoscopic", 3}, {"grazing", 2}};
  for (const auto& [name, count] : expected) {
    const auto entry = std::find_if(scenarios.begin(), scenarios.end(),
                                    [&](const Json& s) { return s.at("scene").at("name") == name; });
    ASSERT_NE(entry, scenarios.end()) << name;
    EXPECT_EQ(entry->at("summary").at("collision_count"), count) << name;
    EXPECT_EQ(entry->at("summary").at("predicted_collision_count"), count) << name;
    EXPECT_TRUE(entry->at("events").empty()) << name;  // a batch shows no events by default
    EXPECT_EQ(entry->at("summary").at("model"), name == "no_collision" ? "no_collisions" : "three_body_rotation");
  }
  // Scenes of other sizes sit in the same batch, each with its model (counts by hand:
  // shared/physics.md and config/scenarios.yaml).
  const std::vector<std::tuple<std::string, std::string, int>> nbody = {
      {"two_carts", "two_body", 1}, {"cradle_5", "ghosts", 4}, {"equal_masses_100", "ghosts", 2441}};
  for (const auto& [name, model, count] : nbody) {
    const auto entry = std::find_if(scenarios.begin(), scenarios.end(),
                                    [&](const Json& s) { return s.at("scene").at("name") == name; });
    ASSERT_NE(entry, scenarios.end()) << name;
    EXPECT_EQ(entry->at("summary").at("model"), model) << name;
    EXPECT_EQ(entry->at("summary").at("predicted_collision_count"), count) << name;
  }

  const CliOutput table = run({"--scenario", kPresets});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("pi_digits_5"), std::string::npos);
  EXPECT_NE(table.out.find("31415"), std::string::npos);
}

TEST(CliScenarioFile, NameAloneUsesThePackagePresets) {
  EXPECT_EQ(runJson({"--name", "pi_digits_2"}).at("summary").at("collision_count"), 31);
}

// The catkin install layout: <prefix>/lib/collision_lab/collision_lab_cli and
// <prefix>/share/collision_lab/config/scenarios.yaml. The install's own presets (here one
// that the source tree does not have) win over the source tree's, wherever the prefix is.
TEST(CliScenarioFile, AnInstalledCliReadsItsInstalledPresets) {
  namespace fs = std::filesystem;
  char pattern[] = "/tmp/collision_lab_install_XXXXXX";
  ASSERT_NE(mkdtemp(pattern), nullptr);
  const fs::path prefix = pattern;
  fs::create_directories(prefix / "lib/collision_lab");
  fs::create_directories(prefix / "share/collision_lab/config");
  const fs::path cli = prefix / "lib/collision_lab/collision_lab_cli";
  fs::copy_file(COLLISION_LAB_CLI_PATH, cli);
  fs::permissions(cli, fs::perms::owner_all);
  std::ofstream(prefix / "share/collision_lab/config/scenarios.yaml")
      << "installed_only:\n  description: \"only in the install\"\n"
         "  masses: [1, 1, 1]\n  positions: [2, 1, -1]\n  velocities: [-1, 0, 1]\n";
  const CliOutput listed = runProgram(cli.string(), {"--list", "--format", "csv"}, prefix.string());
  const CliOutput ran = runProgram(cli.string(), {"--name", "installed_only", "--format", "json"}, prefix.string());
  fs::remove_all(prefix);
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  EXPECT_EQ(listed.out, "name,description\ninstalled_only,only in the install\n");
  ASSERT_EQ(ran.exit_code, 0) << ran.err;
  EXPECT_EQ(Json::parse(ran.out).at("summary").at("collision_count"), 3);  // equal masses: 3 impacts
}

TEST(CliHelp, HelpGoesToStdoutAndExitsZero) {
  const CliOutput result = run({"--help"});
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_EQ(result.err, "");
  EXPECT_NE(result.out.find("--velocities"), std::string::npos);
}

TEST(CliOutputs, AnOutputThatCannotBeWrittenExitsNonZeroWithOneLine) {
  // /dev/full fails every write with ENOSPC: a table, a streamed JSON report of 31 events,
  // a batch, the list of presets and the help.
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--masses", "1,2,3", "--positions", "2,0,-2", "--velocities", "-1,0.5,1"},
        {"--name", "pi_digits_2", "--format", "json", "--events", "all"},
        {"--scenario", "config/scenarios.yaml", "--format", "csv"},
        {"--list"},
        {"--help"}}) {
    SCOPED_TRACE(args.front());
    const CliOutput result = runCli(args, COLLISION_LAB_SOURCE_DIR, "/dev/null", "/dev/full");
    EXPECT_EQ(result.exit_code, 3);
    EXPECT_EQ(result.err, "collision_lab_cli: cannot write to standard output; the output is incomplete\n");
  }
}

// ---------------------------------------------------------------------------------------
// Issue 14 as a user meets it: the issue's own commands and exact figures.

TEST(CliDoubleRange, ASubnormalSpeedOfTheOtherPairIsNoReasonToReject) {
  const Json doc = runJson({"--masses", "1,2,3", "--positions", "2,1,0", "--velocities", "-1,0,5e-324"});
  EXPECT_EQ(doc.at("summary").at("collision_count"), 2);
  const std::vector<double> v = doubles(doc.at("summary").at("final_velocities"));
  EXPECT_NEAR(v[0], 1.0 / 3, 1e-15);    // exact: 1/3
  EXPECT_NEAR(v[1], 2.0 / 15, 1e-15);   // 2/15
  EXPECT_NEAR(v[2], -8.0 / 15, 1e-15);  // -8/15 + 1e-324
  // The third impact comes at 2.02e323 s, beyond a double: counted, its time null (+inf).
  const Json three = runJson({"--masses", "1,1,1", "--positions", "2,1,0", "--velocities=-1,-5e-324,0"});
  EXPECT_EQ(three.at("summary").at("collision_count"), 3);
  EXPECT_EQ(three.at("summary").at("predicted_collision_count"), 3);
  EXPECT_EQ(three.at("summary").at("truncated"), false);
  EXPECT_EQ(three.at("summary").at("time_beyond_range"), true);
  ASSERT_EQ(three.at("events").size(), 3u);
  EXPECT_TRUE(three.at("events")[2].at("time").is_null());
}

TEST(CliDoubleRange, CountsPast2To53AreJsonIntegers) {
  const Json pi = runJson({"--masses", "1e32,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0", "--mode", "predict"})
                      .at("summary");
  ASSERT_TRUE(pi.at("predicted_collision_count").is_number_unsigned());
  EXPECT_EQ(pi.at("predicted_collision_count").get<std::uint64_t>(), 31415926535897933u);
  EXPECT_EQ(pi.at("max_possible_collision_count").get<std::uint64_t>(), 31415926535897934u);
  const Json heavy = runJson({"--masses", "1e36,1,1e36", "--positions", "2,1,0", "--velocities", "-1,0,0", "--mode",
                              "predict"})
                         .at("summary");
  EXPECT_EQ(heavy.at("predicted_collision_count").get<std::uint64_t>(), 2221441469079183170u);
  EXPECT_EQ(heavy.at("max_possible_collision_count").get<std::uint64_t>(), 2221441469079183171u);
  const Json inside = runJson({"--masses", "8e36,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0", "--mode",
                               "predict"})
                          .at("summary");
  EXPECT_EQ(inside.at("predicted_collision_count").get<std::uint64_t>(), 8885765876316732682u);
  // The table prints the integer too.
  const CliOutput table =
      run({"--masses", "1e36,1,1e36", "--positions", "2,1,0", "--velocities", "-1,0,0", "--mode", "predict"});
  EXPECT_NE(table.out.find("2221441469079183170"), std::string::npos) << table.out;
}

TEST(CliDoubleRange, PositionsOfImpactsShorterThanTheSmallestDouble) {
  const Json doc = runJson({"--masses", "1,2,3", "--positions", "3e-200,1e-200,0", "--velocities", "-1e150,0,1e150"});
  const Json& events = doc.at("events");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_NEAR(events[1].at("position").get<double>(), 1.5454545454545453e-200, 1e-209);
  EXPECT_NEAR(events[2].at("position").get<double>(), 1.2857142857142857e-200, 1e-209);
  EXPECT_EQ(events[2].at("time"), 0.0);  // 1e-350 s rounds to 0
}

TEST(CliDoubleRange, SubnormalApproachSpeed) {
  const Json doc = runJson({"--masses", "3e-300,1e-300,5e-301", "--positions", "2e-200,1e-200,0", "--velocities",
                            "-1e-300,0,0"});
  const Json& third = doc.at("events").at(2);
  EXPECT_NEAR(third.at("time").get<double>() / 4.8256457640483526e+116, 1.0, 1e-9);
  EXPECT_NEAR(third.at("position").get<double>() / -2.4128228820241767e-184, 1.0, 1e-9);
}

TEST(CliDoubleRange, AnImpactAfterTheLargestDoubleIsCountedWithANullTime) {
  // The fourth impact comes after the largest double, within the engine's working range: it
  // is counted with events and without, its time null (+inf) and the summary saying why.
  const std::vector<std::string> scene = {"--masses", "3,2,10", "--positions", "2,1,0", "--velocities=-1,0,5e-324"};
  std::vector<std::string> quiet_args = scene;
  quiet_args.insert(quiet_args.end(), {"--events", "none"});
  const Json all = runJson(scene);
  const Json quiet = runJson(quiet_args);
  EXPECT_EQ(all.at("summary").at("collision_count"), 4);
  EXPECT_EQ(quiet.at("summary").at("collision_count"), 4);
  EXPECT_EQ(all.at("summary").at("truncated"), false);
  EXPECT_EQ(all.at("summary").at("time_beyond_range"), true);
  ASSERT_EQ(all.at("events").size(), 4u);
  EXPECT_TRUE(all.at("events")[3].at("time").is_null());
  EXPECT_TRUE(all.at("events")[2].at("time").is_number());
  EXPECT_EQ(all.at("summary").at("final_velocities"), quiet.at("summary").at("final_velocities"));
  const CliOutput table = run(scene);
  EXPECT_NE(table.out.find("the last impacts come after t = 1.8e+308 s, the largest double"), std::string::npos)
      << table.out;
}

TEST(CliDoubleRange, ExtremeMassRatiosAreRun) {
  // The second impact comes after the largest double, beyond the engine's working range too:
  // counted all the same (the exact tier takes it), its time null (+inf), events or not.
  for (const char* events : {"all", "none"}) {
    const Json doc = runJson({"--masses", "1e-300,1,inf", "--positions", "2,1,0", "--velocities", "-1e-140,0,0",
                              "--events", events});
    EXPECT_EQ(doc.at("summary").at("collision_count"), 2) << events;
    EXPECT_EQ(doc.at("summary").at("predicted_collision_count"), 2);
    EXPECT_EQ(doc.at("summary").at("truncated"), false);
    EXPECT_EQ(doc.at("summary").at("time_beyond_range"), true);
    if (std::string(events) == "all") {
      ASSERT_EQ(doc.at("events").size(), 2u);
      EXPECT_TRUE(doc.at("events")[1].at("time").is_null());
      EXPECT_EQ(doc.at("events")[1].at("pair"), "BC");
    }
  }
}

// ---------------------------------------------------------------------------------------
// Issue 8, section 4: no output shows a negative zero.

TEST(CliOutputs, NeverPrintANegativeZero) {
  // -0 inputs, a resting wall, bodies at rest: every format.
  const std::regex negative_zero(R"((^|[^0-9.eE])-0(\.0*)?([^0-9.eE]|$))");
  for (const char* format : {"table", "json", "csv"}) {
    for (const std::vector<std::string>& scene :
         {std::vector<std::string>{"--masses", "100,1,inf", "--positions", "2,1,0", "--velocities=-1,-0,-0"},
          std::vector<std::string>{"--masses", "inf,1,1", "--positions", "2,1,0", "--velocities=-0,0.5,-1"}}) {
      std::vector<std::string> args = scene;
      args.insert(args.end(), {"--format", format});
      const CliOutput result = run(args);
      ASSERT_EQ(result.exit_code, 0) << result.err;
      for (const std::string& line : linesOf(result.out)) {
        EXPECT_FALSE(std::regex_search(line, negative_zero)) << format << ": " << line;
      }
    }
  }
}

}  // namespace
