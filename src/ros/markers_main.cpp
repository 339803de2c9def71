// collision_lab_markers: regenerates `markers` from the run topics, on bag replay or (~live
// true) beside a running collision_lab_node, e.g. to follow one student (~follow_student).
#include <ros/ros.h>

#include "collision_lab/RunParameters.h"
#include "collision_lab/ros/marker_view.h"
#include "collision_lab/ros/node_constants.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_markers");
  ros::NodeHandle private_nh("~");
  collision_lab_ros::MarkerView view(ros::NodeHandle(), collision_lab_ros::MarkerViewParams::load(private_nh));
  const bool live = private_nh.param("live", false);
  view.subscribe(live ? collision_lab_ros::kServedInputsTopic : collision_lab_ros::kInitialConditionsTopic);
  // A replayed bag's RunParameters (bag only): printed in the replay's terminal, and a
  // listener on that topic, which `rosbag play --wait-for-subscribers` waits for.
  ros::NodeHandle nh;
  const ros::Subscriber parameters = nh.subscribe<collision_lab::RunParameters>(
      collision_lab_ros::kRunParametersTopic, 10,
      boost::function<void(const collision_lab::RunParameters::ConstPtr&)>([](const collision_lab::RunParameters::ConstPtr& p) {
        ROS_INFO_STREAM("run " << p->run_id << " was served by " << p->node_name << " (collision_lab "
                        << p->package_version << "), max_collisions " << p->max_collisions
                        << ", max_published_events " << p->max_published_events << ", max_bodies "
                        << p->max_bodies);
      }));
  ros::spin();
  return 0;
}
