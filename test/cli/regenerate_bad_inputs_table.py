#!/usr/bin/env python3
"""Compares the catalogue of docs/bad_inputs.md with what the real CLI prints now.

The catalogue's expected columns (reason, code, field, stderr line) are written by hand, so
that a changed message is a decision and not a refresh. This script never writes them: it
runs every row from the repository root and prints, for each row whose output differs, the
documented line and the printed one. Review those by hand.

    test/cli/regenerate_bad_inputs_table.py build_ros/devel/lib/collision_lab/collision_lab_cli
"""
import pathlib
import shlex
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "bad_inputs.md"


def printed_line(cli, args_text):
    result = subprocess.run([cli] + shlex.split(args_text), cwd=ROOT, capture_output=True, text=True, timeout=60)
    return result.returncode, result.stderr.rstrip("\n")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    cli = str(pathlib.Path(sys.argv[1]).resolve())
    differences = 0
    for line in DOC.read_text().splitlines():
        cells = [cell.strip() for cell in line.split(" | ")]
        if not (line.startswith("| ") and len(cells) == 7 and cells[0][2:].isdigit()):
            continue
        documented = cells[6].rstrip(" |").strip("`")
        code, printed = printed_line(cli, cells[2].strip("`"))
        if code != 2 or printed != documented:
            differences += 1
            print(f"row {cells[0][2:]} ({cells[1]}): exit {code}\n  documented: {documented}\n  printed:    {printed}")
    print(f"{differences} rows differ")
    return 1 if differences else 0


if __name__ == "__main__":
    sys.exit(main())
