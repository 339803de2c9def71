// The class's web server (issue 23) against a real collision_lab_node, through a real HTTP
// client (web_test.test): the JSON API, the safety limits one by one, and a run sent over
// ROS found beside the browser's. Counts are checked against pi's digits (m_A/m_B = 100
// against a wall: 31 impacts; 1e4: 314), not against the code under test.
#include <atomic>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/web/run_book.h"
#include "../ros/run_collector.h"
// Last: it includes <resolv.h>, whose macro _res breaks Eigen's headers included after it.
#include <httplib.h>

namespace {

using collision_lab_test::waitUntil;
using nlohmann::json;

constexpr char kUrlParam[] = "/collision_lab/collision_lab_web/url";
constexpr char kCode[] = "sesame";

std::string g_host;
int g_port = 0;

/// A client of the class: every route needs the class code (here in its header).
httplib::Client client() {
  httplib::Client c(g_host, g_port);
  c.set_read_timeout(60, 0);
  c.set_default_headers({{"X-Class-Code", kCode}});
  return c;
}

json piScene(const std::string& student) {
  return {{"student", student},
          {"code", kCode},
          {"masses", {100, 1, "inf"}},
          {"positions", {2, 1, 0}},
          {"velocities", {-1, 0, 0}}};
}

httplib::Result post(const json& body, const httplib::Headers& headers = {}) {
  auto c = client();
  return c.Post("/api/runs", headers, body.dump(), "application/json");
}

/// The run once its state is finished (fails the test when it never is).
json finishedRun(const std::string& run_id) {
  json run;
  waitUntil(
      [&] {
        auto c = client();
        auto res = c.Get(("/api/runs/" + run_id).c_str());
        if (!res || res->status != 200) return false;
        run = json::parse(res->body);
        return run["state"] == "finished";
      },
      "run " + run_id + " to finish");
  return run;
}

std::size_t lines(const std::string& text) {
  std::size_t n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

class WebTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string url;
    waitUntil([&] { return ros::param::get(kUrlParam, url); }, "the web node to publish its address");
    // url: http://HOST:PORT/
    const auto colon = url.rfind(':');
    g_host = url.substr(7, colon - 7);
    g_port = std::stoi(url.substr(colon + 1));
    // The lab node subscribes to the web node's input: a POST answered 202 says so.
    waitUntil(
        [] {
          auto res = post(piScene("warmup"));
          return res && res->status == 202;
        },
        "the web node to reach the lab node");
  }
};

TEST_F(WebTest, BrowserRunIsServedRecordedAndListed) {
  auto res = post(piScene("ana"));
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const std::string run_id = json::parse(res->body)["run_id"];
  EXPECT_EQ(run_id.rfind("ana.", 0), 0u) << "a student's run is served as <student>.<run_id>";
  const json run = finishedRun(run_id);
  EXPECT_EQ(run.at("summary").at("collision_count"), 31);
  EXPECT_EQ(run.at("prediction").at("collision_count"), 31);
  EXPECT_EQ(run.at("student"), "ana");
  ASSERT_EQ(run.at("plots").at("velocity").size(), 3u);
  // The final velocity of the light ball (body 1) in the plot is the summary's.
  EXPECT_NEAR(run.at("plots").at("velocity")[1].at("points").back()[1].get<double>(),
              run.at("summary").at("final_velocities")[1].get<double>(), 1e-5);

  auto c = client();
  auto csv = c.Get(("/api/runs/" + run_id + "/events.csv").c_str());
  ASSERT_TRUE(csv);
  EXPECT_EQ(csv->status, 200);
  EXPECT_EQ(lines(csv->body), 1u + 31u) << "a header and one row per impact";

  auto bag = c.Get(("/api/runs/" + run_id + "/bag").c_str());
  ASSERT_TRUE(bag);
  EXPECT_EQ(bag->status, 200);
  EXPECT_EQ(bag->body.rfind("#ROSBAG V2.0", 0), 0u);

  auto list = c.Get("/api/runs?student=ana");
  ASSERT_TRUE(list);
  const json runs = json::parse(list->body);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].at("run_id"), run_id);

  auto page = c.Get(("/runs/" + run_id).c_str());
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("data-run-id=\"" + run_id + "\""), std::string::npos);
}

