#!/usr/bin/python3
"""Plots for docs/fusion.md from `posefair bench fusion` output.

    build/tools/posefair bench fusion -o build/bench-fusion
    /usr/bin/python3 tools/plot_fusion.py build/bench-fusion docs/img

fusion-9d.png: total RMSE per BROAD trial in 9D (BROAD's published Madgwick figure, ours, Mahony,
VQF); fusion-6d.png: inclination RMSE per trial in 6D. Needs python3-matplotlib.
"""
import csv
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    """{mode: {method: {trial: value}}} (9D: total, 6D: inclination) and the published figures."""
    values = defaultdict(lambda: defaultdict(dict))
    published = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            key = "total_deg" if row["mode"] == "9D" else "inclination_deg"
            values[row["mode"]][row["method"]][row["trial"]] = float(row[key])
            if row["published_madgwick_total_deg"]:
                published[row["trial"]] = float(row["published_madgwick_total_deg"])
    return values, published


def bars(ax, series, trials):
    width = 0.8 / len(series)
    for i, (label, by_trial) in enumerate(series):
        xs = [t + (i - (len(series) - 1) / 2) * width for t in range(len(trials))]
        ax.bar(xs, [by_trial.get(t, float("nan")) for t in trials], width, label=label)
    ax.set_xticks(range(len(trials)))
    ax.set_xticklabels(trials)
    ax.set_xlabel("BROAD trial")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=8)


def main():
    src, out = Path(sys.argv[1]), Path(sys.argv[2])
    values, published = read(src / "fusion-trials.csv")
    trials = sorted({t for m in values["9D"].values() for t in m})
    for mode, ylabel, name in (("9D", "total RMSE (°)", "fusion-9d.png"),
                               ("6D", "inclination RMSE (°)", "fusion-6d.png")):
        series = [("BROAD's published Madgwick", published)] if mode == "9D" else []
        series += sorted(values[mode].items())
        fig, ax = plt.subplots(figsize=(9, 4))
        bars(ax, series, trials)
        ax.set_ylabel(ylabel)
        ax.set_title(f"BROAD, {mode}: one parameter set for all trials")
        fig.tight_layout()
        fig.savefig(out / name, dpi=110)
        print("wrote", out / name)


if __name__ == "__main__":
    main()
