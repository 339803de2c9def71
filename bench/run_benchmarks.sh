#!/usr/bin/env bash
# Runs every benchmark and prints each speed goal (issue 13) with its figure and the anchor
# measured beside it in the same run. Regenerates the benchmark outputs in docs/:
#   docs/speed_vs_error.{csv,md,png}      collision_lab_speed_vs_error
#   docs/hard_cases.md                    collision_lab_hard_cases
#   docs/restitution_count.{csv,png}      collision_lab_bench_restitution, bench/plot_restitution_count.py
#   docs/benchmark_goals.md               every "goal:" line of this run, as a table
# and prints the core and N-body speed tables (collision_lab_bench_core, collision_lab_bench_nbody),
# the granular gases' worst case (collision_lab_bench_gas)
# the CLI's output speed against dd (bench/bench_output.sh), and the node against a relay that
# publishes the same messages and against rosbag record (bench/node/*.launch), and the class
# service under thirty students with big jobs and an attacker (bench/web/class_load.py, issue 30).
#
# Usage: bash bench/run_benchmarks.sh [--quick]
#   --quick: fewer scenes, dt values, impacts and repeats (a few minutes); every output goes
#            to $BUILD_DIR/bench_quick/ instead of docs/.
# Environment: BUILD_DIR (default: build_bench next to this repository's sources).
# Needs: libgmp-dev; optional engines libbullet-dev, libode-dev, libbox2d-dev; python3-matplotlib.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$repo/build_bench}"
# catkin's CMake needs Debian's python3 (with catkin_pkg), not a pyenv one earlier on PATH.
export PATH="/usr/bin:$PATH"
quick=""
[[ "${1:-}" == "--quick" ]] && quick="--quick"
# The plots need matplotlib: without it the first benchmark fails after minutes of work.
if ! python3 -c 'import matplotlib' 2>/dev/null; then
  echo "run_benchmarks.sh: python3-matplotlib is missing; install the benchmark packages with" >&2
  echo "  bash scripts/setup_debian.sh --with-bench" >&2
  exit 2
fi

# Every output names the source it measured: the commit, marked when the core has local changes.
COLLISION_LAB_BENCH_SOURCE="$(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown)"
if ! git -C "$repo" diff --quiet HEAD -- src include 2>/dev/null; then
  COLLISION_LAB_BENCH_SOURCE+=" with local changes"
fi
export COLLISION_LAB_BENCH_SOURCE

cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target collision_lab_bench_core collision_lab_bench_nbody collision_lab_speed_vs_error \
  collision_lab_hard_cases collision_lab_bench_restitution collision_lab_bench_gas collision_lab_cli collision_lab_node collision_lab_relay_node \
  collision_lab_node_throughput collision_lab_recording_bench collision_lab_web
bin="$build/devel/lib/collision_lab"

if [[ -n "$quick" ]]; then out="$build/bench_quick"; else out="$repo/docs"; fi
mkdir -p "$out"
log="$build/benchmarks.log"
: > "$log"

# step TITLE COMMAND...: runs one benchmark; its output goes to the terminal and to the log.
step() {
  local title="$1"
  shift
  printf '\n=== %s (%s)\n' "$title" "$(date +%H:%M:%S)" | tee -a "$log"
  "$@" 2>&1 | tee -a "$log"
}

restitution_repeats=()
[[ -n "$quick" ]] && restitution_repeats=(--repeats 1)
step "speed against error" "$bin/collision_lab_speed_vs_error" $quick --csv "$out/speed_vs_error.csv" \
  --md "$out/speed_vs_error.md" --plot "$out/speed_vs_error.png"
step "hard cases" "$bin/collision_lab_hard_cases" $quick --md "$out/hard_cases.md"
step "restitution: impacts against e" "$bin/collision_lab_bench_restitution" "${restitution_repeats[@]}" \
  --csv "$out/restitution_count.csv"
python3 "$repo/bench/plot_restitution_count.py" --csv "$out/restitution_count.csv" --out "$out/restitution_count.png"
step "core speed" "$bin/collision_lab_bench_core" $quick
step "N-body engine speed and memory" "$bin/collision_lab_bench_nbody" $quick
step "granular gases: worst case, impacts, time and stop reason" "$bin/collision_lab_bench_gas" $quick
step "CSV and JSON output against dd" env BUILD_DIR="$build" bash "$repo/bench/bench_output.sh" $quick

# The node against its anchors: a master of its own on a free port, bags in a temporary
# directory that is removed afterwards.
set +u
source "$build/devel/setup.bash"
set -u
bags="$(mktemp -d)"
trap 'rm -rf "$bags"' EXIT
port=$((11700 + RANDOM % 200))
node_runs=(runs:=3000 rounds:=7)
[[ -n "$quick" ]] && node_runs=(runs:=1000 rounds:=3)
step "node throughput against a relay publishing the same messages" \
  roslaunch -p "$port" "$repo/bench/node/node_throughput.launch" "${node_runs[@]}" bag_directory:="$bags/throughput"
step "recording a long run against rosbag record" \
  roslaunch -p "$port" "$repo/bench/node/recording_vs_rosbag.launch" bag_directory:="$bags/recording"
# A class of thirty (lab.launch web:=true, started by the script on free ports with a class code
# and a bag folder of its own): small scenes' time to final, runs lost, memory per run. A long
# class phase, so that memory per run is read in the steady state (docs/benchmarks.md).
class_load=(--runs 180 --max-seconds 900)
[[ -n "$quick" ]] && class_load=(--warmup-runs 3 --runs 15 --gases 2 --huge 2 --slow 40 --wrong-codes 100)
step "a class of thirty with big jobs and an attacker (issue 30)" \
  python3 "$repo/bench/web/class_load.py" "${class_load[@]}"

python3 "$repo/bench/goals_table.py" --log "$log" --source "$COLLISION_LAB_BENCH_SOURCE" --out "$out/benchmark_goals.md"
printf '\n=== Goals (issue 13), each with its anchor from this run\n'
grep '^goal:' "$log" | sed 's/^goal: /  /'
echo "outputs in $out; the whole log in $log" >&2
