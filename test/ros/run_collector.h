// Test client for collision_lab_node: publishes InitialConditions and collects every
// output per run_id. Waits are event-driven (spinning the callback queue until a
// condition holds) and each gives up after kWaitTimeout with a gtest failure that says
// what it waited for, so a regression fails instead of hanging until rostest's limit.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/Rejected.h"
#include "collision_lab/RunProgress.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"
#include "collision_lab/ros/node_constants.h"

namespace collision_lab_test {

/// Guards against hangs, not a performance limit: the slowest single wait in these tests
/// (a 10,000-collision stretch of the crash test's long run) takes a few seconds.
constexpr double kWaitTimeout = 120.0;  ///< [s] wall time

/// Spins the global callback queue until done() holds; false (and a gtest failure naming
/// what) after timeout seconds or when ROS shuts down.
inline bool waitUntil(const std::function<bool()>& done, const std::string& what,
                      double timeout = kWaitTimeout) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (!done()) {
    if (!ros::ok() || ros::WallTime::now() > end) {
      ADD_FAILURE() << "gave up after " << timeout << " s waiting for " << what;
      return false;
    }
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  }
  return true;
}

struct RunOutputs {
  std::vector<collision_lab::Prediction> predictions;
  std::vector<collision_lab::CollisionEvent> events;
  std::vector<collision_lab::Velocities> velocities;
  std::vector<collision_lab::EnergyTransfer> energies;
  std::vector<collision_lab::RunSummary> summaries;
  std::vector<collision_lab::Rejected> rejections;
  std::vector<collision_lab::RunProgress> progress;

  /// A rejection, or a summary with every per-collision message it announces (and, past
  /// ~max_published_events, the RunProgress of the first collision not published).
  bool complete() const {
    if (!rejections.empty()) return true;
    if (summaries.empty() || predictions.empty()) return false;
    const std::uint64_t n = summaries.front().published_events;
    if (summaries.front().events_not_published && progress.empty()) return false;
    return events.size() >= n && velocities.size() >= n && energies.size() >= n;
  }
};

class RunCollector {
 public:
  /// Talks to the node whose topics are in namespace ns.
  explicit RunCollector(const std::string& ns) : nh_(ns) {
    using namespace collision_lab_ros;
    input_pub_ = nh_.advertise<collision_lab::InitialConditions>(kInitialConditionsTopic,
                                                                 kInputQueueSize);
    subscribe<collision_lab::Prediction>(kPredictionsTopic, &RunOutputs::predictions);
    subscribe<collision_lab::CollisionEvent>(kCollisionEventsTopic, &RunOutputs::events);
    subscribe<collision_lab::Velocities>(kVelocitiesTopic, &RunOutputs::velocities);
    subscribe<collision_lab::EnergyTransfer>(kEnergyTransfersTopic, &RunOutputs::energies);
    subscribe<collision_lab::RunSummary>(kRunSummariesTopic, &RunOutputs::summaries);
    subscribe<collision_lab::Rejected>(kRejectedTopic, &RunOutputs::rejections);
    subscribe<collision_lab::RunProgress>(kRunProgressTopic, &RunOutputs::progress);
  }

  /// Returns once the node subscribes to our input and all its outputs reach us.
  void waitForConnection() {
    const auto connected = [this] {
      if (input_pub_.getNumSubscribers() == 0) return false;
      for (const auto& sub : subscribers_) {
        if (sub.getNumPublishers() == 0) return false;
      }
      return true;
    };
    waitUntil(connected, "the node in namespace '" + nh_.getNamespace() +
                             "' to subscribe to our input and publish every output");
  }

  void publish(const collision_lab::InitialConditions& input) { input_pub_.publish(input); }

  /// Waits until the run is complete (see RunOutputs::complete) and returns its outputs,
  /// as far as they came when the wait gives up.
  const RunOutputs& waitFor(const std::string& run_id) {
    waitUntil([&] { return runs_[run_id].complete(); },
              "run '" + run_id + "' to complete (a summary with its announced collisions, or a rejection)");
    return runs_[run_id];
  }

  const std::map<std::string, RunOutputs>& runs() const { return runs_; }

 private:
  template <class Message>
  void subscribe(const std::string& topic, std::vector<Message> RunOutputs::*field) {
    subscribers_.push_back(nh_.subscribe<Message>(
        topic, collision_lab_ros::kOutputQueueSize,
        [this, field](const typename Message::ConstPtr& msg) {
          (runs_[msg->run_id].*field).push_back(*msg);
        }));
  }

  ros::NodeHandle nh_;
  ros::Publisher input_pub_;
  std::vector<ros::Subscriber> subscribers_;
  std::map<std::string, RunOutputs> runs_;
};

inline collision_lab::InitialConditions makeInput(const std::string& run_id,
                                                  const std::array<double, 3>& masses,
                                                  const std::array<double, 3>& positions,
                                                  const std::array<double, 3>& velocities) {
  collision_lab::InitialConditions input;
  input.header.stamp = ros::Time::now();
  input.run_id = run_id;
  input.masses.assign(masses.begin(), masses.end());
  input.positions.assign(positions.begin(), positions.end());
  input.velocities.assign(velocities.begin(), velocities.end());
  return input;
}

/// Calls service like ros::service::call, but gives up after kWaitTimeout with a failure
/// naming the service (the call then finishes, unseen, in its own thread).
template <class Service>
bool callService(const std::string& service, Service& call) {
  struct Shared {
    Service call;
    std::atomic<bool> done{false};
    bool ok = false;
  };
  auto shared = std::make_shared<Shared>();
  shared->call = call;
  std::thread([shared, service] {
    shared->ok = ros::service::call(service, shared->call);
    shared->done = true;
  }).detach();
  if (!waitUntil([&] { return shared->done.load(); }, "an answer from " + service)) return false;
  call = shared->call;
  return shared->ok;
}

}  // namespace collision_lab_test
