// rviz draws the run's view description (RunView), the one the page draws (issue 31): for
// each scene kind (not simulated, truncated, collapse, ring, box, gas) the title, note,
// status line, bodies' legends, the bodies drawn and the T(t) panel are RunView's, for the
// same RunRecord. No master: the runs are hand-made messages or the core engine's.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>
#include <set>
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

/// "0.01" -> -2, "10,000" -> 4, "10^6" -> 6: a decade's label on the T(t) panel (never
/// e-notation).
double exponentOf(const std::string& label) {
  EXPECT_EQ(label.find('e'), std::string::npos) << label;
  if (label.rfind("10^", 0) == 0) return std::stod(label.substr(3));
  std::string digits;
  for (char c : label) if (c != ',') digits += c;
  return std::log10(std::stod(digits));
}

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

/// "#rrggbb" of a colour rviz draws; fails unless each channel is a whole byte (r/255), as
/// the view's hex says it.
std::string hexOf(const std_msgs::ColorRGBA& c) {
  std::string out = "#";
  for (double channel : {c.r, c.g, c.b}) {
    const double byte = channel * 255.0;
    EXPECT_NEAR(byte, std::round(byte), 1e-3) << "not a whole byte: " << channel;
    char hex[3];
    std::snprintf(hex, sizeof hex, "%02x", static_cast<unsigned>(std::lround(byte)));
    out += hex;
  }
  return out;
}

/// Every body rviz draws, in every panel, is in the view's colour of that body (the one
/// the page draws): the scene's bodies and walls, the tags and velocity row, the magnifier,
/// the energy bars and their names, the velocity profile's dots, the velocity and energy
/// series and their names, the x-t diagram's worldlines. Returns how many it checked.
std::size_t expectBodiesInTheViewsColours(const RunRecord& run) {
  const RunView view = makeRunView(run);
  SCOPED_TRACE(view.kind + ": " + view.title);
  const std::size_t n = run.bodies();
  EXPECT_EQ(view.body_colours.size(), n);
  for (const auto* list : {&view.worldline_bodies, &view.velocity_bodies}) {
    for (const ViewBody& body : *list) EXPECT_EQ(body.colour, view.body_colours.at(body.index)) << body.name;
  }
  const auto fixed = buildStaticMarkers(run, "f");
  const auto animated = buildAnimatedMarkers(run, FrameClock{endTime(run), ""}, "f");
  std::size_t checked = 0;
  const auto expectBody = [&](const visualization_msgs::MarkerArray& array, const std::string& ns, int id,
                              std::size_t i) {
    const Marker* m = find(array, ns, id);
    if (m && m->action == Marker::ADD) {
      EXPECT_EQ(hexOf(m->color), view.body_colours.at(i)) << ns << "/" << id << ": body " << i;
      ++checked;
    }
  };
  if (n <= kMaxPlottedBodies) {
    for (std::size_t i = 0; i < n; ++i) {
      const int b = static_cast<int>(i);
      expectBody(animated, ids::ns::kBodies, ids::kBody + b, i);
      expectBody(animated, ids::ns::kZoom, ids::kZoomBody + b, i);
      expectBody(animated, ids::ns::kEnergyBars, ids::kEnergyBar + b, i);
      expectBody(fixed, ids::ns::kEnergy, ids::kEnergyBodyNames + b, i);
      expectBody(fixed, ids::ns::kPlot, ids::kPlotSeriesNames + b, i);
      for (int p = 0; p < 2; ++p) expectBody(fixed, ids::ns::kPlot, ids::kPlotPanelStride * p + ids::kPlotSeries + b, i);
      expectBody(fixed, ids::ns::kConserved, ids::kConservedEnergy + ids::kConservedBodies + b, i);
    }
    for (std::size_t k = 0; k < view.worldline_bodies.size(); ++k) {
      expectBody(fixed, ids::ns::kWorldlines, ids::kWorldLines + static_cast<int>(k), view.worldline_bodies[k].index);
    }
    if (const Marker* dots = find(animated, ids::ns::kVelocitiesNow, ids::kSideBars)) {
      EXPECT_EQ(dots->colors.size(), n);
      for (std::size_t i = 0; i < dots->colors.size(); ++i) {
        EXPECT_EQ(hexOf(dots->colors[i]), view.body_colours.at(i)) << "profile dot of body " << i;
        ++checked;
      }
    }
  } else {
    // The scene's dots, one list per mass class: together, the finite bodies' colours.
    std::vector<std::string> drawn, expected;
    for (int k = 0; k < layout::kMassClasses; ++k) {
      if (const Marker* m = find(animated, ids::ns::kBodies, ids::kBodyClass + k)) {
        for (const auto& c : m->colors) drawn.push_back(hexOf(c));
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isinf(run.input().masses[i])) expected.push_back(view.body_colours[i]);
    }
    std::sort(drawn.begin(), drawn.end()), std::sort(expected.begin(), expected.end());
    EXPECT_EQ(drawn, expected) << "the scene's bodies";
    checked += drawn.size();
    if (run.isWall(0)) expectBody(animated, ids::ns::kBodies, ids::kBodyWall, 0);
    if (run.isWall(n - 1)) expectBody(animated, ids::ns::kBodies, ids::kBodyWall + 1, n - 1);
    for (std::size_t k = 0; k < view.worldline_bodies.size(); ++k) {
      expectBody(animated, ids::ns::kWorldlinesNow, ids::kWorldNowLines + static_cast<int>(k),
                 view.worldline_bodies[k].index);
    }
    for (std::size_t k = 0; k < view.velocity_bodies.size(); ++k) {
      expectBody(fixed, ids::ns::kPlot, ids::kPlotTracked + static_cast<int>(k), view.velocity_bodies[k].index);
    }
    // The scene's colour bar says what the colours mean, in the view's words.
    const std::string caption = textOf(fixed, ids::ns::kScene, ids::kColourCaption);
    EXPECT_NE(caption.find(view.colour_legend), std::string::npos) << caption;
  }
  return checked;
}

