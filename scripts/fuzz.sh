#!/usr/bin/env bash
# Builds a libFuzzer target (clang, ASan + UBSan) in ./build_fuzz and runs it for the given
# number of seconds (default 60), starting from its committed seed corpus: FUZZ_TARGET=core
# (default; fuzz/core_fuzzer.cpp, fuzz/corpus/core) or FUZZ_TARGET=nbody
# (fuzz/nbody_fuzzer.cpp, fuzz/corpus/nbody: rings with events, walls, the restitution
# models). New inputs go to build_fuzz/corpus, crashes, timeouts and
# inputs slower than 1 s to build_fuzz/artifacts. Prints the number of executions.
# Exits non-zero when the fuzzer found a crash, a timeout or a sanitizer error.
# Usage: bash scripts/fuzz.sh [seconds] [extra libFuzzer flags...]
# FUZZ_TIMEOUT (s, default 10): one input's limit; the nbody target's ring seeds of 1500
# impacts (issue 32's crash) take 15 s under the sanitizers: FUZZ_TIMEOUT=60 for them.
set -euo pipefail
cd "$(dirname "$0")/.."
# catkin's CMake needs Debian's python3 (with catkin_pkg), not a pyenv one earlier on PATH.
export PATH=/usr/bin:/bin:$PATH
seconds=${1:-60}
shift || true
build=build_fuzz
target=${FUZZ_TARGET:-core}

if ! command -v clang++ > /dev/null || ! ls /usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a > /dev/null 2>&1; then
  echo "fuzz.sh: needs Debian's clang and libFuzzer: apt-get install clang libclang-rt-14-dev" >&2
  exit 2
fi
# Only the core and the target are built: no messages, no ROS layer, no tests.
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOLLISION_LAB_FUZZ=ON \
  -DCATKIN_ENABLE_TESTING=OFF -DPYTHON_EXECUTABLE=/usr/bin/python3 > "$build.configure.log" 2>&1 \
  || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" --target "collision_lab_${target}_fuzzer" -j"${FUZZ_JOBS:-2}" > "$build.build.log" 2>&1 \
  || { tail -n 40 "$build.build.log"; exit 1; }
fuzzer="$build/devel/lib/collision_lab/collision_lab_${target}_fuzzer"

mkdir -p "$build/corpus/$target" "$build/artifacts"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
log="$build/fuzz.log"
status=0
# -seed fixes libFuzzer's mutations (run-to-run differences remain from timing only).
# -timeout: one input may take 10 s; -report_slow_units: inputs over 1 s are saved.
"$fuzzer" "$build/corpus/$target" "fuzz/corpus/$target" -max_total_time="$seconds" -seed=1 -timeout="${FUZZ_TIMEOUT:-10}" -rss_limit_mb=2048 \
  -report_slow_units=1 -max_len=512 -print_final_stats=1 -artifact_prefix="$build/artifacts/" "$@" \
  > "$log" 2>&1 || status=$?
grep -E "^(INFO: (Loaded|seed corpus)|#[0-9]+ +(INITED|DONE))|stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb|Slowest unit|invariant violated|runtime error|ERROR: " "$log" || true
echo "fuzz.sh: executions $(sed -nE 's/^stat::number_of_executed_units: *([0-9]+)/\1/p' "$log" | tail -n 1), corpus $(ls "$build/corpus/$target" | wc -l) new + $(ls "fuzz/corpus/$target" | wc -l) seeds, artifacts: $(ls "$build/artifacts" | wc -l) (log $log)"
exit $status
