#!/usr/bin/env bash
# Regenerates every benchmark output in docs/ with one command:
#   docs/speed_vs_error.csv, docs/speed_vs_error.md, docs/speed_vs_error.png  (collision_lab_speed_vs_error)
#   docs/hard_cases.md                                                        (collision_lab_hard_cases)
#   docs/restitution_count.csv, docs/restitution_count.png                   (collision_lab_bench_restitution,
#                                                                              bench/plot_restitution_count.py)
# and prints the core speed benchmark (collision_lab_bench_core).
#
# Usage: bash bench/run_benchmarks.sh [--quick]
#   --quick: fewer scenes, dt values and repeats (each program under a minute, except the
#            restitution sweep: one repeat, but its exact run at e = r_c + 1e-6 alone takes
#            about 2 minutes); outputs go to $BUILD_DIR/bench_quick/ instead of docs/.
# Environment: BUILD_DIR (default: build_bench next to this repository's sources).
# Needs: libgmp-dev; optional engines libbullet-dev, libode-dev, libbox2d-dev; python3-matplotlib.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$repo/build_bench}"
# catkin's CMake needs Debian's python3 (with catkin_pkg), not a pyenv one earlier on PATH.
export PATH="/usr/bin:$PATH"

# Every output names the source it measured: the commit, marked when the core has local changes.
COLLISION_LAB_BENCH_SOURCE="$(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown)"
if ! git -C "$repo" diff --quiet HEAD -- src/core include/collision_lab/core 2>/dev/null; then
  COLLISION_LAB_BENCH_SOURCE+=" with local changes in the core"
fi
export COLLISION_LAB_BENCH_SOURCE

cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j2 --target collision_lab_bench_core collision_lab_speed_vs_error collision_lab_hard_cases \
  collision_lab_bench_restitution
bin="$build/devel/lib/collision_lab"

if [[ "${1:-}" == "--quick" ]]; then
  out="$build/bench_quick"
  mkdir -p "$out"
  "$bin/collision_lab_speed_vs_error" --quick --csv "$out/speed_vs_error.csv" --md "$out/speed_vs_error.md" \
    --plot "$out/speed_vs_error.png" >/dev/null
  "$bin/collision_lab_hard_cases" --quick --md "$out/hard_cases.md" >/dev/null
  "$bin/collision_lab_bench_restitution" --repeats 1 --csv "$out/restitution_count.csv" >/dev/null
  python3 "$repo/bench/plot_restitution_count.py" --csv "$out/restitution_count.csv" --out "$out/restitution_count.png"
  "$bin/collision_lab_bench_core" --quick
  echo "quick outputs in $out" >&2
else
  "$bin/collision_lab_speed_vs_error" >/dev/null
  "$bin/collision_lab_hard_cases" >/dev/null
  "$bin/collision_lab_bench_restitution" >/dev/null
  python3 "$repo/bench/plot_restitution_count.py" --csv "$repo/docs/restitution_count.csv" \
    --out "$repo/docs/restitution_count.png"
  "$bin/collision_lab_bench_core"
  echo "regenerated $repo/docs/speed_vs_error.{csv,md,png}, $repo/docs/hard_cases.md and" \
    "$repo/docs/restitution_count.{csv,png}" >&2
fi
