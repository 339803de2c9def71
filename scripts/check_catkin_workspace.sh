#!/usr/bin/env bash
# Checks the usual ROS way on this machine: a fresh catkin workspace with this checkout in
# src/, built with catkin_make (or `catkin build` with --catkin-tools), then rosrun and
# roslaunch find the package, and python3 imports collision_lab. Run after bash scripts/setup_debian.sh. The workspace is a
# temporary folder, removed at the end.
# Usage: bash scripts/check_catkin_workspace.sh [--catkin-tools]
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$PWD
tool=catkin_make
[ "${1:-}" = "--catkin-tools" ] && tool="catkin build"

ws=$(mktemp -d /tmp/collision_lab_ws.XXXXXX)
trap 'rm -rf "$ws"' EXIT
mkdir -p "$ws/src"
ln -s "$repo" "$ws/src/collision_lab"
echo "== $tool in $ws (log in $ws/build.log)"
(
  cd "$ws"
  if [ "$tool" = catkin_make ]; then
    catkin_make -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 -j"$(nproc)"
  else
    catkin init && catkin config --cmake-args -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3
    catkin build --no-status -j"$(nproc)"
  fi
) > "$ws/build.log" 2>&1 || { tail -n 60 "$ws/build.log"; echo "check_catkin_workspace.sh: $tool failed" >&2; exit 1; }

set +u
# A clean environment: only the new workspace's devel space (and /usr underneath).
unset ROS_PACKAGE_PATH CMAKE_PREFIX_PATH
source "$ws/devel/setup.bash"
set -u
found=$(rospack find collision_lab)
[ "$found" = "$ws/src/collision_lab" ] || { echo "rospack finds $found, not the workspace's copy" >&2; exit 1; }
out=$(rosrun collision_lab collision_lab_cli --masses 100,1,inf --positions 2,1,0 --velocities -1,0,0 \
  --mode predict --format json)
echo "$out" | grep -Eq '"collision_count": ?31[,}]' || { echo "rosrun collision_lab_cli gave: $out" >&2; exit 1; }
roslaunch --files collision_lab demo.launch > /dev/null
# The Python module from the devel space, beside its generated messages (issue 33's command).
done_when="import collision_lab as c; print(c.run([100, 1, float('inf')], [2, 1, 0], [-1, 0, 0]).summary['collision_count'])"
count=$(cd / && python3 -c "$done_when")
[ "$count" = 31 ] || { echo "import collision_lab (devel space) gave: $count" >&2; exit 1; }
(cd / && python3 -c "import collision_lab.msg, collision_lab.srv")

# The install space: every program, and an installed CLI that reads the installed presets
# (a preset added to the installed copy only), not the source tree's.
echo "== $tool install into $ws/install"
(
  cd "$ws"
  if [ "$tool" = catkin_make ]; then
    catkin_make install -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 -j"$(nproc)"
  else
    catkin config --install && catkin build --no-status -j"$(nproc)"
  fi
) >> "$ws/build.log" 2>&1 || { tail -n 60 "$ws/build.log"; echo "check_catkin_workspace.sh: $tool install failed" >&2; exit 1; }
installed=$ws/install
for program in collision_lab_cli collision_lab_node collision_lab_markers scenario_publisher bag_to_csv \
               play_run sim_time_guard; do
  [ -x "$installed/lib/collision_lab/$program" ] || { echo "not installed: lib/collision_lab/$program" >&2; exit 1; }
done
for file in config/scenarios.yaml launch/replay.launch rviz/collision_lab.rviz LICENSE package.xml; do
  [ -f "$installed/share/collision_lab/$file" ] || { echo "not installed: share/collision_lab/$file" >&2; exit 1; }
done
# The Python module from the install space alone (a clean environment): run, messages, the sweep tool.
[ -x "$installed/lib/collision_lab/collision_lab_sweep" ] || { echo "not installed: lib/collision_lab/collision_lab_sweep" >&2; exit 1; }
where=$(cd / && env -i HOME="$HOME" PATH=/usr/bin:/bin bash -c "source '$installed/setup.bash' && python3 -c \"import collision_lab, collision_lab.msg; print(collision_lab._core.__file__)\"")
case "$where" in "$installed"/*) ;; *) echo "import collision_lab (install space) found $where" >&2; exit 1 ;; esac
count=$(cd / && env -i HOME="$HOME" PATH=/usr/bin:/bin bash -c "source '$installed/setup.bash' && python3 -c \"$done_when\"")
[ "$count" = 31 ] || { echo "import collision_lab (install space) gave: $count" >&2; exit 1; }
printf 'installed_only:\n  description: "only in the install"\n  masses: [1, 1, 1]\n  positions: [2, 1, -1]\n  velocities: [-1, 0, 1]\n' \
  >> "$installed/share/collision_lab/config/scenarios.yaml"
listed=$("$installed/lib/collision_lab/collision_lab_cli" --list --format csv)
echo "$listed" | grep -q '^installed_only,' || { echo "the installed CLI did not read the installed presets: $listed" >&2; exit 1; }
echo "check_catkin_workspace.sh: $tool workspace OK (rospack, rosrun collision_lab_cli: 31 collisions, roslaunch finds demo.launch; import collision_lab: 31, devel and install space; install space complete, its CLI reads its presets)"
