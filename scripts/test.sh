#!/usr/bin/env bash
# Sets up, builds, checks a catkin-workspace build, and runs every test (core gtests, CLI
# tests, rostests), then prints catkin's summary. Exits non-zero when any test fails.
set -euo pipefail
cd "$(dirname "$0")/.."
# Options go to setup_debian.sh (CI: --with-screenshots, for the browser tests).
bash scripts/setup_debian.sh "$@"
# The usual ROS way works too: a fresh catkin workspace, catkin_make, rosrun, roslaunch.
bash scripts/check_catkin_workspace.sh
export PATH=/usr/bin:/bin:$PATH
set +u
source build_ros/devel/setup.bash
set -u
rm -rf build_ros/test_results
# Build the test executables in parallel; run them one at a time (rostests start masters).
cmake --build build_ros --target tests -- -j"$(nproc)" > build_ros/build_tests.log 2>&1 \
  || { tail -n 60 build_ros/build_tests.log; echo "test.sh: building the tests failed; log in build_ros/build_tests.log" >&2; exit 1; }
# run_tests keeps going past failing tests; catkin_test_results decides the exit code.
cmake --build build_ros --target run_tests -- -j1 -k > build_ros/run_tests.log 2>&1 || true
grep -E "^\[ +(FAILED|PASSED) +\]|^\[ROSTEST\]|^FAILURE|^SUMMARY|tests from .* ran" build_ros/run_tests.log || true
status=0
summary=$(catkin_test_results build_ros/test_results --verbose) || status=$?
echo "$summary" | tail -n 40
# One plain closing line: "N passed, N failed".
echo "$summary" | sed -nE 's/^Summary: ([0-9]+) tests, ([0-9]+) errors, ([0-9]+) failures, ([0-9]+) skipped.*/\1 \2 \3 \4/p' \
  | awk '{ printf "%d passed, %d failed\n", $1 - $2 - $3 - $4, $2 + $3 }'
exit $status
