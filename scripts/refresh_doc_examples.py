#!/usr/bin/python3
"""Regenerates the example outputs in README.md and docs/*.md from the programs themselves.

An example is a marker line followed by a fenced code block:

    <!-- example: collision_lab_cli --name grazing --events none -->
    ```
    (replaced by "$ <command>" and the command's output)
    ```

The command runs from the repository root through bash, with the built executables
(build_ros/devel/lib/collision_lab) first on PATH and the devel space sourced, so roslaunch
and rosrun work too, and with pipefail, so that a failing command inside a pipe fails the
example. A command that fails, or prints nothing, leaves its block unchanged and makes the
script exit 1. Usage: scripts/refresh_doc_examples.py [FILE ...]  (default: README.md docs/*.md)
"""
import glob
import os
import re
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MARKER = re.compile(r"^<!-- example: (.*) -->$")
TIMEOUT_S = 300


def run(command):
    devel = os.path.join(REPO, "build_ros", "devel")
    script = (f"export PATH={devel}/lib/collision_lab:/usr/bin:/bin:$PATH; "
              f"source {devel}/setup.bash; set -o pipefail; {command}")
    result = subprocess.run(["bash", "-c", script], cwd=REPO, capture_output=True, text=True,
                            timeout=TIMEOUT_S)
    if result.returncode not in (0, 2):  # 2: a bad-input example shows its error on purpose
        raise RuntimeError(f"exit {result.returncode}: {result.stderr.strip()[-400:]}")
    output = (result.stdout + result.stderr).rstrip("\n")
    if not output.strip():
        raise RuntimeError("printed nothing (an example must show output)")
    return output


def refresh(path):
    lines = open(path).read().split("\n")
    out, i, failures = [], 0, 0
    while i < len(lines):
        out.append(lines[i])
        match = MARKER.match(lines[i])
        if match and i + 1 < len(lines) and lines[i + 1].startswith("```"):
            end = next((j for j in range(i + 2, len(lines)) if lines[j].startswith("```")), None)
            if end is None:
                raise SystemExit(f"{path}:{i + 1}: code block after the marker is not closed")
            command = match.group(1)
            try:
                body = [f"$ {command}"] + run(command).split("\n")
                print(f"{path}: {command}")
            except (RuntimeError, subprocess.TimeoutExpired) as error:
                print(f"{path}:{i + 1}: {command}: {error}", file=sys.stderr)
                body, failures = lines[i + 2:end], failures + 1
            out += [lines[i + 1]] + body + [lines[end]]
            i = end + 1
            continue
        i += 1
    open(path, "w").write("\n".join(out))
    return failures


def main():
    paths = sys.argv[1:] or [os.path.join(REPO, "README.md")] + sorted(
        glob.glob(os.path.join(REPO, "docs", "*.md")))
    failures = sum(refresh(p) for p in paths)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
