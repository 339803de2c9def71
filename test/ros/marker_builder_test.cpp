// rviz markers from a run's messages (no master). References are independent of the
// marker code: the core's full event list, hand-derived numbers, physical invariants, and
// rviz 1.14's own limits.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/ids.h"
#include "collision_lab/ros/markers/layout.h"
#include "collision_lab/ros/msg_conversion.h"
#include "marker_test_checks.h"

namespace {

using namespace collision_lab_ros;
using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;
using Array3 = std::array<double, 3>;

const double kInf = std::numeric_limits<double>::infinity();

/// A run as the node feeds it to the view, and the core's full event list beside it.
struct Fed {
  RunRecord run;
  std::vector<collision_lab::CollisionEvent> events;
};

struct FeedOptions {
  RecordLimits limits;
  std::uint8_t mode = collision_lab::InitialConditions::MODE_FULL;
  std::uint64_t max_collisions = 10'000'000;
  bool skip_simulation_over_cap = true;  ///< as the node does
  bool keep_events = true;
};

FeedOptions withMode(std::uint8_t mode) {
  FeedOptions o;
  o.mode = mode;
  return o;
}

Fed feed(const Array3& masses, const Array3& positions, const Array3& velocities, const FeedOptions& o = {}) {
  const collision_lab::core::Scene scene = collision_lab::core::threeBodies(masses, positions, velocities);
  const collision_lab::core::RunMode run_mode = *toRunMode(o.mode);
  collision_lab::InitialConditions input = toInitialConditions(scene, run_mode, o.max_collisions);
  input.run_id = "markers";
  Fed fed{RunRecord(input, o.limits), {}};
  // The node's one path: plan, publish the prediction, run, summarise.
  const collision_lab::core::ScenePlan plan = collision_lab::core::planScene(toScene(input));
  fed.run.prediction = toPredictionMsg(plan);
  collision_lab::core::SceneRunOptions options;
  options.lab.mode = run_mode;
  options.lab.max_collisions = o.max_collisions;
  options.lab.events = collision_lab::core::EventPolicy::none();
  options.simulate_to_cap = !o.skip_simulation_over_cap;
  collision_lab::core::SceneVisitors visitors;
  SceneEventConverter converter(plan.scene);
  visitors.impact = [&](const collision_lab::core::ImpactRecord& e) {
    const auto msg = converter.impact(e);
    fed.run.add(msg);
    if (o.keep_events) fed.events.push_back(msg);
  };
  fed.run.summary = toRunSummaryMsg(collision_lab::core::runScene(plan, options, visitors), 3, run_mode);
  return fed;
}

Array3 toArray(const std::vector<double>& a) { return {a.at(0), a.at(1), a.at(2)}; }

// ---- Envelope ----

TEST(Envelope, KeepsFewVerticesExactlyAsSteps) {
  Envelope e;
  e.add(0, 1);
  e.step(1, -2);
  e.step(2, 3);
  e.step(3, 3);  // unchanged: held, no jump
  const auto poly = e.polyline();
  const std::vector<std::pair<double, double>> expected{{0, 1}, {1, 1}, {1, -2}, {2, -2}, {2, 3}, {3, 3}};
  ASSERT_EQ(poly.size(), expected.size());
  for (std::size_t k = 0; k < poly.size(); ++k) {
    EXPECT_EQ(poly[k].x, expected[k].first) << k;
    EXPECT_EQ(poly[k].y, expected[k].second) << k;
  }
  EXPECT_TRUE(e.exact());
  EXPECT_EQ(e.minY(), -2);
  EXPECT_EQ(e.maxY(), 3);
}

TEST(Envelope, ManyVerticesBecomeBoundedColumnsThatKeepEveryExtreme) {
  // A sawtooth +-1 over 100,000 steps, one spike of 1e6 at step 77,777.
  Envelope e(64);
  e.add(0, -1);
  for (int k = 1; k <= 100000; ++k) e.step(k, k == 77777 ? 1e6 : (k % 2 ? 1.0 : -1.0));
  const auto poly = e.polyline();
  EXPECT_FALSE(e.exact());
  EXPECT_LE(poly.size(), 64u);
  double top = -kInf, bottom = kInf;
  for (std::size_t k = 0; k < poly.size(); ++k) {
    if (k > 0) {
      EXPECT_GE(poly[k].x, poly[k - 1].x);
    }
    top = std::max(top, poly[k].y);
    bottom = std::min(bottom, poly[k].y);
    EXPECT_TRUE(poly[k].y == 1 || poly[k].y == -1 || poly[k].y == 1e6) << poly[k].y;
  }
  EXPECT_EQ(top, 1e6);  // a spike one step wide is never averaged away
  EXPECT_EQ(bottom, -1);
  EXPECT_EQ(poly.front().x, 0);
  EXPECT_EQ(poly.back().x, 100000);
}

TEST(Envelope, ColumnEdgesLieOnTheSegmentsTheyCut) {
  // A straight line y = 3 x - 1 given by far-apart vertices: every point drawn is on it.
  Envelope e(16);
  for (int k = 0; k <= 40; ++k) e.add(2.5 * k, 3 * 2.5 * k - 1);
  EXPECT_FALSE(e.exact());
  for (const auto& v : e.polyline()) EXPECT_NEAR(v.y, 3 * v.x - 1, 1e-12 * (1 + std::abs(v.y))) << v.x;
}

// ---- the record and the trajectory shown ----

TEST(MarkerBuilder, StateFollowsTheExactTrajectory) {
  const Fed fed = feed({1, 1, 1}, {2, 1, -1}, {-1, 0, 1});
  const RunRecord& run = fed.run;
  ASSERT_EQ(fed.events.size(), 3u);
  const SceneState start = stateAt(run, 0.0);
  EXPECT_EQ(start.collisions, 0u);
  EXPECT_DOUBLE_EQ(start.positions[0], 2.0);
  const SceneState half = stateAt(run, 0.5);
  EXPECT_DOUBLE_EQ(half.positions[0], 1.5);
  EXPECT_DOUBLE_EQ(half.positions[2], -0.5);
  // At each collision the bodies are where the event says.
  for (std::size_t k = 0; k < fed.events.size(); ++k) {
    const auto& e = fed.events[k];
    const SceneState at = stateAt(run, e.time);
    EXPECT_EQ(at.collisions, k + 1);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(at.positions[i], e.positions[i], 1e-12);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(at.velocities[i], e.velocities_after[i]);
  }
  EXPECT_GT(endTime(run), fed.events.back().time);
}

/// The exact state after `collisions` collisions, flown to t, from the full event list.
void expectExact(const Fed& fed, const SceneState& s, double tolerance) {
  const auto n = static_cast<std::size_t>(s.collisions);
  ASSERT_LE(n, fed.events.size());
  const double from = n == 0 ? 0.0 : fed.events[n - 1].time;
  const double until = n < fed.events.size() ? fed.events[n].time : kInf;
  EXPECT_GE(s.time, from);
  EXPECT_LE(s.time, until) << "collision " << n + 1 << " should have happened by t = " << s.time;
  const Array3 x0 = n == 0 ? toArray(fed.run.input().positions) : toArray(fed.events[n - 1].positions);
  const Array3 v0 = n == 0 ? toArray(fed.run.input().velocities) : toArray(fed.events[n - 1].velocities_after);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(s.velocities[i], v0[i]);
    EXPECT_NEAR(s.positions[i], x0[i] + v0[i] * (s.time - from), tolerance) << i;
  }
  // Never out of order: B between A and C, C at the wall.
  EXPECT_GE(s.positions[0] + tolerance, s.positions[1]);
  EXPECT_GE(s.positions[1] + tolerance, s.positions[2]);
}

