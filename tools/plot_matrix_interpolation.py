#!/usr/bin/python3
"""Plots for docs/matrix-interpolation.md from `posefair camera --study` output.

    build/tools/posefair camera --study build/matrix-interpolation
    /usr/bin/python3 tools/plot_matrix_interpolation.py build/matrix-interpolation docs/img

Writes docs/img/matrix-interpolation-{sqrt,log-eps1,path-length}.png.
Needs python3-matplotlib (tools/setup-debian.sh --plots).
"""
import csv
import math
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(s):
    try:
        v = float(s)
    except ValueError:
        return math.nan
    return v


def plot_sqrt(study, out):
    by = defaultdict(list)
    principal = {}
    for r in rows(study / "sqrt_iterations.csv"):
        by[r["matrix"]].append((int(r["iteration"]), num(r["residual"])))
        principal[r["matrix"]] = r["principal"] == "1"
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for m, pts in by.items():
        x, y = zip(*pts)
        y = [max(v, 1e-17) for v in y]
        ax.semilogy(x, y, color="tab:blue" if principal[m] else "tab:red", alpha=0.35, lw=0.8)
    ax.axhline(1e-6, color="k", ls="--", lw=1, label="eps3 = 1e-6")
    ax.plot([], [], color="tab:blue", label="principal root exists")
    ax.plot([], [], color="tab:red", label="negative real eigenvalue")
    ax.set_xlabel("Denman-Beavers iteration")
    ax.set_ylabel("|XX - A| (inf-norm)")
    ax.set_title("Section 4.2.1: square root residual per iteration")
    ax.set_ylim(1e-17, 1e12)
    ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(out / "matrix-interpolation-sqrt.png", dpi=110)


def plot_log(study, out):
    data = defaultdict(lambda: defaultdict(list))
    for r in rows(study / "log_square_roots.csv"):
        data[r["eps3"]][r["matrix"]].append(r)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    colours = {"1e-06": "tab:blue", "1e-13": "tab:green"}
    for eps3, mats in data.items():
        c = colours.get(eps3, "tab:gray")
        for m, rs in mats.items():
            n = [int(r["square_roots"]) for r in rs]
            ch = [num(r["change"]) for r in rs]
            axes[0].semilogy(n, ch, color=c, alpha=0.3, lw=0.8)
            d = [num(r["distance_to_identity"]) for r in rs]
            e = [num(r["error"]) for r in rs]
            axes[1].loglog(d, e, color=c, alpha=0.3, lw=0.8, marker=".", ms=2)
        axes[0].plot([], [], color=c, label=f"eps3 = {eps3}")
    axes[0].set_xlabel("square roots taken")
    axes[0].set_ylabel("|log_n - log_(n-1)|")
    axes[0].set_title("Fig. 4/5(a): change as square roots are added")
    axes[0].legend()
    for v in (0.5, 1e-4, 1e-6):
        axes[1].axvline(v, color="k", ls=":", lw=1)
    axes[1].invert_xaxis()
    axes[1].set_xlabel("eps1 reached: |A^(1/2^n) - I|")
    axes[1].set_ylabel("relative error vs Eigen log")
    axes[1].set_title("Fig. 5(b): error against eps1 (lines at 0.5, 1e-4, 1e-6)")
    fig.tight_layout()
    fig.savefig(out / "matrix-interpolation-log-eps1.png", dpi=110)


def plot_paths(study, out):
    """Section 5.1 on the uniform-angle key pairs: camera space (the paper's measure) and the
    screen, against the turn drawn, with the arc-over-chord floor of a pure turn."""
    rs = [r for r in rows(study / "path_length.csv") if r["draw"] == "uniform-angle"]
    angle = [num(r["drawn_angle_deg"]) for r in rs]
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.3), sharey=True)
    for a, space, title in ((ax[0], "camera", "camera space (Fig. 8's measure)"), (ax[1], "screen", "screen (x, y after the divide)")):
        a.scatter(angle, [num(r[space + "_parameter"]) for r in rs], s=12, color="tab:red", label="camera-parameter interpolation")
        a.scatter(angle, [num(r[space + "_matrix"]) for r in rs], s=12, color="tab:blue", label="matrix interpolation (eq. 7)")
        th = [0.5 + i for i in range(90)]
        a.plot(th, [100 * ((math.radians(t) / 2) / math.sin(math.radians(t) / 2) - 1) for t in th], color="gray", ls=":",
               label="arc over chord of the turn")
        a.set_yscale("symlog", linthresh=1)
        a.set_xlabel("turn between the keyframes, drawn uniformly in [0, 90) (degrees)")
        a.set_title("Section 5.1: excess path, " + title, fontsize=10)
        a.legend(fontsize=8)
    ax[0].set_ylabel("mean excess path 100 (l - l0)/l0 (%)")
    fig.tight_layout()
    fig.savefig(out / "matrix-interpolation-path-length.png", dpi=110)


def main():
    study, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    plot_sqrt(study, out)
    plot_log(study, out)
    plot_paths(study, out)


if __name__ == "__main__":
    main()
