#!/usr/bin/env python3
"""Plot docs/restitution_count.csv: impacts against e for three equal masses across r_c.

Left: the whole range 0.05 <= e <= 1 (log count; collapses, with infinitely many impacts,
drawn as crosses at the top). Right: the count against e - r_c > 0 on a log axis, where it
grows like 1/sqrt(e - r_c) (the spiral angle phi shrinks), with the engine's count where an
exact simulation reaches the end.

Usage: python3 bench/plot_restitution_count.py --csv FILE --out FILE.png
Needs matplotlib (Debian: python3-matplotlib).
"""
import argparse
import csv
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--csv", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    rows = list(csv.DictReader(open(args.csv)))
    finite = [r for r in rows if r["collapsed"] == "0"]
    collapsed = [r for r in rows if r["collapsed"] == "1"]
    # Runs stopped at the engine's exactness cap (truncated) are not counts: left out.
    engine = [r for r in rows if r["engine_count"] not in ("", None) and r["engine_collapsed"] == "0"
              and r.get("engine_truncated") != "1"]
    rc = float(rows[0]["e"]) - float(rows[0]["e_minus_rc"])
    top = max(int(r["model_count"]) for r in finite) * 3

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.6))
    left.semilogy([float(r["e"]) for r in finite], [int(r["model_count"]) for r in finite], "o-", ms=3,
                  color="#2166ac", label="three_body_spiral prediction")
    left.semilogy([float(r["e"]) for r in engine], [int(r["engine_count"]) for r in engine], "s", mfc="none",
                  color="#e66101", label="exact engine")
    left.semilogy([float(r["e"]) for r in collapsed], [top] * len(collapsed), "x", color="#b2182b",
                  label="collapse (infinitely many impacts)")
    left.axvline(rc, color="gray", ls="--", lw=1)
    left.text(rc, top / 8, "  r_c = 7 - 4 sqrt 3", color="gray")
    left.set_xlabel("restitution e")
    left.set_ylabel("impacts")
    left.set_title("three equal masses, x = (2, 1, 0) m, v = (-1, 0, 0) m/s")
    left.legend(fontsize=8)

    above = [r for r in finite if float(r["e_minus_rc"]) > 0]
    right.loglog([float(r["e_minus_rc"]) for r in above], [int(r["model_count"]) for r in above], "o-", ms=3,
                 color="#2166ac", label="prediction")
    right.loglog([float(r["e_minus_rc"]) for r in engine if float(r["e_minus_rc"]) > 0],
                 [int(r["engine_count"]) for r in engine if float(r["e_minus_rc"]) > 0], "s", mfc="none",
                 color="#e66101", label="exact engine")
    xs = [10 ** (-k / 4) for k in range(4, 37)]
    x0 = float(above[0]["e_minus_rc"])
    c0 = int(above[0]["model_count"]) * math.sqrt(x0)
    right.loglog(xs, [c0 / math.sqrt(x) for x in xs], ":", color="gray", label="~ 1 / sqrt(e - r_c)")
    right.set_xlabel("e - r_c")
    right.set_ylabel("impacts")
    right.set_title("just above r_c: the spiral turns ever more slowly")
    right.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
