#!/usr/bin/python3
"""docs/web.md's commands run as written: each exits 0 and prints what the page shows.

The page's fenced code blocks hold commands, each on a line starting with "$ " (continued
by lines ending in "\\"), followed by its documented output. In the output, "..." stands for
any text within a line, and a line that is only "..." for any lines. A block with a
language (```json) is not run; a block without one must hold commands.

- A `roslaunch` serves until stopped: it runs in the background, and its documented lines
  must appear in its output, in order (each within a line), within kLaunchTimeout. The next
  roslaunch stops the one before, and the last one serves the commands after it.
- Every other command runs in one bash session, in order (so variables carry over), with
  pipefail, and must exit 0 within kCommandTimeout and print exactly what is documented.

What the test changes, and only that: the web port 8080 becomes a free port (in commands
and outputs; roslaunch gets web_port:=), the ROS master its own free port, HOME and
ROS_HOME a fresh folder (so the run index is empty and ana's first run is ana.run1), and
DISPLAY is unset (no rviz).

Besides the page's commands, against the node the page started: a scene of 800 bodies
(about 20 KB, over the 8 KiB that cpp-httplib allowed form-encoded bodies before issue 30)
is refused for its type (415), not its size (413), and accepted with the JSON header.

Usage: web_md_commands_test.py --doc docs/web.md --setup <devel>/setup.bash
       [--gtest_output=xml:FILE] [--text]
"""
import argparse
import json
import os
import queue
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import urllib.error
import urllib.request

kLaunchTimeout = 90.0  # [s] for a roslaunch to print its documented lines
kCommandTimeout = 120.0  # [s] for one command to end
kDocPort = "8080"
kDone = "__web_md_command_done__"
kAnsi = re.compile(r"\x1b\[[0-9;]*m")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Command:
    def __init__(self, line, text):
        self.line = line  # 1-based line of the doc where it starts
        self.text = text
        self.expected = []


def parse_commands(path):
    """Every command of the doc's code blocks with its documented output."""
    commands, problems = [], []
    lines = open(path).read().split("\n")
    i = 0
    while i < len(lines):
        fence = lines[i]
        if not fence.startswith("```"):
            i += 1
            continue
        end = next((j for j in range(i + 1, len(lines)) if lines[j].startswith("```")), None)
        if end is None:
            problems.append(f"{path}:{i + 1}: a code block is not closed")
            break
        body = lines[i + 1:end]
        if fence.strip() == "```":
            if not any(line.startswith("$ ") for line in body):
                problems.append(f"{path}:{i + 1}: a code block without a language holds no '$ ' command")
            k = 0
            while k < len(body):
                if not body[k].startswith("$ "):
                    problems.append(f"{path}:{i + 2 + k}: output before any command: {body[k]!r}")
                    k += 1
                    continue
                command = Command(i + 2 + k, body[k][2:])
                while command.text.endswith("\\") and k + 1 < len(body):
                    k += 1
                    command.text += "\n" + body[k]
                k += 1
                while k < len(body) and not body[k].startswith("$ "):
                    command.expected.append(body[k])
                    k += 1
                commands.append(command)
        i = end + 1
    return commands, problems


def output_pattern(expected):
    """The documented output as a regex: "..." any text in a line, a line "..." any lines."""
    parts = []
    for line in expected:
        if line.strip() == "...":
            parts.append(r"(?:[^\n]*\n)*?")
        else:
            parts.append(".*?".join(re.escape(piece) for piece in line.split("...")) + r"\n")
    return re.compile("".join(parts))


def line_pattern(line):
    return re.compile(".*?".join(re.escape(piece) for piece in line.split("...")))


class Reader(threading.Thread):
    """Reads a pipe line by line into a queue (and a log), so that reads can time out."""

    def __init__(self, pipe):
        super().__init__(daemon=True)
        self.pipe, self.lines, self.log = pipe, queue.Queue(), []
        self.start()

    def run(self):
        for line in iter(self.pipe.readline, ""):
            self.log.append(line)
            self.lines.put(line)
        self.lines.put(None)

    def next_line(self, deadline):
        return self.lines.get(timeout=max(0.0, deadline - time.monotonic()))


