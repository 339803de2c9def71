#!/usr/bin/env bash
# Sets up, builds, and runs every test (core gtests, CLI tests, rostests), then prints
# catkin's summary. Exits non-zero when any test fails.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup_debian.sh
export PATH=/usr/bin:/bin:$PATH
set +u
source build/devel/setup.bash
set -u
rm -rf build/test_results
# run_tests keeps going past failing tests; catkin_test_results decides the exit code.
cmake --build build --target run_tests -- -j1 -k > build/run_tests.log 2>&1 || true
grep -E "^\[ +(FAILED|PASSED) +\]|^\[ROSTEST\]|^FAILURE|^SUMMARY|tests from .* ran" build/run_tests.log || true
status=0
summary=$(catkin_test_results build/test_results --verbose) || status=$?
echo "$summary" | tail -n 40
# One plain closing line: "N passed, N failed".
echo "$summary" | sed -nE 's/^Summary: ([0-9]+) tests, ([0-9]+) errors, ([0-9]+) failures, ([0-9]+) skipped.*/\1 \2 \3 \4/p' \
  | awk '{ printf "%d passed, %d failed\n", $1 - $2 - $3 - $4, $2 + $3 }'
exit $status
