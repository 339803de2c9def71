// collision_lab_markers: regenerates `markers` from the run topics, on bag replay or (~live
// true) beside a running collision_lab_node, e.g. to follow one student (~follow_student).
#include <ros/ros.h>

#include "collision_lab/ros/marker_view.h"
#include "collision_lab/ros/node_constants.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_markers");
  ros::NodeHandle private_nh("~");
  collision_lab_ros::MarkerView view(ros::NodeHandle(), collision_lab_ros::MarkerViewParams::load(private_nh));
  const bool live = private_nh.param("live", false);
  view.subscribe(live ? collision_lab_ros::kServedInputsTopic : collision_lab_ros::kInitialConditionsTopic);
  ros::spin();
  return 0;
}