/// No text writes four digits or more without thousands separators ("1002", "3000"): every
/// count, and every number before a decimal point, is written for people (names such as the
/// run id "box_1002" and "#1001" aside).
void expectCountsWithSeparators(const visualization_msgs::MarkerArray& array) {
  static const std::regex bare("(^|[^0-9.,_A-Za-z#])[0-9]{4,}");
  for (const Marker& m : array.markers) {
    if (m.type == Marker::TEXT_VIEW_FACING) EXPECT_FALSE(std::regex_search(m.text, bare)) << m.ns << "/" << m.id << ": " << m.text;
  }
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
  // And says how to simulate it.
  EXPECT_NE(makeRunView(run).not_simulated.find("set \"Stop after\" (max_collisions) to at least 31"), std::string::npos)
      << makeRunView(run).not_simulated;
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
  // Its time axis ends at a decade beyond 10^5 s, named without e-notation. (Failed before:
  // "1e+08", as in granular_gas_100_end.png.)
  const std::string last = textOf(buildStaticMarkers(r.record, "f"), ids::ns::kTemperature, ids::kTemperatureTimeMax);
  EXPECT_EQ(last.rfind("10^", 0), 0u) << last;
}

// Two carts: a line of few bodies, where the status says the view's counter too.
TEST(MarkerView, FewBodiesSayTheViewsCounter) {
  const auto r = runScene(scene({1, 1}, {1, 0}, {-1, 1}, {0.8}), 100, "carts");
  ASSERT_EQ(makeRunView(r.record).counter, "1 collision, finished");
  expectRvizDrawsTheView(r.record);
}

// One colour per body (issue 31): few bodies in rviz's palette by index (A red, B green, C
// blue, walls grey), in every panel as the view says. (Failed before: rviz drew the pi
// scene's wall C grey where the view, and so the page, said blue.)
TEST(MarkerView, FewBodiesAreDrawnInTheViewsColours) {
  const auto pi = runScene(scene({100, 1, kInf}, {2, 1, 0}, {-1, 0, 0}, {1.0}), 100, "pi");
  ASSERT_EQ(pi.result.impact_count, 31u);
  const RunView view = makeRunView(pi.record);
  EXPECT_FALSE(view.colour_by_start_velocity);
  EXPECT_EQ(view.colour_legend, "");
  EXPECT_EQ(view.body_colours, (std::vector<std::string>{bodyColourHex(0), bodyColourHex(1), "#999999"}));
  EXPECT_GE(expectBodiesInTheViewsColours(pi.record), 10u);
  // Ten bodies, the palette's size: each its own palette colour.
  const auto ten = runScene(manyBodies(10, 10.0, 3), 200, "ten");
  const RunView ten_view = makeRunView(ten.record);
  EXPECT_FALSE(ten_view.colour_by_start_velocity);
  EXPECT_EQ(std::set<std::string>(ten_view.body_colours.begin(), ten_view.body_colours.end()).size(), 10u);
  EXPECT_GE(expectBodiesInTheViewsColours(ten.record), 50u);
}

