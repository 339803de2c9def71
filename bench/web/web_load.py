#!/usr/bin/env python3
"""Thirty students at once against a running class page (docs/web.md; not a test).

Each simulated student sends RUNS scenes through POST /api/runs and follows each run over
its event stream to the `final` event, then fetches the run. The work is bounded by count
(STUDENTS x RUNS runs), not by time. At the end it reports whether every run was answered,
finished and recorded, the HTTP requests per second, the latencies, and the run page's time
to first plot in headless chromium (when installed) while the class is busy.

Usage: roslaunch collision_lab lab.launch web:=true rviz:=false &
       python3 bench/web/web_load.py [--url http://127.0.0.1:8080] [--students 30] [--runs 5]
The lab's runs_per_minute (default 10) must allow RUNS per student.
"""
import argparse
import json
import re
import shutil
import statistics
import subprocess
import tempfile
import threading
import time
import urllib.error
import urllib.request

# Scenes with counts known from pi's digits and the presets' descriptions.
SCENES = [
    ({"masses": [100, 1, "inf"], "positions": [2, 1, 0], "velocities": [-1, 0, 0]}, 31),
    ({"preset": "two_carts"}, 1),
    ({"preset": "cradle_5"}, 4),
    ({"preset": "pi_digits_3"}, 314),
    ({"preset": "equal_masses"}, 3),
]


class Stats:
    def __init__(self):
        self.lock = threading.Lock()
        self.requests = 0
        self.post_latency = []
        self.final_latency = []  # POST sent -> `final` event received [s]
        self.problems = []
        self.runs = []

    def add(self, **kw):
        with self.lock:
            for k, v in kw.items():
                getattr(self, k).append(v)

    def count(self):
        with self.lock:
            self.requests += 1


def request(stats, url, data=None):
    stats.count()
    req = urllib.request.Request(url, data=None if data is None else json.dumps(data).encode(),
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=120) as res:
            return res.status, res.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def follow(stats, base, run_id):
    """Reads the run's event stream up to its `final` event; returns the final run."""
    stats.count()
    with urllib.request.urlopen(f"{base}/api/runs/{run_id}/stream", timeout=300) as res:
        event = None
        for raw in res:
            line = raw.decode().rstrip("\n")
            if line.startswith("event: "):
                event = line[7:]
            elif line.startswith("data: ") and event == "final":
                return json.loads(line[6:])
    return None


def student(stats, base, k, runs):
    for r in range(runs):
        scene, expected = SCENES[(k + r) % len(SCENES)]
        body = dict(scene, student=f"load{k:02d}")
        t0 = time.monotonic()
        status, answer = request(stats, f"{base}/api/runs", body)
        stats.add(post_latency=time.monotonic() - t0)
        if status != 201:
            stats.add(problems=f"load{k:02d} run {r}: HTTP {status} {answer[:120]!r}")
            continue
        run_id = json.loads(answer)["run_id"]
        run = follow(stats, base, run_id)
        stats.add(final_latency=time.monotonic() - t0)
        if run is None:
            stats.add(problems=f"{run_id}: the stream ended without `final`")
            continue
        status, answer = request(stats, f"{base}/api/runs/{run_id}")
        run = json.loads(answer)
        summary = run.get("summary", {})
        if summary.get("collision_count") != expected or not summary.get("recorded"):
            stats.add(problems=f"{run_id}: {summary.get('collision_count')} collisions "
                               f"(expected {expected}), recorded {summary.get('recorded')}")
        stats.add(runs=run_id)


def first_plot_ms(base, run_id):
    if not shutil.which("chromium"):
        return None
    with tempfile.TemporaryDirectory() as profile:
        dom = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu",
                              f"--user-data-dir={profile}", "--virtual-time-budget=30000",
                              "--dump-dom", f"{base}/runs/{run_id}"],
                             capture_output=True, text=True, timeout=300).stdout
    m = re.search(r'data-first-plot-ms="(\d+)"', dom)
    return int(m.group(1)) if m else None


def pct(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--url", default="http://127.0.0.1:8080")
    ap.add_argument("--students", type=int, default=30)
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    base = args.url.rstrip("/")
    stats = Stats()
    # A finished 31,415-impact run for the page's time to first plot under load.
    status, answer = request(stats, f"{base}/api/runs", {"student": "loadpage", "preset": "pi_digits_5"})
    page_run = json.loads(answer)["run_id"]
    follow(stats, base, page_run)

    t0 = time.monotonic()
    threads = [threading.Thread(target=student, args=(stats, base, k, args.runs)) for k in range(args.students)]
    for t in threads:
        t.start()
    busy_first_plot = first_plot_ms(base, page_run)
    for t in threads:
        t.join()
    wall = time.monotonic() - t0
    idle_first_plot = first_plot_ms(base, page_run)

    wanted = args.students * args.runs
    print(f"students {args.students}, runs each {args.runs}: {len(stats.runs)} of {wanted} runs answered, "
          f"finished with the expected count and recorded")
    for p in stats.problems[:20]:
        print("  problem:", p)
    print(f"wall time {wall:.1f} s; HTTP requests {stats.requests} ({stats.requests / wall:.1f} per second; "
          f"an event stream counts as one)")
    print(f"POST /api/runs latency: median {statistics.median(stats.post_latency) * 1e3:.0f} ms, "
          f"p99 {pct(stats.post_latency, 0.99) * 1e3:.0f} ms")
    print(f"POST to `final` event: median {statistics.median(stats.final_latency) * 1e3:.0f} ms, "
          f"p99 {pct(stats.final_latency, 0.99) * 1e3:.0f} ms")
    print(f"run page time to first plot (31,415-impact run, chromium): under load "
          f"{busy_first_plot} ms, idle {idle_first_plot} ms")
    return 0 if len(stats.runs) == wanted and not stats.problems else 1


if __name__ == "__main__":
    raise SystemExit(main())