// A run the model answered has no collision events: its events CSV is a 404 that says why
// (docs/web.md), not an empty file served with 200.
TEST_F(WebTest, EventsCsvOfARunNotSimulatedIs404WithItsReason) {
  json capped = piScene("nan");
  capped["max_collisions"] = 10;  // below the 31 predicted: the model answers
  json predict_only = piScene("nan");
  predict_only["mode"] = 1;
  for (const json& scene : {capped, predict_only}) {
    auto res = post(scene);
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 202) << res->body;
    const std::string run_id = json::parse(res->body)["run_id"];
    const json run = finishedRun(run_id);
    ASSERT_FALSE(run.at("view").at("not_simulated").get<std::string>().empty()) << run.at("view").dump();
    auto csv = client().Get(("/api/runs/" + run_id + "/events.csv").c_str());
    ASSERT_TRUE(csv);
    EXPECT_EQ(csv->status, 404) << run_id << ": " << csv->body.size() << " bytes: " << csv->body;
    const json error = json::parse(csv->body, nullptr, false);
    ASSERT_TRUE(error.is_object()) << csv->body;
    EXPECT_NE(error.value("error", "").find("not simulated"), std::string::npos) << csv->body;
  }
}

TEST_F(WebTest, RunIdsAreNumberedPerStudent) {
  // Classmates' runs do not share numbers: each student's n-th run is <student>.run<n>.
  const auto send = [](const std::string& student) {
    auto res = post(piScene(student));
    EXPECT_TRUE(res);
    if (!res) return std::string();
    EXPECT_EQ(res->status, 202) << res->body;
    return json::parse(res->body).value("run_id", std::string());
  };
  EXPECT_EQ(send("flo"), "flo.run1");
  EXPECT_EQ(send("gus"), "gus.run1");
  EXPECT_EQ(send("flo"), "flo.run2");
}

TEST_F(WebTest, LiveStreamEndsWithTheFinalRun) {
  auto res = post(piScene("ben"));
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const std::string run_id = json::parse(res->body)["run_id"];
  std::string received;
  auto c = client();
  auto stream = c.Get(("/api/runs/" + run_id + "/stream").c_str(), [&](const char* data, std::size_t n) {
    received.append(data, n);
    return true;  // the server ends the stream after its `final` event
  });
  ASSERT_TRUE(stream);
  EXPECT_EQ(stream->status, 200);
  const auto final_at = received.find("event: final\ndata: ");
  ASSERT_NE(final_at, std::string::npos) << received.substr(0, 200);
  const auto data = received.substr(final_at + 19);
  const json run = json::parse(data.substr(0, data.find('\n')));
  EXPECT_EQ(run.at("summary").at("collision_count"), 31);
}

