# The run index (no master): persistence, every state change, two connections on one
# file as two processes.
catkin_add_gtest(run_index_test test/service/run_index_test.cpp)
if(TARGET run_index_test)
  target_link_libraries(run_index_test collision_lab_service GTest::gtest_main)
endif()
