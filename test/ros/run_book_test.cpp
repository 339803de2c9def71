// RunBook (the web server's view of the lab's runs) when the lab node's topics arrive out
// of order: they are separate connections, so a run's summary may come before its served
// input. Bags read on many threads at once. No master needed.
#include <stdlib.h>

#include <atomic>
#include <filesystem>
#include <limits>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <rosbag/bag.h>

#include "collision_lab/web/run_book.h"

namespace {

using nlohmann::json;

json runJson(const collision_lab_web::RunBook& book, const std::string& run_id) {
  auto text = book.json(run_id);
  return text ? json::parse(text->first) : json();
}

TEST(RunBook, SummaryBeforeServedInputWaitsForTheScene) {
  collision_lab_web::RunBook book;
  collision_lab::AcceptedRun accepted;
  accepted.header.stamp.fromSec(1.0e9);
  accepted.run_id = "ana.run1";
  accepted.student = "ana";
  book.onAccepted(accepted);

  // An unrecorded run with no collisions: its summary comes first.
  collision_lab::RunSummary summary;
  summary.run_id = "ana.run1";
  summary.student = "ana";
  summary.recording_ok = false;
  book.onSummary(summary);
  EXPECT_NE(runJson(book, "ana.run1").at("state"), "finished") << "finished without its scene";

  collision_lab::InitialConditions input;
  input.run_id = "ana.run1";
  input.student = "ana";
  input.masses = {1.0, 1.0};
  input.positions = {1.0, 0.0};
  input.velocities = {1.0, -1.0};  // moving apart: no collision
  book.onServedInput(input);
  const json run = runJson(book, "ana.run1");
  EXPECT_EQ(run.at("state"), "finished");
  EXPECT_EQ(run.at("scene").at("positions"), json({1.0, 0.0}));
  EXPECT_TRUE(run.contains("plots"));
}

TEST(RunBook, RunJoinedMidwayEndsWithItsSummary) {
  collision_lab_web::RunBook book;  // no AcceptedRun seen: the web node started later
  collision_lab::RunSummary summary;
  summary.run_id = "old";
  summary.collision_count = 3;
  book.onSummary(summary);
  const json run = runJson(book, "old");
  EXPECT_EQ(run.at("state"), "finished");
  EXPECT_EQ(run.at("summary").at("collision_count"), 3);
}

// The web node rebuilds runs from their bags on threads of their own while HTTP threads
// export events CSVs. rosbag::Bag loads its encryptor plugin through pluginlib, which is not
// thread-safe: thirty students at once crashed the web node (SIGSEGV in class_loader).
TEST(RunBook, BagsReadOnManyThreadsAtOnce) {
  char dir_template[] = "/tmp/run_book_test_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::filesystem::path dir(dir_template);
  const std::string bag_path = (dir / "ana.run1.bag").string();
  {
    rosbag::Bag bag;
    bag.open(bag_path, rosbag::bagmode::Write);
    collision_lab::InitialConditions input;
    input.run_id = "ana.run1";
    input.masses = {1.0, 1.0};
    input.positions = {1.0, 0.0};
    input.velocities = {-1.0, 0.0};
    bag.write("/collision_lab/served_inputs", ros::Time(1.0), input);
    bag.close();
  }
  constexpr int kThreads = 8;
  constexpr int kReadsEach = 40;
  std::atomic<int> read_with_scene{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&] {
      for (int k = 0; k < kReadsEach; ++k) {
        const collision_lab_web::BagRun run = collision_lab_web::readRunFromBag(bag_path, 64);
        if (run.record) ++read_with_scene;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(read_with_scene.load(), kThreads * kReadsEach);
  std::filesystem::remove_all(dir);
}

}  // namespace
