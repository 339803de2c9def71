#!/usr/bin/env bash
# Builds the whole package and its tests with AddressSanitizer + UndefinedBehaviorSanitizer
# (-DCOLLISION_LAB_SANITIZE=ON) in ./build_sanitize, runs every test (core, CLI, ROS unit
# tests and rostests), prints catkin's summary and the wall time. Exits non-zero when the
# build fails, a test fails, or a sanitizer reports an error.
# Usage: bash scripts/sanitize.sh [jobs]   (default 2)
set -euo pipefail
cd "$(dirname "$0")/.."
# catkin's CMake needs Debian's python3 (with catkin_pkg), not a pyenv one earlier on PATH.
export PATH=/usr/bin:/bin:$PATH
jobs=${1:-2}
build=build_sanitize
started=$(date +%s)

# UBSan findings abort (-fno-sanitize-recover=undefined) and print a stack. LeakSanitizer
# is off: roscpp, rosbag and the Python-started nodes keep global singletons alive until
# exit, which LSan reports as leaks; every other ASan check (overflows, use-after-free,
# double free) stays on, also in the nodes that rostest starts (they inherit this).
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# rostest's logs (and the nodes' stderr) go to this build's own folder, not ~/.ros.
export ROS_HOME="$PWD/$build/ros_home"

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOLLISION_LAB_SANITIZE=ON \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 > "$build.configure.log" 2>&1 || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j"$jobs" > "$build.build.log" 2>&1 || { tail -n 60 "$build.build.log"; exit 1; }
cmake --build "$build" --target tests -j"$jobs" >> "$build.build.log" 2>&1 || { tail -n 60 "$build.build.log"; exit 1; }
built=$(date +%s)

set +u
source "$build/devel/setup.bash"
set -u
rm -rf "$build/test_results"
# run_tests keeps going past failing tests; catkin_test_results decides the exit code.
cmake --build "$build" --target run_tests -- -j1 -k > "$build.run_tests.log" 2>&1 || true
status=0
catkin_test_results "$build/test_results" --verbose | tail -n 40 || status=$?
# A sanitizer report in a child process (a node, the CLI) fails the run even when the
# test that started it did not notice.
if grep -E "ERROR: AddressSanitizer|runtime error:|ERROR: LeakSanitizer" -r "$build.run_tests.log" "$build/test_results" \
    "$ROS_HOME" 2>/dev/null | grep -v "^Binary" | head -n 20; then
  echo "sanitize.sh: sanitizer reports above"
  status=1
fi
finished=$(date +%s)
echo "sanitize.sh: build $((built - started)) s, tests $((finished - built)) s, total $((finished - started)) s (-j$jobs)"
exit $status
