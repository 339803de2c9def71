// A live run past the lab's published-event cap (issue 31: the page's counter froze at the
// cap, then jumped to the final count). The real lab and web nodes (web_progress_test.test,
// ~max_published_events 100): the pi billiard with masses 1e10, 1, inf has 314,159 impacts
// (pi's digits, not the code under test). The lab node publishes a RunProgress at the first
// unpublished collision and every 20,000 after it, never into the bag; the web node's run
// JSON shows counts past the cap while the run goes on, then the exact count.
#include <chrono>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/RunProgress.h"
#include "collision_lab/RunSummary.h"
#include "../ros/run_collector.h"
// Last: it includes <resolv.h>, whose macro _res breaks Eigen's headers included after it.
#include <httplib.h>

namespace {

using collision_lab_test::waitUntil;
using nlohmann::json;

constexpr char kUrlParam[] = "/collision_lab/collision_lab_web/url";
constexpr char kCode[] = "sesame";
constexpr std::uint64_t kPublished = 100;          // the lab node's ~max_published_events
constexpr std::uint64_t kProgressEvery = 20'000;   // its ~progress_every_events
constexpr std::uint64_t kPiImpacts = 314'159;      // masses 1e10, 1, inf

/// Everything the lab node publishes on run_progress and run_summaries.
struct LabOutputs {
  std::mutex mutex;
  std::vector<collision_lab::RunProgress> progress;
  std::vector<collision_lab::RunSummary> summaries;
};

TEST(WebProgress, LiveCounterGoesPastThePublishedCapThenEndsExact) {
  ros::NodeHandle nh("collision_lab");
  LabOutputs lab;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  ros::Subscriber progress_sub = nh.subscribe<collision_lab::RunProgress>(
      "run_progress", 1000, [&](const collision_lab::RunProgress::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(lab.mutex);
        lab.progress.push_back(*m);
      });
  ros::Subscriber summary_sub = nh.subscribe<collision_lab::RunSummary>(
      "run_summaries", 1000, [&](const collision_lab::RunSummary::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(lab.mutex);
        lab.summaries.push_back(*m);
      });
  waitUntil([&] { return progress_sub.getNumPublishers() > 0 && summary_sub.getNumPublishers() > 0; },
            "the lab node's run_progress and run_summaries");

  std::string url;
  waitUntil([&] { return ros::param::get(kUrlParam, url); }, "the web node to publish its address");
  const auto colon = url.rfind(':');
  httplib::Client c(url.substr(7, colon - 7), std::stoi(url.substr(colon + 1)));
  c.set_read_timeout(60, 0);
  c.set_default_headers({{"X-Class-Code", kCode}});
  const auto pi = [](double heavy) {
    return json{{"student", "ivy"}, {"code", kCode}, {"masses", {heavy, 1, "inf"}}, {"positions", {2, 1, 0}},
                {"velocities", {-1, 0, 0}}};
  };
  const auto send = [&](const json& scene) {
    std::string run_id;
    waitUntil(
        [&] {
          auto res = c.Post("/api/runs", scene.dump(), "application/json");
          if (!res || res->status != 202) return false;  // 503 until the lab node takes runs
          run_id = json::parse(res->body).at("run_id");
          return true;
        },
        "the web node to take a run");
    return run_id;
  };
  // A first run (31 impacts) to its end: the web node's subscriptions to the lab's topics,
  // made at its start, are connected by then (a run sent at once may find them not yet).
  const std::string warmup = send(pi(100));
  waitUntil(
      [&] {
        auto res = c.Get(("/api/runs/" + warmup).c_str());
        return res && res->status == 200 && json::parse(res->body).at("state") == "finished";
      },
      "the first run to finish");
  const std::string run_id = send(pi(1e10));

  // The run's JSON, as the page reads it, until it is final.
  std::uint64_t most_while_running = 0;
  std::string counter_past_cap;
  std::string seen;  // the states and counts read, for the failure message
  json run;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(240);
  while (std::chrono::steady_clock::now() < give_up) {
    auto res = c.Get(("/api/runs/" + run_id).c_str());
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    run = json::parse(res->body);
    const std::string read = run.at("state").get<std::string>() + " " + run.at("collisions").dump() + "; ";
    if (seen.size() < read.size() || seen.compare(seen.size() - read.size(), read.size(), read) != 0) seen += read;
    if (run.at("state") == "finished") break;
    if (run.at("state") == "running" && !run.contains("summary") && run.contains("view")) {
      const std::uint64_t n = run.at("collisions");
      if (n > kPublished && n > most_while_running) {
        most_while_running = n;
        counter_past_cap = run.at("view").at("counter");
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(run.at("state"), "finished") << run.dump().substr(0, 300);
  EXPECT_GT(most_while_running, kPublished) << "the live count never went past the published events: " << seen;
  EXPECT_NE(counter_past_cap.find(" of 314,159 collisions predicted, running"), std::string::npos)
      << counter_past_cap;
  EXPECT_EQ(run.at("collisions"), kPiImpacts) << "the final count, from the bag";
  EXPECT_EQ(run.at("summary").at("collision_count"), kPiImpacts);
  EXPECT_EQ(run.at("summary").at("published_events"), kPublished);
  EXPECT_EQ(run.at("view").at("counter"), "314,159 collisions, finished");

  // The lab node's progress: at the first unpublished collision, then every 20,000.
  std::vector<collision_lab::RunProgress> progress;
  std::string bag_path;
  waitUntil(
      [&] {
        std::lock_guard<std::mutex> lock(lab.mutex);
        for (const auto& s : lab.summaries) {
          if (s.run_id == run_id) bag_path = s.bag_path;
        }
        return !bag_path.empty();
      },
      "the run's summary");
  {
    std::lock_guard<std::mutex> lock(lab.mutex);
    for (const auto& p : lab.progress) {
      if (p.run_id == run_id) progress.push_back(p);
    }
  }
  const std::uint64_t unpublished = kPiImpacts - kPublished;
  ASSERT_EQ(progress.size(), 1 + (unpublished - 1) / kProgressEvery);
  for (std::size_t k = 0; k < progress.size(); ++k) {
    EXPECT_EQ(progress[k].collisions, kPublished + 1 + k * kProgressEvery) << k;
    EXPECT_EQ(progress[k].latest_event.index, progress[k].collisions) << k;
    EXPECT_EQ(progress[k].published, kPublished) << k;
    EXPECT_EQ(progress[k].latest_event.velocities_after.size(), 3u) << "the state of every body";
    EXPECT_EQ(progress[k].energy_lost, 0.0) << "elastic";
  }

  // Live only: the bag has every collision and no RunProgress.
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::set<std::string> topics;
  for (const rosbag::ConnectionInfo* connection : view.getConnections()) topics.insert(connection->topic);
  for (const std::string& topic : topics) EXPECT_EQ(topic.find("run_progress"), std::string::npos) << topic;
  rosbag::View events(bag, rosbag::TypeQuery("collision_lab/CollisionEvent"));
  EXPECT_EQ(events.size(), kPiImpacts);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "web_progress_test");
  return RUN_ALL_TESTS();
}
