// collision_lab_node end to end (node_test.test): round trip against the core, bad
// input, the collision cap, modes, the published-event cap, bags, the simulated
// timeline, duplicate run_ids, the services, latching and recording faults. Every test
// sends the runs it needs (runs shared between tests are sent once, by whichever test
// asks first), so any subset runs alone.
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/RunPreset.h"
#include "collision_lab/RunScene.h"
#include "collision_lab/ros/msg_conversion.h"
#include "run_collector.h"

namespace {

using collision_lab_test::callService;
using collision_lab_test::makeInput;
using collision_lab_test::RunCollector;
using collision_lab_test::RunOutputs;
using collision_lab_test::waitUntil;
namespace core = collision_lab::core;
namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string g_bag_directory;         // the node's ~bag_directory
std::string g_faulty_bag_directory;  // the faulty node's: under /dev/null, never a folder
RunCollector* g_node = nullptr;      // namespace collision_lab
RunCollector* g_faulty = nullptr;    // namespace collision_lab_faulty
constexpr char kRunScene[] = "/collision_lab/collision_lab_node/run_scene";
constexpr char kRunPreset[] = "/collision_lab/collision_lab_node/run_preset";

/// Publishes input to node unless this run_id was sent before, and waits for the run.
const RunOutputs& runOnce(RunCollector* node, const collision_lab::InitialConditions& input) {
  static std::set<std::string> sent;
  if (sent.insert(input.run_id).second) node->publish(input);
  return node->waitFor(input.run_id);
}

const RunOutputs& roundTrip() {
  return runOnce(g_node, makeInput("round_trip", {1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1}));
}

const RunOutputs& noDisk() {
  return runOnce(g_faulty, makeInput("no_disk", {1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1}));
}

template <class Message>
std::vector<std::uint8_t> bytes(const Message& msg) {
  std::vector<std::uint8_t> buffer(ros::serialization::serializationLength(msg));
  ros::serialization::OStream stream(buffer.data(), buffer.size());
  ros::serialization::serialize(stream, msg);
  return buffer;
}

template <class Message>
std::vector<Message> readTopic(const rosbag::Bag& bag, const std::string& topic) {
  std::vector<Message> messages;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    const auto msg = m.instantiate<Message>();
    EXPECT_TRUE(msg) << topic << " holds another type";
    if (msg) messages.push_back(*msg);
  }
  return messages;
}

template <class Message>
void expectSameMessages(const std::vector<Message>& published, const std::vector<Message>& bagged,
                        const std::string& topic) {
  ASSERT_EQ(published.size(), bagged.size()) << topic;
  for (std::size_t i = 0; i < published.size(); ++i) {
    // roscpp numbers header.seq while publishing; the bag holds the message as given.
    Message received = published[i];
    received.header.seq = 0;
    EXPECT_EQ(bytes(received), bytes(bagged[i])) << topic << " message " << i;
  }
}

void expectArrayEq(const std::vector<double>& actual, const std::array<double, 3>& expected,
                   const std::string& what) {
  ASSERT_EQ(actual.size(), 3u) << what;
  for (int i = 0; i < 3; ++i) EXPECT_EQ(actual[i], expected[i]) << what << "[" << i << "]";
}

/// [ns] from start to stamp.
double nsAfter(const ros::Time& start, const ros::Time& stamp) {
  return static_cast<double>(static_cast<std::int64_t>(stamp.toNSec()) -
                             static_cast<std::int64_t>(start.toNSec()));
}

/// Every collision of the bag at start + scale * time, to the nanosecond; returns the bag.
std::vector<collision_lab::CollisionEvent> expectBagOnTimeline(const std::string& path,
                                                               double scale) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  const std::string ns = "/collision_lab/";
  const auto inputs = readTopic<collision_lab::InitialConditions>(bag, ns + "initial_conditions");
  const auto predictions = readTopic<collision_lab::Prediction>(bag, ns + "predictions");
  const auto events = readTopic<collision_lab::CollisionEvent>(bag, ns + "collision_events");
  const auto summaries = readTopic<collision_lab::RunSummary>(bag, ns + "run_summaries");
  if (inputs.size() != 1 || predictions.size() != 1 || summaries.size() != 1) {
    ADD_FAILURE() << path << " lacks its input, prediction or summary";
    return events;
  }
  const ros::Time start = inputs.front().header.stamp;
  EXPECT_EQ(predictions.front().header.stamp, start);
  EXPECT_EQ(predictions.front().timeline_scale, scale);
  EXPECT_EQ(summaries.front().timeline_scale, scale);
  for (std::size_t k = 0; k < events.size(); ++k) {
    EXPECT_NEAR(nsAfter(start, events[k].header.stamp), scale * events[k].time * 1e9, 1.0)
        << "collision " << k + 1;
  }
  // The bag's own times are the stamps: its duration is the run's scaled duration.
  rosbag::View all(bag);
  EXPECT_EQ(all.getBeginTime(), start);
  const double last = events.empty() ? 0.0 : events.back().time;
  EXPECT_NEAR(nsAfter(start, all.getEndTime()), scale * last * 1e9, 1.0);
  EXPECT_EQ(summaries.front().header.stamp, all.getEndTime());
  return events;
}

// ---- Round trip: every output, equal to the core's run of the same plan ----

