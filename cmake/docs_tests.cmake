# The docs as tests (test/docs, Python unittests through rosunit; catkin's run_tests runs them).
# docs/web.md's commands run as written (roslaunch, curl) against the lab and web nodes the
# page starts, each output as the page shows it (a Python unittest; its own master and ports).
catkin_run_tests_target(doc web_md_commands web_md_commands.xml
  COMMAND "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/docs/web_md_commands_test.py --doc ${PROJECT_SOURCE_DIR}/docs/web.md --setup ${CATKIN_DEVEL_PREFIX}/setup.bash --gtest_output=xml:${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/web_md_commands.xml"
  DEPENDENCIES collision_lab_node collision_lab_web)
# README.md is the front door: at most 250 lines, the two commands first, its links alive.
catkin_run_tests_target(doc readme readme.xml
  COMMAND "/usr/bin/python3 ${PROJECT_SOURCE_DIR}/test/docs/readme_test.py --repo ${PROJECT_SOURCE_DIR} --gtest_output=xml:${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/readme.xml")
