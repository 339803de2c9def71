# Tests of the Python module collision_lab (test/python; docs/python.md).
# pytest, counted by catkin_test_results through its JUnit file: the API against the CLI's
# JSON (the built collision_lab_cli is the reference), errors, Ctrl-C, sweeps (local, Dask
# LocalCluster over TCP, collision_lab_sweep's shards) and issue 33's done-when command.
catkin_run_tests_target(pytest python python.xml
  COMMAND "/usr/bin/python3 -m pytest ${PROJECT_SOURCE_DIR}/test/python -p no:cacheprovider --junitxml=${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/python.xml"
  DEPENDENCIES collision_lab_python_core collision_lab_cli collision_lab_generate_messages_py)
# read_bag on bags the node records (a rostest; its test node is Python).
add_rostest(test/python/read_bag.test DEPENDENCIES collision_lab_node collision_lab_python_core
  collision_lab_generate_messages_py)
