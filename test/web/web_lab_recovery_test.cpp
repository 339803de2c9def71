// The real lab node and the real web node together (issue 30, "It forgets"): nothing stays
// "running". (A web node that missed a run's end: web_restart_test.)
// - The lab node killed mid-run: a run that asks for 2^64-1 impacts is computing when the
//   lab node gets SIGKILL; roslaunch respawns it, it recovers the run's `.active` bag, and
//   the run ends "interrupted" (stop reason INTERRUPTED) with its bag served; runs sent after
//   the respawn finish normally.
// Counts are pi's digits (masses m, 1, wall: m = 100 gives 31 impacts, 1e4 314, 1e8 31415),
// not the code under test's.
#include <signal.h>

#include <chrono>
#include <cstdint>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include "../ros/run_collector.h"
// Last: it includes <resolv.h>, whose macro _res breaks Eigen's headers included after it.
#include <httplib.h>

namespace {

using collision_lab_test::waitUntil;
using nlohmann::json;

constexpr char kWebNode[] = "/collision_lab/collision_lab_web";
constexpr char kLabNode[] = "/collision_lab/collision_lab_node";
constexpr char kUrlParam[] = "/collision_lab/collision_lab_web/url";
/// [s] for a run to end once nothing holds it back: generous, the machine is shared.
constexpr double kEndTimeout = 300.0;
/// [s] the web node is paused (the measurement).
constexpr int kPauseSeconds = 20;

std::string g_host;
int g_port = 0;

httplib::Client client() {
  httplib::Client c(g_host, g_port);
  c.set_read_timeout(60, 0);
  return c;
}

/// The pi scene: a ball of mass `heavy` [kg] pushes a 1 kg ball against a wall.
json piScene(const std::string& student, double heavy) {
  return {{"student", student}, {"masses", {heavy, 1, "inf"}}, {"positions", {2, 1, 0}}, {"velocities", {-1, 0, 0}}};
}

httplib::Result post(const json& scene) {
  auto c = client();
  return c.Post("/api/runs", scene.dump(), "application/json");
}

/// The run_id of a run the web node answered 202 (empty, and a failure, otherwise).
std::string accepted(const json& scene) {
  auto res = post(scene);
  if (!res) {
    ADD_FAILURE() << "no answer to POST /api/runs";
    return "";
  }
  if (res->status != 202) {
    ADD_FAILURE() << "POST /api/runs answered " << res->status << ": " << res->body;
    return "";
  }
  return json::parse(res->body).at("run_id");
}

/// GET /api/runs/<run_id>; null when it does not answer 200.
json getRun(const std::string& run_id) {
  auto c = client();
  auto res = c.Get(("/api/runs/" + run_id).c_str());
  if (!res || res->status != 200) return nullptr;
  return json::parse(res->body);
}

bool ended(const json& run) { return run.is_object() && run["state"] != "queued" && run["state"] != "running"; }

/// A node's process id (its XML-RPC getPid); 0 when it is not registered or does not answer.
int nodePid(const std::string& node) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, false)) return 0;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(static_cast<std::string>(payload), host, port)) return 0;
  XmlRpc::XmlRpcClient rpc(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue pid_args, pid_result;
  pid_args[0] = ros::this_node::getName();
  if (!rpc.execute("getPid", pid_args, pid_result) || pid_result.size() < 3) return 0;
  return static_cast<int>(pid_result[2]);
}

class WebLabRecoveryTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string url;
    waitUntil([&] { return ros::param::get(kUrlParam, url); }, "the web node to publish its address");
    // url: http://HOST:PORT/
    const auto colon = url.rfind(':');
    g_host = url.substr(7, colon - 7);
    g_port = std::stoi(url.substr(colon + 1));
    waitUntil(
        [] {
          auto res = post(piScene("warmup", 1e2));
          return res && res->status == 202;
        },
        "the web node to reach the lab node");
  }
};

TEST_F(WebLabRecoveryTest, LabNodeKilledMidRunLeavesItInterrupted) {
  json endless = piScene("endless", 1e16);
  endless["max_collisions"] = std::numeric_limits<std::uint64_t>::max();
  endless["mode"] = 0;
  const std::string run_id = accepted(endless);
  ASSERT_FALSE(run_id.empty());
  // Computing, with events in its bag: the lab node dies mid-run.
  ASSERT_TRUE(waitUntil(
      [&] {
        const json run = getRun(run_id);
        return run.is_object() && run["state"] == "running" && run["collisions"].get<std::uint64_t>() >= 1000;
      },
      "run " + run_id + " to compute its first 1000 impacts", kEndTimeout));

  const int lab_pid = nodePid(kLabNode);
  ASSERT_GT(lab_pid, 0) << "the lab node's pid from the master";
  ASSERT_EQ(kill(lab_pid, SIGKILL), 0);
  int respawned = 0;
  ASSERT_TRUE(waitUntil([&] { return (respawned = nodePid(kLabNode)) > 0 && respawned != lab_pid; },
                        "roslaunch to respawn the lab node", kEndTimeout));

  json run;
  ASSERT_TRUE(waitUntil([&] { return ended(run = getRun(run_id)); }, "run " + run_id + " to end", kEndTimeout));
  EXPECT_EQ(run["state"], "interrupted") << run.dump().substr(0, 400);
  ASSERT_TRUE(run["summary"].is_object()) << run.dump().substr(0, 400);
  EXPECT_EQ(run["summary"]["stop_reason"], "INTERRUPTED");

  std::size_t bag_bytes = 0;
  std::string bag_head;
  auto c = client();
  auto bag = c.Get(("/api/runs/" + run_id + "/bag").c_str(), [&](const char* data, std::size_t n) {
    if (bag_head.size() < 16) bag_head.append(data, std::min<std::size_t>(n, 16));
    bag_bytes += n;
    return true;
  });
  ASSERT_TRUE(bag);
  EXPECT_EQ(bag->status, 200);
  EXPECT_EQ(bag_head.rfind("#ROSBAG V2.0", 0), 0u) << "the recovered bag is served";
  EXPECT_GT(bag_bytes, 0u);

  // The respawned lab node runs what is sent to it.
  std::string after;
  ASSERT_TRUE(waitUntil(
      [&] {
        auto res = post(piScene("after", 1e2));
        if (res && res->status == 202) after = json::parse(res->body).at("run_id");
        return !after.empty();
      },
      "the web node to reach the respawned lab node", kEndTimeout));
  const std::vector<std::pair<std::string, std::uint64_t>> later = {
      {after, 31}, {accepted(piScene("after", 1e4)), 314}, {accepted(piScene("after2", 1e2)), 31}};
  for (const auto& [id, impacts] : later) {
    ASSERT_FALSE(id.empty());
    json got;
    ASSERT_TRUE(waitUntil([&] { return ended(got = getRun(id)); }, "run " + id + " to end", kEndTimeout));
    EXPECT_EQ(got["state"], "finished") << id << ": " << got.dump().substr(0, 400);
    EXPECT_EQ(got["summary"]["collision_count"], impacts) << id;
  }
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "web_lab_recovery_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
