#include <csignal>
#include <memory>
#include <optional>
#include <stdexcept>

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include "collision_lab/ros/lab_node.h"
#include "collision_lab/ros/marker_view.h"

namespace {
volatile std::sig_atomic_t g_interrupted = 0;
void onSigint(int) { g_interrupted = 1; }
}  // namespace

int main(int argc, char** argv) {
  // SIGINT destroys the node (cancelling its run) before ros::shutdown(), which would first
  // wait for every service call in progress, and so for its whole run (lab_node.h). A
  // shutdown from elsewhere (rosnode kill) is already waiting: the node is destroyed at once.
  ros::init(argc, argv, "collision_lab_node", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, onSigint);
  // Held by main, so that ROS (and its logging) outlives a node that fails to start.
  ros::NodeHandle nh, private_nh("~");
  std::optional<collision_lab_ros::LabNode> node;
  try {
    node.emplace(nh, private_nh, [](ros::NodeHandle node_nh, ros::NodeHandle node_private_nh) {
      return std::make_unique<collision_lab_ros::MarkerView>(node_nh,
                                                              collision_lab_ros::MarkerViewParams::load(node_private_nh));
    });
  } catch (const std::invalid_argument& e) {
    ROS_FATAL_STREAM("collision_lab_node: " << e.what());
    return 1;
  }
  while (ros::ok() && !ros::isShuttingDown() && !g_interrupted) ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
  node.reset();
  ros::shutdown();
  return 0;
}
