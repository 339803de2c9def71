#!/usr/bin/env python3
"""Plot docs/speed_vs_error.csv: wall time against error, log-log.

Two panels per scene, two scenes per row: final-velocity relative error, then trajectory
error (max |x - x_exact| at the scene's end time). One series per method; stepped methods
are swept over dt (smaller dt = further right). Exact zeros sit on a floor line; runs that
got the collision count wrong are crossed out. Rows with a note (the method cannot answer
the scene) have no numbers and are left out.

Usage: plot_speed_vs_error.py --csv FILE --out FILE.png [--title-suffix TEXT]
Needs matplotlib (Debian: python3-matplotlib).
"""
import argparse
import csv
import math
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

FLOOR = 1e-17  # where exact zeros are drawn
STYLE = OrderedDict([
    ("closed_form", dict(color="#2166ac", marker="*", label="closed_form (ours, no positions)")),
    ("nbody_engine", dict(color="#35978f", marker="P", label="nbody_engine, exact N-body engine (ours)")),
    ("model", dict(color="#4393c3", marker="X", label="model, closed form of the scene (ours, no positions)")),
    ("fixed_step", dict(color="#636363", marker="v", label="fixed_step (hand-written), dt sweep")),
    ("bullet", dict(color="#e66101", marker="^", label="Bullet, dt sweep")),
    ("ode", dict(color="#b2182b", marker="<", label="ODE, dt sweep")),
    ("box2d", dict(color="#762a83", marker=">", label="Box2D, dt sweep")),
])
METRICS = [
    ("velocity_rel_error", "final-velocity relative error", 1e-12),
    ("position_abs_error", "trajectory error max|x - x_exact| [m]", 1e-9),
]


def number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--csv", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--title-suffix", default="")
    args = parser.parse_args()

    with open(args.csv, newline="") as f:
        rows = [r for r in csv.DictReader(f) if not r.get("note")]
    scenes = list(OrderedDict.fromkeys(r["scene"] for r in rows))
    methods = [m for m in STYLE if any(r["method"] == m for r in rows)]
    methods += sorted({r["method"] for r in rows} - set(methods))

    per_row = 2  # scenes side by side
    nrows = (len(scenes) + per_row - 1) // per_row
    header = 1.9  # inches above the panels for the title and the legend
    height = 2.9 * nrows + header
    fig, axes = plt.subplots(nrows, 2 * per_row, figsize=(22, height), squeeze=False)
    for i, scene in enumerate(scenes):
        for j, (metric, ylabel, goal) in enumerate(METRICS):
            ax = axes[i // per_row][2 * (i % per_row) + j]
            for method in methods:
                pts = [r for r in rows if r["scene"] == scene and r["method"] == method]
                pts = [r for r in pts if not math.isnan(number(r[metric]))]
                if not pts:
                    continue
                # Stepped methods in sweep order (dt falling); the others by time.
                stepped = all(not math.isnan(number(r["parameter"])) for r in pts)
                pts.sort(key=lambda r: -number(r["parameter"]) if stepped else number(r["wall_time_s"]))
                x = [number(r["wall_time_s"]) for r in pts]
                y = [max(number(r[metric]), FLOOR) for r in pts]
                style = STYLE.get(method, dict(marker="o", label=method))
                ax.plot(x, y, linestyle="-", linewidth=1.2, markersize=6, alpha=0.9,
                        color=style.get("color"), marker=style["marker"])
                if method == "fixed_step":
                    for xx, yy, r in zip(x, y, pts):
                        ax.annotate("dt " + r["parameter"], (xx, yy), textcoords="offset points",
                                    xytext=(0, 5), fontsize=6, color="#636363", ha="center")
                bad = [(xx, yy) for xx, yy, r in zip(x, y, pts) if int(r["count_error"]) != 0]
                if bad:
                    ax.plot([b[0] for b in bad], [b[1] for b in bad], linestyle="none", marker="x",
                            color="black", markersize=11, markeredgewidth=2)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_ylim(FLOOR / 5, 1e3)
            ax.axhline(FLOOR, color="black", linestyle=":", linewidth=0.8)
            ax.text(1.0, FLOOR, " exact (0)", transform=ax.get_yaxis_transform(), fontsize=7,
                    va="bottom", ha="right")
            ax.axhline(goal, color="#2166ac", linestyle="--", linewidth=0.8)
            ax.text(0.0, goal, f" goal {goal:g}", transform=ax.get_yaxis_transform(), fontsize=7,
                    va="bottom", ha="left", color="#2166ac")
            ax.grid(True, which="major", linewidth=0.3)
            ax.set_title(f"{scene}: {ylabel}", fontsize=9)
            ax.tick_params(labelsize=7)
            if i >= len(scenes) - per_row:
                ax.set_xlabel("wall time per run [s] (median)", fontsize=8)
    for k in range(len(scenes), nrows * per_row):  # an odd scene count leaves two panels empty
        for j in range(2):
            axes[k // per_row][2 * (k % per_row) + j].axis("off")

    handles = [Line2D([], [], color=STYLE[m].get("color"), marker=STYLE[m]["marker"], label=STYLE[m]["label"])
               for m in methods if m in STYLE]
    handles.append(Line2D([], [], color="black", marker="x", linestyle="none", markersize=9,
                          markeredgewidth=2, label="wrong collision count"))
    fig.tight_layout()
    fig.subplots_adjust(top=1.0 - header / height)
    fig.suptitle("Speed against error: exact event-driven simulation vs time stepping"
                 + args.title_suffix + "\nlower left is better; each stepped series goes right as dt shrinks "
                 "(1e-2 ... 1e-6 s; real engines to 1e-5 s on the N-body and restitution scenes)", fontsize=12, y=1.0 - 0.05 / height, va="top")
    fig.legend(handles=handles, loc="upper center", ncol=5, fontsize=9, frameon=False,
               bbox_to_anchor=(0.5, 1.0 - 0.5 / height))
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
