// rviz draws the run's view description (RunView), the one the page draws (issue 31): for
// each scene kind (not simulated, truncated, collapse, ring, box, gas) the title, note,
// status line, bodies' legends, the bodies drawn and the T(t) panel are RunView's, for the
// same RunRecord. No master: the runs are hand-made messages or the core engine's.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collision_lab/ros/marker_builder.h"
#include "collision_lab/ros/markers/ids.h"
#include "collision_lab/ros/markers/layout.h"
#include "collision_lab/ros/run_view.h"
#include "marker_test_checks.h"
#include "marker_test_engine.h"

namespace {

using namespace collision_lab_ros;
using collision_lab::core::Scene;
using marker_checks::find;
using marker_engine::runScene;
using visualization_msgs::Marker;
namespace ids = collision_lab_ros::markers;
namespace layout = collision_lab_ros::markers::layout;

const double kInf = std::numeric_limits<double>::infinity();

/// rviz's wrapped text as one line (a line break is where a space was).
std::string unwrapped(std::string s) {
  for (char& c : s) c = c == '\n' ? ' ' : c;
  return s;
}

std::string textOf(const visualization_msgs::MarkerArray& array, const std::string& ns, int id) {
  const Marker* m = find(array, ns, id);
  return m ? unwrapped(m->text) : "(no marker " + ns + "/" + std::to_string(id) + ")";
}

/// "0.01" -> -2: a decade's label on the T(t) panel.
double exponentOf(const std::string& label) { return std::log10(std::stod(label)); }

/// The T(t) panel draws RunView::temperature (its points at t > 0, T > 0, in order, on the
/// log-log axes its labels name) and Haff's law with RunView's T0 and tau, with its legend.
void expectTemperatureIsTheViews(const RunRecord& run, const RunView& view) {
  const auto fixed = buildStaticMarkers(run, "f");
  const Marker* series = find(fixed, ids::ns::kTemperature, ids::kTemperatureSeries);
  ASSERT_TRUE(series);
  const double x0 = exponentOf(textOf(fixed, ids::ns::kTemperature, ids::kTemperatureTimeMin));
  const double x1 = exponentOf(textOf(fixed, ids::ns::kTemperature, ids::kTemperatureTimeMax));
  const double y0 = exponentOf(textOf(fixed, ids::ns::kTemperature, ids::kTemperatureMin));
  const double y1 = exponentOf(textOf(fixed, ids::ns::kTemperature, ids::kTemperatureMax));
  const auto& box = layout::kTemperatureBox;
  // On the axes, values beyond them at their edges.
  auto toX = [&](double t) {
    return box.left + std::clamp((std::log10(t) - x0) / (x1 - x0), 0.0, 1.0) * (box.right - box.left);
  };
  auto toY = [&](double T) {
    return box.bottom + std::clamp((std::log10(T) - y0) / (y1 - y0), 0.0, 1.0) * (box.top - box.bottom);
  };
  std::vector<std::pair<double, double>> shown;
  for (const auto& [t, T] : view.temperature) {
    if (t > 0 && T > 0) shown.emplace_back(t, T);
  }
  ASSERT_GE(shown.size(), 2u);
  ASSERT_EQ(series->points.size(), shown.size());
  for (std::size_t k = 0; k < shown.size(); ++k) {
    EXPECT_NEAR(series->points[k].x, toX(shown[k].first), 1e-9) << k;
    EXPECT_NEAR(series->points[k].y, toY(shown[k].second), 1e-9) << k;
  }
  // To the run's end: the view's last point is at end_time.
  EXPECT_DOUBLE_EQ(view.temperature.back().first, view.end_time);
  const Marker* haff = find(fixed, ids::ns::kTemperature, ids::kTemperatureHaff);
  ASSERT_EQ(haff != nullptr, view.haff_ok);
  if (haff) {
    // Its last point: T0 / (1 + t/tau)^2 at the run's end.
    const double t = view.end_time;
    const double value = view.haff_t0 / ((1 + t / view.haff_tau) * (1 + t / view.haff_tau));
    EXPECT_NEAR(haff->points.back().x, toX(t), 1e-9);
    EXPECT_NEAR(haff->points.back().y, toY(value), 1e-9);
  }
  const std::string legend = textOf(fixed, ids::ns::kTemperature, ids::kTemperatureLegend);
  EXPECT_NE(legend.find(view.temperature_legend), std::string::npos) << legend << "\nvs\n" << view.temperature_legend;
}

/// rviz's texts are the view's for this run: the title, the note, the status line's counter
/// and facts; with many bodies the legends and the bodies drawn; a gas's T(t).
void expectRvizDrawsTheView(const RunRecord& run) {
  const RunView view = makeRunView(run);
  SCOPED_TRACE(view.kind + ": " + view.title);
  const auto fixed = buildStaticMarkers(run, "f");
  const auto animated = buildAnimatedMarkers(run, FrameClock{endTime(run), ""}, "f");
  EXPECT_EQ(textOf(fixed, ids::ns::kTitle, ids::kTitleText), unwrapped(view.title));
  if (view.note.empty()) {
    EXPECT_FALSE(find(fixed, ids::ns::kScene, ids::kSceneNote));
  } else {
    EXPECT_EQ(textOf(fixed, ids::ns::kScene, ids::kSceneNote), view.note);
  }
  const std::string status = textOf(animated, ids::ns::kLabels, ids::kStatus);
  EXPECT_NE(status.find("     run: " + view.counter), std::string::npos) << status << "\nvs\n" << view.counter;
  for (const std::string& fact : {view.collapse, view.ring, view.box}) {
    if (!fact.empty()) EXPECT_NE(status.find(";  " + fact), std::string::npos) << status << "\nvs\n" << fact;
  }
  // A run not simulated has no collisions to count, only the model's answer.
  if (view.not_simulated.empty()) {
    EXPECT_NE(status.find("     collisions "), std::string::npos) << status;
  } else {
    EXPECT_EQ(status.find("     collisions "), std::string::npos) << status;
  }
  if (run.bodies() > kMaxPlottedBodies) {
    EXPECT_EQ(textOf(fixed, ids::ns::kPlot, ids::kPlotLegend), view.velocity_legend);
    const std::string world = textOf(fixed, ids::ns::kWorldlines, ids::kWorldLegend);
    EXPECT_NE(world.find(view.worldline_legend), std::string::npos) << world;
    // One worldline per body the view names, and no more.
    for (std::size_t k = 0; k < view.worldline_bodies.size(); ++k) {
      EXPECT_TRUE(find(animated, ids::ns::kWorldlinesNow, ids::kWorldNowLines + static_cast<int>(k))) << k;
    }
    EXPECT_FALSE(find(animated, ids::ns::kWorldlinesNow, ids::kWorldNowLines + static_cast<int>(view.worldline_bodies.size())));
    // One velocity series per body the view names, and no more.
    for (std::size_t k = 0; k < view.velocity_bodies.size(); ++k) {
      EXPECT_TRUE(find(fixed, ids::ns::kPlot, ids::kPlotTracked + static_cast<int>(k))) << k;
    }
    EXPECT_FALSE(find(fixed, ids::ns::kPlot, ids::kPlotTracked + static_cast<int>(view.velocity_bodies.size())));
    if (!view.ring.empty()) {
      EXPECT_EQ(textOf(animated, ids::ns::kLabels, ids::kSceneRangeNote), "a " + view.ring + ": its ends meet");
    }
  }
  if (run.bodies() <= kMaxPlottedBodies) {
    // Few bodies: each velocity series named as the view names its body.
    for (const ViewBody& body : view.velocity_bodies) {
      EXPECT_EQ(textOf(fixed, ids::ns::kPlot, ids::kPlotSeriesNames + static_cast<int>(body.index)), "v_" + body.name);
    }
  }
  if (view.gas) {
    expectTemperatureIsTheViews(run, view);
  } else {
    EXPECT_FALSE(find(fixed, ids::ns::kTemperature, ids::kTemperatureTitle));
  }
  marker_checks::expectTextsOnScreen(fixed);
  marker_checks::expectTextsOnScreen(animated);
}

Scene scene(std::vector<double> m, std::vector<double> x, std::vector<double> v, std::vector<double> e = {}) {
  Scene s;
  s.masses = m, s.positions = x, s.velocities = v, s.restitution = e;
  return s;
}

/// n bodies of 1 kg and 2 kg alternately, 1 m apart from `right` leftwards, seeded
/// velocities in [-1, 1] m/s.
Scene manyBodies(int n, double right, std::uint64_t seed) {
  Scene s;
  for (int i = 0; i < n; ++i) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    s.masses.push_back(i % 2 ? 2.0 : 1.0);
    s.positions.push_back(right - i);
    s.velocities.push_back(static_cast<double>(seed >> 11) / 9007199254740992.0 * 2 - 1);
  }
  return s;
}

