// A full disk (disk_test.test, issue 49). A lab under its free-space floor refuses every
// input with DISK_SPACE, on the service and on the rejection topic. On a small disk (a 20 MB
// tmpfs; skipped where none may be mounted) a recording run stops at the floor with its bag
// complete (SERVICE_DISK_SPACE). With no floor, a disk that fills under a run keeps the
// run's summary in the index once space is freed, deleting its failed bag frees the space
// (the node holds no descriptor of it), and the next run is recorded. A student whose bags
// pass ~max_student_bag_mb has their recording run stopped (SERVICE_STUDENT_QUOTA, its bag
// complete) and their next input refused (STUDENT_QUOTA), while a classmate is served; once
// their bags are deleted, they are served again.
#include <sys/statvfs.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunPreset.h"
#include "collision_lab/RunScene.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/service/run_index.h"
#include "run_collector.h"

namespace {

namespace fs = std::filesystem;
using collision_lab_test::callService;
using collision_lab_test::waitUntil;

std::string g_tmp;  ///< the launch's folder: <tmp>/<namespace> is each node's bag folder

/// [MB] free and total in the file system of directory.
struct Space {
  double free_mb = 0.0;
  double total_mb = 0.0;
};
Space spaceOf(const std::string& directory) {
  struct statvfs s {};
  if (::statvfs(directory.c_str(), &s) != 0) return {};
  return {static_cast<double>(s.f_bavail) * s.f_frsize / 1e6, static_cast<double>(s.f_blocks) * s.f_frsize / 1e6};
}

/// Whether on_small_tmpfs.sh could give the node in namespace ns its 20 MB disk.
bool onSmallDisk(const std::string& ns) {
  const Space space = spaceOf(g_tmp + "/" + ns);
  return space.total_mb > 0 && space.total_mb < 25;
}

collision_lab::RunScene piScene(const std::string& run_id) {
  collision_lab::RunScene call;
  call.request.run_id = run_id;
  call.request.student = "ana";
  call.request.masses = {100, 1, std::numeric_limits<double>::infinity()};
  call.request.positions = {2, 1, 0};
  call.request.velocities = {-1, 0, 0};
  return call;
}

collision_lab::RunPreset gas(const std::string& run_id) {
  collision_lab::RunPreset call;
  call.request.name = "gas_1000";
  call.request.run_id = run_id;
  call.request.student = "ben";
  return call;
}

/// The events of a complete bag (rosbag throws for one that was not closed) and its summary.
std::uint64_t eventsIn(const std::string& path, collision_lab::RunSummary& summary) {
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  std::uint64_t events = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (m.isType<collision_lab::CollisionEvent>()) ++events;
    if (const auto s = m.instantiate<collision_lab::RunSummary>()) summary = *s;
  }
  return events;
}

TEST(Disk, UnderTheFloorEveryInputIsRefusedAndSaysWhy) {
  ros::NodeHandle nh;
  std::vector<collision_lab::Rejected> published;
  const auto sub = nh.subscribe<collision_lab::Rejected>(
      "/nospace/rejected", 10, [&](const collision_lab::Rejected::ConstPtr& r) { published.push_back(*r); });
  waitUntil([&] { return sub.getNumPublishers() > 0; }, "the rejection topic");
  auto call = piScene("no_room");
  ASSERT_TRUE(callService("/nospace/collision_lab_node/run_scene", call));
  EXPECT_FALSE(call.response.ok);
  const collision_lab::Rejected& r = call.response.rejected;
  EXPECT_EQ(r.reason, collision_lab::Rejected::DISK_SPACE);
  EXPECT_EQ(r.reason_name, "DISK_SPACE");
  EXPECT_EQ(r.field, "bag_directory");
  EXPECT_NE(r.message.find("MB free, under the node's floor ~min_free_space_mb"), std::string::npos) << r.message;
  EXPECT_FALSE(fs::exists(g_tmp + "/nospace/ana.no_room.bag"));
  waitUntil([&] { return !published.empty(); }, "the rejection on its topic");
  ASSERT_EQ(published.size(), 1u);
  EXPECT_EQ(published[0].reason_name, "DISK_SPACE");
  EXPECT_EQ(published[0].student, "ana");
}

TEST(Disk, ARecordingRunStopsAtTheFloorWithItsBagComplete) {
  ASSERT_TRUE(ros::service::waitForService("/floor/collision_lab_node/run_preset", ros::Duration(60)));
  if (!onSmallDisk("floor")) GTEST_SKIP() << "no tmpfs could be mounted here (it takes root)";
  // gas_1000's 245,308 events take about 25 MB of bag: more than the 12 MB above the floor.
  auto call = gas("floor");
  ASSERT_TRUE(callService("/floor/collision_lab_node/run_preset", call));
  ASSERT_TRUE(call.response.ok) << call.response.message;
  const collision_lab::RunSummary& s = call.response.summary;
  EXPECT_EQ(s.stop_reason, "SERVICE_DISK_SPACE");
  EXPECT_TRUE(s.truncated);
  EXPECT_LT(s.collision_count, 245308u);
  EXPECT_NE(s.truncation_reason.find("~min_free_space_mb = 8 MB"), std::string::npos) << s.truncation_reason;
  EXPECT_TRUE(s.recording_ok) << s.recording_error;
  collision_lab::RunSummary recorded;
  EXPECT_EQ(eventsIn(s.bag_path, recorded), s.collision_count);
  EXPECT_EQ(recorded.stop_reason, "SERVICE_DISK_SPACE");
  EXPECT_GT(spaceOf(g_tmp + "/floor").free_mb, 1.0);  // the disk never filled
}

