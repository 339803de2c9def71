// collision_lab_relay_node: the transport limit for collision_lab_node_throughput. It
// subscribes to initial_conditions and, for each message, publishes a RunSummary that
// carries only the run_id, with the lab node's queue sizes and nothing else.
#include <ros/ros.h>

#include "collision_lab/InitialConditions.h"
#include "collision_lab/RunSummary.h"
#include "collision_lab/ros/node_constants.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_relay_node");
  ros::NodeHandle nh;
  ros::Publisher summaries = nh.advertise<collision_lab::RunSummary>(
      collision_lab_ros::kRunSummariesTopic, collision_lab_ros::kOutputQueueSize);
  ros::Subscriber inputs = nh.subscribe<collision_lab::InitialConditions>(
      collision_lab_ros::kInitialConditionsTopic, collision_lab_ros::kInputQueueSize,
      [&summaries](const collision_lab::InitialConditions::ConstPtr& input) {
        collision_lab::RunSummary summary;
        summary.header.stamp = ros::Time::now();
        summary.run_id = input->run_id;
        summary.mode = input->mode;
        summaries.publish(summary);
      });
  ros::spin();
  return 0;
}
