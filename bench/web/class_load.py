#!/usr/bin/env python3
"""A class of thirty against a real lab, with big jobs and an attacker (issue 30; a benchmark, not a test).

Starts `roslaunch collision_lab lab.launch web:=true rviz:=false` itself (its own ROS master
and web port, both free ports on loopback; a class code; a fresh bag folder, removed at the
end), or attaches to a running lab with --url (then ROS_MASTER_URI must name its master).
Each simulated student sends from a loopback address of its own (127.0.0.10 + k), so that
per-address limits see thirty students. Every loop is bounded in count and in time.

Phases:
1. idle anchor: the pi scene, a few times, on the idle lab (time to final);
2. warm-up: each student sends --warmup-runs small scenes, and --warmup-gases gas runs and
   --warmup-huge runs asking for 2^64-1 impacts go with them; then both nodes' VmRSS;
3. the class: each student sends --runs small scenes; meanwhile big jobs (the 1,000-body gas
   preset, and the pi scene at masses (1e16, 1, inf) asking for 2^64-1 impacts; every second
   one of the latter is stopped by its owner with its stop_token when the API gives one), and an
   attacker: slow connections that send a header byte every 4 s, chunked bodies larger than
   the limit, wrong class codes. Then both nodes' VmRSS again: memory per run is the growth
   divided by the runs of this phase.
4. one bad student: one address sends --flood gas_1000 runs under as many names at once while
   ten classmates send pi runs; their time to final (goal: p99 <= 2 s, 0 lost).
5. bad disk (a started lab run as root: its bag folder is then a tmpfs of --disk-mb): a filler
   file leaves the lab's free-space floor plus --disk-headroom MB, one address sends gas_1000
   runs and ten classmates send pi runs; then the filler leaves 5 MB under the floor, and at
   last it goes; the classmates send again each time.
   Each classmate's send is answered: final, or refused with DISK_SPACE; its time to that
   answer (goal: p99 <= 2 s), runs lost (accepted, never final: goal 0), and the phase's runs
   as the index lists them (none interrupted).

--class-defaults runs the lab with a class's defaults (no raised rate limits, no lowered time
ceiling, the model answering over the cap), to measure memory per run as a class meets it.

It prints one block of figures and a `goal:` line per goal (bench/goals_table.py): small
scenes' time to final p99 <= 2 s, 0 runs lost, memory per run < 1 KB (1,000 B) for each node.
Exit status 0 when measured (goals met or not), 2 when the lab could not be started or reached.

It speaks the class API of docs/web.md: 202 {run_id, url, queue_position, lane, stop_token}
(today's server: 201 {run_id, url}), GET /api/runs/<id>, its SSE stream, POST .../stop with
X-Stop-Token, GET /api/queue (skipped when absent), header X-Class-Code on every request.

Usage (Debian's python3; the workspace's devel/setup.bash sourced):
  python3 bench/web/class_load.py [--students 30] [--warmup-runs 10] [--runs 60] [--gases 6] [--huge 4]
          [--slow 80] [--chunked 4] [--wrong-codes 300] [--web-param NAME=VALUE ...] [--lab-param NAME=VALUE ...]
          [--class-defaults] [--disk-mb 4096] [--disk-headroom 40]
  python3 bench/web/class_load.py --url http://127.0.0.1:8080 --code CODE [--ns /collision_lab]
"""
import argparse
import collections
import http.client
import json
import os
import random
import select
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client

PI = {"masses": [100, 1, "inf"], "positions": [2, 1, 0], "velocities": [-1, 0, 0]}
# Small scenes with their exact counts (config/scenarios.yaml): the bulk of the runs.
SMALL_SCENES = [
    ("pi", PI, 31),
    ("two_carts", {"masses": [3, 1], "positions": [1, 0], "velocities": [-1, 1]}, 1),
    ("equal_masses", {"masses": [1, 1, 1], "positions": [2, 1, -1], "velocities": [-1, 0, 1]}, 3),
    ("cradle_5", {"masses": [1, 1, 1, 1, 1], "positions": [4, 3, 2, 1, 0], "velocities": [-1, 0, 0, 0, 0]}, 4),
]
SMALL_KINDS = {name for name, _, _ in SMALL_SCENES}
GAS = {"preset": "gas_1000"}
# Asks for 2^64-1 impacts: only the lab's ceilings (max_collisions, max_run_seconds, bag size) end it.
HUGE = {"masses": [1e16, 1, "inf"], "positions": [2, 1, 0], "velocities": [-1, 0, 0],
        "max_collisions": 2 ** 64 - 1}
FINAL_STATES = ("finished", "interrupted")
# The class's settings that the benchmark sets (launch argument web_<name> or <name> when the
# launch file has one, else the node's private parameter). A class of 30 sends its runs as
# fast as they finish, so the per-student and per-address rate limits must allow that. The runs
# asking 2^64-1 impacts must compute (simulate_to_cap: else the lab answers them from the model
# alone, as the model predicts more impacts than its max_collisions ceiling), and its time
# ceiling ends them so that the benchmark ends.
WEB_SETTINGS = {"runs_per_minute": 600, "runs_per_minute_per_address": 600}
LAB_SETTINGS = {"max_run_seconds": 10, "simulate_to_cap": "true"}
GOAL_P99_S = 2.0
GOAL_BYTES_PER_RUN = 1000


def pct(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))] if values else float("nan")


def parse_value(text):
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    return {"true": True, "false": False}.get(text.lower(), text)


