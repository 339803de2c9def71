# Test support, built once: the exact rational references written for the tests (no
# engine code: rational_reference.h for three bodies, nbody/reference.cpp for N) and the
# seeded scene generators (scenes.h, nbody/random_scenes.h). Used by the core, CLI and
# node tests.
add_library(collision_lab_test_support STATIC EXCLUDE_FROM_ALL test/core/nbody/reference.cpp)
target_include_directories(collision_lab_test_support PUBLIC test/core test/core/nbody)
target_link_libraries(collision_lab_test_support PUBLIC collision_lab_core)

# The long physics test binaries run one process per test, as many at a time as there are
# cores (test/gtest_parallel.py), so that their minutes do not hold CI on one core; the
# result file is gtest's, under gtest's name.
function(collision_lab_add_parallel_gtest target)
  catkin_add_executable_with_gtest(${target} ${ARGN} EXCLUDE_FROM_ALL)
  if(TARGET ${target})
    add_dependencies(tests ${target})
    get_target_property(binary_folder ${target} RUNTIME_OUTPUT_DIRECTORY)
    catkin_run_tests_target("gtest" ${target} "gtest-${target}.xml"
      COMMAND "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/gtest_parallel.py ${binary_folder}/${target} --gtest_output=xml:${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/gtest-${target}.xml"
      DEPENDENCIES ${target})
  endif()
endfunction()

# Pure core tests: gtest, no ROS master.
collision_lab_add_parallel_gtest(collision_lab_core_tests
  test/core/test_validation.cpp
  test/core/test_exact_agreement.cpp
  test/core/test_analytic.cpp
  test/core/test_paper.cpp
  test/core/test_double_range.cpp
  test/core/test_lab_run.cpp
  test/core/test_full_run_accuracy.cpp
  test/core/test_wedge_cycle.cpp
  test/core/test_three_body_rounding.cpp
  test/core/test_long_run_rounding.cpp
  test/core/test_filtered_pass.cpp
  test/core/test_filtered_arithmetic.cpp
  test/core/test_published_rounding.cpp
  test/core/test_totals.cpp)
if(TARGET collision_lab_core_tests)
  target_link_libraries(collision_lab_core_tests collision_lab_test_support GTest::gtest_main)
  # test_long_run_rounding.cpp tests the known-count pass (src/core/nbody/elastic_triple.h),
  # test_filtered_arithmetic.cpp the filter of the published angles (src/core/correct_rounding.h).
  target_include_directories(collision_lab_core_tests PRIVATE src/core/nbody src/core)
endif()

# N-body core (issue 10): scene, models, exact event engine, against the exact rational
# reference of the test support.
collision_lab_add_parallel_gtest(collision_lab_nbody_tests
  test/core/nbody/test_scene.cpp
  test/core/nbody/test_models.cpp
  test/core/nbody/test_engine_hard.cpp
  test/core/nbody/test_engine_random.cpp
  test/core/nbody/test_restitution.cpp
  test/core/nbody/test_impact_stream.cpp
  test/core/nbody/test_spiral_random.cpp
  test/core/nbody/test_simultaneous.cpp
  test/core/nbody/test_wall_collapse.cpp
  test/core/nbody/test_body_state_replay.cpp
  test/core/nbody/test_temperature.cpp
  test/core/nbody/test_gas_budget.cpp
  test/core/nbody/test_two_restitutions.cpp
  test/core/nbody/test_group_collapse.cpp
  test/core/nbody/test_collapse_chain.cpp
  test/core/nbody/test_granular_models.cpp
  test/core/nbody/test_sticking_clusters.cpp
  test/core/nbody/test_sticky_model.cpp
  test/core/nbody/test_two_body_any_ratio.cpp
  test/core/nbody/test_ring_events.cpp
  test/core/nbody/test_wide_range.cpp
  test/core/nbody/test_fma_path.cpp
  test/core/nbody/test_tier_arithmetic.cpp
  test/core/nbody/test_published_rounding_nbody.cpp)
if(TARGET collision_lab_nbody_tests)
  target_link_libraries(collision_lab_nbody_tests collision_lab_test_support GTest::gtest_main)
  # test_fma_path.cpp and test_tier_arithmetic.cpp test the engine's internal arithmetic.
  target_include_directories(collision_lab_nbody_tests PRIVATE src/core/nbody)
endif()

# The fuzz corpora replayed through the fuzz targets' entry points (no libFuzzer needed).
catkin_add_gtest(collision_lab_fuzz_corpus_test test/core/fuzz_corpus_test.cpp fuzz/core_fuzzer.cpp fuzz/nbody_fuzzer.cpp)
if(TARGET collision_lab_fuzz_corpus_test)
  target_link_libraries(collision_lab_fuzz_corpus_test collision_lab_core GTest::gtest_main)
  target_compile_definitions(collision_lab_fuzz_corpus_test PRIVATE COLLISION_LAB_FUZZ_REPLAY
                             COLLISION_LAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()
