// The web node restarted (issue 30: "a restart of the web node lists 2 of 2,143 runs; old
// links give 404"): the run index and the bags are written as the lab node writes them, the
// web node is killed (SIGKILL) and respawned by roslaunch; it still lists every run, serves
// an old run's page and JSON, and its bag. A web node that missed a run's last events and
// its summary (dropped messages, a paused node) ends it finished or interrupted from the
// index and the bag: nothing stays "running".
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <iterator>
#include <mutex>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <httplib.h>
#include <nlohmann/json.hpp>
#include <ros/network.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include "collision_lab/AcceptedRun.h"
#include "collision_lab/CollisionEvent.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/service/run_index.h"
#include "collision_lab/ros/run_index_recorder.h"

namespace {

using nlohmann::json;

constexpr char kWebNode[] = "/collision_lab/collision_lab_web";
constexpr char kUrlParam[] = "/collision_lab/collision_lab_web/url";
constexpr int kRuns = 40;

void waitUntil(const std::function<bool()>& condition, const std::string& what) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!condition()) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "timed out waiting for " << what;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

/// The web node's process id (its XML-RPC getPid); 0 when it is not registered.
int webPid(const std::string& node = kWebNode) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, false)) return 0;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(static_cast<std::string>(payload), host, port)) return 0;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue pid_args, pid_result;
  pid_args[0] = ros::this_node::getName();
  if (!client.execute("getPid", pid_args, pid_result) || pid_result.size() < 3) return 0;
  return static_cast<int>(pid_result[2]);
}

/// The web node's address once it answers: {host, port}.
std::pair<std::string, int> webAddress(const std::string& url_param = kUrlParam) {
  std::pair<std::string, int> address;
  waitUntil(
      [&] {
        std::string url;
        if (!ros::param::get(url_param, url)) return false;
        const auto colon = url.rfind(':');
        address = {url.substr(7, colon - 7), std::stoi(url.substr(colon + 1))};
        httplib::Client c(address.first, address.second);
        auto res = c.Get("/login");
        return res && res->status == 200;
      },
      "the web node to answer");
  return address;
}

/// Every run's bag and index row, as the lab node writes them: kRuns - 1 finished, the last
/// interrupted (its node died) with the events its bag holds.
void writeDay(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  collision_lab::service::RunIndex index(collision_lab::service::RunIndex::defaultPath(dir.string()));
  for (int k = 1; k <= kRuns; ++k) {
    const std::string run_id = "s" + std::to_string(k % 4) + ".run" + std::to_string(k);
    const std::string bag_path = (dir / (run_id + ".bag")).string();
    collision_lab::InitialConditions input;
    input.run_id = run_id;
    input.student = "s" + std::to_string(k % 4);
    input.masses = {1.0, 1.0};
    input.positions = {1.0, 0.0};
    input.velocities = {-1.0, 1.0};
    collision_lab::CollisionEvent event;
    event.run_id = run_id;
    event.index = 1;
    event.pair_index = 0;
    event.first_moved = 0;
    event.last_moved = 1;
    event.time = 0.5;
    event.restitution = 1.0;
    event.pair_velocities_after = {1.0, -1.0};
    collision_lab::RunSummary summary;
    summary.run_id = run_id;
    summary.student = input.student;
    summary.collision_count = 1;
    summary.published_events = 1;
    summary.stop_reason = "NO_MORE_COLLISIONS";
    summary.model_name = "two_body";
    summary.recording_ok = true;
    summary.bag_path = bag_path;
    const bool interrupted = k == kRuns;
    {
      rosbag::Bag bag;
      bag.open(bag_path, rosbag::bagmode::Write);
      bag.write("/collision_lab/served_inputs", ros::Time(1.0), input);
      bag.write("/collision_lab/collision_events", ros::Time(2.0), event);
      if (!interrupted) bag.write("/collision_lab/run_summaries", ros::Time(3.0), summary);
      bag.close();
    }
    collision_lab::service::IndexedRun row;
    row.run_id = run_id;
    row.student = input.student;
    row.state = collision_lab::service::RunState::kQueued;
    row.accepted_at = 1.0e9 + k;
    row.scene_json = json({{"masses", input.masses}}).dump();
    row.body_count = static_cast<std::uint32_t>(input.masses.size());
    row.bag_path = bag_path;
    index.accepted(row);
    index.started(run_id, row.accepted_at + 0.1);
    if (interrupted) {
      index.interrupted(run_id, row.accepted_at + 0.2, "", 1, bag_path);
    } else {
      index.finished(run_id, row.accepted_at + 0.2, collision_lab_ros::summaryJson(summary), summary.stop_reason, 1,
                     bag_path, collision_lab_ros::endingOf(summary));  // as the lab node writes it
    }
  }
}

