#!/usr/bin/env python3
"""Refreshes the rviz screenshots of docs/screenshots (listed in its README): the hint before
the first run, one run of each scene kind at its end, the rejection banner and a replay after
rosbag play is done. Starts lab.launch (rviz off, bags in a temporary folder) on a master of
its own, rviz with rviz/collision_lab.rviz on an Xvfb display, sends the scenes through the
node's run_preset and run_scene services, and grabs the screen while the animation holds a
run's last frame. Needs rviz, xvfb and imagemagick (setup_debian.sh --with-screenshots).

Usage, after `source build_ros/devel/setup.bash`:
  python3 scripts/rviz_screenshots.py [shot ...]      (no shot: all of them but box_to_cap)
  python3 scripts/rviz_screenshots.py --simulate-to-cap box_to_cap
(the node's ~simulate_to_cap, so that the box goes on to its cap of 100,000 impacts).
KEEP_TMP=1 keeps the temporary folder (the processes' logs, the last raw grab) and prints it.
"""
import math
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "docs", "screenshots")
NODE = "/collision_lab/collision_lab_node/"
# The node's animation (node_constants.h): an auto-timed loop of kAutoLoopDuration
# (1 + log10(1 + n) / 6) wall s for n collisions, then kMarkerEndHold s on the last frame.
AUTO_LOOP = 8.0
END_HOLD = 2.5
# rviz's 3D view in its 1280 x 800 window (docks hidden), as the README's shots are cropped.
CROP = "1248x708+16+62"

processes = []


def start(args, log, env=None):
    process = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, env=env, start_new_session=True)
    processes.append(process)
    return process


def stop_all():
    for process in reversed(processes):
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGINT)
    for process in reversed(processes):
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


def grab(display, name):
    """Grabs the screen, crops it to the 3D view, reduces it to 255 colours."""
    raw = os.path.join(tmp, "raw.png")
    subprocess.run(["import", "-display", display, "-window", "root", raw], check=True)
    subprocess.run(["convert", raw, "-crop", CROP, "+repage", "-colors", "255", os.path.join(OUT, name)], check=True)
    print("wrote docs/screenshots/" + name, flush=True)


def loop_seconds(collisions):
    return AUTO_LOOP * (1.0 + math.log10(1.0 + collisions) / 6.0)


def view_collisions(summary):
    """The collisions the view animates: none of a run that was not simulated."""
    return summary.collision_count if summary.simulated else 0


def shoot_end(display, name, sent, finished, collisions):
    """Waits for a hold of the last frame that begins after the run finished, and grabs it
    1 s into the hold. The loop starts when the view gets the run's input (about `sent`)."""
    loop = loop_seconds(collisions)
    period = loop + END_HOLD
    k = 0
    while sent + k * period + loop < finished + 1.5:
        k += 1
    time.sleep(max(sent + k * period + loop + 1.0 - time.time(), 0.0))
    grab(display, name)


