# Tests of the ROS layer. Unit tests need no master; the rostests start the real node.
catkin_add_gtest(ros_layer_unit_test
  test/ros/msg_conversion_test.cpp
  test/ros/run_recorder_test.cpp
  test/ros/marker_builder_test.cpp
  test/ros/marker_nbody_test.cpp
  test/ros/marker_granular_test.cpp
  test/ros/marker_view_test.cpp
  test/ros/run_view_test.cpp)
if(TARGET ros_layer_unit_test)
  target_link_libraries(ros_layer_unit_test collision_lab_views GTest::gtest_main)
endif()

# The run timeline and bag_to_csv (no master).
catkin_add_gtest(ros_tools_unit_test
  test/ros/run_timeline_test.cpp
  test/ros/bag_csv_test.cpp)
if(TARGET ros_tools_unit_test)
  target_link_libraries(ros_tools_unit_test collision_lab_tools collision_lab_test_support GTest::gtest_main)
  add_dependencies(ros_tools_unit_test bag_to_csv)
  target_compile_definitions(ros_tools_unit_test PRIVATE
    COLLISION_LAB_BAG_TO_CSV="$<TARGET_FILE:bag_to_csv>")
endif()

find_package(rostest REQUIRED)
foreach(name node_test nbody_node_test burst_test demo_test crash_test markers_test markers_clock_test class_test
    shared_folder_test service_test memory_test disk_test)
  add_rostest_gtest(${name} test/ros/${name}.test test/ros/${name}.cpp)
  target_link_libraries(${name} collision_lab_ros ${catkin_LIBRARIES})
  # The rostests start these nodes.
  add_dependencies(${name} collision_lab_node collision_lab_markers scenario_publisher)
endforeach()
# demo_test converts the demo's bags with bag_csv.
target_link_libraries(demo_test collision_lab_tools)
# nbody_node_test checks the node against the exact rational reference of the test support.
target_link_libraries(nbody_node_test collision_lab_test_support)
# node_test reads the bad-input catalogue, docs/bad_inputs.md; demo_test runs scripts/play_run.
target_compile_definitions(node_test PRIVATE COLLISION_LAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
target_compile_definitions(demo_test PRIVATE COLLISION_LAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# class_test runs scripts/list_runs.
target_compile_definitions(class_test PRIVATE COLLISION_LAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# crash_test starts and kills the node itself.
target_compile_definitions(crash_test PRIVATE COLLISION_LAB_NODE_PATH="$<TARGET_FILE:collision_lab_node>")

# Every launch file parses, and the packages and node executables it names exist
# (roslaunch-check): a broken launch file fails the tests.
find_package(roslaunch REQUIRED)
file(GLOB collision_lab_LAUNCH_FILES RELATIVE ${PROJECT_SOURCE_DIR} ${PROJECT_SOURCE_DIR}/launch/*.launch)
foreach(launch_file ${collision_lab_LAUNCH_FILES})
  # student.launch needs a student: its default is $(env COLLISION_LAB_STUDENT).
  roslaunch_add_file_check(${launch_file} COLLISION_LAB_STUDENT=ana
    DEPENDENCIES collision_lab_node collision_lab_markers scenario_publisher)
endforeach()

