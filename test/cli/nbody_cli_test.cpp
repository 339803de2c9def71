// collision_lab_cli on scenes of any size (issue 10), run as a user runs it. Expected values
// are derived by hand (in the comments), from conservation laws computed here, or from an
// inversion count by a plain O(N^2) loop: none shares code with the program.
#include <gtest/gtest.h>

#include <cmath>

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <boost/math/constants/constants.hpp>
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <nlohmann/json.hpp>

#include "cli_json.h"
#include "cli_process.h"

namespace {

using namespace collision_lab_test;  // run, runJson, runPreset, doubles, Json, kPresets

/// A unique temporary file holding `text`; removed when the object goes.
class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    char name[] = "/tmp/collision_lab_bodies_XXXXXX";
    const int fd = mkstemp(name);
    if (fd < 0) throw std::runtime_error("mkstemp failed");
    close(fd);
    path_ = name;
    std::ofstream(path_) << text;
  }
  ~TempFile() { unlink(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

struct Bodies {
  std::vector<double> masses, positions, velocities;
};

/// N bodies 1 m apart (x = N-1, ..., 0), velocities uniform in [-1, 1) from a seeded
/// generator, masses from `mass(i)`. Uses its own mapping of 53 random bits, so the
/// scene is the same with every standard library.
Bodies seededBodies(std::size_t n, std::uint64_t seed, const std::function<double(std::mt19937_64&)>& mass) {
  std::mt19937_64 rng(seed);
  const auto unit = [&] { return static_cast<double>(rng() >> 11) * 0x1p-53; };
  Bodies bodies;
  for (std::size_t i = 0; i < n; ++i) {
    bodies.masses.push_back(mass(rng));
    bodies.positions.push_back(static_cast<double>(n - 1 - i));
    bodies.velocities.push_back(2.0 * unit() - 1.0);
  }
  return bodies;
}

std::string bodiesCsv(const Bodies& bodies) {
  std::string text = "mass,position,velocity\n";
  char line[128];
  for (std::size_t i = 0; i < bodies.masses.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", bodies.masses[i], bodies.positions[i],
                  bodies.velocities[i]);
    text += line;
  }
  return text;
}

/// Pairs i < j with v_i < v_j, by the plain O(N^2) loop.
std::uint64_t inversionsByLoop(const std::vector<double>& v) {
  std::uint64_t count = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    for (std::size_t j = i + 1; j < v.size(); ++j) count += v[i] < v[j] ? 1 : 0;
  }
  return count;
}

// Four bodies with --restitution 0, by hand: m = (1, 2, 3, 4) kg, v = (-1, 0, 0, 1) m/s all
// meet and stick: momentum 3 kg m/s over 10 kg, 0.3 m/s; three impacts; heat 2.5 - 0.45 J.
TEST(NBodyCli, EveryPairStickingIsTheStickyModel) {
  const Json doc = runJson({"--masses", "1,2,3,4", "--positions", "3,2,1,0", "--velocities", "-1,0,0,1",
                            "--restitution", "0"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "sticky");
  EXPECT_EQ(summary.at("collision_count"), 3);
  EXPECT_EQ(summary.at("predicted_collision_count"), 3);
  EXPECT_EQ(summary.at("matches_prediction"), true);
  EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>(4, 0.3)));
}

// Two bodies at any mass ratio (issue 32): 1e-300 kg at -1 m/s bounces elastically off
// 1e300 kg at +1 m/s: v' = 2V - v rounds to (3, 1) m/s; they meet at t = 0.5 s, x = 0.5 m.
TEST(NBodyCli, TwoBodiesAtAnyMassRatioAreAccepted) {
  const Json doc = runJson({"--masses", "1e-300,1e300", "--positions", "1,0", "--velocities", "-1,1"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "two_body");
  EXPECT_EQ(summary.at("collision_count"), 1);
  EXPECT_EQ(summary.at("matches_prediction"), true);
  EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>{3, 1}));
  ASSERT_EQ(doc.at("events").size(), 1u);
  EXPECT_EQ(doc.at("events")[0].at("time"), 0.5);
  EXPECT_EQ(doc.at("events")[0].at("position"), 0.5);
}

// Two carts, by hand: m = (3, 1) kg, x = (1, 0) m, v = (-1, 1) m/s. They close at 2 m/s over
// 1 m: t = 0.5 s at x = 0.5 m. V = (3*(-1) + 1*1)/4 = -0.5 m/s, v' = 2V - v = (0, -2) m/s.
// A's energy goes from 1.5 J to 0, B's from 0.5 J to 2 J.
TEST(NBodyCli, TwoCartsMeetOnceAsComputedByHand) {
  for (const Json& doc : {runJson({"--masses", "3,1", "--positions", "1,0", "--velocities", "-1,1"}),
                          runPreset("two_carts")}) {
    const Json& summary = doc.at("summary");
    EXPECT_EQ(summary.at("model"), "two_body");
    EXPECT_FALSE(summary.at("model_reason").get<std::string>().empty());
    EXPECT_EQ(summary.at("collision_count"), 1);
    EXPECT_EQ(summary.at("predicted_collision_count"), 1);
    EXPECT_EQ(summary.at("matches_prediction"), true);
    EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>{0, -2}));
    EXPECT_EQ(summary.at("energy_lost"), 0.0);
    ASSERT_EQ(doc.at("events").size(), 1u);
    const Json& event = doc.at("events")[0];
    EXPECT_EQ(event.at("pair"), "AB");
    EXPECT_EQ(event.at("pair_index"), 0);
    EXPECT_EQ(event.at("time"), 0.5);
    EXPECT_EQ(event.at("position"), 0.5);
    EXPECT_EQ(doubles(event.at("pair_velocities_after")), (std::vector<double>{0, -2}));
    EXPECT_EQ(doubles(event.at("pair_energy_transfer")), (std::vector<double>{-1.5, 1.5}));
    EXPECT_EQ(event.at("energy_lost"), 0.0);
  }
}