def main():
    global tmp
    import rospy  # noqa: E402 (after the environment is set)
    from collision_lab.srv import RunPreset, RunScene

    to_cap = "--simulate-to-cap" in sys.argv[1:]
    wanted = set(sys.argv[1:]) - {"--simulate-to-cap"}
    shots = ["hint", "not_simulated", "pi", "pi_long", "walls", "box", "collapse", "cluster", "ring", "gas", "granular_gas",
             "rejected", "replay"]
    if to_cap:
        shots = ["box_to_cap"]
    if wanted - set(shots):
        sys.exit("rviz_screenshots.py: unknown shots %s; known: %s" % (sorted(wanted - set(shots)), shots))
    shots = [s for s in shots if not wanted or s in wanted]

    port = 20000 + random.randrange(10000)
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_HOME=tmp)
    os.environ.update(env)
    display = ":%d" % (100 + random.randrange(100))
    log = open(os.path.join(tmp, "processes.log"), "w")
    start(["Xvfb", display, "-screen", "0", "1280x800x24"], log)
    start(["roslaunch", "-p", str(port), "collision_lab", "lab.launch", "rviz:=false", "record:=true",
           "simulate_to_cap:=" + ("true" if to_cap else "false"), "bag_directory:=" + os.path.join(tmp, "bags")],
          log, env)
    time.sleep(3)
    start(["rviz", "-d", os.path.join(ROOT, "rviz", "collision_lab.rviz")], log, dict(env, DISPLAY=display))
    rospy.init_node("rviz_screenshots", anonymous=True, disable_signals=True)
    rospy.wait_for_service(NODE + "run_preset", timeout=60)
    run_preset = rospy.ServiceProxy(NODE + "run_preset", RunPreset)
    run_scene = rospy.ServiceProxy(NODE + "run_scene", RunScene)
    time.sleep(15)  # rviz up, the latched hint received

    def preset(name, file, **fields):
        sent = time.time()
        answer = run_preset(name=name, **fields)
        if not answer.ok:
            sys.exit("rviz_screenshots.py: %s: %s" % (name, answer.message))
        shoot_end(display, file, sent, time.time(), view_collisions(answer.summary))
        return answer

    def scene(file, **fields):
        sent = time.time()
        answer = run_scene(**fields)
        if not answer.ok:
            sys.exit("rviz_screenshots.py: %s: %s" % (file, answer.message))
        shoot_end(display, file, sent, time.time(), view_collisions(answer.summary))
        return answer

    inf = float("inf")
    for shot in shots:
        if shot == "hint":
            grab(display, "before_first_run_hint.png")
        elif shot == "not_simulated":
            # The pi scene with a cap of 10: 31 predicted, over the cap, so not simulated.
            scene("kind_not_simulated_pi_cap_10.png", run_id="pi_cap_10", masses=[100, 1, inf],
                  positions=[2, 1, 0], velocities=[-1, 0, 0], max_collisions=10)
        elif shot == "pi":
            preset("pi_digits_2", "collisions_31_pi_digits_2.png")
        elif shot == "pi_long":
            preset("pi_digits_5", "collisions_31415_pi_digits_5_end.png")
        elif shot == "walls":
            # Infinitely many predicted: cut at the node's cap of 1,000 impacts, one period drawn.
            preset("ball_between_walls", "nbody_ball_between_walls_end.png")
        elif shot == "box":
            # Two walls: without simulate_to_cap the node stops after the first 1,000 impacts.
            preset("granular_box_1000", "granular_box_1000_cap_1000_end.png")
        elif shot == "box_to_cap":
            preset("granular_box_1000", "granular_box_1000_end.png")
        elif shot == "collapse":
            preset("collapse_equal", "nbody_collapse_equal_end.png")
        elif shot == "cluster":
            preset("cluster_collapse_5", "cluster_collapse_5_end.png")
        elif shot == "ring":
            preset("granular_ring", "granular_ring_end.png")
        elif shot == "gas":
            preset("gas_1000", "nbody_gas_1000_end.png")
        elif shot == "granular_gas":
            # A free granular gas: 100 bodies of 1 and 2 kg, 1 m apart, seeded velocities in
            # [-1, 1] m/s, e = 0.9, no walls: T(t) and Haff's fit until it stops colliding.
            rng = random.Random(31)
            scene("granular_gas_100_end.png", run_id="granular_gas_100", masses=[1 + i % 2 for i in range(100)],
                  positions=[99.0 - i for i in range(100)], velocities=[rng.uniform(-1, 1) for _ in range(100)],
                  restitution=[0.9], max_collisions=100000)
        elif shot == "rejected":
            answer = run_scene(run_id="seven", student="ben", masses=[4, 1, 4, 1, 4, 1, 4],
                               positions=[0, 1, 2, 3, 4, 5, 6], velocities=[-1, 0, 0, 0, 0, 0, 1])
            if answer.ok:
                sys.exit("rviz_screenshots.py: the unordered input was served")
            time.sleep(3)
            grab(display, "rejected_input_banner.png")
        elif shot == "replay":
            # Seven bodies (README: nbody_seven_replay_done.png), recorded, then replayed at
            # half speed by replay.launch without the lab node; shot after rosbag play is done.
            answer = run_scene(run_id="seven", masses=[4, 1, 4, 1, 4, 1, 4], positions=[6, 5, 4, 3, 2, 1, 0],
                               velocities=[-1, 0, 0, 0, 0, 0, 1])
            if not answer.ok:
                sys.exit("rviz_screenshots.py: seven: " + answer.message)
            bag = answer.summary.run_id
            # The lab (and its master) and rviz end; a master of the replay's own, and the
            # replay's rviz (an rviz does not register again with a new master).
            for process in (processes[2], processes[1]):
                os.killpg(process.pid, signal.SIGINT)
                process.wait(timeout=30)
            start(["roscore", "-p", str(port)], log, env)
            time.sleep(5)
            replay_log = open(os.path.join(tmp, "replay.log"), "w")
            start(["roslaunch", "collision_lab", "replay.launch", "bag:=" + bag, "rate:=0.5",
                   "bag_directory:=" + os.path.join(tmp, "bags")], replay_log, dict(env, DISPLAY=display))
            deadline = time.time() + 120
            while time.time() < deadline and "Done." not in open(os.path.join(tmp, "replay.log")).read():
                time.sleep(0.5)
            # The replay goes on to the run's end (1.25 x the last impact) and holds it.
            time.sleep(15)
            grab(display, "nbody_seven_replay_done.png")


if __name__ == "__main__":
    tmp = tempfile.mkdtemp()
    try:
        main()
    finally:
        stop_all()
        if os.environ.get("KEEP_TMP"):
            print("logs in " + tmp)
        else:
            shutil.rmtree(tmp, ignore_errors=True)
