#!/usr/bin/env bash
# Refreshes the class pages' screenshots in docs/screenshots (docs/web.md): the start page,
# a live run (the 1,000-body gas while it runs), the finished 31,415-impact pi run, the
# finished gas and the teacher page. Starts lab.launch web:=true on a master of its own
# (bags in a temporary folder) and shoots with headless chromium.
# Usage (after setup_debian.sh --with-screenshots): bash scripts/web_screenshots.sh
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH=/usr/bin:/bin:$PATH
set +u; source build_ros/devel/setup.bash; set -u
command -v chromium > /dev/null || { echo "web_screenshots.sh: chromium is not installed" >&2; exit 1; }
tmp=$(mktemp -d)
master_port=$((20000 + RANDOM % 10000))
web_port=$((30000 + RANDOM % 10000))
export ROS_MASTER_URI=http://127.0.0.1:$master_port ROS_HOME=$tmp
roslaunch -p "$master_port" collision_lab lab.launch web:=true rviz:=false web_port:="$web_port" \
  bag_directory:="$tmp/bags" > "$tmp/launch.log" 2>&1 &
launch_pid=$!
trap 'kill $launch_pid 2>/dev/null; wait $launch_pid 2>/dev/null; rm -rf "$tmp"' EXIT
url=http://127.0.0.1:$web_port
out=docs/screenshots

send() {  # student preset -> run_id (retries until the lab node listens)
  local answer
  for _ in $(seq 100); do
    answer=$(curl -s -X POST -H "Content-Type: application/json" -d "{\"student\":\"$1\",\"preset\":\"$2\"}" "$url/api/runs" || true)
    case "$answer" in *run_id*) echo "$answer" | sed -E 's/.*"run_id":"([^"]*)".*/\1/'; return ;; esac
    sleep 0.2
  done
  echo "web_screenshots.sh: no answer to $1's $2: $answer" >&2; exit 1
}
wait_finished() {
  until curl -s "$url/api/runs/$1" | grep -q '"state":"finished"'; do sleep 0.5; done
}
shoot() {  # page file height
  chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$tmp/profile" \
    --window-size=1280,"$3" --virtual-time-budget=8000 --screenshot="$out/$2" "$url$1" 2>/dev/null
  echo "wrote $out/$2"
}
# A live page keeps its event stream open, and headless chromium's virtual time waits for
# the network to settle: a live page is shot from a real window on a virtual display.
shoot_live() {  # page file
  local display=:$((90 + RANDOM % 100))
  Xvfb "$display" -screen 0 1280x1250x24 > /dev/null 2>&1 &
  local xvfb=$!
  sleep 1
  DISPLAY=$display chromium --no-sandbox --disable-gpu --user-data-dir="$tmp/live" --no-first-run \
    --window-position=0,0 --window-size=1280,1250 --kiosk "$url$1" > /dev/null 2>&1 &
  local browser=$!
  sleep 5
  DISPLAY=$display import -window root "$out/$2"
  kill "$browser" "$xvfb"
  wait "$browser" "$xvfb" 2>/dev/null || true
  echo "wrote $out/$2"
}

pi=$(send ana pi_digits_5)
wait_finished "$pi"
gas=$(send bob gas_1000)
sleep 1
shoot_live "/runs/$gas" web_run_live_gas_1000.png
wait_finished "$gas"
shoot "/runs/$pi" web_run_31415_pi_digits_5.png 1250
shoot "/runs/$gas" web_run_gas_1000.png 1250
for preset in two_carts_inelastic cradle_5; do wait_finished "$(send cleo $preset)"; done
wait_finished "$(send dan collapse_equal)"
rosservice call /collision_lab/collision_lab_node/run_preset "{name: pi_digits_2, student: ros_user}" > /dev/null
shoot / web_start_page.png 1400
shoot /teacher web_teacher_page.png 1000
