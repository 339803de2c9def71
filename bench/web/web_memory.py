#!/usr/bin/env python3
"""Resident memory per run of the class's web node after warm-up (docs/web.md, "Memory and
restarts"; a measurement, not a test).

Starts its own master (a free port) with web_memory.launch: a lab node recording into a fresh
folder and a web node with a small ~memory_budget_bytes, so that the warm-up fills the budget. Sends WARMUP small
runs (the pi scene, 31 impacts) as students do (POST /api/runs), waits until the web node has every one finished,
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
import urllib.error
import urllib.request
import xmlrpc.client


def free_ports(count):
    """count distinct free TCP ports."""
    sockets = [socket.socket() for _ in range(count)]
    for s in sockets:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in sockets]
    for s in sockets:
        s.close()
    return ports


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

    master_port, web_port = free_ports(2)
    env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{master_port}", ROS_HOME=tempfile.mkdtemp())
    os.environ.update(env)
    bags = tempfile.mkdtemp(prefix="web_memory_bags_")
    procs = []
    log = tempfile.NamedTemporaryFile("w", prefix="web_memory_nodes_", suffix=".log", delete=False)
    try:
        here = os.path.dirname(os.path.abspath(__file__))
        procs.append(subprocess.Popen(
            ["roslaunch", "-p", str(master_port), os.path.join(here, "web_memory.launch"), f"bags:={bags}",
             f"port:={web_port}", f"budget:={args.budget}"], env=env, stdout=log, stderr=log))
        import rosgraph
        deadline = time.time() + 60
        while not rosgraph.Master("/web_memory_bench").is_online():
            if time.time() > deadline or procs[0].poll() is not None:
                sys.exit(f"no master on port {master_port} (see {log.name})")
            time.sleep(0.5)

        
        web_name = "/collision_lab/collision_lab_web"
        deadline = time.time() + 60
        while True:
            try:
                web_pid = xmlrpc.client.ServerProxy(rosgraph.Master("/web_memory_bench").lookupNode(web_name)).getPid("/b")[2]
                get_json(f"http://127.0.0.1:{web_port}/api/runs")
                break
            except Exception as e:
                if time.time() > deadline:
                    sys.exit(f"the web node did not start ({e}; see {log.name})")
                time.sleep(0.5)

        base = f"http://127.0.0.1:{web_port}"

        def send(first, count):
            """POSTs the runs as students do (one at a time), then waits until the last is finished."""
            for k in range(first, first + count):
                body = {"student": f"s{k % 30}", "run_id": f"m{k}", "masses": [100, 1, "inf"],
                        "positions": [2, 1, 0], "velocities": [-1, 0, 0]}
                req = urllib.request.Request(f"{base}/api/runs", data=json.dumps(body).encode(),
                                             headers={"Content-Type": "application/json"}, method="POST")
                for attempt in range(120):  # 503 until the lab node listens (its start)
                    try:
                        with urllib.request.urlopen(req, timeout=60) as r:
                            ids.append(json.loads(r.read())["run_id"])
                        break
                    except urllib.error.HTTPError as e:
                        if e.code != 503 or attempt == 119:
                            raise
                        time.sleep(0.5)
                if k % 250 == 0:
                    print(f"sent {k + 1}", flush=True)
            end = time.time() + 300
            while time.time() < end:
                try:
                    if get_json(f"{base}/api/runs/{ids[-1]}").get("state") == "finished":
                        return
                except Exception:
                    pass
                time.sleep(0.2)
            sys.exit("the web node did not finish " + ids[-1])

        ids = []
        start_rss = rss_kib(web_pid)
        send(0, args.warmup)
        time.sleep(3)
        warm_rss = rss_kib(web_pid)
        t0 = time.time()
        send(args.warmup, args.runs)
        time.sleep(3)
        end_rss = rss_kib(web_pid)
        elapsed = time.time() - t0
        # Old runs read back from their bags (evicted under the budget).
        for run_id in ids[:args.warmup:max(1, args.warmup // 20)]:
            run = get_json(f"{base}/api/runs/{run_id}")
            if run.get("state") != "finished" or run.get("collisions") != 31:
                sys.exit(f"{run_id} read back wrong: {run.get('state')}, {run.get('collisions')} collisions")
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
