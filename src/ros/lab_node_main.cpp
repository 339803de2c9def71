#include <ros/ros.h>

#include "collision_lab/ros/lab_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_lab_node");
  collision_lab_ros::LabNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  ros::spin();
  return 0;
}
