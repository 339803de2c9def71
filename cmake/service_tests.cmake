# The run index (no master): persistence, every state change, two connections on one
# file as two processes.
catkin_add_gtest(run_index_test test/service/run_index_test.cpp)
if(TARGET run_index_test)
  target_link_libraries(run_index_test collision_lab_service GTest::gtest_main)
endif()

# An address's bounded share of the class's runs (no master).
catkin_add_gtest(address_share_test test/service/address_share_test.cpp)
if(TARGET address_share_test)
  target_link_libraries(address_share_test collision_lab_service GTest::gtest_main)
endif()

# The envelope of an input, as the lab node and the web check it (no master).
catkin_add_gtest(envelope_test test/service/envelope_test.cpp)
if(TARGET envelope_test)
  target_link_libraries(envelope_test collision_lab_service GTest::gtest_main)
endif()

# A run's budget: the lab's limits lowered by the input's, and the service's stop reasons (no master).
catkin_add_gtest(run_budget_test test/service/run_budget_test.cpp)
if(TARGET run_budget_test)
  target_link_libraries(run_budget_test collision_lab_service GTest::gtest_main)
endif()

# The run_id a run is served under, against a ledger the test keeps (no master).
catkin_add_gtest(run_ids_test test/service/run_ids_test.cpp)
if(TARGET run_ids_test)
  target_link_libraries(run_ids_test collision_lab_service GTest::gtest_main)
endif()

# A student's share of the lab's disk (no master).
catkin_add_gtest(student_quota_test test/service/student_quota_test.cpp)
if(TARGET student_quota_test)
  target_link_libraries(student_quota_test collision_lab_service GTest::gtest_main)
endif()

# Whether the lab takes a run: the bag folder's floor and the student's quota, on a
# disk the test sets (no master, no root).
catkin_add_gtest(admission_test test/service/admission_test.cpp)
if(TARGET admission_test)
  target_link_libraries(admission_test collision_lab_service GTest::gtest_main)
endif()

# The lab node's side (no master): the bag claim's lock, recovery of a killed writer's
# .active bag (reindexed with `rosbag reindex`), stale rows ended, ~list_runs' rows.
catkin_add_gtest(run_index_recorder_test test/ros/run_index_recorder_test.cpp)
if(TARGET run_index_recorder_test)
  target_link_libraries(run_index_recorder_test collision_lab_ros GTest::gtest_main)
endif()

# The real nodes (rostest): a lab node killed with SIGKILL and respawned by roslaunch
# lists every earlier run and leaves a live node's bag alone.
add_rostest_gtest(index_restart_test test/ros/index_restart_test.test test/ros/index_restart_test.cpp)
target_link_libraries(index_restart_test collision_lab_ros ${catkin_LIBRARIES})
add_dependencies(index_restart_test collision_lab_node)
