# A ROS-free test of the run service (no master): test/service/<name>.cpp, linked with the
# service library (and the core, whose scheduler the workers use).
function(collision_lab_service_test name)
  catkin_add_gtest(${name} test/service/${name}.cpp)
  if(TARGET ${name})
    target_link_libraries(${name} collision_lab_service collision_lab_core Threads::Threads GTest::gtest_main)
  endif()
endfunction()

# The run index (no master): persistence, every state change, two connections on one
# file as two processes.
collision_lab_service_test(run_index_test)

# An address's bounded share of the class's runs (no master).
collision_lab_service_test(address_share_test)

# The envelope of an input, as the lab node and the web check it (no master).
collision_lab_service_test(envelope_test)

# A run's budget: the lab's limits lowered by the input's, and the service's stop reasons (no master).
collision_lab_service_test(run_budget_test)

# The run_id a run is served under, against a ledger the test keeps (no master).
collision_lab_service_test(run_ids_test)

# A student's share of the lab's disk (no master).
collision_lab_service_test(student_quota_test)

# Whether the lab takes a run: the bag folder's floor and the student's quota, on a
# disk the test sets (no master, no root).
collision_lab_service_test(admission_test)

# The fair run queue: each student in turn, the short lane.
collision_lab_service_test(fair_scheduler_test)

# The workers: fair order, the short lane, the watchdog, cancel, shutdown, the queue's notices.
collision_lab_service_test(worker_pool_test)

# The lab node's side (no master): the bag claim's lock, recovery of a killed writer's
# .active bag (reindexed with `rosbag reindex`), stale rows ended, ~list_runs' rows.
catkin_add_gtest(run_index_recorder_test test/ros/run_index_recorder_test.cpp)
if(TARGET run_index_recorder_test)
  target_link_libraries(run_index_recorder_test collision_lab_ros GTest::gtest_main)
  target_compile_definitions(run_index_recorder_test PRIVATE COLLISION_LAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()

# The real nodes (rostest): a lab node killed with SIGKILL and respawned by roslaunch
# lists every earlier run and leaves a live node's bag alone.
add_rostest_gtest(index_restart_test test/ros/index_restart_test.test test/ros/index_restart_test.cpp)
target_link_libraries(index_restart_test collision_lab_ros ${catkin_LIBRARIES})
add_dependencies(index_restart_test collision_lab_node)
