#!/usr/bin/env bash
# The main job: set up, build, and run launch/demo.launch on the shipped presets.
# With a display, rviz opens; without one, every preset runs headless, a table of runs is
# printed, one bag per run is left in the bag directory, and the launch ends by itself.
# Usage: bash scripts/demo.sh [roslaunch args, e.g. scenarios:="pi_digits_3 grazing"]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_debian.sh
if [ -n "${DISPLAY:-}" ]; then rviz=true; else rviz=false; fi
export PATH=/usr/bin:/bin:$PATH
set +u
source build_ros/devel/setup.bash
set -u
# roslaunch exits 0 even when the required publisher fails; its last line says which.
log=$(mktemp /tmp/collision_lab_demo.XXXXXX.log)
roslaunch collision_lab demo.launch rviz:=$rviz "$@" 2>&1 | tee "$log"
if grep -q "demo FAILED" "$log"; then rm -f "$log"; exit 1; fi
rm -f "$log"
