#!/usr/bin/env python3
"""Refreshes the catalogue table of docs/bad_inputs.md from the real CLI.

The catalogue's expected texts are written by hand (a changed message is a decision);
use this only to see what the CLI prints now, and review the diff before keeping any of it.

The rows' "Bad input" and "Arguments" columns are the source; reason, code, field and
message are rewritten from what collision_lab_cli prints when run from the repository root
(bad_inputs_test.cpp then checks them). To add a row, append it with any placeholder in
the last four columns and run:

    test/cli/regenerate_bad_inputs_table.py build/devel/lib/collision_lab/collision_lab_cli
"""
import json
import pathlib
import shlex
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "bad_inputs.md"


def run(cli, args):
    return subprocess.run([cli] + args, cwd=ROOT, capture_output=True, text=True, timeout=60)


def refreshed_row(cli, number, label, args_text):
    args = shlex.split(args_text)
    plain = run(cli, args)
    line = plain.stderr.rstrip("\n")
    if plain.returncode != 2 or plain.stdout or "\n" in line:
        sys.exit(f"row {number} ({args_text}): expected exit 2 and one stderr line, got {plain.returncode}")
    # The JSON document names reason, code and field; --format rows are parsed from the line.
    if "--format" in args:
        prefix, rest = line[len("collision_lab_cli: invalid "):].split(" (", 1)
        reason = rest.split(")", 1)[0]
        code = {"INVALID_OPTION": 104, "USAGE": 100}[reason]
        field = prefix
    else:
        error = json.loads(run(cli, args + ["--format", "json"]).stdout)["error"]
        reason, code, field = error["reason"], error["code"], error["field"]
    return f"| {number} | {label} | `{args_text}` | {reason} | {code} | `{field}` | `{line}` |"


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    cli = str(pathlib.Path(sys.argv[1]).resolve())
    lines = DOC.read_text().splitlines()
    for i, line in enumerate(lines):
        cells = [cell.strip() for cell in line.split(" | ")]
        if line.startswith("| ") and len(cells) == 7 and cells[0][2:].isdigit():
            lines[i] = refreshed_row(cli, int(cells[0][2:]), cells[1], cells[2].strip("`"))
    DOC.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
