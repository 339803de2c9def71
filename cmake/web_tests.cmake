# The class's web server against a real lab node (rostest): the JSON API over a real HTTP
# client and each safety limit; the pages in a real browser. Included after
# ros_tests.cmake, which finds rostest.
add_rostest_gtest(web_test test/web/web_test.test test/web/web_test.cpp)
target_link_libraries(web_test collision_lab_web_lib PkgConfig::CPP_HTTPLIB ${catkin_LIBRARIES})
add_dependencies(web_test collision_lab_node collision_lab_web)
# Its defences and run controls (issue 30): slow and large clients, Origin/Host, codes, stop.
add_rostest_gtest(web_access_test test/web/web_access_test.test test/web/web_access_test.cpp)
target_link_libraries(web_access_test collision_lab_web_lib PkgConfig::CPP_HTTPLIB ${catkin_LIBRARIES})
add_dependencies(web_access_test collision_lab_node collision_lab_web)
# The pages in headless chromium (skipped without it); reads test/web/web_form_driver.html.
add_rostest_gtest(web_browser_test test/web/web_browser_test.test test/web/web_browser_test.cpp)
target_link_libraries(web_browser_test collision_lab_web_lib PkgConfig::CPP_HTTPLIB ${catkin_LIBRARIES})
add_dependencies(web_browser_test collision_lab_node collision_lab_web)
target_compile_definitions(web_browser_test PRIVATE COLLISION_LAB_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
# RunBook with the lab's topics out of order (no master).
catkin_add_gtest(run_book_test test/web/run_book_test.cpp)
# collision_lab_views: the test compares the page's view with rviz's markers.
target_link_libraries(run_book_test collision_lab_web_lib collision_lab_views ${catkin_LIBRARIES} GTest::gtest_main)
# The web node killed and respawned: every run of the run index still listed and served;
# runs whose end it missed end from the index.
add_rostest_gtest(web_restart_test test/web/web_restart_test.test test/web/web_restart_test.cpp)
target_link_libraries(web_restart_test collision_lab_web_lib PkgConfig::CPP_HTTPLIB ${catkin_LIBRARIES})
add_dependencies(web_restart_test collision_lab_node collision_lab_web)
# The real lab and web nodes together: a paused web node misses events, the lab node is
# killed mid-run and respawned; every run ends finished or interrupted, none stays running.
add_rostest_gtest(web_lab_recovery_test test/web/web_lab_recovery_test.test test/web/web_lab_recovery_test.cpp)
target_link_libraries(web_lab_recovery_test collision_lab_web_lib PkgConfig::CPP_HTTPLIB ${catkin_LIBRARIES})
add_dependencies(web_lab_recovery_test collision_lab_node collision_lab_web)
# A live run past the lab's ~max_published_events: RunProgress moves the page's counter.
add_rostest_gtest(web_progress_test test/web/web_progress_test.test test/web/web_progress_test.cpp)
target_link_libraries(web_progress_test collision_lab_web_lib PkgConfig::CPP_HTTPLIB ${catkin_LIBRARIES})
add_dependencies(web_progress_test collision_lab_node collision_lab_web)