/// The list and an old run, as a browser after the restart asks for them.
void expectEveryRunServed(const std::pair<std::string, int>& address) {
  httplib::Client c(address.first, address.second);
  auto list = c.Get("/api/runs");
  ASSERT_TRUE(list);
  ASSERT_EQ(list->status, 200);
  const json runs = json::parse(list->body);
  ASSERT_EQ(runs.size(), static_cast<std::size_t>(kRuns)) << "every run of the day is listed";
  EXPECT_EQ(runs[0].at("run_id"), "s1.run1");
  EXPECT_EQ(runs[0].at("model"), "two_body") << "the model, read back from the index";
  EXPECT_EQ(runs[kRuns - 1].at("state"), "interrupted");
  auto page = c.Get("/runs/s3.run3");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200) << "an old link works";
  auto run = c.Get("/api/runs/s3.run3");
  ASSERT_TRUE(run);
  ASSERT_EQ(run->status, 200);
  const json body = json::parse(run->body);
  EXPECT_EQ(body.at("state"), "finished");
  EXPECT_EQ(body.at("collisions"), 1);
  auto bag = c.Get("/api/runs/s3.run3/bag");
  ASSERT_TRUE(bag);
  EXPECT_EQ(bag->status, 200);
  EXPECT_GT(bag->body.size(), 0u);
}

TEST(WebRestart, RespawnedWebNodeListsAndServesEveryRun) {
  ros::NodeHandle pnh("~");
  std::string dir;
  ASSERT_TRUE(pnh.getParam("bag_directory", dir));
  writeDay(dir);
  const auto first = webAddress();
  expectEveryRunServed(first);

  int pid = 0;
  waitUntil([&] { return (pid = webPid()) > 0; }, "the web node's pid");
  ros::param::del(kUrlParam);
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  int respawned = 0;
  waitUntil([&] { return (respawned = webPid()) > 0 && respawned != pid; }, "roslaunch to respawn the web node");
  expectEveryRunServed(webAddress());
}


