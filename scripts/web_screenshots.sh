#!/usr/bin/env bash
# Refreshes the class pages' screenshots in docs/screenshots (docs/web.md): the start page,
# a live run (the 1,000-body gas while it runs), the finished 31,415-impact pi run, the
# finished gas and the teacher page. Starts lab.launch web:=true on a master of its own
# (bags in a temporary folder) and shoots with headless chromium.
# Usage (after setup_debian.sh --with-screenshots): bash scripts/web_screenshots.sh [--views]
# (--views: only the run page of each scene kind, web_view_*.png, and the teacher page with
# rejections, web_teacher_rejections.png)
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
  send_body "{\"student\":\"$1\",\"preset\":\"$2\"}"
}
send_body() {  # JSON body of POST /api/runs -> run_id
  local answer
  # Every send counts towards the web node's runs per address a minute: retry slowly.
  for _ in $(seq 60); do
    answer=$(curl -s -X POST -H "Content-Type: application/json" -d "$1" "$url/api/runs" || true)
    case "$answer" in *run_id*) echo "$answer" | sed -E 's/.*"run_id":"([^"]*)".*/\1/'; return ;; esac
    sleep 1
  done
  echo "web_screenshots.sh: no answer to $1: $answer" >&2; exit 1
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

# The run page of each scene kind (issue 31; docs/web.md "What the run page shows"). Only
# these with --views.
shoot_views() {
  local run
  run=$(send_body '{"student":"eve","masses":[100,1,"inf"],"positions":[2,1,0],"velocities":[-1,0,0],"max_collisions":10}')
  wait_finished "$run"; shoot "/runs/$run" web_view_not_simulated.png 1250
  run=$(send eve collapse_equal); wait_finished "$run"; shoot "/runs/$run" web_view_collapse.png 1250
  run=$(send eve near_collapse); wait_finished "$run"; shoot "/runs/$run" web_view_near_collapse.png 1250
  # collapse_equal a billion times smaller: the view's small numbers in the page's style (×10⁻⁹).
  run=$(send_body '{"student":"eve","masses":[1,1,1],"positions":[2e-9,1e-9,0],"velocities":[-1,0,0],"restitution":0.05}')
  wait_finished "$run"; shoot "/runs/$run" web_view_small_numbers.png 1250
  run=$(send eve two_carts); wait_finished "$run"; shoot "/runs/$run" web_view_two_carts.png 1250
  # The state after the last collision: each plot goes on one past it (the heat of an
  # inelastic pair, equal_masses' A at +1 m/s), and a run without collisions.
  run=$(send_body '{"student":"eve","masses":[2,1],"positions":[1,0],"velocities":[-1,1],"restitution":[0.5]}')
  wait_finished "$run"; shoot "/runs/$run" web_view_two_body_inelastic.png 1250
  run=$(send eve equal_masses); wait_finished "$run"; shoot "/runs/$run" web_view_equal_masses.png 1250
  run=$(send eve no_collision); wait_finished "$run"; shoot "/runs/$run" web_view_no_collision.png 1250
  run=$(send eve moving_wall); wait_finished "$run"; shoot "/runs/$run" web_view_moving_wall.png 1400
  # A value the run could not certify is named in the summary table (cluster_collapse_5's final time).
  run=$(send eve cluster_collapse_5); wait_finished "$run"; shoot "/runs/$run" web_view_uncertified.png 1400
  run=$(send_body '{"student":"eve","preset":"granular_ring","max_collisions":5000}')
  wait_finished "$run"; shoot "/runs/$run" web_view_ring.png 1250
  run=$(send_body '{"student":"eve","preset":"granular_box_1000","max_collisions":5000}')
  wait_finished "$run"; shoot "/runs/$run" web_view_box_truncated.png 1250  # the box stops at the lab's cap
  # The teacher page with rejections: the lab node's (a numbered send: no run_id asked for)
  # and the web node's own (400 with a typed run_id, 415, 413).
  curl -s -o /dev/null -X POST -H "Content-Type: application/json" \
    -d '{"student":"ben","masses":[1,1],"positions":[0,1],"velocities":[0,0]}' "$url/api/runs"
  curl -s -o /dev/null -X POST -H "Content-Type: application/json" \
    -d '{"student":"ben","run_id":"mine","masses":[1,"heavy"],"positions":[1,0],"velocities":[0,0]}' "$url/api/runs"
  curl -s -o /dev/null -X POST -d '{"student":"ben","preset":"pi_digits_2"}' "$url/api/runs"
  head -c 2000000 /dev/zero | tr '\0' ' ' | curl -s -o /dev/null -X POST -H "Content-Type: application/json" \
    --data-binary @- "$url/api/runs"
  sleep 1
  shoot /teacher web_teacher_rejections.png 1400
}
if [ "${1:-}" = --views ]; then shoot_views; exit 0; fi

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