// Restitution, by hand: equal carts at -1 and +1 m/s, V = 0. With e the relative velocity
// 2 m/s becomes -2e: v' = (e, -e). Energy 1 J before, e^2 J after: 1 - e^2 J lost.
TEST(NBodyCli, RestitutionScalesTheRelativeVelocityAndLosesEnergy) {
  for (const auto& [e, lost] : {std::pair{"0.5", 0.75}, std::pair{"0", 1.0}}) {
    const Json doc =
        runJson({"--masses", "1,1", "--positions", "1,0", "--velocities", "-1,1", "--restitution", e});
    const double ev = std::stod(e);
    const Json& summary = doc.at("summary");
    EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>{ev, -ev})) << e;
    EXPECT_DOUBLE_EQ(summary.at("energy_lost").get<double>(), lost) << e;
    ASSERT_EQ(doc.at("events").size(), 1u);
    EXPECT_DOUBLE_EQ(doc.at("events")[0].at("energy_lost").get<double>(), lost) << e;
    EXPECT_EQ(doubles(doc.at("scene").at("restitution")), std::vector<double>{ev});
  }
  // The preset: e = 0.8 on a relative speed of 2 m/s, so +-0.8 m/s after; heat 1 J - 0.64 J.
  const Json preset = runPreset("two_carts_inelastic");
  EXPECT_EQ(doubles(preset.at("summary").at("final_velocities")), (std::vector<double>{0.8, -0.8}));
  EXPECT_NEAR(preset.at("summary").at("energy_lost").get<double>(), 0.36, 1e-15);
}

// Issue 21, by hand (test/core/nbody/test_granular_models.cpp has the derivation): A at 2 m
// (-1 m/s) hits B (1 m) at t = 1; B then hits C (0 m) 4/3 s later, within t_c = 2 s, so that
// impact is elastic; A reaches B again at t = 5, dissipating. Velocities -0.0625, -0.1875, -0.75.
TEST(NBodyCli, TcModelMakesTheQuickReboundElastic) {
  const Json doc = runJson({"--masses", "1,1,1", "--positions", "2,1,0", "--velocities", "-1,0,0", "--restitution",
                            "0.5", "--restitution-model", "tc", "--tc", "2"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "event_engine");
  EXPECT_NE(summary.at("model_reason").get<std::string>().find("TC model"), std::string::npos);
  EXPECT_EQ(summary.at("collision_count"), 3);
  EXPECT_EQ(summary.at("rule_elastic_impacts"), 1);
  EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>{-0.0625, -0.1875, -0.75}));
  EXPECT_EQ(doc.at("scene").at("restitution_model"), "tc");
  EXPECT_EQ(doc.at("scene").at("tc"), 2.0);
  // A parameter without its model is a usage error.
  const CliOutput orphan = run({"--masses", "1,1", "--positions", "1,0", "--velocities", "-1,1", "--tc", "2"});
  EXPECT_EQ(orphan.exit_code, 2);
  EXPECT_NE(orphan.err.find("--tc belongs to --restitution-model tc"), std::string::npos) << orphan.err;
}

// The seam by hand: on a ring of 10 m, A (1 kg, 9 m, +1 m/s) meets B (3 kg, 1 m, -1 m/s)
// across the seam at t = 1 s, x = 0: B stops, A leaves at -2 m/s.
TEST(NBodyCli, RingSeamImpact) {
  const Json doc = runJson({"--masses", "1,3", "--positions", "9,1", "--velocities", "1,-1", "--ring", "10",
                            "--max-collisions", "1"});
  ASSERT_EQ(doc.at("events").size(), 1u);
  const Json& event = doc.at("events")[0];
  EXPECT_EQ(event.at("pair_index"), 1);
  EXPECT_EQ(event.at("pair"), "BA");  // B right, A left across the seam
  EXPECT_EQ(event.at("bodies"), (Json{"B", "A"}));
  EXPECT_EQ(event.at("time"), 1.0);
  EXPECT_EQ(event.at("position"), 0.0);
  EXPECT_EQ(doubles(event.at("pair_velocities_after")), (std::vector<double>{0, -2}));  // B, A
  EXPECT_EQ(doubles(event.at("velocities_after")), (std::vector<double>{-2, 0}));       // every body: A, B
  EXPECT_EQ(doubles(doc.at("summary").at("final_velocities")), (std::vector<double>{-2, 0}));
  EXPECT_EQ(doc.at("scene").at("ring"), 10.0);
  const CliOutput outside = run({"--masses", "1,3", "--positions", "11,1", "--velocities", "1,-1", "--ring", "10"});
  EXPECT_EQ(outside.exit_code, 2);
  EXPECT_NE(outside.err.find("(RING)"), std::string::npos) << outside.err;
}

// Body names past Z in the CSV's pair and bodies cells: 30 equal carts 1 m apart on a ring
// of 40 m, A (30 m) at +1 m/s and #29 (1 m) at -1 m/s, the rest at rest; by hand they meet
// first across the seam (11 m apart) at t = 5.5 s, x = 35.5 m, and swap velocities.
TEST(NBodyCli, CsvNamesTheSeamPairOfALargeRing) {
  std::string masses, positions, velocities;
  for (int i = 0; i < 30; ++i) {
    masses += std::string(i ? "," : "") + "1";
    positions += std::string(i ? "," : "") + std::to_string(30 - i);
    velocities += std::string(i ? "," : "") + (i == 0 ? "1" : i == 29 ? "-1" : "0");
  }
  const CliOutput out = run({"--masses", masses, "--positions", positions, "--velocities", velocities, "--ring", "40",
                             "--max-collisions", "1", "--format", "csv"});
  ASSERT_EQ(out.exit_code, 0) << out.err;
  EXPECT_NE(out.out.find("\nimpact,1,#29-A,29,#29;A,5.5,35.5,1,29,0,false,-1,1,1,-1,"), std::string::npos) << out.out;
}

// Newton's cradle with gaps (shared/physics.md): the pulse runs down the chain, one impact
// per pair at t = 1, 2, 3, 4 s at x = 3, 2, 1, 0 m; the last ball leaves at -1 m/s.
TEST(NBodyCli, CradleGivesFourImpactsAndTheLastBallLeaves) {
  const Json doc = runPreset("cradle_5");
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "ghosts");
  EXPECT_EQ(summary.at("collision_count"), 4);
  EXPECT_EQ(summary.at("predicted_collision_count"), 4);
  EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>{0, 0, 0, 0, -1}));
  const std::vector<std::string> pairs = {"AB", "BC", "CD", "DE"};
  ASSERT_EQ(doc.at("events").size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    const Json& event = doc.at("events")[k];
    EXPECT_EQ(event.at("pair"), pairs[k]);
    EXPECT_EQ(event.at("pair_index"), k);
    EXPECT_EQ(event.at("time"), k + 1.0);
    EXPECT_EQ(event.at("position"), 3.0 - k);
    EXPECT_EQ(doubles(event.at("pair_velocities_after")), (std::vector<double>{0, -1}));
  }
}

