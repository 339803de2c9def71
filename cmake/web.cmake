# The class's web server (issues 23 and 30, docs/web.md): a node of its own beside the lab
# node, an asynchronous HTTP server on Boost.Beast/Asio (Debian's libboost-dev, header-only
# here) with pages under web/ and Chart.js from Debian's libjs-chart.js (no CDN: a lab may
# have no internet). cpp-httplib (libcpp-httplib-dev) is only the tests' HTTP client.
# (include, not find_package: bench.cmake finds PkgConfig too, and catkin_lint flags a second find_package.)
include(FindPkgConfig)
# The web tests' HTTP client (cmake/web_tests.cmake); the server itself does not use it.
pkg_check_modules(CPP_HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
find_package(Threads REQUIRED)
add_library(collision_lab_web_lib
  src/web/http_server.cpp
  src/web/run_book.cpp
  src/web/index_run_source.cpp
  src/web/web_secrets.cpp
  src/web/web_server.cpp
  src/web/web_access.cpp
  src/web/web_post.cpp
  src/web/web_exports.cpp
  src/web/web_stream.cpp
  src/web/window_worldlines.cpp)
target_include_directories(collision_lab_web_lib PUBLIC include)
target_link_libraries(collision_lab_web_lib PUBLIC collision_lab_ros collision_lab_view_model collision_lab_service Threads::Threads)
add_executable(collision_lab_web src/web/web_node_main.cpp)
target_link_libraries(collision_lab_web PRIVATE collision_lab_web_lib)
set_target_properties(collision_lab_web PROPERTIES
  RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})

install(TARGETS collision_lab_web_lib collision_lab_service
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(TARGETS collision_lab_web RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