class Client:
    """HTTP/1.1 requests to the web node from a chosen loopback source address."""

    def __init__(self, host, port, code):
        self.host, self.port, self.code = host, port, code
        self.origin = f"http://{host}:{port}"

    def headers(self, extra=None):
        h = {"Origin": self.origin}
        if self.code:
            h["X-Class-Code"] = self.code
        h.update(extra or {})
        return h

    def connect(self, source, timeout):
        return http.client.HTTPConnection(self.host, self.port, timeout=timeout, source_address=(source, 0))

    def request(self, method, path, source, body=None, headers=None, timeout=60.0):
        """(status, headers, body bytes); status None with the error text on a connection error or timeout."""
        conn = self.connect(source, timeout)
        try:
            data = None if body is None else json.dumps(body).encode()
            h = self.headers(headers)
            if data is not None:
                h["Content-Type"] = "application/json"
            conn.request(method, path, body=data, headers=h)
            res = conn.getresponse()
            return res.status, dict(res.getheaders()), res.read()
        except (OSError, http.client.HTTPException) as e:
            return None, {}, f"{type(e).__name__}: {e}".encode()
        finally:
            conn.close()


class Stats:
    """Everything the students and the attacker count; one lock."""

    def __init__(self):
        self.lock = threading.Lock()
        self.status = {}            # students' HTTP answers: status (or "no answer") -> count
        self.runs = []              # one dict per POST that got a run_id
        self.unanswered_posts = 0   # POSTs with no 2xx/4xx answer after their retries
        self.not_sent = 0           # runs never sent: the phase's time bound ran out
        self.small_failed = 0       # small scenes of the class phase whose POST got no run_id
        self.problems = []
        self.stops = []             # (status of POST .../stop, final stop_reason)

    def count(self, status):
        with self.lock:
            key = status if status is not None else "no answer"
            self.status[key] = self.status.get(key, 0) + 1

    def problem(self, text):
        with self.lock:
            if len(self.problems) < 1000:
                self.problems.append(text)


class Student:
    def __init__(self, name, source, client, stats, args):
        self.name, self.source, self.client, self.stats, self.args = name, source, client, stats, args
        self.run_ids = set()

    def post(self, scene):
        """POSTs a scene, waiting out 429s (Retry-After, at most 5 times); (status, answer, send time)."""
        body = dict(scene, student=self.name)
        for _ in range(6):
            sent = time.monotonic()
            status, headers, answer = self.client.request("POST", "/api/runs", self.source, body,
                                                          timeout=self.args.post_timeout)
            self.stats.count(status)
            if status != 429:
                return status, answer, sent
            time.sleep(min(15.0, float(headers.get("Retry-After", "1") or 1)))
        return status, answer, sent

    def get_run(self, run_id):
        status, _, answer = self.client.request("GET", f"/api/runs/{run_id}", self.source, timeout=30)
        self.stats.count(status)
        try:
            return status, json.loads(answer) if status == 200 else None
        except ValueError:
            return status, None

    def follow(self, run_id, deadline):
        """The run's final JSON and the time it was seen final; over its SSE stream, else by polling."""
        conn = self.client.connect(self.source, 30)
        try:
            conn.request("GET", f"/api/runs/{run_id}/stream", headers=self.client.headers())
            res = conn.getresponse()
            self.stats.count(res.status)
            if res.status == 200:
                event = None
                while time.monotonic() < deadline:
                    raw = res.readline()
                    if not raw:
                        break
                    line = raw.decode(errors="replace").rstrip("\r\n")
                    if line.startswith("event: "):
                        event = line[7:]
                    elif line.startswith("data: ") and event == "final":
                        return json.loads(line[6:]), time.monotonic()
        except (OSError, http.client.HTTPException, ValueError):
            pass
        finally:
            conn.close()
        while time.monotonic() < deadline:
            status, run = self.get_run(run_id)
            if run and run.get("state") in FINAL_STATES:
                return run, time.monotonic()
            if status == 404:
                return {"state": "404"}, time.monotonic()
            time.sleep(0.5)
        return None, None

    def send(self, kind, scene, expected, phase, stop_after=None):
        status, answer, sent = self.post(scene)
        try:
            reply = json.loads(answer) if status in (200, 201, 202) else {}
        except ValueError:
            reply = {}
        if status not in (200, 201, 202):
            with self.stats.lock:
                if status is None or status >= 500:
                    self.stats.unanswered_posts += 1
                if phase == "class" and kind in SMALL_KINDS:
                    self.stats.small_failed += 1
            self.stats.problem(f"{self.name} {kind}: HTTP {status} {answer[:100]!r}")
            return
        run = {"run_id": reply.get("run_id"), "student": self.name, "kind": kind, "phase": phase,
               "post_s": time.monotonic() - sent, "queue_position": reply.get("queue_position"),
               "lane": reply.get("lane"), "final": None, "to_final_s": None, "count_ok": None, "stop_reason": None}
        with self.stats.lock:
            self.stats.runs.append(run)
        if not run["run_id"]:
            self.stats.problem(f"{self.name} {kind}: HTTP {status} without a run_id")
            return
        self.run_ids.add(run["run_id"])
        if stop_after is not None and reply.get("stop_token"):
            time.sleep(stop_after)
            st, _, _ = self.client.request("POST", f"/api/runs/{run['run_id']}/stop", self.source,
                                           body={}, headers={"X-Stop-Token": reply["stop_token"]}, timeout=30)
            self.stats.count(st)
            run["stopped_by_owner"] = st
        final, at = self.follow(run["run_id"], sent + self.args.final_timeout)
        if final is None:
            return
        run["final"] = final.get("state")
        run["to_final_s"] = at - sent
        summary = final.get("summary") or {}
        run["stop_reason"] = summary.get("stop_reason")
        run["collisions"] = summary.get("collision_count")
        if expected is not None:
            run["count_ok"] = summary.get("collision_count") == expected
            if not run["count_ok"]:
                self.stats.problem(f"{run['run_id']}: {summary.get('collision_count')} impacts, expected {expected}")

    def work(self, jobs, phase, end_by):
        for kind, scene, expected, stop_after in jobs:
            if time.monotonic() > end_by:
                with self.stats.lock:
                    self.stats.not_sent += 1
                continue
            self.send(kind, scene, expected, phase, stop_after)