// A ball at x = 0.5 m between walls at 1 m and 0 m, at +1 m/s: impacts at t = 0.5, 1.5,
// 2.5, ... s, alternately on A and C. After an odd number it moves at -1 m/s, after an
// even number at +1 m/s. The run never ends by itself: it stops at the cap, truncated.
TEST(NBodyCli, BallBetweenWallsStopsAtTheCapMarkedTruncated) {
  const Json preset = runPreset("ball_between_walls", {"--events", "none"});
  const Json& summary = preset.at("summary");
  EXPECT_EQ(summary.at("model"), "two_walls_infinite");
  EXPECT_EQ(summary.at("predicted_infinite"), true);
  EXPECT_EQ(summary.at("truncated"), true);
  EXPECT_EQ(summary.at("stop_reason"), "CAP");
  EXPECT_EQ(summary.at("collision_count"), 1000);  // the preset's own cap
  EXPECT_EQ(summary.at("final_time"), 999.5);
  EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>{0, 1, 0}));

  const Json odd = runPreset("ball_between_walls", {"--max-collisions", "7", "--events", "none"});
  EXPECT_EQ(odd.at("summary").at("collision_count"), 7);
  EXPECT_EQ(odd.at("summary").at("final_time"), 6.5);
  EXPECT_EQ(doubles(odd.at("summary").at("final_velocities")), (std::vector<double>{0, -1, 0}));
}

// The granular box (1,000 bodies between two walls) is a box, not a ball between two walls:
// its model says so, and that the engine simulates its endless impacts up to the cap.
TEST(NBodyCli, AGranularBoxIsNamedABoxAndSimulatedToTheCap) {
  const Json preset = runPreset("granular_box_1000", {"--events", "none"});
  const Json& summary = preset.at("summary");
  EXPECT_EQ(summary.at("model"), "box_infinite");
  const std::string reason = summary.at("model_reason");
  EXPECT_NE(reason.find("a box: walls at both ends"), std::string::npos) << reason;
  EXPECT_NE(reason.find("confine the bodies between them"), std::string::npos) << reason;
  EXPECT_NE(reason.find("the exact event engine simulates them up to the run's cap"), std::string::npos) << reason;
  EXPECT_EQ(summary.at("predicted_infinite"), true);
  EXPECT_EQ(summary.at("truncated"), true);
  EXPECT_EQ(summary.at("stop_reason"), "CAP");
  EXPECT_EQ(summary.at("collision_count"), 1000);
}

