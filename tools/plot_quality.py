#!/usr/bin/python3
"""Plots for docs/benchmarks.md from `posefair bench quality` output.

    build/tools/posefair bench quality -o build/bench-quality
    /usr/bin/python3 tools/plot_quality.py build/bench-quality docs/img

One panel per data set: error against lag and jitter against lag, every configuration of
every family (the lower-left corner is best). Needs python3-matplotlib.
"""
import csv
import math
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "posefair": dict(color="C0", marker="o", s=10, alpha=0.5),
    "posefair-gn": dict(color="C2", marker="^", s=14, alpha=0.7),
    "posefair-sweeps": dict(color="C4", marker="s", s=14, alpha=0.8),
    "one-euro": dict(color="C1", marker="x", s=14, alpha=0.6),
    "slerp": dict(color="C3", marker="+", s=20, alpha=0.8),
    "raw": dict(color="k", marker="*", s=80, alpha=1.0),
}


def main():
    src, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    runs = defaultdict(lambda: defaultdict(list))
    with open(src / "quality-runs.csv", newline="") as f:
        for row in csv.DictReader(f):
            runs[row["dataset"]][row["family"]].append(row)
    for metric, label, name in (("error", "error (rad; BROAD: rad/s vs gyro)", "quality-error-vs-lag.png"),
                                ("jitter", "jitter, RMS angular acceleration (rad/s²)", "quality-jitter-vs-lag.png")):
        sets = list(runs)
        cols = 3
        rows = math.ceil(len(sets) / cols)
        fig, axes = plt.subplots(rows, cols, figsize=(5 * cols, 3.6 * rows), squeeze=False)
        for ax, ds in zip(axes.flat, sets):
            raw = runs[ds]["raw"][0]
            for fam, rs in runs[ds].items():
                xs = [float(r["lag_ms"]) for r in rs]
                ys = [float(r[metric]) for r in rs]
                ax.scatter(xs, ys, label=fam, **STYLE.get(fam, {}))
            ax.set_yscale("log")
            top = float(raw[metric]) * 3
            ax.set_ylim(top=top)
            ax.set_xlim(-2, 60)
            ax.set_title(ds, fontsize=9)
            ax.set_xlabel("measured lag (ms)")
            ax.set_ylabel(label, fontsize=8)
        for ax in list(axes.flat)[len(sets):]:
            ax.axis("off")
        axes.flat[0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(out / name, dpi=90)
        plt.close(fig)
        print("wrote", out / name)


if __name__ == "__main__":
    main()