TEST_F(WebTest, RunBeyondThePublishedEventsIsRebuiltFromItsBag) {
  auto res = post({{"student", "cleo"}, {"code", kCode}, {"preset", "pi_digits_3"}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const json run = finishedRun(json::parse(res->body)["run_id"]);
  EXPECT_EQ(run.at("summary").at("published_events"), 100) << "the lab node's max_published_events";
  EXPECT_EQ(run.at("collisions"), 314) << "every impact, from the bag";
  EXPECT_FALSE(run.contains("bag_error"));
  // Light: at most the envelope's points per series whatever the count.
  for (const auto& series : run.at("plots").at("velocity")) EXPECT_LE(series.at("points").size(), 1024u);
}

TEST_F(WebTest, RejectionCarriesReasonAndField) {
  json scene = piScene("dora");
  scene["positions"] = {0, 1, 2};  // not strictly decreasing
  auto res = post(scene);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 422);
  const json body = json::parse(res->body);
  EXPECT_EQ(body.at("rejected").at("reason_name"), "POSITIONS_NOT_ORDERED");
  EXPECT_EQ(body.at("rejected").at("field").get<std::string>().rfind("positions", 0), 0u);

  scene = piScene("dora");
  scene["velocities"] = {-1, "fast", 0};
  res = post(scene);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  EXPECT_EQ(json::parse(res->body)["field"], "velocities[1]");
}

// The API takes every scene the CLI takes (a ring, a restitution model), and refuses what it
// does not know by name (a ring used to be dropped, and the scene ran on a plain line).
TEST_F(WebTest, RingsAndModelsAreTakenAndUnknownKeysRefused) {
  json ring = {{"student", "ring"}, {"masses", {1, 2}}, {"positions", {5, 0}}, {"velocities", {-1, 0}},
               {"ring", 10}, {"restitution", {0.9}}, {"restitution_model", "tc"}, {"tc", 0.001},
               {"max_collisions", 5}};
  auto res = post(ring);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  const json run = finishedRun(json::parse(res->body)["run_id"]);
  EXPECT_EQ(run.at("scene").at("ring"), 10.0);
  EXPECT_EQ(run.at("scene").at("restitution_model"), "tc");
  EXPECT_EQ(run.at("summary").at("collision_count"), 5);  // a ring never ends: the cap

  json unknown = piScene("ring");
  unknown["rings"] = 10;
  res = post(unknown);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  EXPECT_EQ(json::parse(res->body).at("field"), "rings");
  EXPECT_NE(json::parse(res->body).at("error").get<std::string>().find("unknown key \"rings\""), std::string::npos);

  json model = piScene("ring");
  model["restitution_model"] = "sticky";
  res = post(model);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  EXPECT_EQ(json::parse(res->body).at("field"), "restitution_model");

  res = post({{"student", "ring"}, {"preset", "pi_digits_2"}, {"ring", 10}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  EXPECT_EQ(json::parse(res->body).at("field"), "ring");
}

TEST_F(WebTest, TheTeacherSeesEachStudentsRejectedInputs) {
  json bad = piScene("jo");
  bad["positions"] = {0, 1, 2};  // not strictly decreasing
  for (int k = 0; k < 2; ++k) {
    auto res = post(bad);
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 422) << res->body;
  }
  // Rejected sends are no runs: the student's first run is still run1.
  auto good = post(piScene("jo"));
  ASSERT_TRUE(good);
  ASSERT_EQ(good->status, 202) << good->body;
  EXPECT_EQ(json::parse(good->body).at("run_id"), "jo.run1");

  json rejections;
  waitUntil(
      [&] {
        auto res = client().Get("/api/rejections?student=jo");
        if (!res || res->status != 200) return false;
        rejections = json::parse(res->body);
        return rejections.size() >= 2;
      },
      "the lab node's rejections in the run index");
  ASSERT_EQ(rejections.size(), 2u) << rejections.dump();
  for (const json& r : rejections) {
    EXPECT_EQ(r.at("student"), "jo");
    EXPECT_EQ(r.at("run_id"), "") << "jo typed no run_id (the page numbered the send): " << r.dump();
    EXPECT_EQ(r.at("by"), "lab node");
    EXPECT_EQ(r.at("reason_name"), "POSITIONS_NOT_ORDERED");
    EXPECT_EQ(r.at("field").get<std::string>().rfind("positions", 0), 0u) << r.dump();
    EXPECT_FALSE(r.at("message").get<std::string>().empty());
    EXPECT_GT(r.at("at").get<double>(), 1.6e9) << "a wall time [s since the epoch]";
  }
  EXPECT_GE(rejections[0].at("at").get<double>(), rejections[1].at("at").get<double>()) << "newest first";
  // Everyone's, with jo's among them; another student's filter leaves jo's out.
  auto all = client().Get("/api/rejections");
  ASSERT_TRUE(all);
  EXPECT_GE(json::parse(all->body).size(), 2u);
  auto other = client().Get("/api/rejections?student=nobody");
  ASSERT_TRUE(other);
  EXPECT_EQ(json::parse(other->body).size(), 0u);
}

// The web node's own refusals (400, 413, 415, 429) never reach the lab node's run index:
// the web node lists them beside the lab's rejections, per student where the body named one.
TEST_F(WebTest, TheTeacherSeesTheWebNodesOwnRefusals) {
  json bad = piScene("kim");
  bad["velocities"] = {-1, "fast", 0};
  bad["run_id"] = "mine";  // typed: listed as asked for
  auto res = post(bad);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 400) << res->body;
  res = client().Post("/api/runs", piScene("kim").dump(), "text/plain");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 415) << res->body;
  json large = piScene("kim");
  large["padding"] = std::string(10000, 'x');  // over max_body_bytes = 8192: never read
  res = post(large);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 413);

  auto listed = client().Get("/api/rejections?student=kim");
  ASSERT_TRUE(listed);
  ASSERT_EQ(listed->status, 200);
  const json kim = json::parse(listed->body);
  ASSERT_EQ(kim.size(), 2u) << kim.dump();
  EXPECT_EQ(kim[0].at("reason_name"), "HTTP 415") << "newest first";
  EXPECT_EQ(kim[0].at("run_id"), "");
  EXPECT_NE(kim[0].at("message").get<std::string>().find("Content-Type: application/json"), std::string::npos);
  EXPECT_EQ(kim[1].at("reason_name"), "HTTP 400");
  EXPECT_EQ(kim[1].at("run_id"), "mine");
  EXPECT_EQ(kim[1].at("field"), "velocities[1]");
  for (const json& r : kim) {
    EXPECT_EQ(r.at("by"), "web node");
    EXPECT_GT(r.at("at").get<double>(), 1.6e9) << "a wall time [s since the epoch]";
  }
  // The 413's body was never read: listed without a student.
  const json all = json::parse(client().Get("/api/rejections")->body);
  bool too_large = false;
  for (const json& r : all) too_large = too_large || (r.at("reason_name") == "HTTP 413" && r.at("student") == "");
  EXPECT_TRUE(too_large) << all.dump();
}