TEST(LabNode, RoundTripMatchesCore) {
  const auto input = makeInput("round_trip", {1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1});
  const RunOutputs& out = roundTrip();
  ASSERT_TRUE(out.rejections.empty()) << out.rejections.front().message;

  const core::Scene scene = collision_lab_ros::toScene(input);
  const core::ScenePlan plan = core::planScene(scene);
  ASSERT_FALSE(plan.error);
  ASSERT_TRUE(plan.prediction && plan.prediction->impact_count && plan.prediction->max_possible_impact_count);
  core::SceneRunOptions options;
  options.lab.events = collision_lab::core::EventPolicy::all();
  const core::SceneRunResult run = core::runScene(plan, options);
  const core::SceneSimulation& expected = run.simulation;
  ASSERT_GT(expected.impacts.size(), 0u);

  ASSERT_EQ(out.predictions.size(), 1u);
  ASSERT_EQ(out.summaries.size(), 1u);
  ASSERT_EQ(out.events.size(), expected.impacts.size());
  ASSERT_EQ(out.velocities.size(), expected.impacts.size());
  ASSERT_EQ(out.energies.size(), expected.impacts.size());

  // The rotation model's prediction, as every scene's: its plan's.
  auto prediction = collision_lab_ros::toPredictionMsg(plan);
  EXPECT_EQ(prediction.collision_count, *plan.prediction->impact_count);
  EXPECT_EQ(prediction.max_possible_collision_count, *plan.prediction->max_possible_impact_count);
  EXPECT_EQ(prediction.psi, plan.prediction->psi.value());
  prediction.timeline_scale = 1.0;  // the node's: first contact after 4/3 s, an ordinary scene
  auto received_prediction = out.predictions.front();
  received_prediction.header = prediction.header;
  received_prediction.run_id = prediction.run_id;
  EXPECT_EQ(bytes(received_prediction), bytes(prediction));

  collision_lab_ros::SceneEventConverter converter(scene);
  for (std::size_t k = 0; k < expected.impacts.size(); ++k) {
    const core::ImpactRecord& e = expected.impacts[k];
    auto event = converter.impact(e);
    event.header = out.events[k].header, event.run_id = "round_trip";
    EXPECT_EQ(bytes(out.events[k]), bytes(event)) << "collision " << k + 1;
    // The plot topics: the simulated values of the same collision, at the same stamp.
    const collision_lab::Velocities& v = out.velocities[k];
    EXPECT_EQ(v.header.stamp, out.events[k].header.stamp) << "collision " << k + 1;
    EXPECT_EQ(v.run_id, "round_trip");
    EXPECT_EQ(v.index, e.index);
    EXPECT_EQ(v.time, e.time);
    expectArrayEq({{v.v_a, v.v_b, v.v_c}}, e.model->velocities_after, "v after collision " + std::to_string(k + 1));
    const collision_lab::EnergyTransfer& t = out.energies[k];
    EXPECT_EQ(t.header.stamp, out.events[k].header.stamp) << "collision " << k + 1;
    EXPECT_EQ(t.index, e.index);
    EXPECT_EQ(t.time, e.time);
    expectArrayEq({{t.delta_a, t.delta_b, t.delta_c}}, e.model->energy_transfer, "delta " + std::to_string(k + 1));
    expectArrayEq({{t.kinetic_a, t.kinetic_b, t.kinetic_c}}, e.model->kinetic_energy_after, "kinetic " + std::to_string(k + 1));
  }

  const auto& summary = out.summaries.front();
  EXPECT_EQ(summary.collision_count, expected.impact_count);
  EXPECT_EQ(summary.predicted_collision_count, *plan.prediction->impact_count);
  EXPECT_FALSE(summary.truncated);
  EXPECT_TRUE(summary.simulated);
  EXPECT_EQ(summary.final_velocities, expected.final_velocities);
  EXPECT_EQ(summary.max_prediction_error, expected.max_prediction_error);
  EXPECT_EQ(summary.energy_relative_drift, expected.energy_relative_drift);
  EXPECT_EQ(summary.published_events, expected.impacts.size());
  EXPECT_FALSE(summary.events_not_published);
  EXPECT_TRUE(summary.recording_ok) << summary.recording_error;
  EXPECT_EQ(summary.bag_path, g_bag_directory + "/round_trip.bag");

  // Stamps follow the publishing order: prediction, collisions, summary.
  ros::Time last = out.predictions.front().header.stamp;
  EXPECT_GE(last, ros::TIME_MIN);
  for (const auto& e : out.events) {
    EXPECT_GE(e.header.stamp, last);
    last = e.header.stamp;
  }
  EXPECT_GE(summary.header.stamp, last);
}

// ---- Bag: exactly the published messages, one per collision (docs/messages.md) ----