// The pi scene with "Stop after 10": the model answered 31, nothing was simulated.
TEST(MarkerView, NotSimulatedRunSaysTheModelsAnswerAsTheViewDoes) {
  collision_lab::InitialConditions in;
  in.run_id = "pi_cap";
  in.masses = {100, 1, kInf}, in.positions = {2, 1, 0}, in.velocities = {-1, 0, 0};
  in.restitution = {1.0, 1.0};
  in.max_collisions = 10;
  RunRecord run(in);
  collision_lab::Prediction p;
  p.model = collision_lab::Prediction::MODEL_THREE_BODY_ROTATION;
  p.model_name = "three_body_rotation";
  p.collision_count = 31;
  p.collision_count_defined = true;
  p.final_velocities = {-0.98, 0.31, 0.0};
  run.prediction = p;
  collision_lab::RunSummary s;
  s.simulated = false;
  s.stop_reason = "NOT_SIMULATED";
  s.collision_count = 31;
  s.final_velocities = p.final_velocities;
  run.summary = s;
  ASSERT_EQ(makeRunView(run).state, "not simulated");
  expectRvizDrawsTheView(run);
  const auto status = textOf(buildAnimatedMarkers(run, FrameClock{0.0, ""}, "f"), ids::ns::kLabels, ids::kStatus);
  EXPECT_NE(status.find("run: not simulated: "), std::string::npos) << status;
  EXPECT_NE(status.find("predicted 31 collisions"), std::string::npos) << status;
}