TEST_F(WebTest, ClassCodeIsNeededEverywhere) {
  json scene = piScene("eve");
  scene.erase("code");
  httplib::Client bare(g_host, g_port);  // no X-Class-Code
  auto res = bare.Post("/api/runs", scene.dump(), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 403);
  scene["code"] = "guess";
  res = bare.Post("/api/runs", scene.dump(), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 403);
  // In a header instead of the body.
  scene.erase("code");
  res = post(scene);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 202) << res->body;
  // Reading needs it too: the API answers 403, a page sends to the code page.
  for (const char* path : {"/api/runs", "/api/queue", "/api/presets", "/static/app.js"}) {
    auto read = bare.Get(path);
    ASSERT_TRUE(read) << path;
    EXPECT_EQ(read->status, 403) << path;
  }
  auto page = bare.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 303);
  EXPECT_EQ(page->get_header_value("Location"), "/login");
  auto login_page = bare.Get("/login");
  ASSERT_TRUE(login_page);
  EXPECT_EQ(login_page->status, 200);
}

TEST_F(WebTest, LargeBodyIs413) {
  json scene = piScene("fay");
  scene["padding"] = std::string(10000, 'x');  // over max_body_bytes = 8192
  auto res = post(scene);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 413);
}

TEST_F(WebTest, TooManyBodiesIs422) {
  json scene = {{"student", "gus"}, {"code", kCode}};
  for (int i = 0; i < 21; ++i) {  // max_bodies = 20
    scene["masses"].push_back(1);
    scene["positions"].push_back(21 - i);
    scene["velocities"].push_back(0);
  }
  auto res = post(scene);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 422);
  const json body = json::parse(res->body);
  EXPECT_EQ(body.at("rejected").at("reason_name"), "TOO_MANY_BODIES");
  EXPECT_EQ(body.at("rejected").at("field"), "masses");
}

TEST_F(WebTest, TheEnvelopeIsCheckedHereInTheLabsWords) {
  // The web checks a send's envelope with the lab's own function (service::checkEnvelope):
  // the lab's reason and words, answered by the web node without a round trip (failed
  // before: an invalid student or mode was listed as the lab node's, and a scene with more
  // positions than max_bodies but few masses went to the lab).
  json dotted = piScene("dot.ted");
  json mode = piScene("lou");
  mode["mode"] = 3;
  json long_positions = piScene("lou");
  for (int i = 0; i < 21; ++i) long_positions["positions"].push_back(100 + i);  // max_bodies = 20
  const std::tuple<json, const char*, const char*, const char*> cases[] = {
      {dotted, "INVALID_STUDENT", "student",
       "student 'dot.ted' may contain only letters, digits, '_' and '-' ('.' separates it from the run_id)"},
      {mode, "INVALID_MODE", "mode", "mode 3 is not one of MODE_FULL (0), MODE_PREDICT_ONLY (1), MODE_SUMMARY_ONLY (2)"},
      {long_positions, "TOO_MANY_BODIES", "masses",
       "24 bodies are more than this node's ~max_bodies = 20; send a smaller scene, or start the node with a larger "
       "~max_bodies"}};
  for (const auto& [scene, reason, field, message] : cases) {
    auto res = post(scene);
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 422) << res->body;
    const json rejected = json::parse(res->body).at("rejected");
    EXPECT_EQ(rejected.at("reason_name"), reason);
    EXPECT_EQ(rejected.at("field"), field);
    EXPECT_EQ(rejected.at("message"), message);
    const json listed = json::parse(client().Get(("/api/rejections?student=" + scene["student"].get<std::string>()).c_str())->body);
    ASSERT_FALSE(listed.empty());
    EXPECT_EQ(listed[0].at("reason_name"), reason);
    EXPECT_EQ(listed[0].at("by"), "web node") << listed.dump();
  }
}

TEST_F(WebTest, RunsPerStudentPerMinuteIs429ForThatStudentOnly) {
  for (int i = 0; i < 3; ++i) {  // runs_per_minute = 3
    auto res = post(piScene("hal"));
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 202) << res->body;
  }
  auto res = post(piScene("hal"));
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 429);
  EXPECT_FALSE(res->get_header_value("Retry-After").empty());
  // The teacher sees it, under hal, with its reason.
  const json listed = json::parse(client().Get("/api/rejections?student=hal")->body);
  ASSERT_EQ(listed.size(), 1u) << listed.dump();
  EXPECT_EQ(listed[0].at("reason_name"), "HTTP 429");
  EXPECT_EQ(listed[0].at("by"), "web node");
  EXPECT_NE(listed[0].at("message").get<std::string>().find("runs per student per minute"), std::string::npos);
  res = post(piScene("ivy"));
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 202) << "another student is not held back";
}

