# Pure core tests: gtest, no ROS master.
catkin_add_gtest(collision_lab_core_tests
  test/core/test_validation.cpp
  test/core/test_exact_agreement.cpp
  test/core/test_analytic.cpp
  test/core/test_paper.cpp
  test/core/test_double_range.cpp
  test/core/test_lab_run.cpp
  test/core/test_full_run_accuracy.cpp)
if(TARGET collision_lab_core_tests)
  target_link_libraries(collision_lab_core_tests collision_lab_core GTest::gtest_main)
endif()

# N-body core (issue 10): scene, models, exact event engine, against an exact rational
# reference written in the test directory.
catkin_add_gtest(collision_lab_nbody_tests
  test/core/nbody/reference.cpp
  test/core/nbody/test_scene.cpp
  test/core/nbody/test_models.cpp
  test/core/nbody/test_engine_hard.cpp
  test/core/nbody/test_engine_random.cpp
  test/core/nbody/test_restitution.cpp
  test/core/nbody/test_impact_stream.cpp
  test/core/nbody/test_spiral_random.cpp
  test/core/nbody/test_simultaneous.cpp
  test/core/nbody/test_wall_collapse.cpp)
if(TARGET collision_lab_nbody_tests)
  target_link_libraries(collision_lab_nbody_tests collision_lab_core GTest::gtest_main)
endif()
