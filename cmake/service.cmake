# The class's run index (issue 30, docs/ros.md "The run index"): a ROS-free library on
# SQLite (Debian's libsqlite3-dev), written by the lab node and read by the web node and
# ~list_runs.
find_package(SQLite3 REQUIRED)
find_package(Threads REQUIRED)
add_library(collision_lab_service
  src/service/admission.cpp
  src/service/envelope.cpp
  src/service/run_budget.cpp
  src/service/run_ids.cpp
  src/service/run_index.cpp)
target_include_directories(collision_lab_service PUBLIC include)
target_link_libraries(collision_lab_service PUBLIC SQLite::SQLite3)

install(TARGETS collision_lab_service
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
