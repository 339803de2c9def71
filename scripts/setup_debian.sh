#!/usr/bin/env bash
# Installs what collision_lab needs on Debian 12 (as root) and builds it into ./build_ros, a
# standalone catkin devel space. Afterwards `source build_ros/devel/setup.bash` makes rosrun,
# roslaunch, rostest and rosservice find the package and every executable. (rosrun skips
# every path under <package>/build/, so the folder must not be called build.)
# Idempotent: apt-get runs only when a package is missing; the build is incremental.
# Usage: bash scripts/setup_debian.sh [--no-build] [--with-screenshots] [--with-bench]
#   --no-build: install the packages only (for a catkin workspace of your own).
#   --with-screenshots: xvfb, imagemagick and chromium (rviz screenshots, the browser tests).
set -euo pipefail
cd "$(dirname "$0")/.."

# catkin's CMake needs Debian's python3 (with catkin_pkg), not a pyenv one earlier on PATH.
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH

# Every command that the README, the launch files and the tests use, on a bare machine:
# rostest (python3-rostest) and rosrun (rosbash) are not part of ros-core-dev; rostopic
# needs the Python messages of other packages to echo /diagnostics and the markers, and
# rosservice those of std_srvs to pause a replay (/rosbag_play/pause_playback); rviz is
# opened by the launch files whenever a display is set. The class's web server
# (docs/web.md) is on Boost.Beast (libboost-dev), its tests' client is cpp-httplib, and it
# serves Debian's Chart.js; docs/web.md's commands (run as written by a test) use curl;
# its browser tests and screenshots need chromium (--with-screenshots, as CI).
# The Python module (docs/python.md): pybind11, numpy, pandas, Dask's distributed, pytest;
# the notebooks: matplotlib, nbclient, nbformat, ipykernel.
packages=(
  build-essential cmake libgtest-dev
  ros-core-dev rosout rosbash python3-rostest
  python3-rostopic python3-roslaunch python3-rosbag python3-rosmaster python3-rosmsg
  python3-rosnode python3-rosservice python3-rosparam
  python3-std-srvs
  libeigen3-dev libboost-dev libgmp-dev libvisualization-msgs-dev libdiagnostic-msgs-dev
  libdiagnostic-updater-dev
  python3-visualization-msgs python3-diagnostic-msgs
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
  rviz
  libcpp-httplib-dev libjs-chart.js
  libsqlite3-dev
  curl
  pybind11-dev python3-numpy python3-pandas python3-distributed python3-pytest python3-yaml
  python3-matplotlib python3-nbclient python3-nbformat python3-ipykernel
)
build=true
for arg in "$@"; do
  case "$arg" in
    --no-build) build=false ;;
    --with-screenshots) packages+=(xvfb imagemagick chromium) ;;
    --with-bench) packages+=(libbullet-dev libode-dev libbox2d-dev gnuplot python3-matplotlib) ;;
    *) echo "setup_debian.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "== installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

$build || exit 0
echo "== building into ./build_ros (log in build_ros.log)"
{ cmake -S . -B build_ros -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 \
    && cmake --build build_ros -j"$(nproc)"; } > build_ros.log 2>&1 \
  || { tail -n 60 build_ros.log; echo "setup_debian.sh: the build failed; whole log in build_ros.log" >&2; exit 1; }
echo "== built: source build_ros/devel/setup.bash, then rosrun collision_lab collision_lab_cli --help"
