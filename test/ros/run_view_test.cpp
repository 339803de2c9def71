// RunView, the view description rviz and the page share, on small RunRecords built from
// hand-made messages (no master): each scene kind of issue 31.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "collision_lab/ros/markers/draw.h"
#include "collision_lab/ros/run_view.h"

namespace {

using collision_lab::CollisionEvent;
using collision_lab::InitialConditions;
using collision_lab_ros::makeRunView;
using collision_lab_ros::RunRecord;

const double kInf = std::numeric_limits<double>::infinity();

InitialConditions input(std::vector<double> m, std::vector<double> x, std::vector<double> v) {
  InitialConditions in;
  in.run_id = "test";
  in.masses = m;
  in.positions = x;
  in.velocities = v;
  in.restitution.assign(m.size() > 1 ? m.size() - 1 : 0, 1.0);
  in.max_collisions = 1000;
  return in;
}

CollisionEvent impact(std::uint64_t index, std::uint32_t pair, double t, double x, double v_right, double v_left) {
  CollisionEvent e;
  e.kind = CollisionEvent::KIND_IMPACT;
  e.index = index;
  e.pair_index = pair;
  e.first_moved = pair;
  e.last_moved = pair + 1;
  e.time = t;
  e.position = x;
  e.restitution = 1.0;
  e.pair_velocities_after = {v_right, v_left};
  return e;
}

collision_lab::RunSummary simulatedSummary(std::uint64_t count) {
  collision_lab::RunSummary s;
  s.run_id = "test";
  s.simulated = true;
  s.collision_count = count;
  s.stop_reason = "FINISHED";
  return s;
}

TEST(RunView, CountsAreWrittenForPeople) {
  EXPECT_EQ(collision_lab_ros::collisionsText(1), "1 collision");
  EXPECT_EQ(collision_lab_ros::collisionsText(31415), "31,415 collisions");
  EXPECT_EQ(collision_lab_ros::bodyColourHex(0), "#f24040");  // rviz's red for A
}

// Numbers for people, in rviz's font too: no e-notation that wraps, no superscript digits.
TEST(RunView, NumbersAreWrittenWithoutENotation) {
  EXPECT_EQ(collision_lab_ros::numberText(2.119e8), "2.119×10^8");
  EXPECT_EQ(collision_lab_ros::numberText(1.2e-7), "1.2×10^-7");
  EXPECT_EQ(collision_lab_ros::numberText(0.0065), "0.0065");
  EXPECT_EQ(collision_lab_ros::numberText(12.0), "12");
  EXPECT_EQ(collision_lab_ros::numberText(1.31316e8, 6), "1.31316×10^8");
  EXPECT_EQ(collision_lab_ros::numberText(0.25, 6), "0.25");
}

// rviz's status line names a long run's time in the same style (it used "t = 1.31316e+08 s").
TEST(RunView, StatusLineTimeHasNoENotation) {
  collision_lab_ros::SceneState state;
  state.time = 1.31316e8;
  const std::string line = collision_lab_ros::markers::statusLine(collision_lab_ros::RunView{}, state, {});
  EXPECT_EQ(line.rfind("t = 1.31316×10^8 s", 0), 0u) << line;
  EXPECT_EQ(line.find("e+"), std::string::npos) << line;
}

TEST(RunView, NotSimulatedRunClaimsNoSimulatedCount) {
  auto in = input({100, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  in.max_collisions = 10;
  RunRecord run(in);
  collision_lab::Prediction p;
  p.model = collision_lab::Prediction::MODEL_THREE_BODY_ROTATION;
  p.collision_count = 31;
  p.collision_count_defined = true;
  run.prediction = p;
  collision_lab::RunSummary s;
  s.simulated = false;
  s.stop_reason = "NOT_SIMULATED";
  s.collision_count = 31;  // the model's count, not a simulated one
  run.summary = s;
  const auto view = makeRunView(run);
  EXPECT_EQ(view.state, "not simulated");
  EXPECT_EQ(view.not_simulated.rfind("not simulated: ", 0), 0u) << view.not_simulated;
  EXPECT_NE(view.not_simulated.find("than the cap of 10,"), std::string::npos) << view.not_simulated;
  EXPECT_FALSE(view.simulated);
  EXPECT_FALSE(view.simulated_collisions.has_value());
  ASSERT_TRUE(view.predicted_collisions.has_value());
  EXPECT_EQ(*view.predicted_collisions, 31u);
  EXPECT_EQ(view.counter.find("finished"), std::string::npos) << view.counter;
  EXPECT_NE(view.counter.find("predicted 31 collisions"), std::string::npos) << view.counter;
  // The note is true on the page (no plots, the model's answer) and in rviz (the closed
  // form's final velocities as dots). (Failed before: "the plots show ...".)
  EXPECT_EQ(view.note.find("plots"), std::string::npos) << view.note;
  EXPECT_NE(view.note.find("no collision simulated"), std::string::npos) << view.note;
  EXPECT_NE(view.note.find("the final velocities shown are the closed form's"), std::string::npos) << view.note;

  // The cap named is the one that applied: the lab's when the input asked for none, or for
  // more than the prediction (its ceiling lowered it). (Failed before: "the cap of 0", "the
  // cap of 18,446,744,073,709,551,615".)
  for (const std::uint64_t asked : {std::uint64_t{0}, std::numeric_limits<std::uint64_t>::max()}) {
    in.max_collisions = asked;
    RunRecord lab_capped(in);
    lab_capped.prediction = p;
    lab_capped.summary = s;
    const std::string text = makeRunView(lab_capped).not_simulated;
    EXPECT_NE(text.find("than this lab's cap (its ~max_collisions"), std::string::npos) << text;
    EXPECT_EQ(text.find("cap of"), std::string::npos) << text;
  }
}

TEST(RunView, TruncatedRunSaysSoInOneSentence) {
  RunRecord run(input({1, 1}, {1, 0}, {-1, 1}));
  auto s = simulatedSummary(1000);
  s.truncated = true;
  s.truncation_reason = "stopped at the cap of 1000 impacts (truncated); two walls keep the bodies colliding";
  run.summary = s;
  const auto view = makeRunView(run);
  EXPECT_EQ(view.state, "truncated");
  EXPECT_EQ(view.truncated, "stopped at the cap of 1000 impacts; two walls keep the bodies colliding.");
  EXPECT_EQ(view.note.find("(truncated"), std::string::npos) << view.note;
  EXPECT_EQ(view.note, collision_lab_ros::markers::runNote(run));  // rviz's note is the view's
}

TEST(RunView, CollapseIsNamedWithTimePointAndBodies) {
  auto in = input({1, 1, 1}, {2, 1, 0}, {-1, 0, 1});
  in.restitution = {0.05, 0.05};
  RunRecord run(in);
  CollisionEvent collapse;
  collapse.kind = CollisionEvent::KIND_COLLAPSE;
  collapse.index = 0;
  collapse.first_moved = 0;
  collapse.last_moved = 2;
  collapse.time = 3.5;
  collapse.position = 1.25;
  collapse.pair_velocities_after = {0.0, 0.0};
  run.add(collapse);
  auto s = simulatedSummary(0);
  s.collapsed = true;
  s.collapse_count = 1;
  run.summary = s;
  const auto view = makeRunView(run);
  EXPECT_EQ(view.collapse, "collapse at t = 3.5 s, x = 1.25 m, bodies A..C");
  EXPECT_NE(view.title.find("+ 1 collapse"), std::string::npos) << view.title;
  EXPECT_EQ(view.title.find("collapse(s)"), std::string::npos) << view.title;
}

// cluster_collapse_5: A..C collapse at t = 3.5 s after impact 8, then A..E at t = 10.43 s
// after impact 16. Both are named, and the counter and the title count both (the counter
// said "+ 1 collapse", and only the first was named).
TEST(RunView, EveryCollapseIsNamedAndCounted) {
  auto in = input({1, 1, 1, 1, 1}, {4, 3, 2, 1, 0}, {-1, 0, 0, 0, 0});
  in.restitution = {0.05};
  RunRecord run(in);
  const auto collapseAfter = [](std::uint64_t index, std::uint32_t last, double t, double x, double v) {
    CollisionEvent c;
    c.kind = CollisionEvent::KIND_COLLAPSE;
    c.index = index;
    c.first_moved = 0;
    c.last_moved = last;
    c.time = t;
    c.position = x;
    c.pair_velocities_after = {v, v};
    return c;
  };
  for (std::uint64_t k = 1; k <= 16; ++k) {
    run.add(impact(k, static_cast<std::uint32_t>(k % 4), 0.5 * static_cast<double>(k), 1.0, -0.2, -0.2));
    if (k == 8) run.add(collapseAfter(8, 2, 3.5, 1.8333333333333333, -1.0 / 3));
  }
  run.add(collapseAfter(16, 4, 10.433529702243725, -0.08670594044874491, -0.2));
  auto s = simulatedSummary(16);
  s.collapsed = true;
  s.collapse_count = 2;
  run.summary = s;
  const auto view = makeRunView(run);
  EXPECT_EQ(view.collapse_count, 2u);
  EXPECT_EQ(view.collapse,
            "collapse at t = 3.5 s, x = 1.83333 m, bodies A..C; collapse 2 at t = 10.4335 s, x = -0.0867059 m, "
            "bodies A..E");
  EXPECT_EQ(view.collapse_brief, "collapse at t = 3.5 s, x = 1.83333 m, bodies A..C; 1 more");
  EXPECT_EQ(view.counter, "16 collisions + 2 collapses, finished");
  EXPECT_NE(view.title.find("16 + 2 collapses"), std::string::npos) << view.title;
}

// Three equal masses at e = 0.05 collapse; at 0.072 they do not, but their final velocities
// round to the same doubles (-1/3 m/s): the restitution against the critical one tells them
// apart (issue 45: both pages looked alike).
TEST(RunView, CollapseAndNearMissAreToldApart) {
  const auto viewAt = [](double e, bool collapsed, std::uint64_t count) {
    auto in = input({1, 1, 1}, {2, 1, 0}, {-1, 0, 0});
    in.restitution = {e};
    RunRecord run(in);
    collision_lab::Prediction p;
    p.model_name = "three_body_spiral";
    p.critical_restitution = 0.07179676972449082;
    p.collapsed = collapsed;
    p.collision_count_defined = !collapsed;
    p.collision_count = count;
    p.final_velocities = {-1.0 / 3, -1.0 / 3, -1.0 / 3};
    run.prediction = p;
    return makeRunView(run);
  };
  EXPECT_EQ(viewAt(0.05, true, 0).spiral,
            "collapse: e = 0.05 is at most the critical restitution r_c = 0.0717968: infinitely many collisions in a "
            "finite time, then the three move as one");
  EXPECT_EQ(viewAt(0.072, false, 63).spiral,
            "no collapse: after 63 collisions the bodies move apart (e = 0.072 is above the critical restitution "
            "r_c = 0.0717968), more slowly than the digits shown can tell");
  // Below r_c and no collapse all the same (e = 0 sticks: 2 collisions): the model decides.
  EXPECT_EQ(viewAt(0.0, false, 2).spiral,
            "no collapse: after 2 collisions the bodies move apart, more slowly than the digits shown can tell");
  EXPECT_EQ(makeRunView(RunRecord(input({1, 2, 3}, {2, 1, 0}, {-1, 0, 0}))).spiral, "");
}

TEST(RunView, WorldlinesReachTheRunsEnd) {
  // Two carts meet at t = 0.5 s and part: the diagram goes on past the impact.
  RunRecord run(input({1, 1}, {1, 0}, {-1, 1}));
  run.add(impact(1, 0, 0.5, 0.5, 1.0, -1.0));
  run.summary = simulatedSummary(1);
  const auto view = makeRunView(run);
  ASSERT_GT(view.end_time, 0.5);
  EXPECT_EQ(view.counter, "1 collision, finished");
  const auto lines = collision_lab_ros::worldlineSegments(run, view.end_time);
  ASSERT_EQ(lines.size(), 2u);
  for (const auto& line : lines) {
    ASSERT_FALSE(line.segments.back().empty());
    EXPECT_DOUBLE_EQ(line.segments.back().back().first, view.end_time) << "body " << line.body;
  }
  EXPECT_NEAR(lines[0].segments.back().back().second, 0.5 + (view.end_time - 0.5), 1e-12);
  EXPECT_EQ(view.worldline_legend, "all 2 bodies");
  ASSERT_EQ(view.worldline_bodies.size(), 2u);
  EXPECT_EQ(view.worldline_bodies[1].name, "B");
  EXPECT_EQ(view.worldline_bodies[1].colour, collision_lab_ros::bodyColourHex(1));
}

TEST(RunView, RingIsNamedAndItsWorldlinesAreCutAtTheSeam) {
  auto in = input({1, 1}, {900, 100}, {-300, 300});  // they meet across the seam at x = 0
  in.ring = 1000;
  RunRecord run(in);
  run.add(impact(1, 0, 0.5 / 3, 0.0, 300.0, -300.0));
  run.summary = simulatedSummary(1);
  const auto view = makeRunView(run);
  EXPECT_EQ(view.kind, "ring");
  EXPECT_EQ(view.ring, "ring of 1,000 m");
  const auto lines = collision_lab_ros::worldlineSegments(run, view.end_time);
  std::size_t segments = 0;
  for (const auto& line : lines) {
    segments += line.segments.size();
    EXPECT_DOUBLE_EQ(line.segments.back().back().first, view.end_time);
    for (const auto& segment : line.segments) {
      for (std::size_t k = 0; k < segment.size(); ++k) {
        EXPECT_GE(segment[k].second, 0.0);
        EXPECT_LE(segment[k].second, 1000.0);
        if (k > 0) {
          EXPECT_LE(std::abs(segment[k].second - segment[k - 1].second), 500.0) << "spans the seam";
        }
      }
    }
  }
  EXPECT_GT(segments, lines.size()) << "no worldline was cut at the seam";
}

TEST(RunView, BoxOfManyBodiesNamesTheShownBodies) {
  std::vector<double> m(1002, 1.0), x(1002), v(1002, 0.0);
  m.front() = m.back() = kInf;
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(x.size() - 1 - i);
  v[1] = -1.0;
  auto in = input(m, x, v);
  in.restitution.assign(in.restitution.size(), 0.9);  // a granular gas in a box
  RunRecord run(in);
  const auto view = makeRunView(run);
  EXPECT_TRUE(view.gas);
  ASSERT_FALSE(view.temperature.empty());
  // T = (sum m v^2 - P^2 / M) / N over the 1,000 finite masses [J].
  EXPECT_DOUBLE_EQ(view.temperature.front().first, 0.0);
  EXPECT_NEAR(view.temperature.front().second, (1.0 - 1.0 / 1000) / 1000, 1e-15);
  EXPECT_EQ(view.kind, "box");
  EXPECT_EQ(view.box, "box: walls at both ends");
  EXPECT_EQ(view.worldline_legend, "24 of 1,002 bodies, evenly spaced, the outermost two included");
  ASSERT_EQ(view.worldline_bodies.size(), 24u);
  EXPECT_EQ(view.worldline_bodies.front().name, "A");
  EXPECT_EQ(view.worldline_bodies.back().name, "#1001");
  EXPECT_EQ(view.state, "running");
}

}  // namespace