TEST(LabNode, BagHoldsExactlyThePublishedMessagesAndOneMessagePerCollision) {
  const RunOutputs& out = roundTrip();
  ASSERT_EQ(out.summaries.size(), 1u);
  const std::string path = out.summaries.front().bag_path;
  ASSERT_TRUE(fs::exists(path)) << path;
  EXPECT_FALSE(fs::exists(path + ".active"));

  rosbag::Bag bag(path, rosbag::bagmode::Read);
  const std::string ns = "/collision_lab/";
  const auto inputs = readTopic<collision_lab::InitialConditions>(bag, ns + "initial_conditions");
  ASSERT_EQ(inputs.size(), 1u);
  EXPECT_EQ(inputs.front().run_id, "round_trip");
  expectArrayEq(inputs.front().velocities, {-1, 0.5, 1}, "bagged velocities");
  expectSameMessages(out.predictions, readTopic<collision_lab::Prediction>(bag, ns + "predictions"),
                     "predictions");
  expectSameMessages(out.events, readTopic<collision_lab::CollisionEvent>(bag, ns + "collision_events"),
                     "collision_events");
  // The plot topics are live only: a CollisionEvent holds all they carry.
  EXPECT_TRUE(readTopic<collision_lab::Velocities>(bag, ns + "velocities").empty());
  EXPECT_TRUE(readTopic<collision_lab::EnergyTransfer>(bag, ns + "energy_transfers").empty());
  expectSameMessages(out.summaries, readTopic<collision_lab::RunSummary>(bag, ns + "run_summaries"),
                     "run_summaries");
  EXPECT_EQ(rosbag::View(bag).size(), 4 + out.events.size());  // and run_parameters
}

// ---- Bad input: rejected with the right reason, then the next valid run is served ----

struct BadCase {
  collision_lab::InitialConditions input;
  std::uint8_t reason;
  std::string field_prefix;
};

TEST(LabNode, BadInputIsRejectedAndTheNextRunServed) {
  using collision_lab::Rejected;
  std::vector<BadCase> cases = {
      {makeInput("bad_nan", {1, 1, 1}, {2, 1, 0}, {-1, kNaN, 0}), Rejected::NON_FINITE_VALUE, "velocities"},
      {makeInput("bad_mass", {1, -2, 1}, {2, 1, 0}, {-1, 0, 0}), Rejected::NON_POSITIVE_MASS, "masses"},
      {makeInput("bad_middle", {1, kInf, 1}, {2, 1, 0}, {-1, 0, 0}), Rejected::WALL_NOT_AT_END, "masses"},
      {makeInput("bad_order", {1, 1, 1}, {0, 1, 2}, {-1, 0, 0}), Rejected::POSITIONS_NOT_ORDERED, "positions"},
      {makeInput("bad_triple", {1, 1, 1}, {1, 0, -1}, {-1, 0, 1}), Rejected::TRIPLE_COLLISION, ""},
      {makeInput("../escape", {1, 1, 1}, {2, 1, 0}, {-1, 0, 0}), Rejected::INVALID_RUN_ID, "run_id"},
      {makeInput("bad_mode", {1, 1, 1}, {2, 1, 0}, {-1, 0, 0}), Rejected::INVALID_MODE, "mode"},
  };
  cases.back().input.mode = 7;
  // Walls at both ends around a body are a valid scene since issue 10 (two_walls_infinite);
  // two walls alone are not.
  BadCase walls{makeInput("bad_walls", {kInf, kInf, 1}, {2, 1, 0}, {0, 0, 0}), Rejected::TWO_WALLS, "masses"};
  walls.input.masses.pop_back(), walls.input.positions.pop_back(), walls.input.velocities.pop_back();
  cases.push_back(walls);

  for (const auto& c : cases) {
    SCOPED_TRACE(c.input.run_id);
    g_node->publish(c.input);
    const RunOutputs& out = g_node->waitFor(c.input.run_id);
    ASSERT_EQ(out.rejections.size(), 1u);
    const auto& rejected = out.rejections.back();
    EXPECT_EQ(rejected.reason, c.reason) << rejected.reason_name << ": " << rejected.message;
    EXPECT_EQ(rejected.field.rfind(c.field_prefix, 0), 0u) << rejected.field;
    EXPECT_FALSE(rejected.message.empty());
    EXPECT_FALSE(rejected.reason_name.empty());
    EXPECT_TRUE(out.summaries.empty());
    EXPECT_TRUE(out.predictions.empty());
    EXPECT_FALSE(fs::exists(g_bag_directory + "/" + c.input.run_id + ".bag"));

    const std::string next = "after_" + std::to_string(&c - cases.data());
    g_node->publish(makeInput(next, {1, 1, 1}, {2, 1, -1}, {-1, 0, 1}));
    const RunOutputs& served = g_node->waitFor(next);
    ASSERT_EQ(served.summaries.size(), 1u);
    EXPECT_EQ(served.summaries.front().collision_count, 3u);
  }
}

// ---- docs/bad_inputs.md: every catalogue row that is a scene, through the node ----

/// Comma-separated doubles, as the catalogue writes them; empty if not that.
std::optional<std::vector<double>> parseList(const std::string& text) {
  std::vector<double> values;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    if (item.empty()) return std::nullopt;
    values.push_back(std::strtod(item.c_str(), &end));
    if (*end != '\0' || std::isinf(values.back()) != (item.find("inf") != std::string::npos)) {
      return std::nullopt;  // not a number, or out of a double's range
    }
  }
  if (values.empty()) return std::nullopt;
  return values;
}

struct CatalogueRow {
  std::string number;
  collision_lab::InitialConditions input;
  int code = 0;
  std::string field;
  std::string message;
};

