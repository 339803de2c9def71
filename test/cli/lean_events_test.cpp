// The lean event record of long runs (--full-state-every K, issue 34): impact 1 and every
// K-th impact carry every body's state, the others only their pair's; a reader that replaces
// the pair's velocities in the state it holds rebuilds every state of the full record.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cli_json.h"

namespace {

using namespace collision_lab_test;  // run, runJson, doubles, Json

/// Rebuilds every impact's velocities_after from the lean record and checks them, and every
/// other field the lean record keeps, against the full record of the same run.
void expectLeanRebuildsTheFull(const std::vector<std::string>& scene, std::uint64_t every) {
  std::vector<std::string> lean_args = scene;
  lean_args.insert(lean_args.end(), {"--full-state-every", std::to_string(every)});
  const Json full = runJson(scene);
  const Json lean = runJson(lean_args);
  EXPECT_EQ(lean["options"]["full_state_every"], every);
  EXPECT_FALSE(full["options"].contains("full_state_every"));
  EXPECT_EQ(lean["summary"], [&] {  // the run itself is the same
    Json s = full["summary"];
    s["compute_time_s"] = lean["summary"]["compute_time_s"];
    return s;
  }());
  const Json& events = full["events"];
  ASSERT_EQ(lean["events"].size(), events.size());
  ASSERT_GT(events.size(), 2 * every);
  std::vector<double> state;  // the reader's velocities [m/s]
  for (std::size_t k = 0; k < events.size(); ++k) {
    const Json& f = events[k];
    const Json& l = lean["events"][k];
    SCOPED_TRACE("event " + std::to_string(k + 1));
    for (const char* key : {"kind", "index", "pair", "pair_index", "time", "position", "first_moved", "last_moved",
                            "pair_velocities_before", "pair_velocities_after", "pair_energy_transfer",
                            "energy_lost"}) {
      EXPECT_EQ(l[key], f[key]) << key;
    }
    const std::uint64_t index = f["index"];
    const bool full_state = f["kind"] == "collapse" || index == 1 || index % every == 0;
    // A lean event leaves out the full state's keys (absent, not null).
    for (const char* key : {"positions", "velocities_before", "velocities_after", "energy_transfer",
                            "kinetic_energy_after", "total_energy", "total_momentum", "predicted_velocities_after",
                            "predicted_energy_transfer", "paper_velocities_after", "paper_energy_transfer"}) {
      EXPECT_EQ(l.contains(key), full_state) << key;
    }
    if (full_state) {
      EXPECT_EQ(l, f);
      state = doubles(l["velocities_after"]);
    } else {
      ASSERT_FALSE(state.empty());
      // The bodies the impact moved: first_moved..p at the right's velocity, the rest of
      // first_moved..last_moved at the left's (p + 1: body 0 across a ring's seam).
      const std::size_t p = l["pair_index"], first = l["first_moved"], last = l["last_moved"];
      const std::size_t left = (p + 1) % state.size();
      if (left == 0) {
        state[p] = l["pair_velocities_after"][0];
        state[0] = l["pair_velocities_after"][1];
      } else {
        for (std::size_t i = first; i <= last; ++i) state[i] = l["pair_velocities_after"][i <= p ? 0 : 1];
      }
    }
    EXPECT_EQ(state, doubles(f["velocities_after"]));
  }
}

TEST(LeanEvents, ThePiBilliardRebuildsFromEveryTenth) {
  expectLeanRebuildsTheFull({"--masses", "10000,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0"}, 10);
}

TEST(LeanEvents, FiveInelasticBodiesRebuildFromEveryFourth) {
  expectLeanRebuildsTheFull({"--masses", "3,1,2,1,4", "--positions", "4,3,2,1,0", "--velocities", "-1,0.5,0,-0.25,1",
                             "--restitution", "0.9"},
                            4);
}

TEST(LeanEvents, ARingRebuildsAcrossItsSeam) {
  expectLeanRebuildsTheFull({"--masses", "1,2,3,4", "--positions", "3.5,2.5,1.5,0.5", "--velocities", "1,-1,0.5,-0.5",
                             "--ring", "4", "--max-collisions", "60", "--simulate-to-cap"},
                            5);
}

/// The CSV row of impact `index` ("impact,<index>,...", without its line break).
std::string csvRow(const std::string& csv, int index) {
  const std::string start = "\nimpact," + std::to_string(index) + ",";
  const std::size_t at = csv.find(start);
  if (at == std::string::npos) return "";
  return csv.substr(at + 1, csv.find('\n', at + 1) - at - 1);
}

TEST(LeanEvents, CsvLeavesTheStateCellsEmpty) {
  const std::vector<std::string> scene = {"--masses", "100,1,inf", "--positions", "2,1,0", "--velocities", "-1,0,0",
                                          "--format", "csv"};
  std::vector<std::string> lean_args = scene;
  lean_args.insert(lean_args.end(), {"--full-state-every", "10"});
  const CliOutput full = run(scene), lean = run(lean_args);
  ASSERT_EQ(lean.exit_code, 0) << lean.err;
  EXPECT_NE(lean.out.find("# full_state_every,10\n"), std::string::npos);
  for (int index : {1, 2, 10, 11, 31}) {
    const std::string f = csvRow(full.out, index), l = csvRow(lean.out, index);
    ASSERT_FALSE(f.empty()) << index;
    if (index == 1 || index % 10 == 0) {
      EXPECT_EQ(l, f);
    } else {
      // The pair's 18 cells as the full row has them, then the 11 state and model cells empty.
      const std::string empty_state(11, ',');
      ASSERT_GT(l.size(), empty_state.size());
      EXPECT_EQ(l.substr(l.size() - empty_state.size()), empty_state) << l;
      EXPECT_EQ(f.compare(0, l.size() - empty_state.size(), l, 0, l.size() - empty_state.size()), 0) << f << "\n" << l;
    }
  }
}

TEST(LeanEvents, KMustBeAPositiveInteger) {
  for (const char* bad : {"0", "-3", "2.5", "ten"}) {
    const CliOutput out = run({"--masses", "1,1", "--positions", "1,0", "--velocities", "-1,0", "--format", "json",
                               "--full-state-every", bad});
    EXPECT_EQ(out.exit_code, 2) << bad;
    const Json error = Json::parse(out.out)["error"];
    EXPECT_EQ(error["reason"], "INVALID_OPTION") << bad;
    EXPECT_EQ(error["field"], "full-state-every") << bad;
  }
}

}  // namespace