TEST(Disk, AFullDiskKeepsTheSummaryAndADeletedBagFreesItsSpace) {
  ASSERT_TRUE(ros::service::waitForService("/nofloor/collision_lab_node/run_preset", ros::Duration(60)));
  if (!onSmallDisk("nofloor")) GTEST_SKIP() << "no tmpfs could be mounted here (it takes root)";
  const std::string dir = g_tmp + "/nofloor";
  auto call = gas("full");
  ASSERT_TRUE(callService("/nofloor/collision_lab_node/run_preset", call));
  ASSERT_TRUE(call.response.ok) << call.response.message;
  const collision_lab::RunSummary& s = call.response.summary;
  EXPECT_EQ(s.stop_reason, "FINISHED");
  EXPECT_EQ(s.collision_count, 245308u);  // the run itself is whole
  EXPECT_FALSE(s.recording_ok);
  EXPECT_FALSE(s.recording_error.empty());
  EXPECT_LT(spaceOf(dir).free_mb, 1.0);

  const std::string failed_bag = dir + "/ben.full.bag.active";
  ASSERT_TRUE(fs::exists(failed_bag));
  fs::remove(failed_bag);
  waitUntil([&] { return spaceOf(dir).free_mb > 15.0; }, "the deleted bag's space to come back");

  collision_lab::service::RunIndex index(collision_lab::service::RunIndex::defaultPath(dir));
  waitUntil(
      [&] {
        const auto row = index.find("ben.full");
        return row && row->state == collision_lab::service::RunState::kFinished;
      },
      "the run's end in the index once space is freed");
  const auto row = index.find("ben.full");
  ASSERT_TRUE(row);
  EXPECT_EQ(row->collision_count, 245308u);
  EXPECT_NE(row->summary_json.find("\"recorded\":false"), std::string::npos) << row->summary_json;

  auto next = piScene("after");
  ASSERT_TRUE(callService("/nofloor/collision_lab_node/run_scene", next));
  ASSERT_TRUE(next.response.ok) << next.response.message;
  EXPECT_TRUE(next.response.summary.recording_ok) << next.response.summary.recording_error;
  collision_lab::RunSummary recorded;
  EXPECT_EQ(eventsIn(next.response.summary.bag_path, recorded), 31u);
}

TEST(Disk, AStudentOverTheirQuotaOfBagsStartsNoRunAndAClassmateDoes) {
  // gas_1000 records about 25 MB of messages: each run of ben's stops at the quota of 1 MB
  // (counted as recorded while it runs, as it stands on disk after), until ben's bags on disk
  // reach 1 MB and the next run is refused.
  std::vector<std::string> bens_bags;
  collision_lab::RunPreset call;
  for (int k = 0; k < 10; ++k) {
    call = gas("quota" + std::to_string(k));
    ASSERT_TRUE(callService("/quota/collision_lab_node/run_preset", call));
    if (!call.response.ok) break;
    const collision_lab::RunSummary& s = call.response.summary;
    EXPECT_EQ(s.stop_reason, "SERVICE_STUDENT_QUOTA") << s.truncation_reason;
    EXPECT_NE(s.truncation_reason.find("student 'ben''s bags passed the node's ~max_student_bag_mb = 1 MB"),
              std::string::npos)
        << s.truncation_reason;
    collision_lab::RunSummary recorded;
    EXPECT_EQ(eventsIn(s.bag_path, recorded), s.collision_count);
    bens_bags.push_back(s.bag_path);
  }
  ASSERT_FALSE(call.response.ok) << "ben was never refused";
  const collision_lab::Rejected& r = call.response.rejected;
  EXPECT_EQ(r.reason, collision_lab::Rejected::STUDENT_QUOTA);
  EXPECT_EQ(r.reason_name, "STUDENT_QUOTA");
  EXPECT_EQ(r.field, "student");
  EXPECT_NE(r.message.find("student 'ben' has"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("~max_student_bag_mb = 1.0 MB or more"), std::string::npos) << r.message;
  std::uint64_t on_disk = 0;
  for (const std::string& bag : bens_bags) on_disk += fs::file_size(bag);
  EXPECT_GE(on_disk, 1000000u);

  auto classmate = piScene("classmate");
  classmate.request.student = "cy";
  ASSERT_TRUE(callService("/quota/collision_lab_node/run_scene", classmate));
  EXPECT_TRUE(classmate.response.ok) << classmate.response.rejected.message;
  EXPECT_EQ(classmate.response.summary.collision_count, 31u);

  // Counted on disk again at most once a second: within a few seconds of the deletion.
  for (const std::string& bag : bens_bags) fs::remove(bag);
  collision_lab::RunScene again;
  waitUntil(
      [&] {
        again = piScene("again");
        again.request.student = "ben";
        return callService("/quota/collision_lab_node/run_scene", again) && again.response.ok;
      },
      "ben to be served once his bags are deleted", 10.0);
  EXPECT_EQ(again.response.summary.collision_count, 31u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "disk_test");
  ros::NodeHandle private_nh("~");
  private_nh.getParam("tmp", g_tmp);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  for (const char* ns : {"floor", "nofloor"}) {
    const std::string dir = g_tmp + "/" + ns;
    if (onSmallDisk(ns)) std::system(("umount -l '" + dir + "'").c_str());
  }
  return result;
}