// A class with codes (the "coded" web node, its own folder; the test answers as its lab
// node): a login cookie and a run's stop token from before a kill -9 still work after it.
// (Failed before: the cookie was 403 and the stop 404 after the restart.)
TEST(WebRestart, LoginsAndStopTokensOutliveARestart) {
  constexpr char kCodedNode[] = "/coded/collision_lab_web";
  constexpr char kCodedUrl[] = "/coded/collision_lab_web/url";
  ros::NodeHandle nh("/coded");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  auto accepted = nh.advertise<collision_lab::AcceptedRun>("accepted_runs", 10);
  auto lab = nh.subscribe<collision_lab::InitialConditions>(
      "initial_conditions", 10, [&](const collision_lab::InitialConditions::ConstPtr& in) {
        collision_lab::AcceptedRun run;
        run.header.stamp = ros::Time::now();
        run.run_id = in->student + "." + in->run_id;
        run.requested_run_id = in->run_id;
        run.student = in->student;
        run.lane = "short";
        accepted.publish(run);
      });
  auto address = webAddress(kCodedUrl);
  waitUntil([&] { return accepted.getNumSubscribers() > 0 && lab.getNumPublishers() > 0; }, "the coded web node");

  httplib::Client c(address.first, address.second);
  auto login = c.Post("/api/login", json{{"code", "sesame"}}.dump(), "application/json");
  ASSERT_TRUE(login);
  ASSERT_EQ(login->status, 200);
  const std::string set_cookie = login->get_header_value("Set-Cookie");
  const std::string cookie = set_cookie.substr(0, set_cookie.find(';'));
  ASSERT_EQ(cookie.rfind("collision_lab_class=", 0), 0u) << set_cookie;
  const httplib::Headers with_cookie{{"Cookie", cookie}};
  auto sent = c.Post("/api/runs", with_cookie,
                     json{{"student", "ana"}, {"masses", {100, 1, "inf"}}, {"positions", {2, 1, 0}}, {"velocities", {-1, 0, 0}}}.dump(),
                     "application/json");
  ASSERT_TRUE(sent);
  ASSERT_EQ(sent->status, 202) << sent->body;
  const json run = json::parse(sent->body);
  const std::string stop = "/api/runs/" + run.at("run_id").get<std::string>() + "/stop";

  // A graceful stop (SIGINT, as roslaunch stops a node) ends an open stream with an event
  // `restart`, which the page answers by polling; the stream does not just break off.
  std::mutex streamed_mutex;
  std::string streamed;
  const auto seen = [&](const std::string& text) {
    std::lock_guard<std::mutex> lock(streamed_mutex);
    return streamed.find(text) != std::string::npos;
  };
  std::thread reader([&] {
    httplib::Client s(address.first, address.second);
    s.set_read_timeout(30, 0);
    s.Get(("/api/runs/" + run.at("run_id").get<std::string>() + "/stream").c_str(), with_cookie,
          [&](const char* data, std::size_t n) {
            std::lock_guard<std::mutex> lock(streamed_mutex);
            streamed.append(data, n);
            return true;
          });
  });
  waitUntil([&] { return seen("event: run"); }, "the stream's first event");
  int pid = 0;
  waitUntil([&] { return (pid = webPid(kCodedNode)) > 0; }, "the coded web node's pid");
  ros::param::del(kCodedUrl);
  ASSERT_EQ(kill(pid, SIGINT), 0);
  reader.join();
  EXPECT_TRUE(seen("event: restart\ndata: ")) << streamed.substr(streamed.size() > 300 ? streamed.size() - 300 : 0);
  waitUntil([&] { const int again = webPid(kCodedNode); return again > 0 && again != pid; }, "the coded web node to respawn");
  address = webAddress(kCodedUrl);

  // Then a kill -9.
  waitUntil([&] { return (pid = webPid(kCodedNode)) > 0; }, "the respawned coded web node's pid");
  ros::param::del(kCodedUrl);
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  waitUntil([&] { const int again = webPid(kCodedNode); return again > 0 && again != pid; }, "the coded web node to respawn");
  address = webAddress(kCodedUrl);
  httplib::Client after(address.first, address.second);
  auto listed = after.Get("/api/runs", with_cookie);
  ASSERT_TRUE(listed);
  EXPECT_EQ(listed->status, 200) << "the login cookie of before the restart";
  auto wrong = after.Post(stop.c_str(), {{"Cookie", cookie}, {"X-Stop-Token", std::string(64, '0')}}, "", "application/json");
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->status, 403);
  // The owner's token is taken: the stop goes on to the lab node's ~cancel, which this test
  // does not serve (503), instead of 404 (no such run) or 403.
  auto owner = after.Post(stop.c_str(), {{"Cookie", cookie}, {"X-Stop-Token", run.at("stop_token").get<std::string>()}}, "",
                          "application/json");
  ASSERT_TRUE(owner);
  EXPECT_EQ(owner->status, 503) << owner->body;
  // Only hashes of the tokens are on disk.
  ros::NodeHandle pnh("~");
  std::string dir;
  ASSERT_TRUE(pnh.getParam("coded_directory", dir));
  std::ifstream tokens(dir + "/web_stop_tokens");
  const std::string stored((std::istreambuf_iterator<char>(tokens)), std::istreambuf_iterator<char>());
  EXPECT_NE(stored.find(run.at("run_id").get<std::string>()), std::string::npos) << stored;
  EXPECT_EQ(stored.find(run.at("stop_token").get<std::string>()), std::string::npos) << stored;

}

/// A three-body run's messages and bag: `recorded` of its `collisions` events in the bag,
/// with the summary when all are.
struct LateRun {
  collision_lab::AcceptedRun accepted;
  collision_lab::InitialConditions input;
  std::vector<collision_lab::CollisionEvent> events;
  std::string bag_path;
};