/// The rows given as --masses/--positions/--velocities (and --restitution) with a core
/// reason (codes 1-13).
std::vector<CatalogueRow> sceneRows(const std::string& path) {
  std::vector<CatalogueRow> rows;
  std::ifstream file(path);
  std::string line;
  while (std::getline(file, line)) {
    std::vector<std::string> cells;
    std::istringstream in(line);
    std::string cell;
    while (std::getline(in, cell, '|')) cells.push_back(cell);
    if (cells.size() < 8 || line.rfind("| ", 0) != 0) continue;
    const auto unquote = [](const std::string& c) {
      const auto a = c.find('`'), b = c.rfind('`');
      return a == std::string::npos || b <= a ? std::string() : c.substr(a + 1, b - a - 1);
    };
    std::istringstream args(unquote(cells[3]));
    std::map<std::string, std::string> options;
    std::string flag, value;
    while (args >> flag) {
      if (!(args >> value)) options.clear();
      options[flag] = value;
    }
    const auto m = parseList(options["--masses"]);
    const auto x = parseList(options["--positions"]);
    const auto v = parseList(options["--velocities"]);
    const bool has_e = options.count("--restitution") > 0;
    const auto e = has_e ? parseList(options["--restitution"]) : std::vector<double>{};
    const int code = std::atoi(cells[5].c_str());
    if (options.size() != 3u + has_e || !m || !x || !v || !e || code < 1 || code > 13) continue;
    CatalogueRow row;
    row.number = cells[1].substr(1, cells[1].size() - 2);
    row.input.header.stamp = ros::Time::now();
    row.input.run_id = "catalogue_" + row.number;
    row.input.masses = *m, row.input.positions = *x, row.input.velocities = *v, row.input.restitution = *e;
    row.code = code;
    row.field = unquote(cells[6]);
    const std::string seen = unquote(cells[7]);
    const std::string reason = cells[4].substr(1, cells[4].size() - 2);
    const auto start = seen.find("(" + reason + "): ");
    row.message = start == std::string::npos ? seen : seen.substr(start + reason.size() + 4);
    rows.push_back(row);
  }
  return rows;
}

TEST(LabNode, EveryBadSceneOfTheCatalogueIsRejectedAsTheCliSays) {
  const auto rows = sceneRows(COLLISION_LAB_SOURCE_DIR "/docs/bad_inputs.md");
  ASSERT_GE(rows.size(), 22u) << "docs/bad_inputs.md lost its scene rows";
  std::set<int> codes;
  for (const auto& row : rows) codes.insert(row.code);
  // Every core reason but EMPTY_SCENE, which the catalogue gives as a bodies file (below),
  // and INFINITE_MIDDLE_MASS, no longer given (a wall inside is WALL_NOT_AT_END for every N).
  EXPECT_EQ(codes, (std::set<int>{1, 2, 3, 5, 6, 7, 8, 9, 11, 12, 13}));
  for (const auto& row : rows) {
    SCOPED_TRACE("catalogue row " + row.number);
    g_node->publish(row.input);
    const RunOutputs& out = g_node->waitFor(row.input.run_id);
    ASSERT_EQ(out.rejections.size(), 1u);
    EXPECT_TRUE(out.summaries.empty());
    EXPECT_EQ(out.rejections.front().reason, row.code);
    EXPECT_EQ(out.rejections.front().field, row.field);
    EXPECT_EQ(out.rejections.front().message, row.message);

    const std::string next = "after_catalogue_" + row.number;
    g_node->publish(makeInput(next, {1, 1, 1}, {2, 1, -1}, {-1, 0, 1}));
    EXPECT_EQ(g_node->waitFor(next).summaries.size(), 1u);
  }
}

TEST(LabNode, AnEmptySceneIsRejectedAsTheCatalogueSays) {
  // docs/bad_inputs.md row 55 gives it as a bodies file; through the node it is empty lists.
  collision_lab::InitialConditions input;
  input.run_id = "empty_scene";
  g_node->publish(input);
  const RunOutputs& out = g_node->waitFor("empty_scene");
  ASSERT_EQ(out.rejections.size(), 1u);
  EXPECT_EQ(out.rejections.front().reason, collision_lab::Rejected::EMPTY_SCENE);
  EXPECT_EQ(out.rejections.front().reason_name, "EMPTY_SCENE");
  EXPECT_EQ(out.rejections.front().field, "masses");
  EXPECT_EQ(out.rejections.front().message,
            "the scene has no bodies; give at least one mass, position and velocity");
}

// ---- The collision cap: answered at once, never simulated up to the cap ----

// The over-cap rule (runScene): the model answers, complete, with its count as the run's.
TEST(LabNode, OverCapRunIsAnsweredByTheModel) {
  auto input = makeInput("over_cap", {1e12, 1, 1e12}, {2, 1, 0}, {-1, 0, 0});
  input.max_collisions = 1000;
  g_node->publish(input);
  const RunOutputs& out = g_node->waitFor("over_cap");
  ASSERT_EQ(out.summaries.size(), 1u);
  ASSERT_EQ(out.predictions.size(), 1u);
  EXPECT_EQ(out.predictions.front().collision_count, 2221441u);
  const auto& summary = out.summaries.front();
  EXPECT_FALSE(summary.truncated);
  EXPECT_FALSE(summary.simulated);
  EXPECT_EQ(summary.stop_reason, "NOT_SIMULATED");
  EXPECT_EQ(summary.collision_count, 2221441u);
  EXPECT_EQ(summary.predicted_collision_count, 2221441u);
  EXPECT_TRUE(out.events.empty());
}

// ---- Modes ----

