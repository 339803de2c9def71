# The class's web server against a real lab node (rostest): the JSON API over a real HTTP
# client and each safety limit. Included after ros_tests.cmake, which finds rostest.
add_rostest_gtest(web_test test/ros/web_test.test test/ros/web_test.cpp)
target_link_libraries(web_test collision_lab_web_lib ${catkin_LIBRARIES})
add_dependencies(web_test collision_lab_node collision_lab_web)
