# Tests of collision_lab_io (test/io) and collision_lab_cli (test/cli) (gtest, no master).
# The CLI tests run the built binary as a child process, from the source folder.
catkin_add_gtest(collision_lab_io_test test/io/scenario_file_test.cpp test/io/scene_run_test.cpp
  test/io/number_format_test.cpp test/io/report_stream_test.cpp test/io/report_values_test.cpp)
if(TARGET collision_lab_io_test)
  target_link_libraries(collision_lab_io_test collision_lab_io GTest::gtest_main)
  target_include_directories(collision_lab_io_test PRIVATE src/io)  # the report stream's cache, tested directly
  target_compile_definitions(collision_lab_io_test PRIVATE COLLISION_LAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
endif()

catkin_add_gtest(collision_lab_cli_test
  test/cli/cli_test.cpp
  test/cli/bad_inputs_test.cpp
  test/cli/random_input_test.cpp
  test/cli/nbody_cli_test.cpp
  test/cli/lean_events_test.cpp
  test/cli/collapse_cli_test.cpp
  test/cli/temperature_cli_test.cpp
  test/cli/three_body_report_test.cpp
  test/cli/cli_process.cpp)
if(TARGET collision_lab_cli_test)
  # collapse_cli_test checks the CLI against the exact rational reference of the test support.
  target_link_libraries(collision_lab_cli_test collision_lab_test_support nlohmann_json::nlohmann_json
    GTest::gtest_main)
  target_compile_definitions(collision_lab_cli_test PRIVATE
    COLLISION_LAB_CLI_PATH="$<TARGET_FILE:collision_lab_cli>"
    COLLISION_LAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  add_dependencies(collision_lab_cli_test collision_lab_cli)
endif()
