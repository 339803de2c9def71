# Thin ROS layer in four libraries, as grid_map does, over the ROS-free core:
#   collision_lab_ros    the node: message <-> core conversion, the lab node, per-run bags
#                        and their exports (bag_csv: the events CSV, the class table)
#   collision_lab_view_model  a run kept for drawing and its view description, which rviz
#                        and the web page share (no marker types)
#   collision_lab_views  the rviz markers over the view model (links the node library for
#                        RunObserver, the node's hook for an in-process view)
#   collision_lab_tools  the scenario publisher
# Each executable links the library it runs.
# ROS headers for this layer and everything built after it (nodes, ROS tests, the node
# benchmarks); the core, built before, never sees them.
include_directories(SYSTEM ${catkin_INCLUDE_DIRS})
add_library(collision_lab_ros
  src/ros/msg_conversion.cpp
  src/ros/bag_reading.cpp
  src/ros/bag_csv.cpp
  src/ros/run_recorder.cpp
  src/ros/run_timeline.cpp
  src/ros/run_index_recorder.cpp
  src/ros/lab_node.cpp
  src/ros/lab_node_diagnostics.cpp
  src/ros/lab_node_inputs.cpp
  src/ros/lab_node_params.cpp
  src/ros/lab_node_shared.cpp
  src/ros/lab_node_runs.cpp
  src/ros/served_runs.cpp)
target_include_directories(collision_lab_ros PUBLIC include)
# collision_lab_io: the node reads the presets of ~run_preset.
# collision_lab_service: the run index the node writes and ~list_runs reads.
target_link_libraries(collision_lab_ros PUBLIC collision_lab_core collision_lab_io collision_lab_service
  nlohmann_json::nlohmann_json ${catkin_LIBRARIES})
add_dependencies(collision_lab_ros ${PROJECT_NAME}_generate_messages_cpp ${catkin_EXPORTED_TARGETS})
# The version recorded in every bag (RunParameters.package_version): package.xml's, as
# catkin_package() read it.
target_compile_definitions(collision_lab_ros PRIVATE COLLISION_LAB_VERSION="${collision_lab_VERSION}")

# The view model rviz and the web page share: a run kept for drawing (run_record), its view
# description (run_view) and style (view_style); no marker types.
add_library(collision_lab_view_model
  src/ros/run_record.cpp
  src/ros/run_view.cpp
  src/ros/view_style.cpp)
target_link_libraries(collision_lab_view_model PUBLIC collision_lab_ros)

add_library(collision_lab_views
  src/ros/marker_builder.cpp
  src/ros/marker_view.cpp
  # the rviz views, one file each, and what they share (include/.../ros/markers/)
  src/ros/markers/draw.cpp
  src/ros/markers/run_facts.cpp
  src/ros/markers/scene.cpp
  src/ros/markers/magnifier.cpp
  src/ros/markers/wedge.cpp
  src/ros/markers/steps.cpp
  src/ros/markers/worldlines.cpp
  src/ros/markers/energy_bars.cpp
  src/ros/markers/velocities.cpp
  src/ros/markers/overlays.cpp
  src/ros/markers/temperature.cpp
  src/ros/markers/clusters.cpp
  src/ros/markers/rviz_limits.cpp)
target_link_libraries(collision_lab_views PUBLIC collision_lab_view_model)

add_library(collision_lab_tools
  src/ros/scenario_publisher.cpp)
# collision_lab_io: the scenario files the publisher reads.
target_link_libraries(collision_lab_tools PUBLIC collision_lab_ros collision_lab_io)

# Executables go to the devel space's package folder, where rosrun and roslaunch look.
set(collision_lab_ROS_EXECUTABLES
  collision_lab_node collision_lab_markers scenario_publisher bag_to_csv)
# The node feeds the marker view in-process (~publish_markers): it links the views too.
add_executable(collision_lab_node src/ros/lab_node_main.cpp)
target_link_libraries(collision_lab_node PRIVATE collision_lab_ros collision_lab_views)
add_executable(collision_lab_markers src/ros/markers_main.cpp)
target_link_libraries(collision_lab_markers PRIVATE collision_lab_views)
add_executable(scenario_publisher src/ros/scenario_publisher_main.cpp)
target_link_libraries(scenario_publisher PRIVATE collision_lab_tools)
add_executable(bag_to_csv src/ros/bag_to_csv_main.cpp)
target_link_libraries(bag_to_csv PRIVATE collision_lab_ros)
set_target_properties(${collision_lab_ROS_EXECUTABLES} PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})

install(TARGETS collision_lab_ros collision_lab_view_model collision_lab_views collision_lab_tools
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(TARGETS ${collision_lab_ROS_EXECUTABLES}
  RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
# replay.launch's bag resolver (bag:=latest, a run_id or a path), found in the source
# folder by rosrun and roslaunch, installed beside the executables.
install(PROGRAMS scripts/play_run DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
# The teacher's list of runs from the bags (docs/ros.md), installed the same way.
install(PROGRAMS scripts/list_runs DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
# replay.launch's guard that removes /use_sim_time when the replay ends.
catkin_install_python(PROGRAMS scripts/sim_time_guard DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