TEST(MarkerBuilder, PiDigitsFiveIsNeverExtrapolatedAndTheCounterReachesTheTrueCount) {
  // Galperin's billiard, m_A/m_B = 1e8: the count is the first 5 digits of pi.
  const Fed fed = feed({1e8, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  const RunRecord& run = fed.run;
  ASSERT_EQ(fed.events.size(), 31415u);
  EXPECT_TRUE(run.finished());
  EXPECT_LE(run.keyframes().size(), kMarkerKeyframes);
  const double end = endTime(run);
  for (int k = 0; k <= 4000; ++k) expectExact(fed, stateAt(run, end * k / 4000), 1e-9);
  const TimeWarp warp(run);
  std::uint64_t previous = 0;
  for (int k = 0; k <= 4000; ++k) {
    const SceneState s = stateAt(run, warp.timeAt(k / 4000.0));
    expectExact(fed, s, 1e-9);
    EXPECT_GE(s.collisions, previous);
    previous = s.collisions;
  }
  EXPECT_EQ(stateAt(run, warp.timeAt(1.0)).collisions, 31415u);
  // The old view stopped at 1,000 and flew B off at 998 m/s: far past the wall.
  EXPECT_GT(stateAt(run, end).positions[1], 0.0);
}

TEST(MarkerBuilder, HeavilyDecimatedRecordShowsOnlyExactStates) {
  // 314 collisions kept in 16 keyframes: most instants are not kept, none is invented.
  FeedOptions small;
  small.limits = RecordLimits{16, 64};
  const Fed fed = feed({1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}, small);
  ASSERT_EQ(fed.events.size(), 314u);
  EXPECT_LE(fed.run.keyframes().size(), 16u);
  EXPECT_EQ(fed.run.keyframes().front().index, 1u);
  EXPECT_EQ(fed.run.keyframes().back().index, 314u);
  const double end = endTime(fed.run);
  for (int k = 0; k <= 3000; ++k) expectExact(fed, stateAt(fed.run, end * k / 3000), 1e-9);
  EXPECT_EQ(stateAt(fed.run, end).collisions, 314u);
}

TEST(MarkerBuilder, MillionsOfCollisionsInBoundedMemory) {
  // (1e12, 1, 1e12) from rest: 2,221,441 collisions (shared/physics.md).
  FeedOptions lean;
  lean.keep_events = false;
  const Fed fed = feed({1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0}, lean);
  const RunRecord& run = fed.run;
  EXPECT_EQ(run.collisions(), 2221441u);
  EXPECT_TRUE(run.finished());
  EXPECT_LE(run.keyframes().size(), kMarkerKeyframes);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(run.velocity(i).polyline().size(), kMarkerEnvelopeVertices);
    EXPECT_LE(run.worldline(i).polyline().size(), kMarkerEnvelopeVertices);
  }
  EXPECT_EQ(stateAt(run, TimeWarp(run).timeAt(1.0)).collisions, 2221441u);
}

TEST(MarkerBuilder, UnfinishedRunsStopWhereTheirKnownTrajectoryEnds) {
  // Predict-only over the cap: A (2 m, -1 m/s) reaches B (1 m, at rest) at t = 1 s; what
  // happens after is not simulated, so the picture holds there.
  const Fed over =
      feed({1e30, 1, kInf}, {2, 1, 0}, {-1, 0, 0}, withMode(collision_lab::InitialConditions::MODE_PREDICT_ONLY));
  EXPECT_FALSE(over.run.finished());
  const SceneState held = stateAt(over.run, 1e9);
  EXPECT_EQ(held.collisions, 0u);
  EXPECT_DOUBLE_EQ(held.time, 1.0);
  EXPECT_DOUBLE_EQ(held.positions[0], 1.0);
  EXPECT_DOUBLE_EQ(held.positions[1], 1.0);
  EXPECT_DOUBLE_EQ(endTime(over.run), 1.0);

  // Truncated at 10 collisions: shown up to the 11th contact, never beyond.
  FeedOptions capped;
  capped.max_collisions = 10;
  capped.skip_simulation_over_cap = false;
  const Fed cut = feed({1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}, capped);
  ASSERT_EQ(cut.events.size(), 10u);
  EXPECT_FALSE(cut.run.finished());
  const SceneState last = stateAt(cut.run, 1e9);
  EXPECT_EQ(last.collisions, 10u);
  EXPECT_NEAR(freeFlightHorizon(last.positions, last.velocities), 0.0, 1e-12);
  expectExact(cut, last, 1e-12);

  // Nothing collides and the run is over: the free flight is exact for ever.
  const Fed apart = feed({1, 1, 1}, {2, 1, 0}, {1, 0, -1});
  EXPECT_TRUE(apart.run.finished());
  const SceneState later = stateAt(apart.run, 5.0);
  EXPECT_DOUBLE_EQ(later.positions[0], 7.0);
  EXPECT_DOUBLE_EQ(later.positions[2], -5.0);
}

TEST(MarkerBuilder, RepeatedAndMissingCollisionsAreNotInvented) {
  Fed fed = feed({1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  collision_lab::InitialConditions input = fed.run.input();
  RunRecord gappy(input);
  for (std::size_t k = 0; k < fed.events.size(); ++k) {
    if (k == 5 || k == 6) continue;  // lost on the way
    gappy.add(fed.events[k]);
    if (k == 3) gappy.add(fed.events[k]);  // delivered twice
  }
  EXPECT_EQ(gappy.missedCollisions(), 2u);
  EXPECT_EQ(gappy.collisions(), 314u);
  // Between collisions 5 and 8 nothing is known beyond the instants of 5 and 8.
  const double t5 = fed.events[4].time, t8 = fed.events[7].time;
  const SceneState s = stateAt(gappy, (t5 + t8) / 2);
  EXPECT_TRUE(s.time == t5 || s.time == t8) << s.time;
}

TEST(MarkerBuilder, TimelineClockFollowsRosTime) {
  const ros::Time start(1000, 0);
  EXPECT_DOUBLE_EQ(simulatedTimeOnTimeline(ros::Time(1003, 0), start, 2.0), 1.5);
  EXPECT_DOUBLE_EQ(simulatedTimeOnTimeline(ros::Time(1003, 0), start, 0.0), 3.0);
  EXPECT_DOUBLE_EQ(simulatedTimeOnTimeline(ros::Time(1003, 0), start, -1.0), 3.0);
  EXPECT_DOUBLE_EQ(simulatedTimeOnTimeline(ros::Time(1003, 0), start, std::nan("")), 3.0);
  EXPECT_DOUBLE_EQ(simulatedTimeOnTimeline(ros::Time(999, 0), start, 1.0), 0.0);
}

TEST(MarkerBuilder, ReplayNeverShowsATimeBeforeTheNewestCollisionReceived) {
  // Equal masses at (2, 1, -1) m, v = (-1, 0, 1) m/s: collisions at t = 1, 1.5 and 2 s (by
  // hand: equal masses swap velocities). Replayed at 2 bag s per simulated s from 1000 s.
  const Fed fed = feed({1, 1, 1}, {2, 1, -1}, {-1, 0, 1});
  ASSERT_EQ(fed.events.size(), 3u);
  collision_lab::InitialConditions input = fed.run.input();
  input.header.stamp = ros::Time(1000, 0);
  RunRecord replay(input);
  replay.prediction = fed.run.prediction;
  replay.prediction->timeline_scale = 2.0;
  replay.add(fed.events[0]);
  replay.add(fed.events[1]);
  // The clock ahead of the newest collision received: the timeline's time.
  EXPECT_DOUBLE_EQ(replayedTime(replay, ros::Time(1003, 500'000'000)), 1.75);
  // rosbag play's clock 5 ms short of the last collision's stamp (1004 s): its time.
  replay.add(fed.events[2]);
  EXPECT_NEAR(fed.events[2].time, 2.0, 1e-15);
  EXPECT_EQ(replayedTime(replay, ros::Time(1003, 995'000'000)), fed.events[2].time);
  EXPECT_EQ(stateAt(replay, replayedTime(replay, ros::Time(1003, 995'000'000))).collisions, 3u);
}

TEST(MarkerBuilder, ReplayGoesOnToTheRunsEndOnceTheBagsClockHasStopped) {
  // The same run as above (collisions at t = 1, 1.5 and 2 s, stamped at 2 bag s per simulated
  // s from 1000 s); its summary is the bag's last message, stamped at the last collision
  // (1004 s), where rosbag play's clock stops. The live view goes on to endTime = 2.5 s (25 %
  // past the last collision): A and C have parted from B. (Failed before: the replay stayed at
  // the last impact, 2 s, with A and B at one point.)
  const Fed fed = feed({1, 1, 1}, {2, 1, -1}, {-1, 0, 1});
  collision_lab::InitialConditions input = fed.run.input();
  input.header.stamp = ros::Time(1000, 0);
  RunRecord replay(input);
  replay.prediction = fed.run.prediction;
  replay.prediction->timeline_scale = 2.0;
  for (const auto& event : fed.events) replay.add(event);
  const double end = endTime(fed.run);
  ASSERT_DOUBLE_EQ(end, 2.5);
  const ros::Time stopped(1004, 0);
  ReplayClock clock;
  // Before the summary the bag may be paused: the clock holds.
  EXPECT_DOUBLE_EQ(clock.at(replay, stopped, 4.0), 2.0);
  EXPECT_DOUBLE_EQ(clock.at(replay, stopped, 4.2), 2.0);
  EXPECT_DOUBLE_EQ(replayedTime(replay, stopped), 2.0);  // where the replay ended before
  // The summary has come 4 wall s into the replay, at t = 2 s: 0.5 simulated s per wall s.
  replay.summary = fed.run.summary;
  EXPECT_DOUBLE_EQ(clock.at(replay, stopped, 4.0), 2.0);
  EXPECT_DOUBLE_EQ(clock.at(replay, stopped, 4.5), 2.25);
  EXPECT_DOUBLE_EQ(clock.at(replay, stopped, 30.0), end);
  const SceneState last = stateAt(replay, clock.at(replay, stopped, 30.0));
  EXPECT_EQ(last.collisions, 3u);
  EXPECT_GT(last.positions[0] - last.positions[1], 0.4);  // A and B apart again
  // A ROS clock ahead of the wall-time pace (a bag that goes on) is followed, up to the end.
  EXPECT_DOUBLE_EQ(clock.at(replay, ros::Time(1004, 600'000'000), 4.5), 2.3);
  // A new run starts afresh.
  clock.reset();
  EXPECT_DOUBLE_EQ(clock.at(replay, stopped, 10.0), 2.0);
}

TEST(MarkerBuilder, WarpPlaysDenseBurstsInSlowMotion) {
  const Fed fed = feed({1e8, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  const TimeWarp warp(fed.run);
  EXPECT_EQ(warp.timeAt(0.0), 0.0);
  EXPECT_EQ(warp.timeAt(1.0), endTime(fed.run));
  // The warp gives 85 % of the loop to the collision index and 15 % to time (so half-way
  // through the loop, between 0.35 / 0.85 and 0.5 / 0.85 of the collisions are done).
  const double done = static_cast<double>(stateAt(fed.run, warp.timeAt(0.5)).collisions) / 31415.0;
  EXPECT_GT(done, 0.35 / 0.85 - 0.01);
  EXPECT_LT(done, 0.5 / 0.85 + 0.01);
}

// ---- markers ----

using marker_checks::expectFitForRviz;
using marker_checks::expectOneMarkerPerId;
using marker_checks::find;

TEST(MarkerBuilder, EveryViewFitsRvizForEveryCount) {
  const std::vector<Fed> runs = {
      feed({1, 1, 1}, {2, 1, 0}, {1, 0, -1}),                  // 0 collisions
      feed({1, 1, 1}, {2, 1, 0}, {-1, 0, -2}),                 // 1
      feed({3, 1, 0.5}, {2, 1, 0}, {-1, 0, 0}),                // 2 (grazing)
      feed({1, 1, 1}, {2, 1, -1}, {-1, 0, 1}),                 // 3
      feed({100, 1, kInf}, {2, 1, 0}, {-1, 0, 0}),             // 31
      feed({1e8, 1, kInf}, {2, 1, 0}, {-1, 0, 0}),             // 31,415
      feed({1e30, 1, kInf}, {2, 1, 0}, {-1, 0, 0}, withMode(1)),  // predict-only, over any cap
      feed({1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}, withMode(2)),   // summary-only
      feed({kInf, 1, 2}, {3, 1, 0}, {-0.5, 0, 0}),             // moving wall
  };
  const std::vector<std::uint64_t> counts = {0, 1, 2, 3, 31, 31415, 0, 0};
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const RunRecord& run = runs[r].run;
    SCOPED_TRACE(r);
    if (r < counts.size()) {
      EXPECT_EQ(run.collisions(), counts[r]);
    }
    const auto fixed = buildStaticMarkers(run, "f");
    expectFitForRviz(fixed);
    std::set<std::string> namespaces;
    for (const auto& m : fixed.markers) namespaces.insert(m.ns);
    for (const char* ns : {markers::ns::kTitle, markers::ns::kScene, markers::ns::kWedge, markers::ns::kPlot,
                           markers::ns::kConserved, markers::ns::kWorldlines, markers::ns::kEnergy}) {
      EXPECT_TRUE(namespaces.count(ns)) << ns;
    }
    expectOneMarkerPerId(fixed);
    marker_checks::expectLegendMatchesDots(fixed);
    const double end = endTime(run);
    for (double t : {0.0, 0.3 * end, end, 2 * end}) {
      const auto animated = buildAnimatedMarkers(run, FrameClock{t, "test"}, "f");
      expectFitForRviz(animated);
      expectOneMarkerPerId(animated);
    }
  }
}

TEST(MarkerBuilder, RejectionBannerNamesTheRunAndTheStudent) {
  // (Failed before: the banner named the run only, so a class could not tell whose it was.)
  collision_lab::Rejected rejected;
  rejected.run_id = "pi_try";
  rejected.student = "ben";
  rejected.reason_name = "POSITIONS_NOT_ORDERED";
  rejected.field = "positions";
  rejected.message = "positions must be strictly decreasing";
  MarkerArray array;
  array.markers = rejectedBanner(rejected, "f");
  const Marker* text = find(array, markers::ns::kRejected, markers::kFramedText);
  ASSERT_TRUE(text);
  EXPECT_EQ(text->text.rfind("REJECTED run 'pi_try' of student 'ben': POSITIONS_NOT_ORDERED in positions", 0), 0u)
      << text->text;
  // Without a run_id (the node could not read one): still whose.
  rejected.run_id.clear();
  array.markers = rejectedBanner(rejected, "f");
  text = find(array, markers::ns::kRejected, markers::kFramedText);
  ASSERT_TRUE(text);
  EXPECT_EQ(text->text.rfind("REJECTED an input of student 'ben': ", 0), 0u) << text->text;
  // Without a student: the run alone, as before.
  rejected.run_id = "pi_try";
  rejected.student.clear();
  array.markers = rejectedBanner(rejected, "f");
  text = find(array, markers::ns::kRejected, markers::kFramedText);
  ASSERT_TRUE(text);
  EXPECT_EQ(text->text.rfind("REJECTED run 'pi_try': ", 0), 0u) << text->text;
}

TEST(MarkerBuilder, HintIsDrawnBoldSoThatItsUnderscoresShow) {
  // The hint is a command to copy, "/collision_lab/initial_conditions": rviz draws an
  // underscore a pixel thin and faint. It is drawn twice, a pixel apart, both over the panel.
  // (Failed before: one text, its underscores nearly invisible in the screenshot.)
  MarkerArray array;
  array.markers = hintMarkers("rostopic pub -1 /collision_lab/initial_conditions", "f");
  expectFitForRviz(array);
  const Marker* text = find(array, markers::ns::kHint, markers::kFramedText);
  const Marker* bold = find(array, markers::ns::kHint, markers::kFramedTextBold);
  const Marker* panel = find(array, markers::ns::kHint, markers::kFramedBox);
  ASSERT_TRUE(text && bold && panel);
  EXPECT_EQ(bold->text, text->text);
  EXPECT_EQ(bold->pose.position.x, text->pose.position.x);
  EXPECT_NEAR(text->pose.position.y - bold->pose.position.y, markers::layout::kBoldDy, 1e-12);
  EXPECT_LT(markers::layout::kBoldDy * 46, 1.5);  // about a pixel at rviz/collision_lab.rviz's scale
  EXPECT_GT(bold->pose.position.z, panel->pose.position.z);
  // The banner is not bold.
  collision_lab::Rejected rejected;
  rejected.reason_name = "EMPTY_SCENE";
  MarkerArray banner;
  banner.markers = rejectedBanner(rejected, "f");
  EXPECT_FALSE(find(banner, markers::ns::kRejected, markers::kFramedTextBold));
}

TEST(MarkerBuilder, RejectionBannerHoldsItsWholeTextOnAnOpaquePanelOverThePanelTitles) {
  // A message wider than the screen. (Failed before: the text ran out of its frame, the
  // frame had no background, and it lay on the panels' titles.)
  collision_lab::Rejected rejected;
  rejected.run_id = "student 7";
  rejected.reason_name = "POSITIONS_NOT_ORDERED";
  rejected.field = "positions";
  rejected.message = "positions (0, 1, 2, 3, 4, 5, 6) m must be strictly decreasing, x_A > x_B > x_C > x_D > x_E > "
                     "x_F > x_G: body A at 0 m is left of body B at 1 m, and so on for every pair";
  const auto banner = rejectedBanner(rejected, "f");
  MarkerArray array;
  array.markers = banner;
  expectFitForRviz(array);
  marker_checks::expectTextsOnScreen(array);
  const Marker* text = find(array, markers::ns::kRejected, markers::kFramedText);
  const Marker* panel = find(array, markers::ns::kRejected, markers::kFramedBox);
  ASSERT_TRUE(text && panel);
  // Every word is there, in order (wrapped, never cut).
  std::string words = text->text;
  std::replace(words.begin(), words.end(), '\n', ' ');
  EXPECT_NE(words.find(rejected.message), std::string::npos) << text->text;
  // An opaque panel, filled in rviz's background colour, over every view (bodies reach
  // z = 0.45) and under its text.
  ASSERT_EQ(panel->type, Marker::TRIANGLE_LIST);
  ASSERT_EQ(panel->colors.size(), panel->points.size());
  EXPECT_EQ(panel->colors.front().a, 1.0f);
  EXPECT_LT(panel->colors.front().r + panel->colors.front().g + panel->colors.front().b, 0.5f);
  EXPECT_GT(panel->pose.position.z, 0.45);
  EXPECT_GT(text->pose.position.z, panel->pose.position.z);
  double left = kInf, right = -kInf, bottom = kInf, top = -kInf;
  for (const auto& p : panel->points) {
    left = std::min(left, p.x), right = std::max(right, p.x), bottom = std::min(bottom, p.y), top = std::max(top, p.y);
  }
  const auto box = marker_checks::textBox(*text);
  EXPECT_GE(box.left, left);
  EXPECT_LE(box.right, right);
  EXPECT_GE(box.bottom, bottom);
  EXPECT_LE(box.top, top);
  EXPECT_GE(left, -10.7);
  EXPECT_LE(right, 16.3);
  // Clear of the panels' titles (at y = 4.55, 0.32 high).
  EXPECT_GT(bottom, markers::layout::kPanelTitleY + markers::layout::kTextSize / 2);
}

TEST(MarkerBuilder, RvizGuardThinsLongLinesAndDropsWhatRvizRejects) {
  MarkerArray array;
  Marker strip;
  strip.type = Marker::LINE_STRIP;
  strip.scale.x = 0.1;
  for (int k = 0; k < 40000; ++k) strip.points.emplace_back();
  Marker odd_list;
  odd_list.type = Marker::LINE_LIST;
  odd_list.id = 1;
  odd_list.points.resize(3);
  Marker blank;
  blank.type = Marker::TEXT_VIEW_FACING;
  blank.id = 2;
  blank.text = " \n";
  array.markers = {strip, odd_list, blank};
  EXPECT_EQ(enforceRvizLimits(array), 3u);
  ASSERT_EQ(array.markers.size(), 1u);
  EXPECT_LE(array.markers[0].points.size(), kRvizMaxLinePoints);
  EXPECT_GE(array.markers[0].points.size(), kRvizMaxLinePoints / 2);
}

TEST(MarkerBuilder, VelocitiesArePlottedAsSteps) {
  // Equal masses exchange velocities: v_A is -1, then 0 (after AB), 0 (BC), 1 (AB).
  const Fed fed = feed({1, 1, 1}, {2, 1, -1}, {-1, 0, 1});
  const auto poly = fed.run.velocity(0).polyline();
  const std::vector<std::pair<double, double>> expected{{0, -1}, {1, -1}, {1, 0}, {2, 0}, {3, 0}, {3, 1}};
  ASSERT_EQ(poly.size(), expected.size());
  for (std::size_t k = 0; k < poly.size(); ++k) {
    EXPECT_EQ(poly[k].x, expected[k].first) << k;
    EXPECT_EQ(poly[k].y, expected[k].second) << k;
  }
  // On screen every segment of every velocity line is horizontal or vertical.
  const auto fixed = buildStaticMarkers(fed.run, "f");
  for (int i = 0; i < 3; ++i) {
    const Marker* line = find(fixed, markers::ns::kPlot, markers::kPlotSeries + i);
    ASSERT_TRUE(line);
    ASSERT_EQ(line->type, Marker::LINE_STRIP);
    for (std::size_t k = 1; k < line->points.size(); ++k) {
      const auto& a = line->points[k - 1];
      const auto& b = line->points[k];
      EXPECT_TRUE(a.x == b.x || a.y == b.y) << i << ": " << k;
    }
  }
}

TEST(MarkerBuilder, PaperSeriesShownWhereItDiffers) {
  // shared/physics.md, erratum 2: masses (1, 1, 1), v0 = (-1, 0.3, 0.7); after 2
  // collisions the truth is (0.3, 0.7, -1), eq. (2.15) gives (-1.2125, 0.5125, -0.475).
  const Fed fed = feed({1, 1, 1}, {2, 1, 0}, {-1, 0.3, 0.7});
  const Array3 paper{-1.2125, 0.5125, -0.475}, truth{0.3, 0.7, -1};
  for (int i = 0; i < 3; ++i) {
    bool seen = false;
    for (const auto& v : fed.run.paperVelocity(i).polyline()) {
      if (v.x == 2 && std::abs(v.y - paper[i]) < 1e-12) {
        seen = true;
        EXPECT_NEAR(v.mark, std::abs(paper[i] - truth[i]), 1e-12);
      }
    }
    EXPECT_TRUE(seen) << i;
    const Marker* segments = find(buildStaticMarkers(fed.run, "f"), markers::ns::kPlot, markers::kPlotPaper + i);
    ASSERT_TRUE(segments) << i;
    EXPECT_EQ(segments->type, Marker::LINE_LIST);
  }
  // With a wall the printed formulas are undefined: no series, and the legend says so.
  const Fed wall = feed({100, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  const auto fixed = buildStaticMarkers(wall.run, "f");
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(find(fixed, markers::ns::kPlot, markers::kPlotPaper + i));
  const Marker* legend = find(fixed, markers::ns::kPlot, markers::kPlotLegend);
  ASSERT_TRUE(legend);
  EXPECT_NE(legend->text.find("undefined with a wall"), std::string::npos);
}

TEST(MarkerBuilder, BGetsItsOwnScaleWhenItDwarfsAandC) {
  // m_A/m_B = 1e4: B reaches about sqrt(1e4) = 100 m/s, A and C stay within 1 m/s.
  const auto labels = [](const MarkerArray& array) {
    std::set<std::string> texts;
    for (const auto& m : array.markers) {
      if (m.ns == markers::ns::kPlot) texts.insert(m.text);
    }
    return texts;
  };
  const auto pi = labels(buildStaticMarkers(feed({1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}).run, "f"));
  EXPECT_TRUE(pi.count("v_B [m/s]") && pi.count("v_A, v_C [m/s]"));
  const auto equal = labels(buildStaticMarkers(feed({1, 1, 1}, {2, 1, -1}, {-1, 0, 1}).run, "f"));
  EXPECT_TRUE(equal.count("v [m/s]") && !equal.count("v_B [m/s]"));
}

TEST(MarkerBuilder, WedgePathStaysOnItsCircle) {
  // |u_perp| is conserved by every collision, so every simulated point of the path lies
  // on one circle around the wedge's centre.
  const Fed fed = feed({1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0});
  const auto fixed = buildStaticMarkers(fed.run, "f");
  const Marker* path = find(fixed, markers::ns::kWedge, markers::kWedgeSimulated);
  const Marker* circle = find(fixed, markers::ns::kWedge, markers::kWedgeCircle);
  ASSERT_TRUE(path && circle);
  ASSERT_EQ(path->points.size(), fed.events.size() + 1);
  const double cx = (circle->points[0].x + circle->points[48].x) / 2;
  const double cy = (circle->points[0].y + circle->points[48].y) / 2;
  const double r = std::hypot(circle->points[0].x - cx, circle->points[0].y - cy);
  for (const auto& p : path->points) EXPECT_NEAR(std::hypot(p.x - cx, p.y - cy), r, 1e-6 * r);
}

}  // namespace