// A gas between two walls stopped at the cap: truncated, a box, a gas with T(t).
TEST(MarkerView, TruncatedBoxSaysWhatTheViewSays) {
  Scene box = manyBodies(40, 40.0, 21);
  box.masses.insert(box.masses.begin(), kInf), box.positions.insert(box.positions.begin(), 41.0);
  box.velocities.insert(box.velocities.begin(), 0.0);
  box.masses.push_back(kInf), box.positions.push_back(-1.0), box.velocities.push_back(0.0);
  box.restitution = {0.9};
  const auto r = runScene(box, 2000, "box_cap");
  ASSERT_TRUE(r.result.truncated);
  const RunView view = makeRunView(r.record);
  ASSERT_EQ(view.kind, "box");
  ASSERT_EQ(view.state, "truncated");
  ASSERT_TRUE(view.gas);
  ASSERT_EQ(view.worldline_legend, "24 of 42 bodies, evenly spaced, the outermost two included");
  expectRvizDrawsTheView(r.record);
}

// Three equal masses at e = 0.05 collapse: the status names it with its time, point and bodies.
TEST(MarkerView, CollapseIsNamedAsTheViewNamesIt) {
  const auto r = runScene(scene({1, 1, 1}, {2, 1, 0}, {-1, 0, 0}, {0.05}), 1000, "collapse");  // collapse_equal
  const RunView view = makeRunView(r.record);
  ASSERT_FALSE(view.collapse.empty()) << r.result.stop_message;
  expectRvizDrawsTheView(r.record);
}

// Twelve bodies on a ring of 1,000 m: the ring is named as the view names it.
TEST(MarkerView, RingIsNamedAsTheViewNamesIt) {
  Scene ring = manyBodies(12, 900.0, 7);
  for (std::size_t i = 0; i < ring.positions.size(); ++i) ring.positions[i] = 900.0 - 75.0 * static_cast<double>(i);
  for (double& v : ring.velocities) v *= 100.0;
  ring.ring = 1000.0;
  const auto r = runScene(ring, 300, "ring");
  const RunView view = makeRunView(r.record);
  ASSERT_EQ(view.ring, "ring of 1,000 m");
  ASSERT_EQ(view.kind, "ring");
  expectRvizDrawsTheView(r.record);
}

// A free granular gas (no walls): T(t) and Haff's fit are the view's. It cools in its first
// seconds and then flies apart for 1e4 s and more: T(t) keeps its states evenly in log t,
// so the cooling is on the log axis. (Failed before: T was kept evenly in t, its first
// column 1/1000 of the run wide: the early cooling was lost on the log axis, as the free
// gas of granular_gas_100_end.png that began flat at 1e4 s.)
TEST(MarkerView, FreeGasDrawsTheViewsTemperature) {
  const auto r = runScene([] {
    Scene gas = manyBodies(100, 100.0, 5);
    gas.restitution = {0.9};
    return gas;
  }(), 20000, "gas");
  const RunView view = makeRunView(r.record);
  ASSERT_EQ(view.kind, "gas");
  ASSERT_TRUE(view.gas);
  ASSERT_GT(view.end_time, 1e4);
  ASSERT_GT(r.result.impact_count, 2 * kMarkerEnvelopeVertices);  // more than a plot keeps evenly in t
  std::size_t early = 0;
  for (const auto& [t, T] : view.temperature) early += t > 0 && t < view.end_time * 1e-3 ? 1 : 0;
  EXPECT_GE(early, 20u);
  expectRvizDrawsTheView(r.record);
}

// Two carts: a line of few bodies, where the status says the view's counter too.
TEST(MarkerView, FewBodiesSayTheViewsCounter) {
  const auto r = runScene(scene({1, 1}, {1, 0}, {-1, 1}, {0.8}), 100, "carts");
  ASSERT_EQ(makeRunView(r.record).counter, "1 collision, finished");
  expectRvizDrawsTheView(r.record);
}

}  // namespace