TEST_F(WebTest, ConcurrentStreamsAreLimited) {
  // A run that never finishes: an AcceptedRun with no run behind it.
  ros::NodeHandle nh;
  ros::Publisher accepted = nh.advertise<collision_lab::AcceptedRun>("/collision_lab/accepted_runs", 10);
  collision_lab::AcceptedRun phantom;
  phantom.run_id = "phantom";
  phantom.student = "nobody";
  auto bump = [&] {
    phantom.header.stamp = ros::Time::now();
    accepted.publish(phantom);
  };
  ASSERT_TRUE(waitUntil(
      [&] {
        bump();
        auto c = client();
        auto res = c.Get("/api/runs/phantom");
        return res && res->status == 200;
      },
      "the phantom run to be listed"));

  std::atomic<bool> close_first{false}, close_all{false};
  std::atomic<int> open{0}, ended{0};
  std::vector<std::thread> streams;
  for (int k = 0; k < 2; ++k) {  // max_streams = 2
    streams.emplace_back([&, k] {
      auto c = client();
      bool counted = false;
      c.Get("/api/runs/phantom/stream", [&](const char*, std::size_t) {
        if (!counted) counted = true, ++open;
        return !(close_all || (k == 0 && close_first));
      });
      ++ended;
    });
  }
  ASSERT_TRUE(waitUntil(
      [&] {
        bump();  // each stream sends the changed run: its first bytes arrive
        return open == 2;
      },
      "two streams to open"));
  auto c = client();
  auto third = c.Get("/api/runs/phantom/stream");
  ASSERT_TRUE(third);
  EXPECT_EQ(third->status, 503);

  // The first stream closes; its slot is free once the server notices (at its next write).
  close_first = true;
  EXPECT_TRUE(waitUntil(
      [&] {
        bump();
        bool got = false;
        auto cc = client();
        cc.Get("/api/runs/phantom/stream", [&](const char*, std::size_t) {
          got = true;
          return false;
        });
        return got;
      },
      "a stream slot to be free again"));
  close_all = true;
  waitUntil(
      [&] {
        bump();
        return ended == 2;
      },
      "the streams to close");
  for (auto& t : streams) t.join();
}

TEST_F(WebTest, NoPathLeavesTheServedFiles) {
  auto c = client();
  for (const char* path : {"/runs/../../etc/passwd", "/static/../../etc/passwd", "/api/runs/..%2F..%2Fetc%2Fpasswd/bag",
                           "/api/runs/../../../etc/passwd/events.csv", "/static/..%2f..%2fetc%2fpasswd"}) {
    auto res = c.Get(path);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 404) << path;
    EXPECT_EQ(res->body.find("root:"), std::string::npos) << path;
  }
}

TEST_F(WebTest, NamesAreEscapedInPages) {
  EXPECT_EQ(collision_lab_web::htmlEscape("<b onclick='x'>&\"</b>"),
            "&lt;b onclick=&#39;x&#39;&gt;&amp;&quot;&lt;/b&gt;");
  auto c = client();
  auto res = c.Get("/runs/%3Cscript%3Ealert(1)%3C%2Fscript%3E");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 404);
  EXPECT_EQ(res->body.find("<script"), std::string::npos);
}

TEST_F(WebTest, RunSentOverRosIsShownToo) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<collision_lab::InitialConditions>("/collision_lab/initial_conditions", 10);
  ASSERT_TRUE(waitUntil([&] { return pub.getNumSubscribers() > 0; }, "the lab node to subscribe"));
  collision_lab::InitialConditions input;
  input.student = "rosie";
  input.masses = {100.0, 1.0, std::numeric_limits<double>::infinity()};
  input.positions = {2.0, 1.0, 0.0};
  input.velocities = {-1.0, 0.0, 0.0};
  input.header.stamp = ros::Time::now();
  pub.publish(input);
  json runs;
  ASSERT_TRUE(waitUntil(
      [&] {
        auto c = client();
        auto res = c.Get("/api/runs?student=rosie");
        if (!res || res->status != 200) return false;
        runs = json::parse(res->body);
        return runs.size() == 1 && runs[0]["state"] == "finished";
      },
      "the ROS run to be listed"));
  EXPECT_EQ(runs[0].at("collisions"), 31);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "web_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
