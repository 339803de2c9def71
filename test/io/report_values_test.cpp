// The report as values (io::makeSceneReportValues, what the Python module reads) against the
// JSON report's text, parsed: the same scene, options, units and summary, key for key, and
// the same events, for a scene of each layout (the rotation model's, every scene's) and a
// ring. runReported is the one path for both, so a difference is the writers'.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "collision_lab/core/scene_run.h"
#include "collision_lab/io/event_record.h"
#include "collision_lab/io/scene_report.h"

namespace {

namespace core = collision_lab::core;
namespace io = collision_lab::io;
using io::Json;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Keeps what the values writer hands over; each event as the JSON's keys that tell it apart.
struct KeptValues : io::ReportValues {
  Json scene, options, units, kept_summary;
  Json events = Json::array();
  std::size_t seam_impacts = 0;  ///< impacts across a ring's seam (last_moved below pair_index)
  void head(const Json& s, const Json& o, const Json& u) override { scene = s, options = o, units = u; }
  void event(const io::EventRecord& r) override {
    if (!r.collapse && r.last_moved < r.pair_index) ++seam_impacts;
    events.push_back({{"kind", r.collapse ? "collapse" : "impact"},
                      {"index", r.index},
                      {"pair", io::eventPairName(r)},
                      {"time", r.time},
                      {"pair_velocities_after", {r.pair_velocities_after[0], r.pair_velocities_after[1]}}});
  }
  void summary(const Json& s) override { kept_summary = s; }
};

/// A Json value as its JSON text reads back (NaN and the infinities are null there).
Json asText(const Json& value) { return Json::parse(value.dump()); }

Json withoutComputeTime(Json summary) {
  summary.erase("compute_time_s");
  return summary;
}

/// Compares the two and returns the values (for what a test checks besides).
KeptValues expectValuesAreTheJsonReport(const core::Scene& scene, core::RunOptions options) {
  const io::SceneEntry entry{"scene", "", scene, 0};
  const core::ScenePlan plan = core::planScene(scene);
  EXPECT_FALSE(plan.error);
  io::ReportedRun run;
  run.options = options;
  std::ostringstream text;
  const auto json_writer = io::makeSceneReportWriter(io::ReportFormat::kJson, text);
  io::runReported(entry, plan, run, *json_writer);
  const Json report = Json::parse(text.str());
  KeptValues kept;
  const auto values_writer = io::makeSceneReportValues(kept);
  io::runReported(entry, plan, run, *values_writer);

  EXPECT_EQ(asText(kept.scene), report["scene"]);
  EXPECT_EQ(asText(kept.options), report["options"]);
  EXPECT_EQ(asText(kept.units), report["units"]);
  EXPECT_EQ(withoutComputeTime(asText(kept.kept_summary)), withoutComputeTime(report["summary"]));
  EXPECT_EQ(kept.events.size(), report["events"].size());
  for (std::size_t i = 0; i < std::min(kept.events.size(), report["events"].size()); ++i) {
    for (const auto& [key, value] : kept.events[i].items()) {
      EXPECT_EQ(asText(value), report["events"][i][key]) << "event " << i << ", " << key;
    }
  }
  return kept;
}

TEST(ReportValues, ThreeElasticBodiesAreTheRotationModelsReport) {
  core::Scene pi;  // the pi billiard, M/m = 100: 31 impacts
  pi.masses = {100, 1, kInf};
  pi.positions = {2, 1, 0};
  pi.velocities = {-1, 0, 0};
  expectValuesAreTheJsonReport(pi, {});
}

TEST(ReportValues, ASpiralWithItsCollapseIsEveryScenesReport) {
  core::Scene spiral;  // three equal masses, e = 0.05: eight impacts, then the collapse
  spiral.masses = {1, 1, 1};
  spiral.positions = {2, 1, 0};
  spiral.velocities = {-1, 0, 0};
  spiral.restitution = {0.05};
  expectValuesAreTheJsonReport(spiral, {});
}

TEST(ReportValues, ARingWithTheTcModelAndLeanRecordsIsEveryScenesReport) {
  core::Scene ring;
  ring.masses = {1, 2, 3, 1.5, 1};
  ring.positions = {4, 3, 2, 1, 0};
  ring.velocities = {-1, 0.5, 0, 0.2, 1};
  ring.restitution = {0.8};
  ring.restitution_model.kind = core::RestitutionModelKind::kTc;
  ring.restitution_model.tc = 1e-3;
  ring.ring = 10;
  core::RunOptions options;
  options.max_collisions = 200;
  options.events.full_state_every = 7;
  const KeptValues kept = expectValuesAreTheJsonReport(ring, options);
  EXPECT_GT(kept.seam_impacts, 0u);  // so that the seam's pair name ("EA") was compared
}

}  // namespace