LateRun lateRun(const std::filesystem::path& dir, const std::string& run_id, std::uint64_t collisions,
                std::uint64_t recorded) {
  LateRun run;
  run.accepted.header.stamp = ros::Time::now();
  run.accepted.run_id = run_id;
  run.accepted.student = "late";
  run.input.run_id = run_id;
  run.input.student = "late";
  run.input.masses = {1.0, 2.0, 3.0};
  run.input.positions = {2.0, 1.0, 0.0};
  run.input.velocities = {-1.0, 0.0, 1.0};
  for (std::uint64_t k = 1; k <= collisions; ++k) {
    collision_lab::CollisionEvent e;
    e.run_id = run_id;
    e.index = k;
    e.pair_index = static_cast<std::uint32_t>(k % 2);
    e.first_moved = e.pair_index;
    e.last_moved = e.pair_index + 1;
    e.time = 0.1 * static_cast<double>(k);
    e.restitution = 1.0;
    e.pair_velocities_after = {0.5, -0.5};
    run.events.push_back(e);
  }
  run.bag_path = (dir / (run_id + ".bag")).string();
  rosbag::Bag bag;
  bag.open(run.bag_path, rosbag::bagmode::Write);
  bag.write("/collision_lab/served_inputs", ros::Time(1.0), run.input);
  for (std::uint64_t k = 0; k < recorded; ++k) bag.write("/collision_lab/collision_events", ros::Time(2.0), run.events[k]);
  if (recorded == collisions) {
    collision_lab::RunSummary summary;
    summary.run_id = run_id;
    summary.student = "late";
    summary.collision_count = collisions;
    summary.published_events = collisions;
    summary.stop_reason = "NO_MORE_COLLISIONS";
    summary.recording_ok = true;
    summary.bag_path = run.bag_path;
    bag.write("/collision_lab/run_summaries", ros::Time(3.0), summary);
  }
  bag.close();
  return run;
}

/// The run's JSON once its state is not "running" (generous timeout: the web node checks
/// every 2 s).
json settledRun(const std::pair<std::string, int>& address, const std::string& run_id) {
  json run;
  waitUntil(
      [&] {
        httplib::Client c(address.first, address.second);
        auto res = c.Get("/api/runs/" + run_id);
        if (!res || res->status != 200) return false;
        run = json::parse(res->body);
        return run.at("state") != "running" && run.at("state") != "queued";
      },
      run_id + " to end");
  return run;
}

TEST(WebMissedEvents, RunsWhoseEndWasMissedEndFromTheIndex) {
  ros::NodeHandle nh("/collision_lab"), pnh("~");
  std::string dir;
  ASSERT_TRUE(pnh.getParam("bag_directory", dir));
  std::filesystem::create_directories(dir);
  const auto address = webAddress();
  // The lab node's topics, published by the test: the web node gets only the start of each run.
  auto accepted = nh.advertise<collision_lab::AcceptedRun>("accepted_runs", 10);
  auto inputs = nh.advertise<collision_lab::InitialConditions>("served_inputs", 10);
  auto events = nh.advertise<collision_lab::CollisionEvent>("collision_events", 100);
  waitUntil([&] { return accepted.getNumSubscribers() > 0 && inputs.getNumSubscribers() > 0 &&
                         events.getNumSubscribers() > 0; }, "the web node to subscribe");
  const LateRun finished = lateRun(dir, "late.finished", 10, 10);
  const LateRun interrupted = lateRun(dir, "late.interrupted", 10, 6);  // its node died after 6
  collision_lab::service::RunIndex index(collision_lab::service::RunIndex::defaultPath(dir));
  for (const LateRun* run : {&finished, &interrupted}) {
    collision_lab::service::IndexedRun row;
    row.run_id = run->input.run_id;
    row.student = "late";
    row.state = collision_lab::service::RunState::kQueued;
    row.accepted_at = run->accepted.header.stamp.toSec();
    row.bag_path = run->bag_path;
    index.accepted(row);
    index.started(row.run_id, row.accepted_at);
    accepted.publish(run->accepted);
    inputs.publish(run->input);
    for (std::size_t k = 0; k < 3; ++k) events.publish(run->events[k]);
  }
  waitUntil(
      [&] {
        httplib::Client c(address.first, address.second);
        auto res = c.Get("/api/runs/late.interrupted");
        return res && res->status == 200 && json::parse(res->body).at("collisions") == 3;
      },
      "the web node to see the runs running");
  EXPECT_EQ(json::parse(httplib::Client(address.first, address.second).Get("/api/runs/late.finished")->body).at("state"),
            "running");
  // The rest of the events and the summaries are never delivered; the lab node's index says how they ended.
  index.finished("late.finished", ros::Time::now().toSec(), "", "NO_MORE_COLLISIONS", 10, finished.bag_path, {});
  index.interrupted("late.interrupted", ros::Time::now().toSec(), "", 6, interrupted.bag_path);
  const json done = settledRun(address, "late.finished");
  EXPECT_EQ(done.at("state"), "finished");
  EXPECT_EQ(done.at("collisions"), 10);
  const json cut = settledRun(address, "late.interrupted");
  EXPECT_EQ(cut.at("state"), "interrupted");
  EXPECT_EQ(cut.at("collisions"), 6);
  EXPECT_EQ(cut.at("summary").at("stop_reason"), "INTERRUPTED");
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "web_restart_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
