#!/usr/bin/env python3
"""Writes the "goal:" lines of one run of bench/run_benchmarks.sh as a markdown table.

Each benchmark prints a goal as one line:
  goal: <what> = <figure> against <anchor> = <anchor figure> (<ratio; goal>): met|missed
Lines that do not follow the pattern are kept whole in the table's first column, so nothing
printed is lost. A missed goal may be followed by lines
  why: <what was measured to find out where the time goes>
which are listed under the table, each with its goal.

Usage: goals_table.py --log LOG --source COMMIT --out FILE.md
"""
import argparse
import re
import sys

GOAL = re.compile(r"^goal: (?P<what>.+) = (?P<figure>[^=]+?) against (?P<anchor>.+?) = (?P<anchor_figure>[^(]+?) "
                  r"\((?P<terms>.*)\): (?P<status>met|missed)\s*$")


def rows(log_lines):
    """The goals in order, each as [what, figure, anchor, anchor's figure, terms, status, whys]."""
    table = []
    for line in log_lines:
        if line.startswith("why:") and table:
            table[-1][6].append(line[len("why:"):].strip())
            continue
        if not line.startswith("goal:"):
            continue
        match = GOAL.match(line)
        if match:
            table.append([match[k] for k in ("what", "figure", "anchor", "anchor_figure", "terms", "status")] + [[]])
        else:
            table.append([line[len("goal:"):].strip(), "", "", "", "", "", []])
    return table


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", required=True)
    parser.add_argument("--source", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    with open(args.log, encoding="utf-8") as log:
        table = rows(log)
    if not table:
        sys.exit(f"goals_table.py: no goal lines in {args.log}")
    met = sum(row[5] == "met" for row in table)
    with open(args.out, "w", encoding="utf-8") as out:
        out.write("# Speed goals, each with its anchor from the same run\n\n")
        out.write(f"*Written by `bash bench/run_benchmarks.sh` on {args.source}: {met} of {len(table)} goals met. "
                  "Shared 2-core machine; each figure and its anchor come from the same process or launch.*\n\n")
        out.write("| goal | figure | anchor | anchor's figure | ratio; target | |\n|---|---|---|---|---|---|\n")
        for row in table:
            out.write("| " + " | ".join(cell.replace("|", "\\|") for cell in row[:6]) + " |\n")
        explained = [row for row in table if row[6]]
        if explained:
            out.write("\n## Where the time goes in the missed goals (measured in the same run)\n\n")
            for row in explained:
                out.write(f"- **{row[0]}**\n")
                for why in row[6]:
                    out.write(f"  - {why}\n")


if __name__ == "__main__":
    main()
