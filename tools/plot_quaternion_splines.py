#!/usr/bin/python3
"""Plots for docs/quaternion-splines.md from CSV written by `posefair spline`.

Runs the posefair binary on docs/examples/quaternion-splines-7keys.txt (the 7-keyframe example),
keeps its --stages-csv / --trace-csv output in DATA_DIR, and draws docs/img/quaternion-splines-*.png:
  objective.png  objective after each stage against algorithm time (Fig. 3), both optimisers,
                 with the optimum estimated with 54 variable frames
  norm.png       |q| - 1 along the path: unoptimised, alpha 1000 with 4 frames, alpha 1e4 with 24 (Fig. 4)
  el.png         |EL| along the path before and after optimisation (Fig. 5)

Usage: /usr/bin/python3 tools/plot_quaternion_splines.py BUILD_DIR [DATA_DIR]
  e.g. /usr/bin/python3 tools/plot_quaternion_splines.py build /tmp/qs-data
"""
import csv
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KEYS = os.path.join(ROOT, "docs", "examples", "quaternion-splines-7keys.txt")
IMG = os.path.join(ROOT, "docs", "img")


def run(binary, data, name, *args):
    stages = os.path.join(data, name + "-stages.csv")
    trace = os.path.join(data, name + "-trace.csv")
    out = os.path.join(data, name + "-curve.txt")
    cmd = [binary, "spline", KEYS, "-o", out, "--rate", "200", "--stages-csv", stages, "--trace-csv", trace, *args]
    subprocess.run(cmd, check=True, stderr=subprocess.DEVNULL)
    return read(stages), read(trace)


def fastest(binary, data, name, repeats, *args):
    """The stages of `repeats` identical runs with each stage's smallest time: on a shared
    machine single runs are stretched by preemption; the optimiser itself is deterministic."""
    best, trace = run(binary, data, name, *args)
    for _ in range(repeats - 1):
        s, _ = run(binary, data, name, *args)
        assert s["objective"] == best["objective"]
        best["seconds"] = [min(a, b) for a, b in zip(best["seconds"], s["seconds"])]
    return best, trace


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    binary = os.path.join(sys.argv[1], "tools", "posefair")
    data = sys.argv[2] if len(sys.argv) > 2 else os.path.join(sys.argv[1], "quaternion-splines-data")
    os.makedirs(data, exist_ok=True)
    os.makedirs(IMG, exist_ok=True)

    lbfgs, lbfgs_trace = fastest(binary, data, "alpha1000-4frames-lbfgs", 15, "--frames", "4")
    slsqp, _ = fastest(binary, data, "alpha1000-4frames-slsqp", 15, "--frames", "4", "--optimizer", "slsqp")
    optimum, _ = run(binary, data, "alpha1000-optimum", "--segments", "10", "--frames", "54", "--frames-per-round", "54")
    _, fine_trace = run(binary, data, "alpha10000-24frames", "--alpha", "10000", "--frames", "24", "--frames-per-round", "24")
    best = optimum["objective"][-1]

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for s, label, style in ((lbfgs, "L-BFGS", "o-"), (slsqp, "SLSQP", "s--")):
        ax.plot([1e3 * t for t in s["seconds"]], s["objective"], style, label=label)
    ax.axhline(best, color="k", lw=0.8, label="optimum estimate (54 variable frames) %.5f" % best)
    ax.axhline(best * 1.001, color="k", lw=0.8, ls=":", label="0.1 % above it")
    ax.set_xscale("log")
    ax.set_xlabel("algorithm time, fastest of 15 runs (ms)\nstages: none, velocities, +1 ... +4 variable frames")
    ax.set_ylabel("objective (eq. 3)")
    ax.set_ylim(best * 0.99, lbfgs["objective"][1] * 1.02)
    ax.annotate("unoptimised (off scale): %.2f" % lbfgs["objective"][0], xy=(0.02, 0.03), xycoords="axes fraction")
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title("7-keyframe example, alpha = 1000")
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, "quaternion-splines-objective.png"), dpi=110)

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    t = lbfgs_trace["t"]
    ax.plot(t, [n - 1 for n in lbfgs_trace["norm_initial"]], "b:", label="unoptimised")
    ax.plot(t, [n - 1 for n in lbfgs_trace["norm_final"]], "m-.", label="alpha 1000, 4 variable frames")
    ax.plot(fine_trace["t"], [n - 1 for n in fine_trace["norm_final"]], "r-", label="alpha 10000, 24 variable frames")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("|q| - 1")
    ax.legend(fontsize=8)
    ax.set_title("Unit norm (cf. the paper's Fig. 4)")
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, "quaternion-splines-norm.png"), dpi=110)

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    ax.semilogy(t, lbfgs_trace["el_initial"], "b:", label="unoptimised")
    ax.semilogy(t, lbfgs_trace["el_final"], "r-", label="alpha 1000, 4 variable frames")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("|EL|")
    ax.legend(fontsize=8)
    ax.set_title("Euler-Lagrange error before and after (cf. Fig. 5)")
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, "quaternion-splines-el.png"), dpi=110)
    print("wrote", ", ".join("docs/img/quaternion-splines-%s.png" % n for n in ("objective", "norm", "el")), "from", data)


if __name__ == "__main__":
    main()
