# collision_lab_io: ROS-free scenario files and run reports, shared by the CLI and the
# ROS layer. Links the core, yaml-cpp and nlohmann_json.
add_library(collision_lab_io
  src/io/number_text.cpp
  src/io/scenario_file.cpp
  src/io/bodies_csv.cpp
  src/io/scene_report.cpp
  src/io/report.cpp
  src/io/temperature_csv.cpp)
target_link_libraries(collision_lab_io PUBLIC collision_lab_core yaml-cpp nlohmann_json::nlohmann_json)

install(TARGETS collision_lab_io
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  RUNTIME DESTINATION ${CATKIN_GLOBAL_BIN_DESTINATION})
