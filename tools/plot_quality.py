#!/usr/bin/python3
"""Plots for docs/benchmarks.md from `posefair bench quality` output.

    build/tools/posefair bench quality -o build/bench-quality
    /usr/bin/python3 tools/plot_quality.py build/bench-quality docs/img

quality-error-vs-lag.png, quality-jitter-vs-lag.png: one panel per data set, every
configuration of every family at its mean over the report sequences: error at the best
alignment (view b) or jitter against lag (b); the fixed rows (raw, the two defaults) as large
markers, the lag budgets as dotted lines. The lower-left corner is best.
quality-prediction.png: prediction error against horizon, one line per predictor, the tuned
One Euro at its configuration picked on the training split. Needs python3-matplotlib.
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
    "posefair-gn": dict(color="C2", marker="^", s=12, alpha=0.6),
    "posefair-sweeps": dict(color="C4", marker="s", s=12, alpha=0.6),
    "posefair-bound": dict(color="C5", marker="D", s=12, alpha=0.6),
    "one-euro": dict(color="C1", marker="x", s=14, alpha=0.6),
    "slerp": dict(color="C3", marker="+", s=20, alpha=0.8),
    "raw": dict(color="k", marker="*", s=90, alpha=1.0),
    "posefair-default": dict(color="C0", marker="P", s=110, alpha=1.0, edgecolors="k"),
    "one-euro-default": dict(color="C1", marker="X", s=110, alpha=1.0, edgecolors="k"),
}
PREDICTION_STYLE = {
    "hold": dict(color="k", linestyle=":", marker="."),
    "dead-reckoning": dict(color="C2", marker="^"),
    "slerp-extrapolation": dict(color="C3", marker="+", linestyle="--"),
    "one-euro-dr-default": dict(color="C1", marker="X", linestyle=":"),
    "one-euro-dr": dict(color="C1", marker="x"),
    "posefair-default": dict(color="C0", marker="P", linewidth=2),
}
BUDGETS_MS = (0.0, 10.0, 30.0)


def mean(xs):
    return sum(xs) / len(xs)


def report_means(path):
    """{dataset: {family: [(config, mean lag, mean error_b, mean jitter)]}} over report sequences."""
    acc = defaultdict(lambda: defaultdict(list))
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if "report" not in row["role"]:
                continue
            acc[row["dataset"]][(row["family"], row["config"])].append(row)
    out = defaultdict(lambda: defaultdict(list))
    for ds, configs in acc.items():
        for (fam, config), rows in configs.items():
            vals = [[float(r[k]) for r in rows] for k in ("lag_ms", "error_aligned", "jitter")]
            if any(not math.isfinite(v) for vs in vals for v in vs):
                continue
            out[ds][fam].append((config, mean(vals[0]), mean(vals[1]), mean(vals[2])))
    return out


def scatter(runs, out, metric, label, name):
    sets = list(runs)
    cols = 3
    rows = math.ceil(len(sets) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5 * cols, 3.6 * rows), squeeze=False)
    index = 2 if metric == "error" else 3
    for ax, ds in zip(axes.flat, sets):
        for fam, pts in runs[ds].items():
            ax.scatter([p[1] for p in pts], [p[index] for p in pts], label=fam, **STYLE.get(fam, {}))
        for b in BUDGETS_MS:
            ax.axvline(b, color="0.6", linestyle=":", linewidth=0.8)
        raw = runs[ds]["raw"][0][index]
        ax.set_yscale("log")
        ax.set_ylim(top=raw * 3)
        ax.set_xlim(-5, 60)
        ax.set_title(ds, fontsize=9)
        ax.set_xlabel("lag (b), ms")
        ax.set_ylabel(label, fontsize=8)
    for ax in list(axes.flat)[len(sets):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(out / name, dpi=90)
    plt.close(fig)
    print("wrote", out / name)


def prediction(path, out, name):
    series = defaultdict(lambda: defaultdict(list))
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            series[row["dataset"]][row["family"]].append((float(row["horizon_ms"]), float(row["error_mean"])))
    sets = list(series)
    if not sets:
        return
    cols = 3
    rows = math.ceil(len(sets) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(5 * cols, 3.4 * rows), squeeze=False)
    for ax, ds in zip(axes.flat, sets):
        for fam, pts in series[ds].items():
            pts.sort()
            ax.plot([p[0] for p in pts], [p[1] for p in pts], label=fam, **PREDICTION_STYLE.get(fam, {}))
        ax.set_yscale("log")
        ax.set_title(ds, fontsize=9)
        ax.set_xlabel("horizon h (ms)")
        ax.set_ylabel("RMS error at t + h (rad)", fontsize=8)
        ax.set_xticks([10, 20, 30])
    for ax in list(axes.flat)[len(sets):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(out / name, dpi=90)
    plt.close(fig)
    print("wrote", out / name)


def main():
    src, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    runs = report_means(src / "quality-runs.csv")
    scatter(runs, out, "error", "error (b): rad; BROAD rad/s vs gyro", "quality-error-vs-lag.png")
    scatter(runs, out, "jitter", "jitter, RMS angular acceleration (rad/s²)", "quality-jitter-vs-lag.png")
    prediction(src / "quality-prediction-summary.csv", out, "quality-prediction.png")


if __name__ == "__main__":
    main()
