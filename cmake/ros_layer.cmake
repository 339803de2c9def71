# Thin ROS layer: message <-> core conversion, the lab node, per-run bags, rviz markers,
# and the scenario publisher. Links the core (and collision_lab_io for scenario files).
# ROS headers for this layer and everything built after it (nodes, ROS tests, the node
# benchmarks); the core, built before, never sees them.
include_directories(SYSTEM ${catkin_INCLUDE_DIRS})
add_library(collision_lab_ros
  src/ros/msg_conversion.cpp
  src/ros/run_recorder.cpp
  src/ros/run_timeline.cpp
  src/ros/bag_csv.cpp
  src/ros/lab_node.cpp
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
target_include_directories(collision_lab_ros PUBLIC include)
# collision_lab_io: the node reads the presets of ~run_preset.
target_link_libraries(collision_lab_ros PUBLIC collision_lab_core collision_lab_io ${catkin_LIBRARIES})
add_dependencies(collision_lab_ros ${PROJECT_NAME}_generate_messages_cpp ${catkin_EXPORTED_TARGETS})
# The version recorded in every bag (RunParameters.package_version): package.xml's, as
# catkin_package() read it.
target_compile_definitions(collision_lab_ros PRIVATE COLLISION_LAB_VERSION="${collision_lab_VERSION}")

# Executables go to the devel space's package folder, where rosrun and roslaunch look.
set(collision_lab_ROS_EXECUTABLES
  collision_lab_node collision_lab_markers scenario_publisher bag_to_csv)
add_executable(collision_lab_node src/ros/lab_node_main.cpp)
target_link_libraries(collision_lab_node PRIVATE collision_lab_ros)
add_executable(collision_lab_markers src/ros/markers_main.cpp)
target_link_libraries(collision_lab_markers PRIVATE collision_lab_ros)
add_executable(scenario_publisher src/ros/scenario_publisher.cpp)
target_link_libraries(scenario_publisher PRIVATE collision_lab_ros collision_lab_io)
add_executable(bag_to_csv src/ros/bag_to_csv_main.cpp)
target_link_libraries(bag_to_csv PRIVATE collision_lab_ros)
set_target_properties(${collision_lab_ROS_EXECUTABLES} PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})

install(TARGETS collision_lab_ros
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