TEST(LabNode, PredictOnlyAndSummaryOnlyPublishNoCollisions) {
  auto predict_only = makeInput("predict_only", {1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1});
  predict_only.mode = collision_lab::InitialConditions::MODE_PREDICT_ONLY;
  auto summary_only = makeInput("summary_only", {1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1});
  summary_only.mode = collision_lab::InitialConditions::MODE_SUMMARY_ONLY;
  g_node->publish(predict_only);
  g_node->publish(summary_only);

  const RunOutputs& p = g_node->waitFor("predict_only");
  ASSERT_EQ(p.summaries.size(), 1u);
  EXPECT_FALSE(p.summaries.front().simulated);
  EXPECT_EQ(p.summaries.front().mode, collision_lab::InitialConditions::MODE_PREDICT_ONLY);
  EXPECT_EQ(p.predictions.front().collision_count, 3u);
  EXPECT_TRUE(p.events.empty());

  const RunOutputs& s = g_node->waitFor("summary_only");
  ASSERT_EQ(s.summaries.size(), 1u);
  EXPECT_TRUE(s.summaries.front().simulated);
  EXPECT_EQ(s.summaries.front().collision_count, 3u);
  EXPECT_TRUE(s.events.empty());
  EXPECT_TRUE(s.velocities.empty());
  EXPECT_TRUE(s.energies.empty());
}

// ---- ~max_published_events (50 in node_test.test): the rest goes to the bag only ----

TEST(LabNode, EventsBeyondThePublishCapAreRecordedOnly) {
  const RunOutputs& out = runOnce(g_node, makeInput("pi_digits_3", {1e4, 1, kInf}, {2, 1, 0}, {-1, 0, 0}));
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& summary = out.summaries.front();
  EXPECT_EQ(summary.collision_count, 314u);
  EXPECT_EQ(summary.published_events, 50u);
  EXPECT_TRUE(summary.events_not_published);
  EXPECT_EQ(out.events.size(), 50u);
  EXPECT_EQ(out.velocities.size(), 50u);
  EXPECT_EQ(out.energies.size(), 50u);
  ASSERT_TRUE(summary.recording_ok) << summary.recording_error;

  rosbag::Bag bag(summary.bag_path, rosbag::bagmode::Read);
  const auto events = readTopic<collision_lab::CollisionEvent>(bag, "/collision_lab/collision_events");
  ASSERT_EQ(events.size(), 314u);
  for (std::size_t k = 0; k < events.size(); ++k) EXPECT_EQ(events[k].index, k + 1);
  // The bag-only collisions sit on the run's timeline too.
  expectBagOnTimeline(summary.bag_path, 1.0);

  // Past the cap, run_progress (live only) says how far the run got: first at collision 51,
  // with its state, then at most every ~progress_period (0.1 s) of wall time.
  ASSERT_FALSE(out.progress.empty());
  const collision_lab::RunProgress& first = out.progress.front();
  EXPECT_EQ(first.collisions, 51u);
  EXPECT_EQ(first.published, 50u);
  EXPECT_EQ(first.latest_event.index, 51u);
  EXPECT_EQ(first.latest_event.velocities_after, events[50].velocities_after);
  EXPECT_EQ(first.latest_event.positions, events[50].positions);
  EXPECT_EQ(first.latest_event.header.stamp, events[50].header.stamp);
  EXPECT_DOUBLE_EQ(first.time, events[50].time);
  for (std::size_t k = 1; k < out.progress.size(); ++k) {
    EXPECT_GT(out.progress[k].collisions, out.progress[k - 1].collisions);
    EXPECT_LE(out.progress[k].collisions, 314u);
  }
  for (const rosbag::ConnectionInfo* connection : rosbag::View(bag).getConnections()) {
    EXPECT_EQ(connection->topic.find("run_progress"), std::string::npos) << "live only, not recorded";
  }
}

// ---- Recording faults: everything is still published, the summary says why ----

TEST(LabNode, UnwritableBagDirectoryStillPublishesEverything) {
  const RunOutputs& out = noDisk();
  ASSERT_EQ(out.summaries.size(), 1u);
  const auto& summary = out.summaries.front();
  EXPECT_FALSE(summary.recording_ok);
  EXPECT_NE(summary.recording_error.find(g_faulty_bag_directory), std::string::npos)
      << summary.recording_error;
  EXPECT_EQ(summary.collision_count, 3u);
  EXPECT_EQ(out.predictions.size(), 1u);
  EXPECT_EQ(out.events.size(), 3u);
  EXPECT_EQ(out.velocities.size(), 3u);
  EXPECT_EQ(out.energies.size(), 3u);

  // The node keeps serving.
  g_faulty->publish(makeInput("no_disk_2", {1, 1, 1}, {2, 1, -1}, {-1, 0, 1}));
  EXPECT_EQ(g_faulty->waitFor("no_disk_2").summaries.size(), 1u);
}


// ---- The simulated timeline: stamp = start + timeline_scale * time, live and in the bag ----

TEST(Timeline, RunIsStampedOnItsSimulatedTimeLiveAndInTheBag) {
  const RunOutputs& out = roundTrip();
  ASSERT_EQ(out.summaries.size(), 1u);
  ASSERT_EQ(out.events.size(), 3u);
  // First contact AB after 2 m / 1.5 m/s: an ordinary scene, scale 1.
  EXPECT_EQ(out.predictions.front().timeline_scale, 1.0);
  const ros::Time start = out.predictions.front().header.stamp;
  for (const auto& e : out.events) {
    EXPECT_NEAR(nsAfter(start, e.header.stamp), e.time * 1e9, 1.0) << "collision " << e.index;
  }
  EXPECT_EQ(out.summaries.front().header.stamp, out.events.back().header.stamp);
  EXPECT_GT(out.events.back().time, 1.0);  // a bag duration of more than a second
  EXPECT_FALSE(out.summaries.front().timeline_saturated);
  expectBagOnTimeline(out.summaries.front().bag_path, 1.0);
}