class Attacker:
    """Slow connections, oversized chunked bodies and wrong class codes, each on its own thread."""

    def __init__(self, client, args, stop):
        self.client, self.args, self.stop = client, args, stop
        self.started = time.monotonic()
        self.slow = {"opened": 0, "refused": 0, "closed_after_s": [], "answers": {}, "open_at_end": 0}
        self.page_latency = []     # GET / during the slow attack: (status or None, seconds)
        self.chunked = []          # (bytes sent, answer or what happened, refused before the end)
        self.codes = {}
        self.first_lockout = None  # the wrong try that first got a 429

    def over(self, end):
        """The slow attack ends at `end`, or when the class is done but not before
        --slow-min-seconds: long enough for any sensible header timeout to show."""
        now = time.monotonic()
        return now >= end or (self.stop.is_set() and now >= self.started + self.args.slow_min_seconds)

    def slow_connections(self):
        payload = f"GET / HTTP/1.1\r\nHost: {self.client.host}:{self.client.port}\r\nX-Slow: ".encode()
        socks = {}
        for i in range(self.args.slow):
            source = f"127.0.1.{1 + i % self.args.slow_addresses}"
            try:
                s = socket.create_connection((self.client.host, self.client.port), timeout=5,
                                             source_address=(source, 0))
                s.setblocking(False)
                socks[s] = [time.monotonic(), 0]
                self.slow["opened"] += 1
            except OSError:
                self.slow["refused"] += 1
        end = time.monotonic() + self.args.slow_seconds
        next_byte = time.monotonic()
        while socks and not self.over(end):
            now = time.monotonic()
            if now >= next_byte:
                for s, state in list(socks.items()):
                    byte = payload[state[1]:state[1] + 1] or b"a"
                    try:
                        s.send(byte)
                        state[1] += 1
                    except OSError:
                        self.slow["closed_after_s"].append(now - state[0])
                        s.close()
                        del socks[s]
                next_byte = now + self.args.slow_interval
            readable, _, _ = select.select(list(socks), [], [], max(0.0, min(0.5, next_byte - now)))
            for s in readable:
                try:
                    data = s.recv(4096)
                except OSError:
                    data = b""
                if data.startswith(b"HTTP/"):
                    code = data.split(b" ", 2)[1].decode(errors="replace")
                    self.slow["answers"][code] = self.slow["answers"].get(code, 0) + 1
                if not data:
                    self.slow["closed_after_s"].append(time.monotonic() - socks[s][0])
                    s.close()
                    del socks[s]
        self.slow["open_at_end"] = len(socks)
        for s in socks:
            s.close()

    def page_probe(self):
        """GET / every 2 s from a student's address while the slow connections hold."""
        end = time.monotonic() + self.args.slow_seconds
        while not self.over(end):
            t0 = time.monotonic()
            status, _, _ = self.client.request("GET", "/", "127.0.0.8", timeout=30)
            self.page_latency.append((status, time.monotonic() - t0))
            time.sleep(2.0)

    def chunked_bodies(self):
        chunk = b"a" * 65536
        for _ in range(self.args.chunked):
            if self.stop.is_set():
                break
            sent, outcome, early = 0, None, False
            try:
                s = socket.create_connection((self.client.host, self.client.port), timeout=10,
                                             source_address=("127.0.0.201", 0))
            except OSError as e:
                self.chunked.append((0, f"connect: {e}", True))
                continue
            head = (f"POST /api/runs HTTP/1.1\r\nHost: {self.client.host}:{self.client.port}\r\n"
                    f"Origin: {self.client.origin}\r\nX-Class-Code: {self.client.code}\r\n"
                    "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n").encode()
            parts = [b'{"student": "chunky", "pad": "'] + [chunk] * (self.args.chunked_bytes // len(chunk)) + [b'"}']
            try:
                s.sendall(head)
                for part in parts:
                    if select.select([s], [], [], 0)[0]:
                        early = True
                        break
                    s.sendall(b"%x\r\n" % len(part) + part + b"\r\n")
                    sent += len(part)
                if not early:
                    s.sendall(b"0\r\n\r\n")
                s.settimeout(60)
                data = s.recv(4096)
                outcome = data.split(b" ", 2)[1].decode(errors="replace") if data.startswith(b"HTTP/") else "closed"
            except socket.timeout:
                outcome = "no answer in 60 s" if sent == sum(map(len, parts)) else "stalled: the server stopped reading"
            except OSError as e:
                early, outcome = True, outcome or f"closed by the server ({type(e).__name__})"
            finally:
                s.close()
            self.chunked.append((sent, outcome, early))

    def wrong_codes(self):
        for k in range(self.args.wrong_codes):
            if self.stop.is_set():
                break
            wrong = Client(self.client.host, self.client.port, f"guess{random.randrange(10 ** 6)}")
            status, _, _ = wrong.request("POST", "/api/runs", "127.0.0.202", dict(PI, student="guesser"), timeout=30)
            key = status if status is not None else "no answer"
            self.codes[key] = self.codes.get(key, 0) + 1
            if status == 429 and self.first_lockout is None:
                self.first_lockout = k + 1

    def threads(self):
        targets = []
        if self.args.slow:
            targets += [self.slow_connections, self.page_probe]
        if self.args.chunked:
            targets.append(self.chunked_bodies)
        if self.args.wrong_codes:
            targets.append(self.wrong_codes)
        return [threading.Thread(target=t, daemon=True) for t in targets]


class Lab:
    """The lab under test: started here (master, lab.launch, bag folder) or attached to."""

    def __init__(self, args):
        self.args = args
        self.procs = []
        self.tmp = None
        self.settings = []

    @staticmethod
    def free_port():
        """A port free on every address, below Linux's ephemeral range (32768-60999), so that no
        client socket of this benchmark or of anything else takes it before the node binds it."""
        for _ in range(100):
            port = random.randrange(20000, 32000)
            with socket.socket() as s:
                try:
                    s.bind(("0.0.0.0", port))
                    return port
                except OSError:
                    continue
        raise RuntimeError("no free port in 20000-32000")

    def master(self):
        return xmlrpc.client.ServerProxy(self.master_uri)

    def start(self):
        args = self.args
        self.tmp = tempfile.mkdtemp(prefix="class_load_")
        self.bags = os.path.join(self.tmp, "bags")
        os.makedirs(self.bags)
        # A disk of its own that the bad-disk phase may fill: a tmpfs (root only).
        self.small_disk = args.disk_mb > 0 and os.geteuid() == 0 and subprocess.run(
            ["mount", "-t", "tmpfs", "-o", f"size={args.disk_mb}m", "tmpfs", self.bags],
            capture_output=True).returncode == 0
        self.code = args.code or f"class{random.randrange(10 ** 6):06d}"
        self.log = open(os.path.join(self.tmp, "launch.log"), "w")
        for attempt in range(3):  # another program may take the port first
            master_port, self.web_port = self.free_port(), self.free_port()
            self.master_uri = f"http://127.0.0.1:{master_port}"
            env = dict(os.environ, ROS_MASTER_URI=self.master_uri, ROS_LOG_DIR=os.path.join(self.tmp, "log"))
            core = subprocess.Popen(["roscore", "-p", str(master_port)], env=env, stdout=self.log,
                                    stderr=subprocess.STDOUT, start_new_session=True)
            self.procs.append(core)
            if self.wait(lambda: core.poll() is None and self.master().getSystemState("/class_load")[0] == 1, 30):
                break
            if attempt == 2:
                raise RuntimeError(f"the ROS master did not start; see {self.log.name} (--keep keeps it)")
        listed = subprocess.run(["roslaunch", "--ros-args", "collision_lab", "lab.launch"], env=env,
                                capture_output=True, text=True, timeout=60).stdout
        launch_args = {line.split()[0].rstrip(":") for line in listed.splitlines() if line.startswith("  ")}
        cmd = ["roslaunch", "collision_lab", "lab.launch", "web:=true", "rviz:=false", f"web_port:={self.web_port}",
               f"web_code:={self.code}", f"bag_directory:={self.bags}"]
        web = dict({} if args.class_defaults else WEB_SETTINGS, **dict(p.split("=", 1) for p in args.web_param))
        lab = dict({} if args.class_defaults else LAB_SETTINGS, **dict(p.split("=", 1) for p in args.lab_param))
        for node, values, arg_prefix in (("collision_lab_web", web, "web_"), ("collision_lab_node", lab, "")):
            for name, value in values.items():
                value = parse_value(str(value))
                if arg_prefix + name in launch_args:
                    cmd.append(f"{arg_prefix}{name}:={value}")
                    self.settings.append(f"{node} {name} = {value} (launch argument {arg_prefix}{name})")
                else:
                    self.master().setParam("/class_load", f"{args.ns}/{node}/{name}", value)
                    self.settings.append(f"{node} {name} = {value} (rosparam)")
        self.procs.append(subprocess.Popen(cmd, env=env, stdout=self.log, stderr=subprocess.STDOUT,
                                           start_new_session=True))
        url_param = f"{args.ns}/collision_lab_web/url"
        if not self.wait(lambda: self.master().getParam("/class_load", url_param)[0] == 1, 120):
            raise RuntimeError(f"the web node did not come up; see {self.log.name}")
        if not self.wait(self.connected, 60):
            raise RuntimeError(f"the web node and the lab node did not connect; see {self.log.name}")
        return f"http://127.0.0.1:{self.web_port}"

    def connected(self):
        """Both nodes registered on the lab's input topic (web publishes, lab subscribes); then 2 s
        for the connection itself, after which the web node's POST no longer answers 503."""
        publishers, subscribers, _ = self.master().getSystemState("/class_load")[2]
        topic = f"{self.args.ns}/initial_conditions"
        pubs = next((nodes for t, nodes in publishers if t == topic), [])
        subs = next((nodes for t, nodes in subscribers if t == topic), [])
        if f"{self.args.ns}/collision_lab_web" in pubs and f"{self.args.ns}/collision_lab_node" in subs:
            time.sleep(2.0)
            return True
        return False

    @staticmethod
    def wait(ready, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            try:
                if ready():
                    return True
            except (OSError, xmlrpc.client.Error):
                pass
            time.sleep(0.5)
        return False

    def param(self, name, default):
        """The lab's parameter <ns>/<name>, else default."""
        try:
            code, _, value = self.master().getParam("/class_load", f"{self.args.ns}/{name}")
            return value if code == 1 else default
        except (OSError, xmlrpc.client.Error):
            return default

    def pid(self, node):
        try:
            code, _, uri = self.master().lookupNode("/class_load", f"{self.args.ns}/{node}")
            return xmlrpc.client.ServerProxy(uri).getPid("/class_load")[2] if code == 1 else None
        except (OSError, xmlrpc.client.Error):
            return None

    @staticmethod
    def memory(pid):
        """(VmRSS, VmHWM) [bytes] of a local process; None when unknown."""
        try:
            with open(f"/proc/{pid}/status") as f:
                fields = dict(line.split(":", 1) for line in f)
            return tuple(int(fields[k].split()[0]) * 1024 for k in ("VmRSS", "VmHWM"))
        except (OSError, KeyError, TypeError):
            return None

    def bag_stats(self):
        sizes = []
        for root, _, files in os.walk(self.bags):
            sizes += [os.path.getsize(os.path.join(root, f)) for f in files]
        return len(sizes), sum(sizes), max(sizes, default=0)

    def stop(self):
        for proc in reversed(self.procs):
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGINT)
                try:
                    proc.wait(30)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait(10)
        if getattr(self, "small_disk", False):
            subprocess.run(["umount", "-l", self.bags], capture_output=True)
        if self.tmp and not self.args.keep:
            shutil.rmtree(self.tmp, ignore_errors=True)


def plan(args, students):
    """Each student's jobs per phase: small scenes in turn; the big jobs go first, one per student
    (the warm-up's gases to the last students, so that memory holds big runs before it is read)."""
    warm = [[] for _ in students]
    main = [[] for _ in students]
    for k in range(len(students)):
        for r in range(args.warmup_runs):
            name, scene, expected = SMALL_SCENES[(k + r) % len(SMALL_SCENES)]
            warm[k].append((name, scene, expected, None))
        for r in range(args.runs):
            name, scene, expected = SMALL_SCENES[(k + r) % len(SMALL_SCENES)]
            main[k].append((name, scene, expected, None))
    big = [("gas_1000", GAS, None, None)] * args.gases + \
          [("huge", HUGE, None, args.stop_after if i % 2 else None) for i in range(args.huge)]
    for i, job in enumerate(big):
        main[i % len(students)].insert(i // len(students), job)
    for i in range(args.warmup_gases):
        warm[(len(students) - 1 - i) % len(students)].insert(0, ("gas_1000", GAS, None, None))
    for i in range(args.warmup_huge):
        warm[i % len(students)].insert(0, ("huge", HUGE, None, args.stop_after if i % 2 else None))
    return warm, main


def run_phase(students, jobs, phase, seconds):
    end_by = time.monotonic() + seconds
    threads = [threading.Thread(target=s.work, args=(j, phase, end_by), daemon=True) for s, j in zip(students, jobs)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()


def queue_length(client):
    """Entries in GET /api/queue (the longest list in its JSON); None when the route is absent."""
    status, _, answer = client.request("GET", "/api/queue", "127.0.0.7", timeout=10)
    if status != 200:
        return None
    try:
        data = json.loads(answer)
    except ValueError:
        return None
    if isinstance(data, list):
        return len(data)
    return max((len(v) for v in data.values() if isinstance(v, list)), default=0) if isinstance(data, dict) else None


def settle(client, seconds=60):
    """Waits until the lab's queue is empty (when it has one), then 6 s more: the web node
    gives the memory it freed back to the system every 5 s, the lab node when idle."""
    end = time.monotonic() + seconds
    while time.monotonic() < end and (queue_length(client) or 0) > 0:
        time.sleep(0.5)
    time.sleep(6.0)


def mb(x):
    return f"{x / 1e6:.1f} MB" if x is not None else "unknown"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", help="attach to a running lab's web node instead of starting one")
    ap.add_argument("--code", default="", help="the class code (with --url: the lab's; else one is made up)")
    ap.add_argument("--ns", default="/collision_lab", help="the lab's namespace")
    ap.add_argument("--students", type=int, default=30)
    ap.add_argument("--warmup-runs", type=int, default=10, help="small runs per student before the first memory reading")
    ap.add_argument("--warmup-gases", type=int, default=2, help="gas_1000 runs in the warm-up")
    ap.add_argument("--warmup-huge", type=int, default=2,
                    help="runs asking for 2^64-1 impacts in the warm-up (a node's memory is read after it has seen every kind of run)")
    ap.add_argument("--runs", type=int, default=60, help="small runs per student in the measured phase")
    ap.add_argument("--gases", type=int, default=6, help="gas_1000 runs in the measured phase")
    ap.add_argument("--huge", type=int, default=4, help="runs asking for 2^64-1 impacts in the measured phase")
    ap.add_argument("--flood", type=int, default=30,
                    help="gas_1000 runs one address sends under as many names in the 'one bad student' phase (0: none)")
    ap.add_argument("--stop-after", type=float, default=3.0, help="every second huge run is stopped by its owner after this [s]")
    ap.add_argument("--slow", type=int, default=80, help="slow connections of the attacker")
    ap.add_argument("--slow-addresses", type=int, default=8, help="loopback addresses they come from (127.0.1.x)")
    ap.add_argument("--slow-interval", type=float, default=4.0, help="one header byte per connection every [s]")
    ap.add_argument("--slow-seconds", type=float, default=120.0, help="the slow attack lasts at most [s]")
    ap.add_argument("--slow-min-seconds", type=float, default=30.0,
                    help="and at least this, even when the class is done sooner [s]")
    ap.add_argument("--chunked", type=int, default=4, help="chunked request bodies over the limit, one after the other")
    ap.add_argument("--chunked-bytes", type=int, default=8 << 20, help="bytes in each [bytes]")
    ap.add_argument("--wrong-codes", type=int, default=300, help="POSTs with a wrong class code")
    ap.add_argument("--post-timeout", type=float, default=60.0, help="a POST without an answer by then counts as unanswered [s]")
    ap.add_argument("--final-timeout", type=float, default=300.0, help="an accepted run not final by then (after its POST) is lost [s]")
    ap.add_argument("--max-seconds", type=float, default=900.0, help="a phase sends no new run after this [s]")
    ap.add_argument("--web-param", action="append", default=[], help="NAME=VALUE for the web node (started lab only)")
    ap.add_argument("--lab-param", action="append", default=[], help="NAME=VALUE for the lab node (started lab only)")
    ap.add_argument("--keep", action="store_true", help="keep the bag folder and the launch log")
    ap.add_argument("--class-defaults", action="store_true",
                    help="the lab as a class gets it: none of the benchmark's raised limits (WEB_SETTINGS, LAB_SETTINGS)")
    ap.add_argument("--disk-mb", type=int, default=4096,
                    help="[MB] the bag folder's tmpfs (root only; 0: none, and no bad-disk phase)")
    ap.add_argument("--disk-headroom", type=float, default=40.0,
                    help="[MB] free above the lab's floor that the bad-disk phase leaves")
    args = ap.parse_args()

    lab = Lab(args)
    try:
        if args.url:
            base = args.url.rstrip("/")
            lab.master_uri = os.environ.get("ROS_MASTER_URI", "http://127.0.0.1:11311")
            lab.code = args.code
        else:
            base = lab.start()
    except (RuntimeError, OSError, subprocess.SubprocessError, xmlrpc.client.Error) as e:
        print(f"class_load.py: {e}", file=sys.stderr)
        lab.stop()
        return 2
    try:
        return measure(args, lab, base)
    finally:
        lab.stop()


def measure(args, lab, base):
    host, port = base.split("//", 1)[1].rsplit(":", 1)
    client = Client(host, int(port.rstrip("/")), lab.code)
    stats = Stats()
    names = [f"student{k:02d}" for k in range(args.students)]
    students = [Student(n, f"127.0.0.{10 + k}", client, stats, args) for k, n in enumerate(names)]
    pids = {n: lab.pid(n) for n in ("collision_lab_web", "collision_lab_node")}
    print(f"=== class load: {args.students} students, {args.warmup_runs} + {args.runs} small runs each, "
          f"{args.gases} gas_1000 and {args.huge} runs asking 2^64-1 impacts; attacker: {args.slow} slow connections, "
          f"{args.chunked} chunked bodies of {args.chunked_bytes} B, {args.wrong_codes} wrong codes")
    print(f"lab: {base}, class code set, pids web {pids['collision_lab_web']} lab {pids['collision_lab_node']}; "
          + ("; ".join(lab.settings) if lab.settings else "attached, settings as found" if args.url
             else "the class's defaults (nothing raised)"))

    anchor = Student("anchor", "127.0.0.9", client, stats, args)
    for _ in range(5):
        anchor.send("pi", PI, 31, "anchor")
    idle = [r["to_final_s"] for r in stats.runs if r["phase"] == "anchor" and r["to_final_s"] is not None]
    anchor_run = next((r["run_id"] for r in stats.runs if r["phase"] == "anchor" and r["final"]), None)
    _, _, served = client.request("GET", f"/api/runs/{anchor_run}", "127.0.0.9") if anchor_run else (None, {}, b"")
    bag = os.path.join(getattr(lab, "bags", ""), f"{anchor_run}.bag")
    bag_bytes = os.path.getsize(bag) if anchor_run and os.path.exists(bag) else None

    warm, jobs = plan(args, students)
    run_phase(students, warm, "warm-up", args.max_seconds)
    settle(client)
    before = {n: lab.memory(p) for n, p in pids.items()}

    stop = threading.Event()
    attacker = Attacker(client, args, stop)
    queue_max = [None]

    def watch_queue():
        while not stop.is_set():
            n = queue_length(client)
            if n is None:
                return
            queue_max[0] = max(queue_max[0] or 0, n)
            stop.wait(1.0)

    side = attacker.threads() + [threading.Thread(target=watch_queue, daemon=True)]
    t0 = attacker.started = time.monotonic()
    for t in side:
        t.start()
    run_phase(students, jobs, "class", args.max_seconds)
    wall = time.monotonic() - t0
    stop.set()
    for t in side:
        t.join(90)
    settle(client)
    after = {n: lab.memory(p) for n, p in pids.items()}

    # Runs made but never answered to their student: in the student's list, not among its run_ids.
    orphans = 0
    for s in students:
        status, _, answer = client.request("GET", f"/api/runs?student={s.name}", s.source, timeout=30)
        try:
            listed = json.loads(answer) if status == 200 else []
        except ValueError:
            listed = []
        if isinstance(listed, dict):
            listed = next((v for v in listed.values() if isinstance(v, list)), [])
        orphans += sum(1 for item in listed if isinstance(item, dict) and item.get("run_id") not in s.run_ids)

    runs = [r for r in stats.runs if r["phase"] != "anchor"]
    class_runs = [r for r in runs if r["phase"] == "class"]
    never_final = [r for r in runs if r["run_id"] and r["final"] not in FINAL_STATES]
    no_run = [r for r in runs if not r["run_id"] or r["final"] == "404"]
    lost = len(never_final) + orphans
    # A small scene that never reached its final for its student (no run_id, or not final in
    # time) counts as an infinite time to final.
    small = [r["to_final_s"] if r["to_final_s"] is not None else float("inf")
             for r in class_runs if r["kind"] in SMALL_KINDS] + [float("inf")] * stats.small_failed
    posts = [r["post_s"] for r in class_runs]
    p50, p99 = pct(small, 0.5), pct(small, 0.99)

    print(f"measured phase: {wall:.1f} s, {len(class_runs)} runs answered with a run_id "
          f"({stats.not_sent} never sent: time bound)")
    print(f"small scenes, POST sent -> run final: p50 {p50:.3f} s, p99 {p99:.3f} s over {len(small)} runs, "
          f"{sum(1 for x in small if x == float('inf'))} of them never final for their student (counted as infinite) "
          f"(idle lab, the pi scene: median {statistics.median(idle) if idle else float('nan'):.3f} s)")
    print(f"POST answer (202/201): p50 {pct(posts, 0.5) * 1e3:.0f} ms, p99 {pct(posts, 0.99) * 1e3:.0f} ms; "
          f"queue_position max {max((r['queue_position'] or 0 for r in runs), default=0)}; "
          f"lanes {sorted({str(r['lane']) for r in runs})}; GET /api/queue longest "
          f"{queue_max[0] if queue_max[0] is not None else 'no such route'}")
    for kind in ("gas_1000", "huge"):
        big = [r for r in class_runs if r["kind"] == kind]
        reasons = {}
        for r in big:
            reasons[str(r["stop_reason"])] = reasons.get(str(r["stop_reason"]), 0) + 1
        times = [r["to_final_s"] for r in big if r["to_final_s"] is not None]
        stopped = [r.get("stopped_by_owner") for r in big if "stopped_by_owner" in r]
        print(f"{kind}: {len(times)} of {len(big)} final, time to final median "
              f"{statistics.median(times) if times else float('nan'):.1f} s; stop reasons {reasons}"
              + (f"; stopped by owner: HTTP {stopped}" if stopped else ""))
    wrong = sum(1 for r in runs if r["count_ok"] is False)
    print(f"runs lost: {lost} (accepted but never final: {len(never_final)}; 2xx without a run: {len(no_run)}; "
          f"made but never answered to their student: {orphans}); POSTs unanswered (5xx or none): "
          f"{stats.unanswered_posts}; wrong impact counts: {wrong}")
    fives = sum(v for k, v in stats.status.items() if isinstance(k, int) and k >= 500)
    print(f"students' HTTP answers: 5xx {fives}, 429 {stats.status.get(429, 0)}, no answer "
          f"{stats.status.get('no answer', 0)}; by status {dict(sorted(stats.status.items(), key=str))}")
    per_run = {}
    for name in ("collision_lab_web", "collision_lab_node"):
        b, a = before.get(name), after.get(name)
        if b and a and class_runs:
            per_run[name] = (a[0] - b[0]) / len(class_runs)
        print(f"{name}: VmRSS {mb(b[0] if b else None)} after warm-up -> {mb(a[0] if a else None)} after "
              f"{len(class_runs)} more runs = {per_run.get(name, float('nan')):.0f} B/run; peak VmHWM {mb(a[1] if a else None)}")
    closed = attacker.slow["closed_after_s"]
    print(f"attacker, slow connections: {attacker.slow['opened']} opened, {attacker.slow['refused']} refused at connect, "
          f"{len(closed)} closed by the server (median after {statistics.median(closed) if closed else float('nan'):.1f} s), "
          f"answers {attacker.slow['answers']}, {attacker.slow['open_at_end']} still open at the end")
    answered = [t for status, t in attacker.page_latency if status == 200]
    print(f"GET / meanwhile: {len(answered)} of {len(attacker.page_latency)} answered 200 "
          f"(answers {dict(collections.Counter(str(status) for status, _ in attacker.page_latency))}), "
          f"p50 {pct(answered, 0.5) * 1e3:.0f} ms, max {max(answered, default=float('nan')) * 1e3:.0f} ms")
    refused = sum(1 for _, _, early in attacker.chunked if early)
    print(f"attacker, chunked bodies of {args.chunked_bytes} B: {refused} of {len(attacker.chunked)} refused before "
          f"their end; (bytes sent, answer): {[(s, o) for s, o, _ in attacker.chunked]}")
    print(f"attacker, wrong codes: {sum(attacker.codes.values())} tries, answers {attacker.codes}, "
          f"first 429 at try {attacker.first_lockout}")
    if hasattr(lab, "bags"):
        files, total, largest = lab.bag_stats()
        print(f"bags: {files} files, {mb(total)}, largest {mb(largest)}")
    for p in stats.problems[:10]:
        print("  problem:", p)

    met = lambda ok: "met" if ok else "missed"  # noqa: E731
    idle_median = statistics.median(idle) if idle else float("nan")
    print(f"goal: class load, small scenes' time to final p99 = {p99:.3f} s against the pi scene on the idle lab = "
          f"{idle_median:.3f} s (p50 {p50:.3f} s; goal <= {GOAL_P99_S:.0f} s): {met(bool(small) and p99 <= GOAL_P99_S)}")
    print(f"goal: class load, runs lost = {lost} against runs answered with a run_id = {len(runs)} "
          f"({stats.unanswered_posts} POSTs unanswered; goal 0 lost): {met(lost == 0)}")
    anchors = {"collision_lab_web": ("a small run's JSON as served", len(served) if served else None),
               "collision_lab_node": ("a small run's bag", bag_bytes)}
    for name, (what, size) in anchors.items():
        figure = per_run.get(name)
        print(f"goal: class load, {name} resident memory per run after warm-up = "
              f"{'unknown' if figure is None else f'{figure:.0f} B'} against {what} = "
              f"{'unknown' if size is None else f'{size} B'} (goal < {GOAL_BYTES_PER_RUN} B): "
              f"{met(figure is not None and figure < GOAL_BYTES_PER_RUN)}")
    bad_student_phase(client, stats, args)
    bad_disk_phase(client, stats, args, lab)
    return 0


def bad_student_phase(client, stats, args):
    """One address sends args.flood gas_1000 runs under as many names at once (each a long run);
    meanwhile ten classmates at their own addresses send pi runs one after another. Reports the
    classmates' time to final and what the flood got; then the flood's runs are stopped."""
    if args.flood <= 0:
        return
    flood_source = "127.0.0.250"
    answers, tokens = collections.Counter(), []

    def flood_one(k):
        status, _, answer = client.request("POST", "/api/runs", flood_source,
                                           dict(GAS, student=f"alias{k:02d}"), timeout=args.post_timeout)
        answers[str(status)] += 1
        if status == 202:
            reply = json.loads(answer)
            tokens.append((reply["run_id"], reply["stop_token"]))

    flooders = [threading.Thread(target=flood_one, args=(k,), daemon=True) for k in range(args.flood)]
    for t in flooders:
        t.start()
    for t in flooders:
        t.join(60)
    mates = [Student(f"mate{k}", f"127.0.2.{10 + k}", client, stats, args) for k in range(10)]
    run_phase(mates, [[("pi", PI, 31, None)] * 3 for _ in mates], "bad student", args.max_seconds)
    times = [r["to_final_s"] if r["to_final_s"] is not None else float("inf")
             for r in stats.runs if r["phase"] == "bad student"]
    for run_id, token in tokens:
        client.request("POST", f"/api/runs/{run_id}/stop", flood_source, body={},
                       headers={"X-Stop-Token": token}, timeout=30)
    p50, p99 = pct(times, 0.5), pct(times, 0.99)
    lost = sum(1 for x in times if x == float("inf"))
    print(f"one bad student: {args.flood} gas_1000 runs from one address under {args.flood} names at once: "
          f"answers {dict(answers)}; meanwhile {len(times)} classmates' pi runs, time to final p50 {p50:.3f} s, "
          f"p99 {p99:.3f} s, {lost} never final")
    print(f"goal: one bad student, classmates' small scenes p99 = {p99:.3f} s (goal <= {GOAL_P99_S:.0f} s, 0 lost): "
          f"{'met' if times and p99 <= GOAL_P99_S and lost == 0 else 'missed'}")


def classmate_send(client, args, name, source, answers):
    """One pi run of a classmate: appends (answer, seconds to it, run_id) to answers, the answer being
    "final", "refused <reason_name>", "lost" (accepted, never final) or "HTTP <status>"."""
    sent = time.monotonic()
    status, _, answer = client.request("POST", "/api/runs", source, dict(PI, student=name), timeout=args.post_timeout)
    try:
        reply = json.loads(answer) if status in (202, 422) else {}
    except ValueError:
        reply = {}
    if status == 422:
        reason = (reply.get("rejected") or {}).get("reason_name")
        answers.append((f"refused {reason}", time.monotonic() - sent, None))
        return
    if status != 202:
        answers.append((f"HTTP {status}", time.monotonic() - sent, None))
        return
    run_id = reply["run_id"]
    student = Student(name, source, client, Stats(), args)
    final, at = student.follow(run_id, sent + args.final_timeout)
    state = final.get("state") if final else None
    answers.append(("final" if state in FINAL_STATES else "lost", (at or time.monotonic()) - sent, run_id))


def bad_disk_phase(client, stats, args, lab):
    """The disk of the bag folder filled to the lab's floor plus args.disk_headroom MB; one address sends
    gas_1000 runs (bags of about 25 MB) while ten classmates send pi runs; then the disk is filled to 5 MB
    under the floor and the classmates send again, and again once the filler is deleted. Reports the
    classmates' time to an answer (final, or refused) and the phase's runs' states."""
    if not getattr(lab, "small_disk", False):
        print("bad disk: skipped (it needs a lab started here as root, whose bag folder is then a tmpfs; --disk-mb)")
        return
    floor = float(lab.param("collision_lab_node/min_free_space_mb", 100.0))
    space = os.statvfs(lab.bags)
    free_mb = space.f_bavail * space.f_frsize / 1e6
    filler = os.path.join(lab.bags, "filler")
    fill_mb = max(0.0, free_mb - floor - args.disk_headroom)
    with open(filler, "wb") as f:
        os.posix_fallocate(f.fileno(), 0, int(fill_mb * 1e6))
    flood_source, flood_answers, flood_runs = "127.0.0.251", collections.Counter(), []

    def flood_one(k):
        status, _, answer = client.request("POST", "/api/runs", flood_source, dict(GAS, student=f"disk{k:02d}"),
                                           timeout=args.post_timeout)
        flood_answers[str(status)] += 1
        if status == 202:
            flood_runs.append(json.loads(answer)["run_id"])

    answers = {"headroom": [], "under": [], "freed": []}

    def classmates(part):
        def one(k):
            for _ in range(3):
                classmate_send(client, args, f"dmate{k}", f"127.0.3.{10 + k}", answers[part])
        threads = [threading.Thread(target=one, args=(k,), daemon=True) for k in range(10)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(args.final_timeout + 60)

    flooders = [threading.Thread(target=flood_one, args=(k,), daemon=True) for k in range(4)]
    for t in flooders:
        t.start()
    classmates("headroom")
    for t in flooders:
        t.join(60)
    settle(client)
    space = os.statvfs(lab.bags)
    with open(filler, "ab") as f:  # now 5 MB under the floor
        os.posix_fallocate(f.fileno(), os.path.getsize(filler),
                           max(1, int(space.f_bavail * space.f_frsize - (floor - 5.0) * 1e6)))
    classmates("under")
    os.remove(filler)
    classmates("freed")
    settle(client)
    states = collections.Counter()
    for run_id in flood_runs + [r for part in answers.values() for _, _, r in part if r]:
        status, _, body = client.request("GET", f"/api/runs/{run_id}", "127.0.0.9", timeout=30)
        try:
            run = json.loads(body) if status == 200 else {}
        except ValueError:
            run = {}
        summary = run.get("summary") or {}
        states[f"{run.get('state', f'HTTP {status}')} {summary.get('stop_reason', '')}".strip()] += 1
    every = [t for part in answers.values() for _, t, _ in part]
    lost = sum(1 for part in answers.values() for a, _, _ in part if a == "lost" or a.startswith("HTTP 5"))
    p99 = pct(every, 0.99)
    for part, what in (("headroom", f"{args.disk_headroom:.0f} MB above the floor of {floor:.0f} MB, gas runs filling it"),
                       ("under", "5 MB under the floor"), ("freed", "after the filler was deleted")):
        got = collections.Counter(a for a, _, _ in answers[part])
        times = [t for _, t, _ in answers[part]]
        print(f"bad disk, {what}: classmates' {len(times)} pi sends answered {dict(got)}, time to the answer "
              f"p50 {pct(times, 0.5):.3f} s, p99 {pct(times, 0.99):.3f} s")
    print(f"bad disk: 4 gas_1000 runs from one address: answers {dict(flood_answers)}; the phase's runs now: "
          f"{dict(states)}")
    print(f"goal: bad disk, classmates' small scenes p99 time to their answer = {p99:.3f} s "
          f"(goal <= {GOAL_P99_S:.0f} s, 0 lost: {lost} lost): {'met' if every and p99 <= GOAL_P99_S and lost == 0 else 'missed'}")


if __name__ == "__main__":
    raise SystemExit(main())
