#!/usr/bin/env bash
# Installs what collision_lab needs on Debian 12 (as root) and builds it into ./build.
# Idempotent: apt-get runs only when a package is missing; the build is incremental.
# Usage: scripts/setup_debian.sh [--with-rviz] [--with-bench]
set -euo pipefail
cd "$(dirname "$0")/.."

# catkin's CMake needs Debian's python3 (with catkin_pkg), not a pyenv one earlier on PATH.
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH

packages=(
  build-essential cmake libgtest-dev
  ros-core-dev python3-rostopic python3-roslaunch python3-rosbag python3-rosmaster
  python3-rosmsg python3-rosnode rosout
  libeigen3-dev libboost-dev libgmp-dev libvisualization-msgs-dev libdiagnostic-msgs-dev
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev
)
for arg in "$@"; do
  case "$arg" in
    --with-rviz) packages+=(rviz xvfb imagemagick) ;;
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

echo "== building into ./build"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 > build.configure.log 2>&1 \
  || { cat build.configure.log; exit 1; }
cmake --build build -j"$(nproc)"
