#!/usr/bin/env python3
"""Thirty students at once against a running class page (docs/web.md; not a test).

Each simulated student sends RUNS scenes through POST /api/runs and follows each run over
its event stream to the `final` event, then fetches the run. The work is bounded by count
(STUDENTS x RUNS runs), not by time. At the end it reports whether every run was answered,
finished and recorded, the HTTP requests per second, the latencies, and the run page's time
to first plot in headless chromium (when installed) while the class is busy.

With --ros (needs Debian's python3 and the workspace's setup.bash sourced) it also checks
that the lab's own ROS side keeps working during the load: a scene is sent over ROS every
second and its summary awaited, and the rate of the `markers` topic (what rviz draws) is
measured before and during the load. With --screenshot PATH it grabs the X display ($DISPLAY,
where the lab's rviz runs) in the middle of the load (ImageMagick's `import`).

Usage: roslaunch collision_lab lab.launch web:=true rviz:=false &
       /usr/bin/python3 bench/web/web_load.py [--url http://127.0.0.1:8080] [--students 30] [--runs 5]
                                              [--ros] [--ns /collision_lab] [--screenshot PATH]
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
        if status != 202:
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


class RosProbe:
    """The lab's ROS side under the class's load: scenes sent over ROS every second, each
    awaited on run_summaries (publish -> summary latency [s]), and the markers topic's rate
    [messages/s] in windows (idle before the load, busy during it)."""

    def __init__(self, ns):
        import rospy
        from collision_lab.msg import AcceptedRun, InitialConditions, RunSummary
        from visualization_msgs.msg import MarkerArray
        self.rospy = rospy
        self.InitialConditions = InitialConditions
        rospy.init_node("web_load_probe", anonymous=True, disable_signals=True)
        self.lock = threading.Lock()
        self.sent = {}       # run_id -> monotonic time sent
        self.summaries = {}  # run_id as served -> (monotonic time received, collision_count)
        self.markers = 0
        self.pub = rospy.Publisher(f"{ns}/initial_conditions", InitialConditions, queue_size=100)
        self.served = {}     # run_id as served -> run_id asked for
        subscribers = [
            rospy.Subscriber(f"{ns}/accepted_runs", AcceptedRun, self.on_accepted, queue_size=1000),
            rospy.Subscriber(f"{ns}/run_summaries", RunSummary, self.on_summary, queue_size=1000),
            rospy.Subscriber(f"{ns}/markers", MarkerArray, self.on_markers, queue_size=100)]
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and (self.pub.get_num_connections() == 0 or
                                               any(s.get_num_connections() == 0 for s in subscribers)):
            time.sleep(0.05)
        self.stop = threading.Event()

    def on_accepted(self, msg):
        with self.lock:
            self.served[msg.run_id] = msg.requested_run_id

    def on_summary(self, msg):
        # Topics are separate connections: a summary may arrive before its AcceptedRun, so
        # it is kept by its served run_id and matched when the probe reports.
        with self.lock:
            self.summaries.setdefault(msg.run_id, (time.monotonic(), msg.collision_count))

    def answered(self):
        """run_id asked for -> (publish to summary [s], collision_count); call with the lock held."""
        out = {}
        for served, (t, count) in self.summaries.items():
            asked = self.served.get(served)
            if asked in self.sent:
                out[asked] = (t - self.sent[asked], count)
        return out

    def on_markers(self, _msg):
        with self.lock:
            self.markers += 1

    def marker_rate(self, seconds):
        with self.lock:
            before = self.markers
        time.sleep(seconds)
        with self.lock:
            return (self.markers - before) / seconds

    def send_every_second(self, phase):
        k = 0
        while not self.stop.is_set():
            msg = self.InitialConditions(run_id=f"{phase}.{k}", student="rosprobe",
                                         masses=[100.0, 1.0, float("inf")], positions=[2.0, 1.0, 0.0],
                                         velocities=[-1.0, 0.0, 0.0])
            with self.lock:
                self.sent[msg.run_id] = time.monotonic()
            self.pub.publish(msg)
            k += 1
            self.stop.wait(1.0)

    def start(self, phase):
        """Sends a scene every second and measures the markers' rate until stopped."""
        self.stop.clear()
        self.rate = []
        self.sender = threading.Thread(target=self.send_every_second, args=(phase,))
        self.sender.start()
        self.meter = threading.Thread(target=lambda: self.rate.append(self.marker_rate(3.0)))
        self.meter.start()

    def finish(self):
        self.stop.set()
        self.sender.join()
        self.meter.join()
        return self.rate[0]

    def report(self, phase, marker_rate):
        """Waits up to 30 s for the phase's summaries; prints the phase's line; True when all came."""
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            with self.lock:
                answered = self.answered()
                sent = [k for k in self.sent if k.startswith(phase)]
            if all(k in answered for k in sent):
                break
            time.sleep(0.1)
        latency = [answered[k][0] for k in sent if k in answered]
        wrong = sum(1 for k in sent if k in answered and answered[k][1] != 31)
        print(f"ROS side, {phase}: {len(latency)} of {len(sent)} scenes sent over ROS answered "
              f"({wrong} with a count other than 31); publish to summary median "
              f"{statistics.median(latency) * 1e3 if latency else float('nan'):.0f} ms, "
              f"p99 {pct(latency, 0.99) * 1e3:.0f} ms; markers topic (what rviz draws) {marker_rate:.1f} messages/s")
        return len(latency) == len(sent) and wrong == 0 and marker_rate > 0


def pct(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--url", default="http://127.0.0.1:8080")
    ap.add_argument("--students", type=int, default=30)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--ros", action="store_true", help="also probe the lab's ROS side during the load")
    ap.add_argument("--ns", default="/collision_lab", help="the lab's namespace (with --ros)")
    ap.add_argument("--screenshot", help="PNG of $DISPLAY (the lab's rviz) taken during the load")
    args = ap.parse_args()
    base = args.url.rstrip("/")
    stats = Stats()
    probe = RosProbe(args.ns) if args.ros else None
    # A finished 31,415-impact run for the page's time to first plot under load.
    status, answer = request(stats, f"{base}/api/runs", {"student": "loadpage", "preset": "pi_digits_5"})
    page_run = json.loads(answer)["run_id"]
    follow(stats, base, page_run)

    if probe:  # the ROS side alone, for comparison
        probe.start("idle")
        time.sleep(5)
        idle_markers = probe.finish()
    t0 = time.monotonic()
    threads = [threading.Thread(target=student, args=(stats, base, k, args.runs)) for k in range(args.students)]
    for t in threads:
        t.start()
    if probe:
        probe.start("busy")
    if args.screenshot:
        time.sleep(2)
        subprocess.run(["import", "-window", "root", args.screenshot], check=True, timeout=60)
    busy_first_plot = first_plot_ms(base, page_run)
    for t in threads:
        t.join()
    wall = time.monotonic() - t0
    if probe:
        busy_markers = probe.finish()
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
    ros_ok = (probe.report("idle", idle_markers) & probe.report("busy", busy_markers)) if probe else True
    return 0 if len(stats.runs) == wanted and not stats.problems and ros_ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
