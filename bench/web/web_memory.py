#!/usr/bin/env python3
"""Resident memory per run of the class's web node after warm-up (docs/web.md, "Memory and
restarts"; a measurement, not a test).

Starts its own master (a free port), a lab node recording into a fresh folder and a web node
with a small ~memory_budget_bytes, so that the warm-up fills the budget. Sends WARMUP small
runs (the pi scene, 31 impacts) over ROS, waits until the web node has every one finished,
reads the web node's VmRSS, sends RUNS more, reads it again, then reads a few old runs back
over HTTP (from their bags). Prints the web node's RSS at each step and
(RSS after - RSS after warm-up) / RUNS, the figure the issue asks to stay under 1 KB.

Usage (Debian's python3, the workspace's devel/setup.bash sourced):
  /usr/bin/python3 bench/web/web_memory.py [--warmup 500] [--runs 2000] [--budget 4194304]
"""
import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
import xmlrpc.client


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def rss_kib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS")


def get_json(url, timeout=30.0):
    with urllib.request.urlopen(url, timeout=timeout) as r:
        return json.loads(r.read())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--warmup", type=int, default=500)
    ap.add_argument("--runs", type=int, default=2000)
    ap.add_argument("--budget", type=int, default=4 << 20, help="web node ~memory_budget_bytes [bytes]")
    args = ap.parse_args()

    master_port, web_port = free_port(), free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{master_port}", ROS_HOME=tempfile.mkdtemp())
    os.environ.update(env)
    bags = tempfile.mkdtemp(prefix="web_memory_bags_")
    procs = []
    log = open(os.path.join(bags, "nodes.log"), "w")
    try:
        procs.append(subprocess.Popen(["roscore", "-p", str(master_port)], env=env, stdout=log, stderr=log))
        time.sleep(3)
        procs.append(subprocess.Popen(
            ["rosrun", "collision_lab", "collision_lab_node", "__ns:=/collision_lab", f"_bag_directory:={bags}",
             "_publish_markers:=false", "_log_runs:=false"], env=env, stdout=log, stderr=log))
        procs.append(subprocess.Popen(
            ["rosrun", "collision_lab", "collision_lab_web", "__ns:=/collision_lab", f"_bag_directory:={bags}",
             f"_port:={web_port}", f"_memory_budget_bytes:={args.budget}"], env=env, stdout=log, stderr=log))

        import rosnode
        import rospy
        from collision_lab.msg import InitialConditions, RunSummary

        rospy.init_node("web_memory_bench", anonymous=True, disable_signals=True)
        web_name = "/collision_lab/collision_lab_web"
        deadline = time.time() + 60
        while True:
            try:
                web_pid = xmlrpc.client.ServerProxy(rosnode.get_api_uri(rospy.get_master(), web_name)).getPid("/b")[2]
                get_json(f"http://127.0.0.1:{web_port}/api/runs")
                break
            except Exception:
                if time.time() > deadline:
                    sys.exit("the web node did not start (see " + log.name + ")")
                time.sleep(0.5)

        done = set()
        rospy.Subscriber("/collision_lab/run_summaries", RunSummary, lambda m: done.add(m.run_id), queue_size=10000)
        pub = rospy.Publisher("/collision_lab/initial_conditions", InitialConditions, queue_size=10000)
        while pub.get_num_connections() == 0:
            time.sleep(0.1)
        time.sleep(1)

        def send(first, count):
            for k in range(first, first + count):
                msg = InitialConditions()
                msg.header.stamp = rospy.Time.now()
                msg.run_id = f"mem{k}"
                msg.student = f"s{k % 30}"
                msg.masses, msg.positions, msg.velocities = [100.0, 1.0, float("inf")], [2.0, 1.0, 0.0], [-1.0, 0.0, 0.0]
                pub.publish(msg)
                while len(done) < k - first - 20 + len(before):  # at most 20 runs in flight
                    time.sleep(0.002)
            last = f"mem{first + count - 1}"
            end = time.time() + 300
            while time.time() < end:  # the web node has them all
                try:
                    if get_json(f"http://127.0.0.1:{web_port}/api/runs/{last}").get("state") == "finished":
                        return
                except Exception:
                    pass
                time.sleep(0.2)
            sys.exit("the web node did not finish " + last)

        start_rss = rss_kib(web_pid)
        before = set(done)
        send(0, args.warmup)
        time.sleep(3)
        warm_rss = rss_kib(web_pid)
        before = set(done)
        t0 = time.time()
        send(args.warmup, args.runs)
        time.sleep(3)
        end_rss = rss_kib(web_pid)
        elapsed = time.time() - t0
        # Old runs read back from their bags (evicted under the budget).
        for k in range(0, args.warmup, max(1, args.warmup // 20)):
            run = get_json(f"http://127.0.0.1:{web_port}/api/runs/mem{k}")
            if run.get("state") != "finished" or run.get("collisions") != 31:
                sys.exit(f"mem{k} read back wrong: {run.get('state')}, {run.get('collisions')} collisions")
        listed = len(get_json(f"http://127.0.0.1:{web_port}/api/runs"))
        total = args.warmup + args.runs
        print(f"web node RSS: start {start_rss} KiB, after {args.warmup} warm-up runs {warm_rss} KiB, "
              f"after {args.runs} more {end_rss} KiB (budget {args.budget} bytes; {elapsed:.0f} s)")
        print(f"resident memory per run after warm-up: {(end_rss - warm_rss) * 1024 / args.runs:.0f} bytes")
        print(f"runs listed: {listed} of {total}; old runs read back from their bags: ok")
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
        log.close()
        shutil.rmtree(bags, ignore_errors=True)


if __name__ == "__main__":
    main()