class Session:
    """The doc's commands as a reader would type them, in one bash and beside one launch."""

    def __init__(self, setup, env, port):
        self.env, self.port, self.launch, self.launch_reader = env, port, None, None
        self.bash = subprocess.Popen(["bash", "--noprofile", "--norc"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env,
                                     start_new_session=True)
        self.reader = Reader(self.bash.stdout)
        self.bash.stdin.write(f"source {setup}\nset -o pipefail\n")
        self.bash.stdin.flush()

    def local(self, text):
        return text.replace(":" + kDocPort, ":" + str(self.port))

    def run(self, command):
        """None when the command did what the doc says; else what went wrong."""
        text = self.local(command.text)
        expected = [self.local(line) for line in command.expected]
        if text.startswith("roslaunch "):
            return self.start_launch(text, expected)
        self.bash.stdin.write(f"{{ {text}\n}} < /dev/null; printf '\\n{kDone} %s\\n' \"$?\"\n")
        self.bash.stdin.flush()
        deadline, out = time.monotonic() + kCommandTimeout, []
        while True:
            try:
                line = self.reader.next_line(deadline)
            except queue.Empty:
                return f"no end within {kCommandTimeout} s; printed so far:\n{''.join(out)}"
            if line is None:
                return f"bash ended; printed:\n{''.join(out)}"
            if line.startswith(kDone):
                status = int(line.split()[1])
                break
            out.append(line)
        printed = "".join(out)
        printed = printed[:-1] if printed.endswith("\n") else printed  # the marker's own newline
        if status != 0:
            return f"exit {status}; printed:\n{printed}"
        actual = printed.rstrip("\n") + "\n" if printed.strip() else ""
        if not output_pattern(expected).fullmatch(actual):
            return "printed:\n" + actual + "but the doc shows:\n" + "\n".join(expected)
        return None

    def start_launch(self, text, expected):
        self.stop_launch()
        if "web_port:=" not in text:
            text += f" web_port:={self.port}"
        self.launch = subprocess.Popen(["bash", "-c", "exec " + text], stdout=subprocess.PIPE,
                                       stderr=subprocess.STDOUT, text=True, env=self.env, start_new_session=True)
        self.launch_reader = Reader(self.launch.stdout)
        wanted = [line_pattern(line) for line in expected if line.strip() != "..."]
        deadline = time.monotonic() + kLaunchTimeout
        while wanted:
            try:
                line = self.launch_reader.next_line(deadline)
            except queue.Empty:
                break
            if line is None:
                break
            if wanted[0].search(kAnsi.sub("", line)):
                wanted.pop(0)
        if wanted:
            return (f"never printed {wanted[0].pattern!r} within {kLaunchTimeout} s; printed:\n" +
                    kAnsi.sub("", "".join(self.launch_reader.log[-40:])))
        return None

    def stop_launch(self):
        if self.launch is None:
            return
        os.killpg(self.launch.pid, signal.SIGINT)
        try:
            self.launch.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(self.launch.pid, signal.SIGKILL)
            self.launch.wait()
        self.launch = None

    def close(self):
        self.stop_launch()
        self.bash.stdin.close()
        try:
            self.bash.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(self.bash.pid, signal.SIGKILL)
            self.bash.wait()


class WebMdCommands(unittest.TestCase):
    doc = setup = None

    @classmethod
    def setUpClass(cls):
        cls.home = tempfile.mkdtemp(prefix="web_md_commands_")
        env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
        env.update(HOME=cls.home, ROS_HOME=os.path.join(cls.home, ".ros"),
                   ROS_MASTER_URI=f"http://127.0.0.1:{free_port()}",
                   PATH="/usr/bin:/bin:" + env.get("PATH", ""))
        cls.port = free_port()
        cls.commands, cls.problems = parse_commands(cls.doc)
        cls.session = Session(cls.setup, env, cls.port)
        cls.failures = []
        for command in cls.commands:
            problem = cls.session.run(command)
            if problem:
                cls.failures.append(f"{cls.doc}:{command.line}: $ {command.text}\n{problem}")

    @classmethod
    def tearDownClass(cls):
        cls.session.close()
        shutil.rmtree(cls.home, ignore_errors=True)

    def test_every_command_runs_as_written(self):
        self.assertEqual(self.problems, [])
        self.assertGreaterEqual(len(self.commands), 10, "the page's commands were not found")
        self.assertTrue(any(c.text.startswith("roslaunch ") for c in self.commands))
        self.assertTrue(any(c.text.startswith("curl ") for c in self.commands))
        self.assertEqual(self.failures, [], "\n\n".join(self.failures))

    def post(self, body, headers):
        request = urllib.request.Request(f"http://127.0.0.1:{self.port}/api/runs", data=body, method="POST",
                                         headers=dict(headers, **{"X-Class-Code": "maple"}))
        try:
            with urllib.request.urlopen(request, timeout=60) as answer:
                return answer.status, json.loads(answer.read())
        except urllib.error.HTTPError as error:
            return error.code, json.loads(error.read())

    def test_a_large_scene_is_refused_for_its_type_not_its_size(self):
        n = 800
        scene = {"student": "cleo", "masses": [1.0 + i / n for i in range(n)],
                 "positions": [float(n - i) for i in range(n)],
                 "velocities": [round((-1) ** i * 0.123456789 * (1 + i / n), 9) for i in range(n)],
                 "max_collisions": 100}
        body = json.dumps(scene).encode()
        self.assertGreater(len(body), 16 * 1024)
        status, answer = self.post(body, {"Content-Type": "application/x-www-form-urlencoded"})  # curl's -d
        self.assertEqual(status, 415, answer)
        self.assertIn("Content-Type: application/json", answer["error"])
        status, answer = self.post(body, {"Content-Type": "application/json"})
        self.assertEqual(status, 202, answer)
        self.assertTrue(answer["run_id"].startswith("cleo."), answer)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--doc", required=True)
    parser.add_argument("--setup", required=True, help="the devel space's setup.bash")
    args, rest = parser.parse_known_args()
    WebMdCommands.doc, WebMdCommands.setup = os.path.abspath(args.doc), os.path.abspath(args.setup)
    import rosunit
    rosunit.unitrun("collision_lab", "web_md_commands", WebMdCommands, sysargs=[sys.argv[0]] + rest)


if __name__ == "__main__":
    main()