// Three bodies with walls at both ends were rejected (TWO_WALLS) and are valid now: B at
// 1 m, +1 m/s, between walls at 2 m and 0 m hits A at t = 1 s, C at t = 3 s, A at t = 5 s.
TEST(NBodyCli, ThreeBodiesBetweenTwoWallsAreAnsweredNotRejected) {
  const Json doc = runJson(
      {"--masses", "inf,1,inf", "--positions", "2,1,0", "--velocities", "0,1,0", "--max-collisions", "3"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "two_walls_infinite");
  EXPECT_EQ(summary.at("truncated"), true);
  EXPECT_EQ(summary.at("collision_count"), 3);
  ASSERT_EQ(doc.at("events").size(), 3u);
  EXPECT_EQ(doc.at("events")[1].at("pair"), "BC");
  EXPECT_EQ(doc.at("events")[2].at("time"), 5.0);
  EXPECT_EQ(doubles(summary.at("final_velocities")), (std::vector<double>{0, -1, 0}));
  EXPECT_EQ(doc.at("scene").at("walls"), (Json{"A", "C"}));
}

// Equal masses: the count is the number of inversions (counted here by a plain loop) and
// the final velocities are the initial ones sorted, fastest rightward first. Without
// events the closed form answers alone; with events the engine runs and must agree.
TEST(NBodyCli, EqualMassesCountInversionsFromABodiesFile) {
  const Bodies bodies = seededBodies(1500, 20261123, [](std::mt19937_64&) { return 2.5; });
  const TempFile file(bodiesCsv(bodies));
  const std::uint64_t inversions = inversionsByLoop(bodies.velocities);
  std::vector<double> sorted = bodies.velocities;
  std::sort(sorted.begin(), sorted.end(), std::greater<double>());

  const Json closed = runJson({"--bodies", file.path(), "--events", "none"});
  EXPECT_EQ(closed.at("summary").at("model"), "ghosts");
  EXPECT_EQ(closed.at("summary").at("simulated"), false);
  EXPECT_EQ(closed.at("summary").at("predicted_collision_count"), inversions);
  EXPECT_EQ(doubles(closed.at("summary").at("final_velocities")), sorted);

  const Json simulated = runJson({"--bodies", file.path(), "--events", "first:0"});
  EXPECT_EQ(simulated.at("summary").at("simulated"), true);
  EXPECT_EQ(simulated.at("summary").at("collision_count"), inversions);
  EXPECT_EQ(simulated.at("summary").at("matches_prediction"), true);
  EXPECT_EQ(doubles(simulated.at("summary").at("final_velocities")), sorted);
  EXPECT_TRUE(simulated.at("events").empty());
}

TEST(NBodyCli, EqualMasses100PresetCountsItsInversions) {
  const Json doc = runPreset("equal_masses_100", {"--events", "none"});
  const std::vector<double> velocities = doubles(doc.at("scene").at("velocities"));
  ASSERT_EQ(velocities.size(), 100u);
  EXPECT_EQ(inversionsByLoop(velocities), 2441u);  // as the preset's description says
  EXPECT_EQ(doc.at("summary").at("predicted_collision_count"), 2441);
  EXPECT_EQ(runPreset("equal_masses_100", {"--events", "first:1"}).at("summary").at("collision_count"), 2441);
}

TEST(NBodyCli, BodiesFromStandardInputEqualBodiesFromAFile) {
  const TempFile file("mass,position,velocity\n1,4,-1\n1,3,0\n1,2,0\r\n# a comment\n\n1,1,0\n1,0,0\n");
  const Json from_file = runJson({"--bodies", file.path()});
  const Json from_stdin = runJson({"--bodies", "-"}, file.path());
  EXPECT_EQ(from_file.at("summary").at("collision_count"), 4);
  EXPECT_EQ(from_stdin.at("summary").at("collision_count"), 4);
  EXPECT_EQ(from_file.at("events"), from_stdin.at("events"));
  EXPECT_EQ(from_stdin.at("scene").at("bodies"), 5);
}

TEST(NBodyCli, BadBodiesFilesNameTheLine) {
  const TempFile no_header("1,4,-1\n");
  const CliOutput header = run({"--bodies", no_header.path()});
  EXPECT_EQ(header.exit_code, 2);
  EXPECT_NE(header.err.find("(BODIES_FILE)"), std::string::npos) << header.err;
  const TempFile two_values("mass,position,velocity\n1,4,-1\n1,3\n");
  const CliOutput count = run({"--bodies", two_values.path()});
  EXPECT_EQ(count.exit_code, 2);
  EXPECT_NE(count.err.find("invalid bodies:3 (WRONG_COUNT)"), std::string::npos) << count.err;
}

// 10^5 bodies of random masses: the engine runs up to the cap. Momentum and kinetic energy
// are recomputed here from the input and the printed final velocities.
TEST(NBodyCli, HundredThousandBodiesKeepMomentumAndEnergy) {
  const Bodies bodies = seededBodies(100000, 7, [](std::mt19937_64& rng) {
    return 1.0 + static_cast<double>(rng() >> 11) * 0x1p-53;
  });
  const TempFile file(bodiesCsv(bodies));
  const Json doc = runJson({"--bodies", file.path(), "--events", "none", "--max-collisions", "200000"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "event_engine");
  EXPECT_EQ(summary.at("count_formula").get<std::string>().rfind("none", 0), 0u);
  EXPECT_EQ(summary.at("collision_count"), 200000);
  EXPECT_EQ(summary.at("truncated"), true);
  const std::vector<double> after = doubles(summary.at("final_velocities"));
  ASSERT_EQ(after.size(), bodies.masses.size());
  double p0 = 0, p1 = 0, scale = 0, e0 = 0, e1 = 0;
  for (std::size_t i = 0; i < after.size(); ++i) {
    const double m = bodies.masses[i], v = bodies.velocities[i];
    p0 += m * v;
    p1 += m * after[i];
    scale += m * std::fabs(v);
    e0 += 0.5 * m * v * v;
    e1 += 0.5 * m * after[i] * after[i];
  }
  EXPECT_LT(std::fabs(p1 - p0) / scale, 1e-12);
  EXPECT_LT(std::fabs(e1 - e0) / e0, 1e-12);
}

// A(3 m, -1 m/s) hits B(2 m) at t = 1 s; B then reaches C(1 m) at t = 2 s, just as D(-1 m,
// +1 m/s) does: two impacts sharing C at one instant, whose outcome is undefined for point
// masses. The run ends there (not a rejected input: it happens later in the run).
TEST(NBodyCli, ALaterMultipleCollisionEndsTheRunNamingBodiesAndTime) {
  const Json doc = runJson({"--masses", "1,1,1,1", "--positions", "3,2,1,-1", "--velocities", "-1,0,0,1"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("stop_reason"), "MULTIPLE_COLLISION");
  EXPECT_EQ(summary.at("collision_count"), 1);
  EXPECT_EQ(summary.at("multiple_collision").at("bodies"), (Json{"B", "C", "D"}));
  EXPECT_EQ(summary.at("multiple_collision").at("time"), 2.0);
  EXPECT_TRUE(summary.at("matches_prediction").is_null());
}

TEST(NBodyCli, OneBodyAndBodiesMovingApartSimulateNothing) {
  for (const Json& doc : {runJson({"--masses", "2", "--positions", "0", "--velocities", "1"}),
                          runJson({"--masses", "2", "--positions", "0", "--velocities", "1", "--events", "none"})}) {
    EXPECT_EQ(doc.at("summary").at("model"), "no_collisions");
    EXPECT_EQ(doc.at("summary").at("predicted_collision_count"), 0);
    EXPECT_EQ(doc.at("summary").at("simulated"), false);
    EXPECT_EQ(doubles(doc.at("summary").at("final_velocities")), std::vector<double>{1});
  }
  // Four bodies, each pair separating (v_p >= v_p+1): nothing approaches.
  const Json apart = runJson({"--masses", "1,2,3,4", "--positions", "3,2,1,0", "--velocities", "2,1,1,-1"});
  EXPECT_EQ(apart.at("summary").at("model"), "no_collisions");
  EXPECT_EQ(apart.at("summary").at("simulated"), false);
  EXPECT_TRUE(apart.at("events").empty());
}

TEST(NBodyCli, UnequalLengthsNameTheThreeLengths) {
  const CliOutput result = run({"--masses", "1,1", "--positions", "1,0,-1", "--velocities", "0,0", "--format", "json"});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("masses 2, positions 3, velocities 2"), std::string::npos) << result.err;
  const Json error = Json::parse(result.out).at("error");
  EXPECT_EQ(error.at("reason"), "UNEQUAL_LENGTHS");
  EXPECT_EQ(error.at("code"), 9);
}

// Three elastic bodies keep the paper's report, now naming the model in every format.
TEST(NBodyCli, ThreeBodyReportsStateTheirModel) {
  const std::vector<std::string> scene = {"--masses", "1,1,1", "--positions", "2,1,-1", "--velocities", "-1,0,1"};
  const Json doc = runJson(scene);
  EXPECT_EQ(doc.at("summary").at("model"), "three_body_rotation");
  EXPECT_EQ(doc.at("summary").at("collision_count"), 3);
  EXPECT_EQ(doc.at("summary").at("max_possible_collision_count"), 3);  // the three-body keys stay
  std::vector<std::string> csv = scene;
  csv.insert(csv.end(), {"--format", "csv"});
  EXPECT_NE(run(csv).out.find("\n# summary.model,three_body_rotation\n"), std::string::npos);
  EXPECT_NE(run(scene).out.find("\nmodel: three_body_rotation - "), std::string::npos);
}

TEST(NBodyCli, TableOfManyBodiesShowsTheEndsAndSaysHowManyItLeavesOut) {
  std::string masses, positions, velocities;
  for (int i = 0; i < 30; ++i) {
    masses += (i ? "," : "") + std::to_string(1 + i % 3);
    positions += (i ? "," : "") + std::to_string(30 - i);
    velocities += std::string(i ? "," : "") + (i == 0 ? "-1" : "0");
  }
  const CliOutput table = run({"--masses", masses, "--positions", positions, "--velocities", velocities});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("(20 bodies left out here; JSON and CSV list every body)"), std::string::npos);
  EXPECT_NE(table.out.find(" #29 "), std::string::npos);
  EXPECT_NE(table.out.find("count formula: none"), std::string::npos);
  EXPECT_NE(table.out.find("model: event_engine - "), std::string::npos);
  const Json doc = runJson({"--masses", masses, "--positions", positions, "--velocities", velocities});
  EXPECT_EQ(doc.at("scene").at("masses").size(), 30u);
  EXPECT_EQ(doc.at("summary").at("final_velocities").size(), 30u);
}

// Restitution presets (issue 11), each against numbers derived by hand or in physics.md.

// A ball between two walls 1 m apart, e = 0.9, starting at 0.5 m moving at 1 m/s: after k
// bounces its speed is 0.9^k m/s, so bounce k + 1 comes 1 / 0.9^k s after bounce k.
TEST(NBodyCli, BouncingBallTimesFormAGeometricSeries) {
  const Json doc = runPreset("bouncing_ball_wall", {"--events", "all"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "two_walls_infinite");
  EXPECT_EQ(summary.at("truncated"), true);
  ASSERT_EQ(doc.at("events").size(), 50u);
  long double time = 0.5L, speed = 1.0L;
  for (std::size_t k = 0; k < 50; ++k) {
    const Json& event = doc.at("events")[k];
    EXPECT_NEAR(event.at("time").get<double>(), static_cast<double>(time), 1e-12 * static_cast<double>(time)) << k;
    speed *= 0.9L;
    time += 1.0L / speed;
  }
  // Heat: the kinetic energy 1/2 m v^2 lost over 50 bounces, 1/2 (1 - 0.81^50) J.
  EXPECT_NEAR(summary.at("energy_lost").get<double>(), 0.5 * (1 - std::pow(0.81, 50)), 1e-14);
}

// Three equal masses from x = (2, 1, 0) m, v = (-1, 0, 0) m/s (physics.md, Restitution):
// e = 0.072 gives 63 impacts; e = 0.05 < r_c = 7 - 4 sqrt 3 collapses, after which all three
// move at the centre-of-mass velocity -1/3 m/s, and 1/2 - 3/2 (1/3)^2 = 1/3 J is heat.
TEST(NBodyCli, NearCollapseAndCollapseOfThreeEqualMasses) {
  const Json near = runPreset("near_collapse").at("summary");
  EXPECT_EQ(near.at("model"), "three_body_spiral");
  EXPECT_EQ(near.at("predicted_collision_count"), 63);
  EXPECT_EQ(near.at("collapsed"), false);
  EXPECT_NEAR(near.at("critical_restitution").get<double>(), 7 - 4 * std::sqrt(3.0), 1e-15);

  const Json collapse = runPreset("collapse_equal", {"--events", "all"});
  const Json& summary = collapse.at("summary");
  EXPECT_EQ(summary.at("model"), "three_body_spiral");
  EXPECT_EQ(summary.at("collapsed"), true);
  EXPECT_EQ(summary.at("truncated"), false);
  for (double v : doubles(summary.at("final_velocities"))) EXPECT_NEAR(v, -1.0 / 3, 1e-15);
  EXPECT_NEAR(summary.at("energy_lost").get<double>(), 1.0 / 3, 1e-15);
  // The collapse comes after the last impact the engine performed (events[7]; events[8] is
  // the collapse itself), and the bodies meet at the centre of mass then: x_cm(t) = 1 - t / 3.
  const double t_c = summary.at("collapse_time").get<double>();
  EXPECT_GT(t_c, collapse.at("events").at(7).at("time").get<double>());
  EXPECT_NEAR(summary.at("collapse_position").get<double>(), 1 - t_c / 3, 1e-12);
  EXPECT_TRUE(summary.at("spiral_angle").is_null());  // real eigenvalues: no spiral
}

// ---- One scene, one run (issue 20): one validation, one answer field, one over-cap rule ----

/// The stderr line of a rejected scene.
std::string rejection(const std::vector<std::string>& args) {
  const CliOutput result = run(args);
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_EQ(result.out, "");
  return result.err;
}

// A wall in the middle has one reason whatever e and N: was INFINITE_MIDDLE_MASS for three
// elastic bodies and WALL_NOT_AT_END at e = 0.5 (failed before).
TEST(OneValidation, AWallInTheMiddleHasOneReasonWhateverEAndN) {
  const std::string expected =
      "collision_lab_cli: invalid masses[1] (WALL_NOT_AT_END): the mass of B is inf, but a wall may only be the "
      "first or the last body; give it a finite mass in kg\n";
  const std::vector<std::string> three = {"--masses", "1,inf,1", "--positions", "2,1,0", "--velocities", "-1,0,0"};
  EXPECT_EQ(rejection(three), expected);
  std::vector<std::string> inelastic = three;
  inelastic.insert(inelastic.end(), {"--restitution", "0.5"});
  EXPECT_EQ(rejection(inelastic), expected);
  EXPECT_EQ(rejection({"--masses", "1,inf,1,1", "--positions", "3,2,1,0", "--velocities", "-1,0,0,0"}), expected);
}

// Four equal masses whose first contact comes at t = 1 / 1e-310 s > 1.8e308 s: a clear
// OVERFLOW as for three (failed before: "internal error: Divide by zero", exit 1).
TEST(OneValidation, AFirstContactBeyondTheLargestDoubleIsOverflowForEveryN) {
  const std::string expected =
      "collision_lab_cli: invalid positions (OVERFLOW): the first contact, of A and B, would come at t = 1e+310 s, "
      "beyond the largest double (1.8e+308); a longer unit of time brings it into range\n";
  EXPECT_EQ(rejection({"--masses", "1,1,1", "--positions", "2,1,0", "--velocities", "-1e-310,0,0"}), expected);
  EXPECT_EQ(rejection({"--masses", "1,1,1,1", "--positions", "3,2,1,0", "--velocities", "-1e-310,0,0,0"}), expected);
}

// A body moving away from a wall: nothing collides, and the answer is 0, not null
// (failed before: collision_count null beside predicted_collision_count 0).
TEST(OneAnswer, NothingCollidingCountsZero) {
  const Json doc = runJson({"--masses", "inf,1", "--positions", "1,0", "--velocities", "0,-1"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "no_collisions");
  EXPECT_EQ(summary.at("simulated"), false);
  EXPECT_EQ(summary.at("collision_count"), 0);
  EXPECT_EQ(summary.at("predicted_collision_count"), 0);
}

// A file with a three-body scene and a cradle, every event asked for: each scene keeps its
// events (failed before: the cradle's 3 were lost). Equal masses 1 m apart, the right one at
// -1 m/s: the velocity passes on at t = 1, 2 (three bodies) and 1, 2, 3 s (four).
TEST(OneRun, ABatchKeepsTheEventsOfEveryScene) {
  const TempFile file(
      "three:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
      "cradle:\n  masses: [1, 1, 1, 1]\n  positions: [3, 2, 1, 0]\n  velocities: [-1, 0, 0, 0]\n");
  const Json doc = runJson({"--scenario", file.path(), "--events", "all"});
  const Json& scenes = doc.at("scenarios");
  ASSERT_EQ(scenes.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s) {
    const Json& events = scenes[s].at("events");
    ASSERT_EQ(events.size(), s + 2) << "scene " << s;
    for (std::size_t k = 0; k < events.size(); ++k) {
      EXPECT_EQ(events[k].at("time"), static_cast<double>(k + 1));
      EXPECT_EQ(events[k].at("pair_index"), k);
    }
    EXPECT_EQ(scenes[s].at("summary").at("collision_count"), s + 2);
  }
}

// The batch format does not depend on what the scenes are: a file of three-body scenes
// gives the same table columns and the same JSON entries as the same file with a four-body
// scene added (failed before: three bodies alone got another table, with final v_A, and JSON
// summaries without model).
TEST(OneRun, ABatchHasOneFormatWhateverItsScenes) {
  const std::string three =
      "pi31:\n  masses: [100, 1, .inf]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
      "equal:\n  masses: [1, 1, 1]\n  positions: [2, 1, -1]\n  velocities: [-1, 0, 1]\n";
  const TempFile only_three(three);
  const TempFile with_four(three + "four:\n  masses: [1, 2, 3, 4]\n  positions: [3, 2, 1, 0]\n  velocities: [-1, 0, 0, 1]\n");
  const CliOutput table_three = run({"--scenario", only_three.path()});
  const CliOutput table_four = run({"--scenario", with_four.path()});
  ASSERT_EQ(table_three.exit_code, 0) << table_three.err;
  ASSERT_EQ(table_four.exit_code, 0) << table_four.err;
  const std::vector<std::string> rows_three = linesOf(table_three.out), rows_four = linesOf(table_four.out);
  ASSERT_EQ(rows_three.size() + 1, rows_four.size());
  for (std::size_t k = 0; k < rows_three.size(); ++k) {
    EXPECT_EQ(rows_three[k], rows_four[k < 3 ? k : k + 1]) << "line " << k;  // row 3: the four-body scene
  }
  EXPECT_EQ(rows_four[3].rfind("four ", 0), 0u) << rows_four[3];
  const CliOutput csv_three = run({"--scenario", only_three.path(), "--format", "csv"});
  const CliOutput csv_four = run({"--scenario", with_four.path(), "--format", "csv"});
  const std::vector<std::string> csv_rows_three = linesOf(csv_three.out), csv_rows_four = linesOf(csv_four.out);
  ASSERT_EQ(csv_rows_three.size(), 3u);  // the header and a row per scene
  ASSERT_EQ(csv_rows_four.size(), 4u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(csv_rows_three[k], csv_rows_four[k]) << "CSV line " << k;
  // With every event kept too: each impact's model block is in the three-body entries' events.
  for (const char* events : {"none", "all"}) {
    SCOPED_TRACE(events);
    Json json_three = runJson({"--scenario", only_three.path(), "--events", events});
    Json json_four = runJson({"--scenario", with_four.path(), "--events", events});
    ASSERT_EQ(json_three.at("scenarios").size(), 2u);
    ASSERT_EQ(json_four.at("scenarios").size(), 3u);
    EXPECT_EQ(json_three.at("units"), json_four.at("units"));
    for (std::size_t k = 0; k < 2; ++k) {
      Json& a = json_three.at("scenarios")[k];
      Json& b = json_four.at("scenarios")[k];
      EXPECT_EQ(a.at("summary").at("model"), "three_body_rotation");
      const Json& shown = a.at("events");
      EXPECT_EQ(shown.size(), std::string(events) == "all" ? a.at("summary").at("collision_count").get<std::size_t>() : 0u);
      for (const Json& event : shown) EXPECT_TRUE(event.at("predicted_velocities_after").is_array()) << event;
      a.at("summary").erase("compute_time_s");  // wall time
      b.at("summary").erase("compute_time_s");
      EXPECT_EQ(a.dump(1), b.dump(1)) << "scene " << k;
    }
    EXPECT_TRUE(json_four.at("scenarios")[2].at("events").empty() ||
                json_four.at("scenarios")[2].at("events")[0].at("predicted_velocities_after").is_null());
  }
}

// 10,000 equal masses with seeded velocities: the ghosts model predicts the inversions,
// more than the default cap of 10^7, so the model answers at once, events asked for or not
// (the final velocities are the initial ones sorted, fastest on the right).
TEST(OverCap, TenThousandEqualMassesAreAnsweredByTheModel) {
  const Bodies bodies = seededBodies(10000, 20, [](std::mt19937_64&) { return 1.0; });
  const std::uint64_t inversions = inversionsByLoop(bodies.velocities);
  ASSERT_GT(inversions, 10000000u);
  std::vector<double> sorted = bodies.velocities;
  std::sort(sorted.begin(), sorted.end(), std::greater<double>());
  const TempFile file(bodiesCsv(bodies));
  const Json doc = runJson({"--bodies", file.path()});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "ghosts");
  EXPECT_EQ(summary.at("simulated"), false);
  EXPECT_EQ(summary.at("truncated"), false);
  EXPECT_EQ(summary.at("stop_reason"), "NOT_SIMULATED");
  EXPECT_EQ(summary.at("collision_count"), inversions);
  EXPECT_EQ(summary.at("predicted_collision_count"), inversions);
  EXPECT_EQ(doubles(summary.at("final_velocities")), sorted);
  EXPECT_TRUE(doc.at("events").empty());
}

// Galperin's billiard against a wall, m_B = 1 kg at rest and m_A = the double nearest 1e36
// kg at -1 m/s: N = floor(pi / alpha) collisions, alpha = atan(sqrt(m_B / m_A)) (the largest
// N with N alpha < pi; pi / alpha is irrational), about 3.14e18, here in 50 digits. Over the
// cap, the closed form answers at once (failed before: simulated up to the cap, 10^7 events).
// The end state, by physics: m_A v_A^2 + m_B v_B^2 = m_A (the wall at rest), and A moves
// away from B (v_A >= v_B).
TEST(OverCap, AThreeBodyRunOf3e18CollisionsIsAnsweredByTheModel) {
  using Float50 = boost::multiprecision::cpp_bin_float_50;
  const double m_a = 1e36;
  const Float50 alpha = atan(sqrt(Float50(1) / Float50(m_a)));
  const auto galperin = static_cast<std::uint64_t>(floor(boost::math::constants::pi<Float50>() / alpha));
  ASSERT_GT(galperin, 3000000000000000000u);
  const Json doc = runJson({"--masses", "1e36,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("model"), "three_body_rotation");
  EXPECT_EQ(summary.at("simulated"), false);
  EXPECT_EQ(summary.at("truncated"), false);
  EXPECT_EQ(summary.at("collision_count"), galperin);
  EXPECT_EQ(summary.at("predicted_collision_count"), galperin);
  EXPECT_TRUE(doc.at("events").empty());
  const std::vector<double> v = doubles(summary.at("final_velocities"));
  ASSERT_EQ(v.size(), 3u);
  EXPECT_NEAR(v[0] * v[0] + v[1] * v[1] / m_a, 1.0, 1e-12);
  EXPECT_GE(v[0], v[1]);
}

// --simulate-to-cap asks for the simulation: 100 equal masses with seeded velocities have
// more inversions (the plain loop counts them) than a cap of 100; asked, the engine
// simulates 100 of them and marks the run truncated.
TEST(OverCap, SimulateToCapSimulatesUpToTheCap) {
  const Bodies bodies = seededBodies(100, 21, [](std::mt19937_64&) { return 1.0; });
  const std::uint64_t inversions = inversionsByLoop(bodies.velocities);
  ASSERT_GT(inversions, 100u);
  const TempFile file(bodiesCsv(bodies));
  const std::vector<std::string> scene = {"--bodies", file.path(), "--max-collisions", "100", "--events", "none"};
  const Json answered = runJson(scene).at("summary");
  EXPECT_EQ(answered.at("simulated"), false);
  EXPECT_EQ(answered.at("collision_count"), inversions);
  std::vector<std::string> asked = scene;
  asked.push_back("--simulate-to-cap");
  const Json simulated = runJson(asked).at("summary");
  EXPECT_EQ(simulated.at("simulated"), true);
  EXPECT_EQ(simulated.at("collision_count"), 100);
  EXPECT_EQ(simulated.at("truncated"), true);
  EXPECT_EQ(simulated.at("predicted_collision_count"), inversions);
}

// Two walls: infinitely many impacts, said at once; 1,000 are simulated for display, not
// the cap of 10^7 (B between walls 2 m apart at 1 m/s hits a wall every 2 s from t = 1 s).
TEST(OverCap, TwoWallsAreSimulatedForDisplayOnly) {
  const Json doc = runJson({"--masses", "inf,1,inf", "--positions", "2,1,0", "--velocities", "0,1,0", "--events",
                            "none"});
  const Json& summary = doc.at("summary");
  EXPECT_EQ(summary.at("predicted_infinite"), true);
  EXPECT_EQ(summary.at("truncated"), true);
  EXPECT_EQ(summary.at("collision_count"), 1000);
  EXPECT_EQ(summary.at("final_time"), 1999.0);
}

// One event schema: a three-body event has pair_index as a four-body event does (failed
// before: "pair" only). (1, 1, 1) at (2, 1, 0) m, A at -1 m/s: AB at t = 1 s, BC at 2 s.
TEST(OneSchema, EveryEventHasItsPairIndex) {
  const Json three = runJson({"--masses", "1,1,1", "--positions", "2,1,0", "--velocities", "-1,0,0"});
  const Json four = runJson({"--masses", "1,1,1,1", "--positions", "3,2,1,0", "--velocities", "-1,0,0,0"});
  for (const Json* doc : {&three, &four}) {
    const Json& events = doc->at("events");
    ASSERT_GE(events.size(), 2u);
    EXPECT_EQ(events[0].at("pair"), "AB");
    EXPECT_EQ(events[0].at("pair_index"), 0);
    EXPECT_EQ(events[1].at("pair"), "BC");
    EXPECT_EQ(events[1].at("pair_index"), 1);
  }
}

// One batch CSV header whatever scenes a file holds (failed before: 15 columns for a file
// of three-body scenes, 7 otherwise).
TEST(OneSchema, TheBatchCsvHeaderIsTheSameWhateverTheScenes) {
  const std::string header = "scenario,bodies,model,collision_count,predicted_collision_count,truncated,energy_lost_J";
  const TempFile three("three:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n");
  const TempFile mixed(
      "three:\n  masses: [1, 1, 1]\n  positions: [2, 1, 0]\n  velocities: [-1, 0, 0]\n"
      "cradle:\n  masses: [1, 1, 1, 1]\n  positions: [3, 2, 1, 0]\n  velocities: [-1, 0, 0, 0]\n");
  for (const TempFile* file : {&three, &mixed}) {
    const CliOutput result = run({"--scenario", file->path(), "--format", "csv"});
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const std::vector<std::string> lines = linesOf(result.out);
    ASSERT_GE(lines.size(), 2u);
    EXPECT_EQ(lines[0], header);
    EXPECT_EQ(lines[1], "three,3,three_body_rotation,2,2,false,0");
  }
}

// One event schema (issue 20): a three-body scene (the rotation's path) and a four-body scene
// (the event engine's) give events with the same keys in the same order, and one CSV header.
// The full state is the bodies' state: the last event's velocities after are the summary's
// final velocities, each event starts where the one before left off, the pair's fields are
// the full state's entries pair_index and pair_index + 1, and the momentum of the full state
// is the initial one (no wall): -1 kg m/s for both scenes. Failed before: the four-body
// events had kind, bodies and energy_gained and the pair's velocities only, the three-body
// events the model's values and no kind; the CSV headers differed.
TEST(NBodyCli, EveryEventOfEverySceneHasTheOneSchemaAndTheFullState) {
  const std::vector<std::vector<std::string>> scenes = {
      {"--masses", "1,2,3", "--positions", "3,2,1", "--velocities", "-1,0,0", "--events", "all"},
      {"--masses", "1,2,3,4", "--positions", "3,2,1,0", "--velocities", "-1,0,0,0", "--events", "all"}};
  std::vector<std::vector<std::string>> keys;
  std::vector<std::string> headers;
  for (const auto& args : scenes) {
    SCOPED_TRACE(args[1]);
    const std::size_t n = args[1] == "1,2,3" ? 3 : 4;
    const Json doc = runJson(args);
    const Json& events = doc.at("events");
    ASSERT_GE(events.size(), 2u);
    std::vector<double> previous = doubles(doc.at("scene").at("velocities"));
    for (const Json& event : events) {
      std::vector<std::string> names;
      for (const auto& item : event.items()) names.push_back(item.key());
      if (keys.empty() || keys.back() != names) keys.push_back(names);
      EXPECT_EQ(event.at("kind"), "impact");
      const std::size_t p = event.at("pair_index").get<std::size_t>();
      const std::vector<double> before = doubles(event.at("velocities_before"));
      const std::vector<double> after = doubles(event.at("velocities_after"));
      const std::vector<double> transfer = doubles(event.at("energy_transfer"));
      ASSERT_EQ(after.size(), n);
      EXPECT_EQ(before, previous);
      previous = after;
      EXPECT_EQ(doubles(event.at("pair_velocities_before")), (std::vector<double>{before[p], before[p + 1]}));
      EXPECT_EQ(doubles(event.at("pair_velocities_after")), (std::vector<double>{after[p], after[p + 1]}));
      EXPECT_EQ(doubles(event.at("pair_energy_transfer")), (std::vector<double>{transfer[p], transfer[p + 1]}));
      EXPECT_NEAR(event.at("total_momentum").get<double>(), -1.0, 1e-14);
      EXPECT_EQ(event.at("predicted_velocities_after").is_null(), n != 3);  // the rotation's block
    }
    EXPECT_EQ(previous, doubles(doc.at("summary").at("final_velocities")));

    std::vector<std::string> csv_args = args;
    csv_args.insert(csv_args.end(), {"--format", "csv"});
    const CliOutput csv = run(csv_args);
    ASSERT_EQ(csv.exit_code, 0) << csv.err;
    std::istringstream lines(csv.out);
    std::string line;
    while (std::getline(lines, line) && line.rfind("#", 0) == 0) {
    }
    headers.push_back(line);
  }
  EXPECT_EQ(keys.size(), 1u) << "every event of both scenes has the same keys";
  ASSERT_EQ(headers.size(), 2u);
  EXPECT_EQ(headers[0], headers[1]);
  EXPECT_EQ(headers[0].rfind("kind,index,pair,pair_index,bodies,", 0), 0u) << headers[0];
}

// Above CollisionEvent::FULL_STATE_MAX_BODIES (64) bodies the full state's keys are absent
// (JSON) and its cells empty (CSV); the pair's fields still carry the event. By hand: 70
// equal masses 1 m apart, A (x = 69 m) at -1 m/s hits B at rest at t = 1 s, x = 68 m, and
// they swap velocities.
TEST(NBodyCli, AboveSixtyFourBodiesTheFullStateIsAbsentAndThePairCarriesTheEvent) {
  std::string masses = "1", positions = "69", velocities = "-1";
  for (int i = 68; i >= 0; --i) {
    masses += ",1";
    positions += "," + std::to_string(i);
    velocities += ",0";
  }
  const std::vector<std::string> args = {"--masses", masses, "--positions", positions, "--velocities", velocities,
                                         "--events", "first:1"};
  const Json doc = runJson(args);
  ASSERT_EQ(doc.at("events").size(), 1u);
  const Json& event = doc.at("events")[0];
  EXPECT_EQ(event.at("time"), 1.0);
  EXPECT_EQ(event.at("position"), 68.0);
  EXPECT_EQ(doubles(event.at("pair_velocities_after")), (std::vector<double>{0, -1}));
  for (const char* key : {"positions", "velocities_before", "velocities_after", "energy_transfer",
                          "kinetic_energy_after", "total_energy", "total_momentum", "predicted_velocities_after"}) {
    EXPECT_FALSE(event.contains(key)) << key;
  }
  std::vector<std::string> csv_args = args;
  csv_args.insert(csv_args.end(), {"--format", "csv"});
  const CliOutput csv = run(csv_args);
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  std::istringstream lines(csv.out);
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) {
    if (line.rfind("#", 0) != 0) rows.push_back(line);
  }
  ASSERT_EQ(rows.size(), 2u);
  // The pair's velocities after, energies gained and the heat, then 11 empty cells: the full
  // state (7) and the model's values (4).
  const std::string tail = ",0,-1,-0.5,0.5,0,,,,,,,,,,,";
  ASSERT_GE(rows[1].size(), tail.size());
  EXPECT_EQ(rows[1].substr(rows[1].size() - tail.size()), tail) << rows[1];
  EXPECT_EQ(std::count(rows[1].begin(), rows[1].end(), ','), std::count(rows[0].begin(), rows[0].end(), ','));
}

}  // namespace