// Many bodies: beyond the palette, each body's colour is its start velocity's, the same in
// the scene, the x-t diagram and the velocity plot, so that a 1,002-body box has no ten
// repeating colours. (Failed before: the view said the palette by index, rviz drew the
// start velocity's colour, and the scene's bodies their velocity now.)
TEST(MarkerView, ManyBodiesAreDrawnInTheViewsColours) {
  Scene box = manyBodies(1000, 1000.0, 11);
  box.masses.insert(box.masses.begin(), kInf), box.positions.insert(box.positions.begin(), 1001.0);
  box.velocities.insert(box.velocities.begin(), 0.0);
  box.masses.push_back(kInf), box.positions.push_back(-1.0), box.velocities.push_back(0.0);
  box.restitution = {0.9};
  const auto r = runScene(box, 3000, "box_1002");
  const RunView view = makeRunView(r.record);
  ASSERT_EQ(view.kind, "box");
  EXPECT_TRUE(view.colour_by_start_velocity);
  EXPECT_EQ(view.body_colours.front(), "#999999");  // the walls
  EXPECT_EQ(view.body_colours.back(), "#999999");
  std::set<std::string> shown;
  for (const ViewBody& body : view.worldline_bodies) shown.insert(body.colour);
  EXPECT_GT(shown.size(), 10u) << "the shown bodies repeat ten colours";
  EXPECT_NE(view.colour_legend.find("blue: moving left"), std::string::npos) << view.colour_legend;
  EXPECT_NE(view.colour_legend.find("red: moving right"), std::string::npos) << view.colour_legend;
  EXPECT_GE(expectBodiesInTheViewsColours(r.record), 1000u);
  expectCountsWithSeparators(buildStaticMarkers(r.record, "f"));
  expectCountsWithSeparators(buildAnimatedMarkers(r.record, FrameClock{endTime(r.record), ""}, "f"));
  // Twelve bodies on a ring: the map too (more bodies than the palette has colours).
  Scene ring = manyBodies(12, 900.0, 7);
  for (std::size_t i = 0; i < ring.positions.size(); ++i) ring.positions[i] = 900.0 - 75.0 * static_cast<double>(i);
  ring.ring = 1000.0;
  const auto on_ring = runScene(ring, 300, "ring");
  EXPECT_TRUE(makeRunView(on_ring.record).colour_by_start_velocity);
  EXPECT_GE(expectBodiesInTheViewsColours(on_ring.record), 12u);
}

}  // namespace

namespace {

// WCAG 2 relative luminance of an sRGB colour given as bytes.
double relativeLuminance(int r, int g, int b) {
  const auto linear = [](int byte) {
    const double c = byte / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  return 0.2126 * linear(r) + 0.7152 * linear(g) + 0.0722 * linear(b);
}

double contrast(double a, double b) { return (std::max(a, b) + 0.05) / (std::min(a, b) + 0.05); }

}  // namespace

// Every body colour, as the page draws it (RunView's "#rrggbb") and rviz too, keeps 3:1
// against the page's white and rviz's background (rviz/collision_lab.rviz: 30; 32; 40).
TEST(MarkerView, BodyColoursKeepAContrastOf3To1OnBothBackgrounds) {
  const double white = relativeLuminance(255, 255, 255), rviz = relativeLuminance(30, 32, 40);
  for (std::size_t i = 0; i < layout::kPaletteSize; ++i) {
    const std::string hex = collision_lab_ros::bodyColourHex(i);
    ASSERT_EQ(hex.size(), 7u) << hex;
    const double l = relativeLuminance(std::stoi(hex.substr(1, 2), nullptr, 16), std::stoi(hex.substr(3, 2), nullptr, 16),
                                       std::stoi(hex.substr(5, 2), nullptr, 16));
    EXPECT_GE(contrast(l, white), 3.0) << "body " << i << " " << hex;
    EXPECT_GE(contrast(l, rviz), 3.0) << "body " << i << " " << hex;
  }
}