TEST(Timeline, NanosecondAndTerasecondScenesGetAPowerOfTen) {
  struct Case {
    std::string run_id;
    double unit;  // [m] and [s]: equal masses, B and C at rest, A at -1 m/s
    double scale;
  };
  for (const Case& c : {Case{"nano_scene", 1e-9, 1e9}, Case{"tera_scene", 1e12, 1e-12}}) {
    SCOPED_TRACE(c.run_id);
    // AB after 1 unit, BC after 2 units (A stops, B takes over, then C): 2 collisions,
    // the first contact 1 bag second after the start.
    const RunOutputs& out = runOnce(
        g_node, makeInput(c.run_id, {1, 1, 1}, {2 * c.unit, c.unit, 0}, {-1, 0, 0}));
    ASSERT_EQ(out.summaries.size(), 1u);
    ASSERT_EQ(out.events.size(), 2u);
    EXPECT_EQ(out.summaries.front().timeline_scale, c.scale);
    const ros::Time start = out.predictions.front().header.stamp;
    EXPECT_NEAR(nsAfter(start, out.events[0].header.stamp), 1e9, 1.0);
    EXPECT_NEAR(nsAfter(start, out.events[1].header.stamp), 2e9, 1.0);
    expectBagOnTimeline(out.summaries.front().bag_path, c.scale);
  }
}

TEST(Timeline, CollisionsBeyondTheRangeSaturateAndTheSummarySaysSo) {
  // AB at t = 1 s (scale 1), then B crosses 1e15 m to C: t = 1e15 + 2 s, beyond 1e9 bag s.
  const RunOutputs& out =
      runOnce(g_node, makeInput("saturated", {1, 1, 1}, {2, 1, -1e15}, {-1, 0, 0}));
  ASSERT_EQ(out.summaries.size(), 1u);
  ASSERT_EQ(out.events.size(), 2u);
  const auto& summary = out.summaries.front();
  EXPECT_EQ(summary.timeline_scale, 1.0);
  EXPECT_TRUE(summary.timeline_saturated);
  EXPECT_EQ(out.events[1].time, 1e15 + 2);  // the true time stays in the message
  const ros::Time start = out.predictions.front().header.stamp;
  EXPECT_NEAR(nsAfter(start, out.events[0].header.stamp), 1e9, 1.0);
  EXPECT_EQ(out.events[1].header.stamp - start, ros::Duration(1e9));
  EXPECT_EQ(summary.header.stamp, out.events[1].header.stamp);
  ASSERT_TRUE(summary.recording_ok) << summary.recording_error;
  rosbag::Bag bag(summary.bag_path, rosbag::bagmode::Read);
  EXPECT_EQ(rosbag::View(bag).size(), 4 + 2u);  // parameters, input, prediction, 2 events, summary
}

// ---- A taken run_id: served under the next free suffix, nothing overwritten ----

TEST(DuplicateRunId, TwentyStudentsTypingTheSameRunIdAreAllServed) {
  const auto input = makeInput("test", {1, 1, 1}, {2, 1, -1}, {-1, 0, 1});
  for (int i = 0; i < 20; ++i) g_node->publish(input);
  for (int i = 1; i <= 20; ++i) {
    const std::string run_id = i == 1 ? "test" : "test." + std::to_string(i);
    SCOPED_TRACE(run_id);
    const RunOutputs& out = g_node->waitFor(run_id);
    ASSERT_EQ(out.summaries.size(), 1u);
    EXPECT_TRUE(out.rejections.empty());
    EXPECT_EQ(out.summaries.front().collision_count, 3u);
    EXPECT_EQ(out.summaries.front().requested_run_id, i == 1 ? "" : "test");
    EXPECT_EQ(out.predictions.front().run_id, run_id);
    EXPECT_EQ(out.summaries.front().bag_path, g_bag_directory + "/" + run_id + ".bag");
    EXPECT_TRUE(fs::exists(out.summaries.front().bag_path));
  }
}

TEST(DuplicateRunId, AnExistingBagIsNeverOverwritten) {
  const std::string existing = g_bag_directory + "/from_last_week.bag";
  fs::create_directories(g_bag_directory);
  std::ofstream(existing) << "a bag of last week\n";
  g_node->publish(makeInput("from_last_week", {1, 1, 1}, {2, 1, -1}, {-1, 0, 1}));
  const RunOutputs& served = g_node->waitFor("from_last_week.2");
  ASSERT_EQ(served.summaries.size(), 1u);
  EXPECT_EQ(served.summaries.front().requested_run_id, "from_last_week");
  EXPECT_EQ(g_node->runs().count("from_last_week"), 0u);  // nothing under the taken name
  std::ifstream file(existing);
  std::string line;
  std::getline(file, line);
  EXPECT_EQ(line, "a bag of last week");
}

// ---- Services: the same serve path as the topic ----

