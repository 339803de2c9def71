// collision_lab_markers: regenerates `markers` from the run topics, e.g. on bag replay.
#include <ros/ros.h>

#include "collision_lab/ros/marker_view.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_markers");
  ros::NodeHandle private_nh("~");
  collision_lab_ros::MarkerView view(ros::NodeHandle(), collision_lab_ros::MarkerViewParams::load(private_nh));
  view.subscribe();
  ros::spin();
  return 0;
}
