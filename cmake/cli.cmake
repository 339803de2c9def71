# collision_lab_cli: no ROS master needed. Placed in the devel space's package bin
# folder so that `rosrun collision_lab collision_lab_cli` finds it.
# The CLI's parser and runner (a library of their own for test/cli).
add_library(collision_lab_cli_runner STATIC
  src/cli/command_line.cpp
  src/cli/progress.cpp
  src/cli/scene_runner.cpp)
target_link_libraries(collision_lab_cli_runner PUBLIC collision_lab_io CLI11::CLI11)
add_executable(collision_lab_cli src/cli/main.cpp)
target_link_libraries(collision_lab_cli PRIVATE collision_lab_cli_runner)
# --name and --list without --scenario read the presets: an installed CLI its install's
# copy (the share folder, relative to the executable), the devel space's the source tree's.
file(RELATIVE_PATH collision_lab_BIN_TO_SHARE
  "/prefix/${CATKIN_PACKAGE_BIN_DESTINATION}" "/prefix/${CATKIN_PACKAGE_SHARE_DESTINATION}")
target_compile_definitions(collision_lab_cli PRIVATE
  COLLISION_LAB_SOURCE_SCENARIOS="${PROJECT_SOURCE_DIR}/config/scenarios.yaml"
  COLLISION_LAB_BIN_TO_SHARE="${collision_lab_BIN_TO_SHARE}")
set_target_properties(collision_lab_cli PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})

install(TARGETS collision_lab_cli RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