TEST(Services, RunSceneAnswersWithTheSummaryOfAPublishedRecordedRun) {
  collision_lab::RunScene call;
  call.request.run_id = "by_service";
  call.request.masses = {{1e4, 1, std::numeric_limits<double>::infinity()}};
  call.request.positions = {{2, 1, 0}};
  call.request.velocities = {{-1, 0, 0}};
  ASSERT_TRUE(callService(kRunScene, call));
  EXPECT_TRUE(call.response.ok) << call.response.message;
  const auto& summary = call.response.summary;
  EXPECT_EQ(summary.run_id, "by_service");
  EXPECT_EQ(summary.collision_count, 314u);  // pi to 3 digits
  EXPECT_NE(call.response.message.find("314 collisions"), std::string::npos) << call.response.message;

  const RunOutputs& out = g_node->waitFor("by_service");  // published like a topic input
  ASSERT_EQ(out.summaries.size(), 1u);
  auto published = out.summaries.front();
  published.header.seq = 0;
  EXPECT_EQ(bytes(published), bytes(summary));
  EXPECT_EQ(out.predictions.size(), 1u);
  ASSERT_TRUE(summary.recording_ok) << summary.recording_error;
  const auto bagged = expectBagOnTimeline(summary.bag_path, 1.0);
  EXPECT_EQ(bagged.size(), 314u);
}

TEST(Services, RunSceneReportsARejection) {
  collision_lab::RunScene call;
  call.request.run_id = "bad_by_service";
  call.request.masses = {{1, 1, 1}};
  call.request.positions = {{0, 1, 2}};
  call.request.velocities = {{-1, 0, 0}};
  ASSERT_TRUE(callService(kRunScene, call));
  EXPECT_FALSE(call.response.ok);
  EXPECT_EQ(call.response.rejected.reason, collision_lab::Rejected::POSITIONS_NOT_ORDERED);
  EXPECT_NE(call.response.message.find("POSITIONS_NOT_ORDERED"), std::string::npos);
  const RunOutputs& out = g_node->waitFor("bad_by_service");  // published on `rejected` too
  ASSERT_EQ(out.rejections.size(), 1u);
  EXPECT_EQ(out.rejections.front().reason, collision_lab::Rejected::POSITIONS_NOT_ORDERED);
}

TEST(Services, RunPresetRunsANamedPresetAndListsTheNamesOfAnUnknownOne) {
  collision_lab::RunPreset call;
  call.request.name = "pi_digits_2";
  call.request.run_id = "preset_run";
  ASSERT_TRUE(callService(kRunPreset, call));
  EXPECT_TRUE(call.response.ok) << call.response.message;
  EXPECT_EQ(call.response.summary.collision_count, 31u);  // pi to 2 digits
  EXPECT_EQ(g_node->waitFor("preset_run").events.size(), 31u);

  collision_lab::RunPreset unnamed;
  unnamed.request.name = "pi_digits_3";  // run_id: <name>_<UTC time>
  ASSERT_TRUE(callService(kRunPreset, unnamed));
  EXPECT_TRUE(unnamed.response.ok) << unnamed.response.message;
  EXPECT_EQ(unnamed.response.summary.run_id.rfind("pi_digits_3_", 0), 0u);

  collision_lab::RunPreset unknown;
  unknown.request.name = "pi_digits_9";
  ASSERT_TRUE(callService(kRunPreset, unknown));
  EXPECT_FALSE(unknown.response.ok);
  for (const char* name : {"pi_digits_9", "equal_masses", "pi_digits_3", "moving_wall"}) {
    EXPECT_NE(unknown.response.message.find(name), std::string::npos) << unknown.response.message;
  }
}

TEST(Services, ConcurrentCallsAndTopicInputsAreAllServedOnce) {
  constexpr int kCalls = 6, kTopicInputs = 3;
  std::atomic<int> done{0};
  std::vector<collision_lab::RunScene> calls(kCalls);
  // One persistent client per thread, alive until every call has returned: no service
  // connection of this test closes while another one opens. roscpp's PollSet hands a stale
  // POLLRDHUP of a just-closed socket to a new socket that reuses its fd number (its
  // just_deleted_ guard skips only ERR/HUP/NVAL) and closes it, so a non-persistent call
  // per thread (ros::service::call) now and then returned false although its run was served.
  ros::NodeHandle nh;
  std::vector<ros::ServiceClient> clients;
  for (int i = 0; i < kCalls; ++i) clients.push_back(nh.serviceClient<collision_lab::RunScene>(kRunScene, true));
  std::vector<std::thread> threads;
  for (int i = 0; i < kCalls; ++i) {
    auto& call = calls[i];
    call.request.run_id = "class";
    call.request.masses = {{1, 2, 3}};
    call.request.positions = {{2, 0, -2}};
    call.request.velocities = {{-1, 0.5, 1}};
    threads.emplace_back([&call, &client = clients[i], &done] {
      if (!client.call(call)) call.response.message = "call failed";
      ++done;
    });
  }
  for (int i = 0; i < kTopicInputs; ++i) {
    g_node->publish(makeInput("class", {1, 2, 3}, {2, 0, -2}, {-1, 0.5, 1}));
  }
  // The main thread spins the collector while the calls wait for their runs.
  const bool returned = waitUntil([&] { return done == kCalls; }, "6 concurrent run_scene calls");
  for (auto& t : threads) t.join();
  ASSERT_TRUE(returned);

  std::set<std::string> expected, by_calls;
  for (int i = 1; i <= kCalls + kTopicInputs; ++i) {
    expected.insert(i == 1 ? "class" : "class." + std::to_string(i));
  }
  for (const auto& call : calls) {
    ASSERT_TRUE(call.response.ok) << call.response.message;
    EXPECT_EQ(expected.count(call.response.summary.run_id), 1u) << call.response.summary.run_id;
    by_calls.insert(call.response.summary.run_id);
  }
  EXPECT_EQ(by_calls.size(), static_cast<std::size_t>(kCalls));  // each call its own run
  for (const auto& run_id : expected) {
    const RunOutputs& out = g_node->waitFor(run_id);
    ASSERT_EQ(out.summaries.size(), 1u) << run_id;
    EXPECT_EQ(out.events.size(), 3u) << run_id;
  }
  EXPECT_EQ(g_node->runs().count("class." + std::to_string(kCalls + kTopicInputs + 1)), 0u);
}

