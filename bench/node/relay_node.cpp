// collision_lab_relay_node: the fair anchor of collision_lab_node_throughput (issue 13). It
// publishes, per input, the very messages a lab node publishes for that run (same topics,
// types, latching, queue sizes, count and sizes) without computing them: at startup it
// sends the benchmark's scene once to the lab node in namespace ~template_from and keeps
// what comes back (prediction, per-collision events, velocities, energy transfers,
// summary). Per input it then sets run_id and header.stamp on those pre-built messages
// and publishes them in the node's order, so the gap between it and the lab node is the
// node's own cost (validation, prediction, simulation, message building, recording).
//
// Private parameters: ~template_from (namespace of a lab node, "/norecord"), ~masses,
// ~positions, ~velocities, ~mode (the scene the benchmark sends), ~timeout (s, 30).
#include <cstdio>
#include <string>
#include <vector>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "collision_lab/CollisionEvent.h"
#include "collision_lab/EnergyTransfer.h"
#include "collision_lab/InitialConditions.h"
#include "collision_lab/Prediction.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/Velocities.h"
#include "collision_lab/ros/node_constants.h"

namespace {

using namespace collision_lab_ros;
constexpr char kTemplateRunId[] = "relay_template";

/// One run's messages as the lab node published them.
struct RunTemplate {
  std::vector<collision_lab::Prediction> predictions;
  std::vector<collision_lab::CollisionEvent> events;
  std::vector<collision_lab::Velocities> velocities;
  std::vector<collision_lab::EnergyTransfer> energies;
  std::vector<collision_lab::RunSummary> summaries;

  bool complete() const {
    if (summaries.empty() || predictions.empty()) return false;
    const std::size_t n = summaries.front().published_events;
    return events.size() == n && velocities.size() == n && energies.size() == n;
  }
};

template <class Message>
ros::Subscriber collect(ros::NodeHandle& nh, const std::string& topic, std::vector<Message>& into) {
  return nh.subscribe<Message>(topic, kOutputQueueSize, [&into](const typename Message::ConstPtr& msg) {
    if (msg->run_id == kTemplateRunId) into.push_back(*msg);
  });
}

/// Serves scene once on the lab node in namespace from; false after timeout seconds.
bool copyRun(const std::string& from, const collision_lab::InitialConditions& scene, double timeout,
             RunTemplate& run) {
  ros::NodeHandle nh(from);
  std::vector<ros::Subscriber> subs{collect(nh, kPredictionsTopic, run.predictions),
                                    collect(nh, kCollisionEventsTopic, run.events),
                                    collect(nh, kVelocitiesTopic, run.velocities),
                                    collect(nh, kEnergyTransfersTopic, run.energies),
                                    collect(nh, kRunSummariesTopic, run.summaries)};
  ros::Publisher input = nh.advertise<collision_lab::InitialConditions>(kInitialConditionsTopic, 1);
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  const auto connected = [&] {
    if (input.getNumSubscribers() == 0) return false;
    for (const auto& sub : subs) {
      if (sub.getNumPublishers() == 0) return false;
    }
    return true;
  };
  bool sent = false;
  while (ros::ok() && ros::WallTime::now() < end && !run.complete()) {
    if (!sent && connected()) {
      collision_lab::InitialConditions msg = scene;
      msg.run_id = kTemplateRunId;
      input.publish(msg);
      sent = true;
    }
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.01));
  }
  return run.complete();
}

template <class Message>
void publishAs(const ros::Publisher& pub, Message& msg, const std::string& run_id, const ros::Time& stamp) {
  msg.run_id = run_id;
  msg.header.stamp = stamp;
  pub.publish(msg);
}

std::vector<double> param(const ros::NodeHandle& pnh, const std::string& name, std::vector<double> fallback) {
  pnh.getParam(name, fallback);
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_relay_node");
  ros::NodeHandle nh, pnh("~");
  collision_lab::InitialConditions scene;
  scene.masses = param(pnh, "masses", {1.0, 2.0, 3.0});
  scene.positions = param(pnh, "positions", {1.0, 0.0, -1.5});
  scene.velocities = param(pnh, "velocities", {-1.0, 0.0, 1.0});
  scene.mode = static_cast<std::uint8_t>(pnh.param("mode", 0));
  scene.max_collisions = static_cast<std::uint64_t>(pnh.param("max_collisions", 0));
  RunTemplate run;
  const std::string from = pnh.param<std::string>("template_from", "/norecord");
  if (!copyRun(from, scene, pnh.param("timeout", 30.0), run)) {
    ROS_FATAL_STREAM("relay: no complete run from the lab node in " << from << " within the timeout");
    return 1;
  }
  ROS_INFO_STREAM("relay: copied a run of " << run.events.size() << " published events from " << from);

  ros::Publisher predictions =
      nh.advertise<collision_lab::Prediction>(kPredictionsTopic, kOutputQueueSize, kLatchPredictions);
  ros::Publisher events = nh.advertise<collision_lab::CollisionEvent>(kCollisionEventsTopic, kOutputQueueSize);
  ros::Publisher velocities = nh.advertise<collision_lab::Velocities>(kVelocitiesTopic, kOutputQueueSize);
  ros::Publisher energies = nh.advertise<collision_lab::EnergyTransfer>(kEnergyTransfersTopic, kOutputQueueSize);
  ros::Publisher summaries =
      nh.advertise<collision_lab::RunSummary>(kRunSummariesTopic, kOutputQueueSize, kLatchRunSummaries);
  ros::Subscriber inputs = nh.subscribe<collision_lab::InitialConditions>(
      kInitialConditionsTopic, kInputQueueSize, [&](const collision_lab::InitialConditions::ConstPtr& input) {
        const ros::Time stamp = ros::Time::now();
        const std::string& id = input->run_id;
        publishAs(predictions, run.predictions.front(), id, stamp);
        // The lab node's order: each collision's event, velocities, energy transfer.
        for (std::size_t i = 0; i < run.events.size(); ++i) {
          publishAs(events, run.events[i], id, stamp);
          publishAs(velocities, run.velocities[i], id, stamp);
          publishAs(energies, run.energies[i], id, stamp);
        }
        publishAs(summaries, run.summaries.front(), id, stamp);
      });
  ros::spin();
  return 0;
}
