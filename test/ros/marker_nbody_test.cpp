// rviz markers of N-body runs (no master). The runs come from the core's exact event
// engine; the CollisionEvent messages are built here from its ImpactRecords (pair fields
// only, as the node sends for N > FULL_STATE_MAX_BODIES, or with the per-body arrays),
// independently of the node's conversion. References: hand-derived numbers, the engine's
// final state, and conservation laws.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collision_lab/core/nbody/engine.h"
#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/ids.h"
#include "collision_lab/ros/markers/layout.h"
#include "marker_test_checks.h"

namespace {

using namespace collision_lab_ros;
using collision_lab::CollisionEvent;
using collision_lab::core::Scene;
using marker_checks::expectFitForRviz;
using marker_checks::expectOneMarkerPerId;
using marker_checks::find;

const double kInf = std::numeric_limits<double>::infinity();

/// The message of one impact. full_state: the per-body arrays too (from `state`, the
/// velocities after every impact so far, kept by the caller).
CollisionEvent impactMessage(const collision_lab::core::ImpactRecord& r, const Scene& scene, bool full_state,
                             std::vector<double>& x, std::vector<double>& since, std::vector<double>& v) {
  CollisionEvent msg;
  msg.run_id = "nbody";
  msg.kind = CollisionEvent::KIND_IMPACT;
  msg.index = r.index;
  msg.pair_index = static_cast<std::uint32_t>(r.pair_index);
  msg.time = r.time;
  msg.position = r.position;
  msg.restitution = scene.restitutionOf(r.pair_index);
  msg.first_moved = msg.pair_index;
  msg.last_moved = msg.pair_index + 1;
  msg.pair_velocities_before = {r.velocities_before[0], r.velocities_before[1]};
  msg.pair_velocities_after = {r.velocities_after[0], r.velocities_after[1]};
  msg.pair_energy_transfer = {r.energy_gained[0], r.energy_gained[1]};
  msg.energy_lost = r.energy_lost;
  msg.total_energy = msg.total_momentum = std::nan("");
  for (std::size_t j : {r.pair_index, r.pair_index + 1}) {
    x[j] = r.position, since[j] = r.time;
    v[j] = r.velocities_after[j - r.pair_index];
  }
  if (full_state) {
    for (std::size_t i = 0; i < v.size(); ++i) msg.positions.push_back(x[i] + v[i] * (r.time - since[i]));
    msg.velocities_after = v;
  }
  return msg;
}

struct NBodyRun {
  Scene scene;
  collision_lab::core::SceneSimulation result;
  std::vector<CollisionEvent> events;  ///< impacts and collapses, in order
  RunRecord run;
};

collision_lab::InitialConditions inputOf(const Scene& scene, std::uint64_t cap) {
  collision_lab::InitialConditions input;
  input.run_id = "nbody";
  input.masses = scene.masses;
  input.positions = scene.positions;
  input.velocities = scene.velocities;
  input.restitution = scene.restitution;
  input.max_collisions = cap;
  return input;
}

/// Runs the scene in the engine and feeds the record as the node would.
NBodyRun runScene(const Scene& scene, bool full_state, std::uint64_t cap = 10'000'000, bool keep = true) {
  EXPECT_FALSE(collision_lab::core::validate(scene).has_value());
  NBodyRun out{scene, {}, {}, RunRecord(inputOf(scene, cap))};
  std::vector<double> x = scene.positions, since(scene.size(), 0.0), v = scene.velocities;
  collision_lab::core::EngineOptions options;
  options.max_impacts = cap;
  std::vector<CollisionEvent> impacts;
  out.result = collision_lab::core::runEngine(scene, options, [&](const collision_lab::core::ImpactRecord& r) {
    impacts.push_back(impactMessage(r, scene, full_state, x, since, v));
  });
  // These scenes have no cluster impacts, so every impact moves exactly its pair.
  EXPECT_EQ(out.result.cluster_impacts, 0u);
  std::size_t next_collapse = 0;
  for (const CollisionEvent& e : impacts) {
    out.run.add(e);
    if (keep) out.events.push_back(e);
    while (next_collapse < out.result.collapses.size() && out.result.collapses[next_collapse].impacts_before == e.index) {
      const auto& c = out.result.collapses[next_collapse++];
      CollisionEvent msg;
      msg.kind = CollisionEvent::KIND_COLLAPSE;
      msg.index = c.impacts_before;
      msg.time = c.time;
      msg.position = c.position;
      msg.first_moved = static_cast<std::uint32_t>(c.first_body);
      msg.last_moved = static_cast<std::uint32_t>(c.last_body);
      msg.pair_index = msg.first_moved;
      // The cluster moves at its centre-of-mass velocity: momentum of its bodies / mass.
      double p = 0.0, m = 0.0;
      for (std::size_t i = c.first_body; i <= c.last_body; ++i) p += scene.masses[i] * v[i], m += scene.masses[i];
      msg.pair_velocities_after = {p / m, p / m};
      msg.total_energy = msg.total_momentum = std::nan("");
      out.run.add(msg);
      out.events.push_back(msg);
    }
  }
  collision_lab::RunSummary summary;
  summary.simulated = true;
  summary.truncated = out.result.truncated;
  summary.collision_count = out.result.impact_count;
  out.run.summary = summary;
  return out;
}

Scene scene(std::vector<double> m, std::vector<double> x, std::vector<double> v, std::vector<double> e = {}) {
  Scene s;
  s.masses = std::move(m), s.positions = std::move(x), s.velocities = std::move(v), s.restitution = std::move(e);
  return s;
}

/// Long after the last impact: the state the run ends in.
SceneState lastState(const RunRecord& run) { return stateAt(run, 1e30); }

void expectViewsFit(const RunRecord& run) {
  const auto fixed = buildStaticMarkers(run, "f");
  expectFitForRviz(fixed);
  expectOneMarkerPerId(fixed);
  marker_checks::expectTextsOnScreen(fixed);
  const double end = endTime(run);
  for (double t : {0.0, 0.3 * end, end}) {
    const auto animated = buildAnimatedMarkers(run, FrameClock{t, "test"}, "f");
    expectFitForRviz(animated);
    expectOneMarkerPerId(animated);
    marker_checks::expectTextsOnScreen(animated);
  }
}

std::set<std::string> namespacesOf(const visualization_msgs::MarkerArray& array) {
  std::set<std::string> out;
  for (const auto& m : array.markers) out.insert(m.ns);
  return out;
}

using TextId = std::pair<std::string, int>;

/// The left column's legends and notes stay on screen (its left edge is at x = -10.7 in
/// rviz/collision_lab.rviz), left of the middle column's value labels (from x = -3.4), and
/// clear of every other text, at the start, midway and at the end.
void expectLeftColumnClear(const RunRecord& run, const std::vector<TextId>& texts) {
  const auto fixed = buildStaticMarkers(run, "f");
  for (double t : {0.0, 0.5 * endTime(run), endTime(run)}) {
    const auto animated = buildAnimatedMarkers(run, FrameClock{t, "test"}, "f");
    for (const auto& [ns, id] : texts) {
      const auto* m = find(fixed, ns, id);
      if (!m) m = find(animated, ns, id);
      ASSERT_TRUE(m) << ns << "/" << id;
      marker_checks::expectTextClear(*m, -10.7, -3.4, {&fixed, &animated});
    }
  }
}

TEST(MarkerNBody, LeftColumnTextsStayOnScreenAndClearOfOtherTexts) {
  // The wedge's legends for a collapse (e = 0.05) and a spiral just above r_c (e = 0.072).
  for (double e : {0.05, 0.072}) {
    SCOPED_TRACE(e);
    NBodyRun r = runScene(scene({1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {e}), true);
    collision_lab::Prediction p;
    p.model = collision_lab::Prediction::MODEL_THREE_BODY_SPIRAL;
    p.collapsed = !r.result.collapses.empty();
    p.critical_restitution = 7 - 4 * std::sqrt(3.0);
    r.run.prediction = p;
    expectLeftColumnClear(r.run, {{markers::ns::kWedge, markers::kWedgeKey}, {markers::ns::kWedge, markers::kWedgeLegend}});
  }
  // A gas of 100 bodies: the histogram's key, the note on its Gaussian, and V and sigma now.
  std::mt19937_64 rng(100);
  std::uniform_real_distribution<double> mass(1.0, 2.0), speed(-1.0, 1.0);
  Scene gas;
  for (int i = 0; i < 100; ++i) {
    gas.masses.push_back(mass(rng)), gas.positions.push_back(99.0 - i), gas.velocities.push_back(speed(rng));
  }
  const NBodyRun r = runScene(gas, false);
  expectLeftColumnClear(r.run, {{markers::ns::kVelocities, markers::kSideLegend},
                                {markers::ns::kVelocities, markers::kSideNote},
                                {markers::ns::kVelocitiesNow, markers::kSideNowText}});
}

TEST(MarkerNBody, TwoCartsWithRestitutionPartAtEightTenths) {
  // 1 kg carts at +-1 m/s, e = 0.8: they part at -+0.8 m/s; heat (1 - 0.64) * 1 J = 0.36 J.
  for (bool full : {true, false}) {
    SCOPED_TRACE(full);
    const NBodyRun r = runScene(scene({1, 1}, {1, 0}, {-1, 1}, {0.8}), full);
    ASSERT_EQ(r.run.collisions(), 1u);
    const SceneState end = lastState(r.run);
    EXPECT_NEAR(end.velocities[0], 0.8, 1e-15);
    EXPECT_NEAR(end.velocities[1], -0.8, 1e-15);
    // They meet at x = 0.5 at t = 0.5 s, then part: at t = 1.5 s they are 0.8 m either side.
    const SceneState later = stateAt(r.run, 1.5);
    EXPECT_NEAR(later.positions[0], 1.3, 1e-12);
    EXPECT_NEAR(later.positions[1], -0.3, 1e-12);
    EXPECT_NEAR(r.run.energyLost().last().y, 0.36, 1e-12);
    EXPECT_NEAR(r.run.energy().last().y, 0.64, 1e-12);
    expectViewsFit(r.run);
  }
}

TEST(MarkerNBody, CradleOfFiveHandsTheVelocityOn) {
  // Five equal masses 1 m apart, the right one at -1 m/s: 4 impacts, the left one leaves.
  for (bool full : {true, false}) {
    SCOPED_TRACE(full);
    NBodyRun r = runScene(scene({1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0}), full);
    ASSERT_EQ(r.run.collisions(), 4u);
    const SceneState end = lastState(r.run);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(end.velocities[i], 0.0) << i;
    EXPECT_EQ(end.velocities[4], -1.0);
    // Impact k comes at t = k s at x = 4 - k: bodies 0..k-1 rest where they were hit.
    const SceneState mid = stateAt(r.run, 2.5);
    EXPECT_EQ(mid.collisions, 2u);
    EXPECT_NEAR(mid.positions[0], 3.0, 1e-12);
    EXPECT_NEAR(mid.positions[1], 2.0, 1e-12);
    EXPECT_NEAR(mid.positions[2], 1.5, 1e-12);
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(end.velocities[i], r.result.final_velocities[i]);
    // Equal elastic masses: the ghosts are drawn over the x-t diagram, the wedge is not.
    collision_lab::Prediction ghosts;
    ghosts.model = collision_lab::Prediction::MODEL_GHOSTS;
    r.run.prediction = ghosts;
    const auto fixed = buildStaticMarkers(r.run, "f");
    const auto* ghost_lines = find(fixed, markers::ns::kWorldlines, markers::kWorldGhosts);
    ASSERT_TRUE(ghost_lines);
    // Each piece of a worldline lies on a ghost's line: the ghosts are dashes drawn over the
    // worldlines, so both show. (Failed before: one solid line per ghost, under them.)
    double highest_worldline = -kInf;
    for (int k = 0; k < 5; ++k) {
      const auto* line = find(fixed, markers::ns::kWorldlines, markers::kWorldLines + k);
      ASSERT_TRUE(line) << k;
      for (const auto& p : line->points) highest_worldline = std::max(highest_worldline, p.z);
    }
    for (const auto& p : ghost_lines->points) EXPECT_GT(p.z, highest_worldline);
    EXPECT_GT(ghost_lines->points.size(), 2u * 5 * 4);
    // The x-t legend names the ghosts as drawn, on screen (right edge x = 16.3) and clear of "t [s]".
    const auto* legend = find(fixed, markers::ns::kWorldlines, markers::kWorldLegend);
    ASSERT_TRUE(legend);
    EXPECT_NE(legend->text.find("grey dashes: ghosts"), std::string::npos) << legend->text;
    marker_checks::expectTextClear(*legend, markers::layout::kWorldBox.left, 16.3, {&fixed});
    EXPECT_FALSE(namespacesOf(fixed).count(markers::ns::kWedge));
    EXPECT_TRUE(namespacesOf(fixed).count(markers::ns::kVelocities));
    // Five labelled bodies with their velocities.
    const auto animated = buildAnimatedMarkers(r.run, FrameClock{0.0, "test"}, "f");
    for (int i = 0; i < 5; ++i) EXPECT_TRUE(find(animated, markers::ns::kLabels, markers::kVelocityRow + i)) << i;
    expectViewsFit(r.run);
  }
}

TEST(MarkerNBody, BallBetweenTwoWallsBouncesAtEverySecond) {
  // Walls at 1 m and 0, the ball at 0.5 m with +1 m/s: bounce k at t = k - 0.5 s, v = (-1)^k.
  NBodyRun r = runScene(scene({kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0}), false, 1000);
  ASSERT_EQ(r.run.collisions(), 1000u);
  const SceneState at = stateAt(r.run, 999.5);
  EXPECT_EQ(at.velocities[1], 1.0);
  EXPECT_NEAR(at.positions[1], 0.0, 1e-9);
  const SceneState between = stateAt(r.run, 500.75);  // after bounce 501 at the right wall
  EXPECT_EQ(between.velocities[1], -1.0);
  EXPECT_NEAR(between.positions[1], 0.75, 1e-9);
  EXPECT_EQ(at.positions[0], 1.0);
  EXPECT_EQ(at.positions[2], 0.0);
  // Infinitely many predicted, 1,000 simulated (the cap): at t = 15.9 s 16 bounces are
  // behind, and the run's counter (the view's) says 1,000, truncated; never a finite count
  // "predicted".
  collision_lab::Prediction infinite;
  infinite.model = collision_lab::Prediction::MODEL_TWO_WALLS_INFINITE;
  infinite.infinite_collisions = true;
  r.run.prediction = infinite;
  const auto status = [&r] {
    const auto animated = buildAnimatedMarkers(r.run, FrameClock{15.9, ""}, "f");
    const auto* m = find(animated, markers::ns::kLabels, markers::kStatus);
    return m ? m->text : std::string("(none)");
  };
  ASSERT_TRUE(r.run.summary && r.run.summary->truncated);
  EXPECT_NE(status().find("collisions 16     run: 1,000 collisions, truncated"), std::string::npos) << status();
  EXPECT_EQ(status().find("predicted"), std::string::npos) << status();
  const auto summary = r.run.summary;
  r.run.summary.reset();  // still running: the prediction is infinitely many
  EXPECT_NE(status().find("collisions 16     run: 1,000 collisions so far (infinitely many predicted), running"),
            std::string::npos)
      << status();
  r.run.summary = summary;
  // The walls are walls (cubes), not spheres.
  const auto animated = buildAnimatedMarkers(r.run, FrameClock{10.0, "test"}, "f");
  for (int i : {0, 2}) {
    const auto* wall = find(animated, markers::ns::kBodies, markers::kBody + i);
    ASSERT_TRUE(wall);
    EXPECT_EQ(wall->type, visualization_msgs::Marker::CUBE);
  }
  expectViewsFit(r.run);
}

/// Seven bodies, 1 m apart: 4 kg at 6, 4, 2 and 0 m, 1 kg between them; the outer heavy
/// ones close in at 1 m/s. A 4 kg body at 1 m/s sends a 1 kg one at rest off at
/// 2 * 4 / 5 = 1.6 m/s (by hand, momentum and energy): faster than any body at the start.
NBodyRun sevenBodies() {
  return runScene(scene({4, 1, 4, 1, 4, 1, 4}, {6, 5, 4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0, 0, 1}), true);
}

TEST(MarkerNBody, VelocitiesNowPanelHoldsEveryVelocityOfTheRun) {
  // The panel once scaled to 1.12 x the start's largest speed: 1.6 m/s was drawn on the
  // 1.12 line. (Failed before: dots at the panel's edge.)
  const NBodyRun r = sevenBodies();
  ASSERT_GT(r.run.maxVelocity(), 1.59);
  const auto& box = markers::layout::kSideBox;
  const double end = endTime(r.run);
  double fastest = 0.0;
  for (int k = 0; k <= 200; ++k) {
    const SceneState state = stateAt(r.run, end * k / 200);
    SCOPED_TRACE(state.time);
    const auto animated = buildAnimatedMarkers(r.run, FrameClock{state.time, "test"}, "f");
    const auto* dots = find(animated, markers::ns::kVelocitiesNow, markers::kSideBars);
    ASSERT_TRUE(dots);
    ASSERT_EQ(dots->points.size(), 7u);
    // Body i's dot (the i-th point, in column 6 - i) lies inside the frame, never on its
    // edge (where a clamped value would sit), and on one straight line y = a + b v through
    // every body's v: no value was clamped.
    std::size_t lo = 0, hi = 0;
    for (std::size_t i = 0; i < 7; ++i) {
      const double v = state.velocities[i];
      fastest = std::max(fastest, std::abs(v));
      if (v < state.velocities[lo]) lo = i;
      if (v > state.velocities[hi]) hi = i;
      const double y = dots->points[i].y;
      EXPECT_GT(y, box.bottom) << i;
      EXPECT_LT(y, box.top) << i;
    }
    if (state.velocities[hi] == state.velocities[lo]) continue;
    const double b = (dots->points[hi].y - dots->points[lo].y) / (state.velocities[hi] - state.velocities[lo]);
    EXPECT_GT(b, 0);
    for (std::size_t i = 0; i < 7; ++i) {
      EXPECT_NEAR(dots->points[i].y, dots->points[lo].y + b * (state.velocities[i] - state.velocities[lo]), 1e-9) << i;
    }
  }
  EXPECT_GT(fastest, 1.59);  // the fast ones were among the frames checked
  // The axis' end values hold the run's range, each with its sign written (rviz's minus is
  // a few pixels wide: "-1.12" read as "1.12", like the other end).
  const auto fixed = buildStaticMarkers(r.run, "f");
  const auto* top = find(fixed, markers::ns::kVelocities, markers::kSideFrame + markers::kFrameTopValue);
  const auto* bottom = find(fixed, markers::ns::kVelocities, markers::kSideFrame + markers::kFrameBottomValue);
  ASSERT_TRUE(top && bottom);
  EXPECT_EQ(top->text.front(), '+') << top->text;
  EXPECT_EQ(bottom->text.front(), '-') << bottom->text;
  EXPECT_GE(std::stod(top->text), 1.6);
  EXPECT_LE(std::stod(bottom->text), -1.6);
}

std::string statusAt(const RunRecord& run, double t) {
  const auto animated = buildAnimatedMarkers(run, FrameClock{t, ""}, "f");
  const auto* m = find(animated, markers::ns::kLabels, markers::kStatus);
  return m ? m->text : std::string("(none)");
}

TEST(MarkerNBody, StatusClaimsOnlyACountTheModelPredicted) {
  // The event engine predicts no count: while the run is coming in, the status says how
  // many collisions were received (the view's counter), never "predicted". (Failed before:
  // "(N predicted)", N being the count received so far.)
  NBodyRun r = sevenBodies();
  const std::uint64_t n = r.run.collisions();
  ASSERT_GT(n, 2u);
  r.run.summary.reset();  // still running
  collision_lab::Prediction engine;
  engine.model = collision_lab::Prediction::MODEL_EVENT_ENGINE;
  engine.collision_count_defined = false;
  r.run.prediction = engine;
  // Just after the first impacts (at t = 1 s, one at each end).
  const double first = r.events.front().time;
  const std::string shown = "collisions " + std::to_string(stateAt(r.run, first).collisions);
  ASSERT_LT(stateAt(r.run, first).collisions, n);
  EXPECT_NE(statusAt(r.run, first).find(shown + "     run: " + std::to_string(n) + " collisions so far, running"),
            std::string::npos)
      << statusAt(r.run, first);
  EXPECT_EQ(statusAt(r.run, first).find("predicted"), std::string::npos) << statusAt(r.run, first);
  // A model that predicts the count: "n of n + 1 collisions predicted".
  collision_lab::Prediction ghosts;
  ghosts.model = collision_lab::Prediction::MODEL_GHOSTS;
  ghosts.collision_count_defined = true;
  ghosts.collision_count = n + 1;
  r.run.prediction = ghosts;
  EXPECT_NE(statusAt(r.run, first).find(shown + "     run: " + std::to_string(n) + " of " + std::to_string(n + 1) +
                                        " collisions predicted, running"),
            std::string::npos)
      << statusAt(r.run, first);
}

TEST(MarkerNBody, LegendNamesTheClosedFormOnlyWhereItsDotsAreDrawn) {
  // The event engine's messages carry no closed-form velocities: no dots, and the legend
  // says none. (Failed before: "dots: closed form" for two carts and seven bodies.)
  for (const NBodyRun& r : {runScene(scene({1, 1}, {1, 0}, {-1, 1}, {0.8}), true), sevenBodies()}) {
    SCOPED_TRACE(r.run.bodies());
    const auto fixed = buildStaticMarkers(r.run, "f");
    marker_checks::expectLegendMatchesDots(fixed);
    const auto* legend = find(fixed, markers::ns::kPlot, markers::kPlotLegend);
    ASSERT_TRUE(legend);
    EXPECT_EQ(legend->text.find("dots"), std::string::npos) << legend->text;
  }
}

TEST(MarkerNBody, TagsOfBodiesCloseTogetherStayApart) {
  // Seven bodies meet in clusters: every frame, no two tags overlap, and none lies on an
  // end label of the axis. (Failed before: "DB" and "GE", a tag on top of another.)
  const NBodyRun r = sevenBodies();
  const auto fixed = buildStaticMarkers(r.run, "f");
  const double end = endTime(r.run);
  for (int k = 0; k <= 400; ++k) {
    const double t = end * k / 400;
    const auto animated = buildAnimatedMarkers(r.run, FrameClock{t, "test"}, "f");
    std::vector<marker_checks::TextBox> boxes;
    for (int i = 0; i < 7; ++i) {
      const auto* tag = find(animated, markers::ns::kLabels, markers::kBodyTag + i);
      ASSERT_TRUE(tag) << i;
      boxes.push_back(marker_checks::textBox(*tag));
    }
    for (int id : {markers::kSceneMinLabel, markers::kSceneMaxLabel}) {
      const auto* label = find(fixed, markers::ns::kScene, id);
      ASSERT_TRUE(label) << id;
      boxes.push_back(marker_checks::textBox(*label));
    }
    for (std::size_t a = 0; a < 7; ++a) {
      for (std::size_t b = a + 1; b < boxes.size(); ++b) {
        EXPECT_TRUE(marker_checks::apart(boxes[a], boxes[b])) << "t = " << t << ": tag " << a << " and text " << b;
      }
    }
  }
}

TEST(MarkerNBody, EnergyBarValuesStayApart) {
  // Seven bars 0.66 units apart, values such as "0.00524" wider than that: neighbours never
  // overlap. (Failed before: "0.001150.00524".)
  const NBodyRun r = sevenBodies();
  const double end = endTime(r.run);
  for (int k = 0; k <= 100; ++k) {
    const double t = end * k / 100;
    const auto animated = buildAnimatedMarkers(r.run, FrameClock{t, "test"}, "f");
    for (int i = 0; i + 1 < 7; ++i) {
      const auto* a = find(animated, markers::ns::kEnergyBars, markers::kEnergyBarValue + i);
      const auto* b = find(animated, markers::ns::kEnergyBars, markers::kEnergyBarValue + i + 1);
      ASSERT_TRUE(a && b) << i;
      EXPECT_TRUE(marker_checks::apart(marker_checks::textBox(*a), marker_checks::textBox(*b)))
          << "t = " << t << ": '" << a->text << "' and '" << b->text << "'";
    }
  }
}

TEST(MarkerNBody, EndLabelsOfTheAxisStayOffTheWalls) {
  // The ball between walls at 0 and 1 m: the walls stand at the axis' ends, and its end
  // labels ("x = -0.06 m") once lay on them. (Failed before.)
  const NBodyRun r = runScene(scene({kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0}), false, 20);
  const auto fixed = buildStaticMarkers(r.run, "f");
  const auto animated = buildAnimatedMarkers(r.run, FrameClock{3.0, "test"}, "f");
  for (int wall : {0, 2}) {
    const auto* cube = find(animated, markers::ns::kBodies, markers::kBody + wall);
    ASSERT_TRUE(cube);
    const marker_checks::TextBox box{cube->pose.position.x - cube->scale.x / 2, cube->pose.position.x + cube->scale.x / 2,
                                     cube->pose.position.y - cube->scale.y / 2, cube->pose.position.y + cube->scale.y / 2};
    for (int id : {markers::kSceneMinLabel, markers::kSceneMaxLabel}) {
      const auto* label = find(fixed, markers::ns::kScene, id);
      ASSERT_TRUE(label) << id;
      EXPECT_TRUE(marker_checks::apart(marker_checks::textBox(*label), box)) << label->text << " on wall " << wall;
    }
  }
}

TEST(MarkerNBody, BallBetweenTwoWallsDrawsOnePeriodAndCountsThem) {
  // Walls at 1 m and 0, the ball at 0.5 m with +1 m/s: periodic, T = 2 (1 - 0) / 1 = 2 s.
  // 1,000 bounces once filled the x-t diagram with 1,000 lines thinner than a pixel; now
  // one period is drawn, the line of now runs at t mod T, and the periods so far are
  // counted. (Failed before.)
  NBodyRun r = runScene(scene({kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0}), false, 1000);
  const auto fixed = buildStaticMarkers(r.run, "f");
  const auto* ball = find(fixed, markers::ns::kWorldlines, markers::kWorldLines + 1);
  ASSERT_TRUE(ball);
  // One period: from 0.5 m to the wall at 1 m (t = 0.5 s), to 0 (1.5 s), back to 0.5 m (2 s).
  ASSERT_EQ(ball->points.size(), 4u);
  const auto* end_label = find(fixed, markers::ns::kWorldlines, markers::kWorldTimeEnd);
  ASSERT_TRUE(end_label);
  EXPECT_EQ(end_label->text, "2");
  const auto* legend = find(fixed, markers::ns::kWorldlines, markers::kWorldLegend);
  ASSERT_TRUE(legend);
  EXPECT_NE(legend->text.find("one period drawn, T = 2 s"), std::string::npos) << legend->text;
  // At t = 15.9 s: 7 periods behind, now at 1.9 s of the period (95 % up the box).
  const auto animated = buildAnimatedMarkers(r.run, FrameClock{15.9, "test"}, "f");
  const auto* periods = find(animated, markers::ns::kWorldlinesNow, markers::kWorldNowPeriods);
  ASSERT_TRUE(periods);
  EXPECT_EQ(periods->text, "periods so far: 7");
  const auto* now = find(animated, markers::ns::kWorldlinesNow, markers::kWorldNowLine);
  ASSERT_TRUE(now);
  const auto& box = markers::layout::kWorldBox;
  EXPECT_NEAR(now->points[0].y, box.bottom + 0.95 * (box.top - box.bottom), 1e-9);
  // The ball's dot on the line of now: at 15.9 s it is at 0.9 m, going left.
  const auto* dots = find(animated, markers::ns::kWorldlinesNow, markers::kWorldNowBodies);
  ASSERT_TRUE(dots);
  EXPECT_NEAR(dots->points[1].y, now->points[0].y, 1e-9);
  // The note says "stopped" once (the engine's reason begins with it).
  r.run.summary->truncation_reason = "stopped at the cap of 1000 impacts (truncated)";
  const auto noted = buildStaticMarkers(r.run, "f");
  const auto* note = find(noted, markers::ns::kScene, markers::kSceneNote);
  ASSERT_TRUE(note);
  EXPECT_EQ(note->text.find("stopped: stopped"), std::string::npos) << note->text;
  EXPECT_NE(note->text.find("stopped at the cap"), std::string::npos) << note->text;
  expectViewsFit(r.run);
}

TEST(MarkerNBody, BallBetweenTwoWallsStepsOnePeriodAndCountsThem) {
  // The same ball: per period T = 2 s one impact on each wall, v = +1, -1, then +1 again
  // (m = 1 kg, so p = v). 1,000 impacts once filled the velocity and momentum plots with
  // steps thinner than a pixel, solid blocks; now steps 0, 1, 2 (one period and its return)
  // are drawn, the cursor at the step within the period, and the periods so far are
  // counted as in the x-t diagram. (Failed before.)
  NBodyRun r = runScene(scene({kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0}), false, 1000);
  const auto fixed = buildStaticMarkers(r.run, "f");
  const auto& box = markers::layout::kVelocityBox;
  const auto stepsOk = [](const visualization_msgs::Marker* m, const markers::Box& b) {
    ASSERT_TRUE(m);
    // (index, p or v): (0, 1) (1, 1) (1, -1) (2, -1) (2, 1) (3, 1), index 3 at the right edge.
    ASSERT_EQ(m->points.size(), 6u);
    const double width = b.right - b.left;
    const double xs[] = {0, 1, 1, 2, 2, 3};
    for (std::size_t k = 0; k < 6; ++k) EXPECT_NEAR(m->points[k].x, b.left + xs[k] / 3 * width, 1e-9) << k;
    EXPECT_NEAR(m->points[0].y, m->points[5].y, 1e-9);
    EXPECT_NEAR(m->points[1].y, m->points[4].y, 1e-9);
    EXPECT_NEAR(m->points[2].y, m->points[3].y, 1e-9);
    EXPECT_GT(m->points[1].y, m->points[2].y);  // +1 over -1
  };
  stepsOk(find(fixed, markers::ns::kPlot, markers::kPlotSeries + 1), box);
  stepsOk(find(fixed, markers::ns::kConserved, markers::kConservedMomentum + markers::kConservedSeries),
          markers::layout::kMomentumBox);
  const auto* legend = find(fixed, markers::ns::kPlot, markers::kPlotLegend);
  ASSERT_TRUE(legend);
  EXPECT_NE(legend->text.find("one period drawn (2 impacts)"), std::string::npos) << legend->text;
  // The index labels: 0, 1, 2 and no more.
  for (int k = 0; k < 3; ++k) {
    const auto* label = find(fixed, markers::ns::kPlot, markers::kPlotIndexLabels + k);
    ASSERT_TRUE(label) << k;
    EXPECT_EQ(label->text, std::to_string(k));
  }
  EXPECT_FALSE(find(fixed, markers::ns::kPlot, markers::kPlotIndexLabels + 3));
  // At t = 15.9 s: 16 impacts, 7 periods (14 impacts) behind: step 2, the return.
  const auto animated = buildAnimatedMarkers(r.run, FrameClock{15.9, "test"}, "f");
  const auto* periods = find(animated, markers::ns::kPlotCursor, markers::kStepsPeriods);
  ASSERT_TRUE(periods);
  EXPECT_EQ(periods->text, "periods so far: 7");
  // Over the velocity plot, clear of its frames' labels (B has a panel of its own).
  marker_checks::expectTextClear(*periods, box.left, box.right, {&fixed, &animated});
  const auto* cursor = find(animated, markers::ns::kPlotCursor, markers::kCursor);
  ASSERT_TRUE(cursor);
  EXPECT_NEAR(cursor->points[0].x, box.left + 2.5 / 3 * (box.right - box.left), 1e-9);
  // At t = 16.6 s: 17 impacts, 8 periods behind: step 1.
  const auto later = buildAnimatedMarkers(r.run, FrameClock{16.6, "test"}, "f");
  cursor = find(later, markers::ns::kPlotCursor, markers::kCursor);
  ASSERT_TRUE(cursor);
  EXPECT_NEAR(cursor->points[0].x, box.left + 1.5 / 3 * (box.right - box.left), 1e-9);
  expectViewsFit(r.run);
  // A short run (under two periods) is drawn as it is, with no count.
  const NBodyRun short_run = runScene(scene({kInf, 1, kInf}, {1, 0.5, 0}, {0, 1, 0}), false, 1);
  const auto once = buildAnimatedMarkers(short_run.run, FrameClock{0.7, "test"}, "f");
  const auto* none = find(once, markers::ns::kPlotCursor, markers::kStepsPeriods);
  EXPECT_TRUE(!none || none->action == visualization_msgs::Marker::DELETE);
}

/// The centres' smallest distance between neighbours of the bodies drawn in `ns` with ids
/// first + i (i < n) [rviz units], and the largest body's diameter.
std::pair<double, double> closestNeighbours(const visualization_msgs::MarkerArray& array, const std::string& ns,
                                            int first, int n) {
  std::vector<double> x;
  double size = 0.0;
  for (int i = 0; i < n; ++i) {
    const auto* body = find(array, ns, first + i);
    if (!body || body->action != visualization_msgs::Marker::ADD) return {0.0, kInf};
    x.push_back(body->pose.position.x);
    size = std::max(size, body->scale.x);
  }
  std::sort(x.begin(), x.end());
  double closest = kInf;
  for (std::size_t i = 0; i + 1 < x.size(); ++i) closest = std::min(closest, x[i + 1] - x[i]);
  return {closest, size};
}

TEST(MarkerNBody, SevenBodiesCrowdedIntoAFewMetresAreMagnified) {
  // Seven bodies 2/3 m apart, 4 m in all; the outer heavy ones close in at 1 m/s, and the
  // run's axis spans over 30 m (where the fastest end up). On the scene's axis the
  // neighbours lie less than a heavy body's diameter apart; the magnifier draws all seven
  // at least twice the largest of its dots apart, in order, at their true separations.
  // (Failed before: the magnifier showed for three bodies only.)
  const double d = 2.0 / 3.0;
  const NBodyRun r = runScene(scene({4, 1, 4, 1, 4, 1, 4}, {6 * d, 5 * d, 4 * d, 3 * d, 2 * d, d, 0},
                                    {-1, 0, 0, 0, 0, 0, 1}), true);
  const auto fixed = buildStaticMarkers(r.run, "f");
  const auto* low = find(fixed, markers::ns::kScene, markers::kSceneMinLabel);
  const auto* high = find(fixed, markers::ns::kScene, markers::kSceneMaxLabel);
  ASSERT_TRUE(low && high);
  EXPECT_GT(std::stod(high->text.substr(4)) - std::stod(low->text.substr(4)), 30.0) << low->text << " " << high->text;
  const auto animated = buildAnimatedMarkers(r.run, FrameClock{0.0, "test"}, "f");
  const auto [scene_gap, scene_size] = closestNeighbours(animated, markers::ns::kBodies, markers::kBody, 7);
  EXPECT_LT(scene_gap, scene_size);  // crowded at full scale
  const auto [zoom_gap, zoom_size] = closestNeighbours(animated, markers::ns::kZoom, markers::kZoomBody, 7);
  EXPECT_GE(zoom_gap, 2 * zoom_size);
  // True separations: 2/3 m between each pair of neighbours, on the window's scale.
  const auto* window = find(animated, markers::ns::kZoom, markers::kZoomWindow);
  ASSERT_TRUE(window);
  EXPECT_EQ(window->text.rfind("window 10 m", 0), 0u) << window->text;
  const double per_metre = (markers::layout::kSceneRight - markers::layout::kSceneLeft - 2 * markers::layout::kZoomInset) / 10;
  for (int i = 0; i + 1 < 7; ++i) {
    const auto* a = find(animated, markers::ns::kZoom, markers::kZoomBody + i);
    const auto* b = find(animated, markers::ns::kZoom, markers::kZoomBody + i + 1);
    ASSERT_TRUE(a && b);
    EXPECT_NEAR(a->pose.position.x - b->pose.position.x, d * per_metre, 1e-9) << i;
  }
  // Once they fly apart, no magnifier.
  const auto apart_now = buildAnimatedMarkers(r.run, FrameClock{endTime(r.run), "test"}, "f");
  const auto* gone = find(apart_now, markers::ns::kZoom, markers::kZoomBody);
  EXPECT_TRUE(gone && gone->action == visualization_msgs::Marker::DELETE);
  expectViewsFit(r.run);
}

TEST(MarkerNBody, CollapseOfThreeEqualMassesEndsAtTheCentreOfMass) {
  // Three equal masses, e = 0.05 < r_c: infinitely many impacts before t_c, then the three
  // move as one at the centre-of-mass velocity -1/3 m/s, along x_cm(t) = 1 - t/3 m.
  NBodyRun r = runScene(scene({1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.05}), true);
  ASSERT_EQ(r.result.collapses.size(), 1u);
  EXPECT_EQ(r.run.collapses(), 1u);
  const double t_c = r.result.collapses[0].time;
  const SceneState after = stateAt(r.run, t_c + 1.0);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(after.velocities[i], -1.0 / 3, 1e-12) << i;
    EXPECT_NEAR(after.velocities[i], r.result.final_velocities[i], 1e-12) << i;
    EXPECT_NEAR(after.positions[i], 1 - (t_c + 1.0) / 3, 1e-9) << i;
  }
  // Before the collapse nothing is invented: every shown state keeps the order.
  for (int k = 0; k <= 200; ++k) {
    const SceneState s = stateAt(r.run, t_c * k / 200);
    EXPECT_GE(s.positions[0] + 1e-12, s.positions[1]);
    EXPECT_GE(s.positions[1] + 1e-12, s.positions[2]);
  }
  // The wedge shows the orbit's directions and the cycle's eigen-directions, r_c in the legend.
  collision_lab::Prediction p;
  p.model = collision_lab::Prediction::MODEL_THREE_BODY_SPIRAL;
  p.collapsed = true;
  p.critical_restitution = 7 - 4 * std::sqrt(3.0);
  r.run.prediction = p;
  const auto fixed = buildStaticMarkers(r.run, "f");
  const auto* eigen = find(fixed, markers::ns::kWedge, markers::kWedgeEigen);
  ASSERT_TRUE(eigen);
  const auto* legend = find(fixed, markers::ns::kWedge, markers::kWedgeLegend);
  ASSERT_TRUE(legend);
  EXPECT_NE(legend->text.find("r_c = 0.0718"), std::string::npos) << legend->text;
  // The collapse record is no collision: u_perp after 8 collisions and a collapse, not "9 of 8".
  ASSERT_EQ(r.result.impact_count, 8u);
  const auto* key = find(fixed, markers::ns::kWedge, markers::kWedgeKey);
  ASSERT_TRUE(key);
  EXPECT_EQ(key->text, "orange: u_perp after 8 collisions and a collapse");
  // The last directions before the collapse lie on an eigen-direction (within 2 degrees).
  const auto* dirs = find(fixed, markers::ns::kWedge, markers::kWedgeDirections);
  ASSERT_TRUE(dirs);
  const auto& centre_a = eigen->points[0];
  const auto& centre_b = eigen->points[1];
  const double cx = (centre_a.x + centre_b.x) / 2, cy = (centre_a.y + centre_b.y) / 2;
  const auto& d = dirs->points.back();
  double best = M_PI;
  for (std::size_t k = 0; k + 1 < eigen->points.size(); k += 2) {
    const double line = std::atan2(eigen->points[k + 1].y - cy, eigen->points[k + 1].x - cx);
    const double angle = std::remainder(std::atan2(d.y - cy, d.x - cx) - line, M_PI);
    best = std::min(best, std::abs(angle));
  }
  EXPECT_LT(best, 2 * M_PI / 180);
  expectViewsFit(r.run);
}

TEST(MarkerNBody, ThousandBodyGasRebuiltFromPairFieldsAlone) {
  // A seeded gas like config/gas_1000.csv: masses in [1, 2] kg, v in [-1, 1] m/s, 1 m apart.
  std::mt19937_64 rng(1000);
  std::uniform_real_distribution<double> mass(1.0, 2.0), speed(-1.0, 1.0);
  Scene gas;
  for (int i = 0; i < 1000; ++i) {
    gas.masses.push_back(mass(rng));
    gas.positions.push_back(999.0 - i);
    gas.velocities.push_back(speed(rng));
  }
  const NBodyRun r = runScene(gas, false, 10'000'000, false);
  ASSERT_FALSE(r.result.truncated);
  EXPECT_GT(r.run.collisions(), 100'000u);
  const SceneState end = lastState(r.run);
  ASSERT_EQ(end.velocities.size(), 1000u);
  for (std::size_t i = 0; i < 1000; ++i) EXPECT_EQ(end.velocities[i], r.result.final_velocities[i]) << i;
  // Momentum and energy are conserved by the rebuilt state (elastic, no walls).
  double p0 = 0, p1 = 0, e0 = 0, e1 = 0, scale = 0;
  for (std::size_t i = 0; i < 1000; ++i) {
    p0 += gas.masses[i] * gas.velocities[i], p1 += gas.masses[i] * end.velocities[i];
    e0 += 0.5 * gas.masses[i] * gas.velocities[i] * gas.velocities[i];
    e1 += 0.5 * gas.masses[i] * end.velocities[i] * end.velocities[i];
    scale += gas.masses[i] * std::abs(gas.velocities[i]);
  }
  EXPECT_NEAR(p1, p0, 1e-12 * scale);
  EXPECT_NEAR(e1, e0, 1e-12 * e0);
  EXPECT_NEAR(r.run.energy().last().y, e0, 1e-9 * e0);  // the running sum
  // Bounded memory: the keyframes hold at most RecordLimits::keyframe_values numbers.
  EXPECT_LE(r.run.keyframes().size() * 1000, RecordLimits{}.keyframe_values + 1000);
  EXPECT_EQ(r.run.trackedBodies().size(), kMaxTrackedBodies);
  EXPECT_TRUE(r.run.plottedBodies().empty());
  // Every shown state is ordered (bodies never pass each other) and keeps momentum.
  const double t_end = endTime(r.run);
  for (int k = 0; k <= 60; ++k) {
    const SceneState s = stateAt(r.run, t_end * k / 60);
    double p = 0;
    for (std::size_t i = 0; i < 1000; ++i) {
      p += gas.masses[i] * s.velocities[i];
      if (i > 0) {
        ASSERT_GE(s.positions[i - 1] + 1e-9, s.positions[i]) << "t = " << s.time << ", body " << i;
      }
    }
    EXPECT_NEAR(p, p0, 1e-12 * scale) << s.time;
  }
  // The gas is coloured by velocity with a legend, and the histogram takes the wedge's place.
  const auto fixed = buildStaticMarkers(r.run, "f");
  EXPECT_TRUE(find(fixed, markers::ns::kScene, markers::kColourBar));
  EXPECT_FALSE(namespacesOf(fixed).count(markers::ns::kWedge));
  const auto animated = buildAnimatedMarkers(r.run, FrameClock{t_end / 2, "test"}, "f");
  const auto* bars = find(animated, markers::ns::kVelocitiesNow, markers::kSideBars);
  ASSERT_TRUE(bars);
  EXPECT_EQ(bars->type, visualization_msgs::Marker::TRIANGLE_LIST);
  std::size_t drawn = 0;
  for (int k = 0; k < 10; ++k) {
    if (const auto* m = find(animated, markers::ns::kBodies, markers::kBodyClass + k)) drawn += m->points.size();
  }
  EXPECT_EQ(drawn, 1000u);
  // After a minute the gas is about 1 km wide, at the end about 1e8 m: the scene's axis
  // follows the bodies now, so at either time they spread over most of it (26 units).
  for (double t : {60.0, t_end}) {
    SCOPED_TRACE(t);
    const auto frame = buildAnimatedMarkers(r.run, FrameClock{t, "test"}, "f");
    double lo = kInf, hi = -kInf;
    for (int k = 0; k < 10; ++k) {
      if (const auto* m = find(frame, markers::ns::kBodies, markers::kBodyClass + k)) {
        for (const auto& p : m->points) lo = std::min(lo, p.x), hi = std::max(hi, p.x);
      }
    }
    EXPECT_GT(hi - lo, 0.8 * (markers::layout::kSceneRight - markers::layout::kSceneLeft));
    ASSERT_TRUE(find(frame, markers::ns::kLabels, markers::kSceneRangeNote));
    // The x-t diagram runs up to now: no worldline goes above the line of now, and the
    // tracked bodies (the outermost two among them) span most of its width.
    const auto* now = find(frame, markers::ns::kWorldlinesNow, markers::kWorldNowLine);
    ASSERT_TRUE(now);
    const auto& box = markers::layout::kWorldBox;
    EXPECT_NEAR(now->points[0].y, box.top, 1e-9);
    double left = kInf, right = -kInf;
    for (std::size_t k = 0; k < kMaxTrackedBodies; ++k) {
      const auto* line = find(frame, markers::ns::kWorldlinesNow, markers::kWorldNowLines + static_cast<int>(k));
      ASSERT_TRUE(line) << k;
      for (const auto& p : line->points) {
        EXPECT_LE(p.y, box.top + 1e-9);
        left = std::min(left, p.x), right = std::max(right, p.x);
      }
    }
    EXPECT_GT(right - left, 0.8 * (box.right - box.left));
  }
  // The velocity plot shows the tracked bodies' steps, each ending at the engine's final velocity.
  for (std::size_t k = 0; k < kMaxTrackedBodies; ++k) {
    EXPECT_TRUE(find(fixed, markers::ns::kPlot, markers::kPlotTracked + static_cast<int>(k))) << k;
    const std::size_t i = r.run.trackedBodies()[k];
    EXPECT_EQ(r.run.trackedVelocity(i).last().y, r.result.final_velocities[i]) << i;
  }
  expectViewsFit(r.run);
}

// One naming and one colour per body in every view (issue 31): body i is core::bodyName(i)
// ("A", "B", ...) wherever a text names it, and is drawn in the palette's colour i
// (layout::kParticleRgb: A red, B green, C blue, ...) wherever it has a colour of its own:
// the scene's sphere, its tag and velocity, the velocity steps and their names, the energy
// steps, the worldlines, the kinetic energy bars and their names, the velocities now.
TEST(MarkerNBody, EveryViewNamesAndColoursABodyTheSameWay) {
  const NBodyRun r = runScene(scene({1, 2, 3, 2, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 1}), false);
  ASSERT_GE(r.result.impact_count, 2u);
  const auto fixed = buildStaticMarkers(r.run, "f");
  const auto animated = buildAnimatedMarkers(r.run, FrameClock{0.5 * endTime(r.run), "test"}, "f");
  namespace ns = markers::ns;
  // The palette's colour as the view's bytes (RunView::body_colours, the page's hex): within
  // half a byte of layout::kParticleRgb.
  const auto expectColour = [](const std_msgs::ColorRGBA& c, std::size_t i, const std::string& where) {
    const auto& rgb = markers::layout::kParticleRgb[i];
    EXPECT_NEAR(c.r, rgb.r, 0.5 / 255 + 1e-6) << where << ", body " << i;
    EXPECT_NEAR(c.g, rgb.g, 0.5 / 255 + 1e-6) << where << ", body " << i;
    EXPECT_NEAR(c.b, rgb.b, 0.5 / 255 + 1e-6) << where << ", body " << i;
  };
  const std::vector<std::string> names{"A", "B", "C", "D", "E"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    const int b = static_cast<int>(i);
    const auto* sphere = find(animated, ns::kBodies, markers::kBody + b);
    const auto* tag = find(animated, ns::kLabels, markers::kBodyTag + b);
    const auto* row = find(animated, ns::kLabels, markers::kVelocityRow + b);
    const auto* steps = find(fixed, ns::kPlot, markers::kPlotSeries + b);
    const auto* steps_name = find(fixed, ns::kPlot, markers::kPlotSeriesNames + b);
    const auto* energy = find(fixed, ns::kConserved, markers::kConservedEnergy + markers::kConservedBodies + b);
    const auto* worldline = find(fixed, ns::kWorldlines, markers::kWorldLines + b);
    const auto* bar = find(animated, ns::kEnergyBars, markers::kEnergyBar + b);
    const auto* bar_name = find(fixed, ns::kEnergy, markers::kEnergyBodyNames + b);
    ASSERT_TRUE(sphere && tag && row && steps && steps_name && energy && worldline && bar && bar_name) << i;
    EXPECT_EQ(tag->text, names[i]);
    EXPECT_EQ(row->text.rfind("v_" + names[i] + " = ", 0), 0u) << row->text;
    EXPECT_EQ(steps_name->text, "v_" + names[i]);
    EXPECT_EQ(bar_name->text, names[i]);
    expectColour(sphere->color, i, "scene");
    expectColour(steps->color, i, "velocity steps");
    expectColour(steps_name->color, i, "velocity steps' name");
    expectColour(energy->color, i, "energy steps");
    expectColour(worldline->color, i, "worldline");
    expectColour(bar->color, i, "energy bar");
    expectColour(bar_name->color, i, "energy bar's name");
  }
  // The velocities now: one dot per body, E (left) to A (right), each in its colour.
  const auto* now = find(animated, ns::kVelocitiesNow, markers::kSideBars);
  ASSERT_TRUE(now);
  ASSERT_EQ(now->colors.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) expectColour(now->colors[i], i, "velocities now");
  // No text says "body 0" (or any body's index) where it names a body.
  for (const auto* array : {&fixed, &animated}) {
    for (const auto& m : array->markers) {
      if (m.type != visualization_msgs::Marker::TEXT_VIEW_FACING) continue;
      for (const char* index_name : {"body 0", "body 1", "body 2", "body 3", "body 4"}) {
        EXPECT_EQ(m.text.find(index_name), std::string::npos) << m.ns << "/" << m.id << " '" << m.text << "'";
      }
    }
  }
}

}  // namespace