// ---- Latching: a late joiner gets the newest prediction, summary and rejection ----

TEST(Latching, ALateJoinerGetsTheNewestPredictionSummaryAndRejection) {
  runOnce(g_node, makeInput("latched_run", {1, 1, 1}, {2, 1, -1}, {-1, 0, 1}));
  runOnce(g_node, makeInput("latched_bad", {1, -1, 1}, {2, 1, -1}, {-1, 0, 1}));
  std::optional<collision_lab::Prediction> prediction;
  std::optional<collision_lab::RunSummary> summary;
  std::optional<collision_lab::Rejected> rejected;
  ros::NodeHandle nh("collision_lab");
  const auto keep = [](auto& slot) {
    return [&slot](const auto& msg) { slot = *msg; };
  };
  const ros::Subscriber a = nh.subscribe<collision_lab::Prediction>(
      "predictions", 1, boost::function<void(const collision_lab::Prediction::ConstPtr&)>(keep(prediction)));
  const ros::Subscriber b = nh.subscribe<collision_lab::RunSummary>(
      "run_summaries", 1, boost::function<void(const collision_lab::RunSummary::ConstPtr&)>(keep(summary)));
  const ros::Subscriber c = nh.subscribe<collision_lab::Rejected>(
      "rejected", 1, boost::function<void(const collision_lab::Rejected::ConstPtr&)>(keep(rejected)));
  ASSERT_TRUE(waitUntil([&] { return prediction && summary && rejected; },
                        "the latched prediction, summary and rejection"));
  EXPECT_EQ(prediction->run_id, "latched_run");
  EXPECT_EQ(summary->run_id, "latched_run");
  EXPECT_EQ(rejected->run_id, "latched_bad");
}

}  // namespace

// ---- /diagnostics: counts, recording state, free space ----

TEST(LabNode, DiagnosticsReportRunsAndRecordingState) {
  roundTrip();
  noDisk();
  runOnce(g_node, makeInput("diagnosed_bad", {1, -1, 1}, {2, 1, 0}, {-1, 0, 0}));
  using Status = diagnostic_msgs::DiagnosticStatus;
  std::map<std::string, Status> latest;
  ros::NodeHandle nh;
  const ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&latest](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
        for (const Status& status : array->status) latest[status.name] = status;
      });
  const auto value = [](const Status& status, const std::string& key) {
    for (const auto& pair : status.values) {
      if (pair.key == key) return pair.value;
    }
    return std::string();
  };
  // diagnostic_updater names a status by the node's name without its leading '/'.
  const std::string healthy = "collision_lab/collision_lab_node: lab runs";
  const std::string faulty = "collision_lab_faulty/collision_lab_node: lab runs";
  // Published once a second; wait for a report from each node after their runs.
  const auto reported = [&] {
    return latest.count(healthy) && latest.count(faulty) && value(latest[healthy], "runs accepted") != "0" &&
           latest[faulty].level == Status::ERROR;
  };
  ASSERT_TRUE(waitUntil(reported, "/diagnostics from both nodes after their runs"));
  EXPECT_GE(std::stoull(value(latest[healthy], "runs accepted")), 1u);
  EXPECT_GE(std::stoull(value(latest[healthy], "runs rejected")), 1u);
  EXPECT_NE(latest[healthy].level, Status::ERROR);
  EXPECT_EQ(value(latest[healthy], "recording"), "on");
  EXPECT_GT(std::stod(value(latest[healthy], "free space in bag directory [MB]")), 0.0);
  EXPECT_NE(latest[faulty].message.find("recording failed"), std::string::npos);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "node_test");
  ros::NodeHandle private_nh("~");
  if (!private_nh.getParam("bag_directory", g_bag_directory) ||
      !private_nh.getParam("faulty_bag_directory", g_faulty_bag_directory)) {
    ADD_FAILURE() << "~bag_directory and ~faulty_bag_directory must be set";
    return 1;
  }
  // The faulty node's bag directory lies under /dev/null (node_test.test): no folder, and so
  // no bag, can ever be made there, whichever process starts first.

  RunCollector node("collision_lab"), faulty("collision_lab_faulty");
  g_node = &node;
  g_faulty = &faulty;
  node.waitForConnection();
  faulty.waitForConnection();
  for (const char* service : {kRunScene, kRunPreset}) {
    if (!ros::service::waitForService(service, ros::Duration(collision_lab_test::kWaitTimeout))) {
      ADD_FAILURE() << "no service " << service << " after " << collision_lab_test::kWaitTimeout << " s";
    }
  }
  const int result = RUN_ALL_TESTS();
  std::error_code ec;
  fs::remove_all(fs::path(g_bag_directory).parent_path(), ec);
  return result;
}
