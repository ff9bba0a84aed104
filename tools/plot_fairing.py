#!/usr/bin/python3
"""Plots for docs/fairing.md from `posefair reproduce lee-shin` output (the traces CSV and the
-curvature.csv and -motion.csv files it writes beside it).

    build/tools/posefair reproduce lee-shin -o build/lee-shin-section6.csv
    /usr/bin/python3 tools/plot_fairing.py build/lee-shin-section6.csv docs/img

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


def load(path):
    runs = defaultdict(lambda: defaultdict(list))
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            r = runs[row["run"]]
            for k, v in row.items():
                if k in ("run", "variant"):
                    continue
                r[k].append(float(v))
    return runs


def save(fig, out, name):
    fig.tight_layout()
    fig.savefig(out / name, dpi=110)
    plt.close(fig)
    print("wrote", out / name)


def main():
    runs = load(sys.argv[1])
    out = Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    perturbation = 0.1

    # Figure 2: average error, m = 2 vs m = 3, λ_r = 0.1, against input and against truth.
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for name, style in (("m2-l0.1", "C0"), ("m3-l0.1", "C1")):
        r = runs[name]
        ax[0].plot(r["iteration"], r["mean_error_to_input"], style, label=name.replace("-l", ", λr="))
        ax[1].plot(r["iteration"], r["mean_error_to_truth"], style, label=name.replace("-l", ", λr="))
    for a, title in zip(ax, ("to the noisy input (paper's Fig. 2)", "to the clean truth")):
        a.axhline(perturbation, color="gray", ls=":", label="perturbation bound 0.1")
        a.set_xscale("symlog", linthresh=10)
        a.set_xlim(left=0)
        a.set_xlabel("iteration")
        a.set_title("mean error " + title)
        a.legend()
    ax[0].set_ylabel("mean dist on S³ (rad)")
    save(fig, out, "fairing-error-m2-m3.png")

    # Figure 3: damping, m = 3, λ_r = 0.1, 0.2, 0.3; right: the same against λ_r·k.
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for i, name in enumerate(("m3-l0.1", "m3-l0.2", "m3-l0.3")):
        r = runs[name]
        lam = r["lambda_r"][0]
        c = f"C{i}"
        ax[0].plot(r["iteration"], r["mean_error_to_truth"], c, label=f"λr={lam:.1f} to truth")
        ax[0].plot(r["iteration"], r["mean_error_to_input"], c, ls="--", label=f"λr={lam:.1f} to input")
        ax[1].plot([lam * k for k in r["iteration"]], r["mean_error_to_truth"], c, ls=("-", "--", ":")[i], label=f"λr={lam:.1f}")
    ax[0].set_xscale("symlog", linthresh=10)
    ax[0].set_xlim(left=0)
    ax[0].set_xlabel("iteration")
    ax[0].set_title("m = 3, damping (paper's Fig. 3)")
    ax[1].set_xscale("symlog", linthresh=1)
    ax[1].set_xlim(0, 100)
    ax[1].set_xlabel("λr × iteration")
    ax[1].set_title("error to truth against λr × iteration")
    ax[0].set_ylabel("mean dist on S³ (rad)")
    for a in ax:
        a.legend(fontsize=8)
    save(fig, out, "fairing-damping.png")

    # Figures 4 and 5: acceleration and angular acceleration against iteration.
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    labels = {"m2-l0.1": "m=2, Section 6 (0.1 rad, 10 mm)", "m3-l0.1": "m=3, Section 6 (0.1 rad, 10 mm)",
              "m3-l0.1-fig4-8": "m=3, Figs. 4–8 (0.2 rad, 20 mm)"}
    for name, label in labels.items():
        r = runs[name]
        ax[0].plot(r["iteration"][:101], r["mean_acceleration"][:101], label=label)
        ax[1].plot(r["iteration"][:101], r["mean_angular_acceleration"][:101], label=label)
    ax[0].set_title("translational acceleration (Fig. 4), λt = 0.5")
    ax[0].set_ylabel("mean ‖D²p‖/Δ² (mm/s²)")
    ax[1].set_title("angular acceleration (Fig. 5)")
    ax[1].set_ylabel("mean 2‖W²q‖/Δ² (rad/s²)")
    for a in ax:
        a.set_yscale("log")
        a.set_xlabel("iteration")
        a.axvline(10, color="gray", ls=":")
        a.legend(fontsize=8)
    save(fig, out, "fairing-acceleration.png")

    # Printed vs corrected operators.
    fig, ax = plt.subplots(figsize=(6, 3.8))
    for name in ("m2-l0.1", "m2-l0.1-printed", "m3-l0.1", "m3-l0.1-printed"):
        r = runs[name]
        ax.plot(r["iteration"], r["mean_error_to_truth"], label=name)
    ax.set_xscale("symlog", linthresh=10)
    ax.set_xlim(left=0)
    ax.set_xlabel("iteration")
    ax.set_ylabel("mean dist to truth (rad)")
    ax.set_title("corrected vs printed operators, λr = 0.1")
    ax.legend()
    save(fig, out, "fairing-variants.png")

    traces = Path(sys.argv[1])
    plot_curvature(traces.with_name(traces.stem + "-curvature.csv"), out, perturbation)
    plot_motion(traces.with_name(traces.stem + "-motion.csv"), out)


def plot_curvature(path, out, perturbation):
    """Claim (a) against how curved the motion is: error after 100 and 1000 sweeps."""
    rows = list(csv.DictReader(open(path, newline="")))
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for a, what, title in zip(ax, ("mean_error_to_input", "mean_error_to_truth"),
                              ("to the noisy input (claim (a))", "to the clean truth")):
        sweeps = sorted({int(r["iteration"]) for r in rows})
        for order, colour in (("2", "C0"), ("3", "C1")):
            for k, style in ((str(sweeps[0]), "--"), (str(sweeps[-1]), "-")):
                sel = [r for r in rows if r["order"] == order and r["iteration"] == k]
                a.plot([float(r["truth_angular_acceleration"]) for r in sel], [float(r[what]) for r in sel], colour,
                       ls=style, marker="o", label=f"m={order}, {k} sweeps")
        a.axhline(perturbation, color="gray", ls=":", label="perturbation bound 0.1")
        a.set_xscale("log")
        a.set_xlabel("mean angular acceleration of the truth (rad/s²)")
        a.set_title("mean error " + title)
        a.legend(fontsize=8)
    ax[0].set_ylabel("mean dist on S³ (rad)")
    save(fig, out, "fairing-curvature.png")


def rotate(q, v):
    """v rotated by the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    tx, ty, tz = 2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])
    return (v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz, v[2] + w * tz + x * ty - y * tx)


def plot_motion(path, out):
    """Figures 6–8: the trajectory, and each sample's orientation as a short needle along its
    body x axis (red) and y axis (blue)."""
    stages = defaultdict(list)
    for r in csv.DictReader(open(path, newline="")):
        stages[r["stage"]].append(r)
    fig = plt.figure(figsize=(13, 4.6))
    titles = (("noisy", "Fig. 6: the initial noisy motion"), ("translation", "Fig. 7: after translational fairing"),
              ("faired", "Fig. 8: the final faired motion"))
    truth = stages["truth"]
    for k, (stage, title) in enumerate(titles):
        a = fig.add_subplot(1, 3, k + 1, projection="3d")
        rows = stages[stage]
        p = [(float(r["px"]), float(r["py"]), float(r["pz"])) for r in rows]
        a.plot([float(r["px"]) for r in truth], [float(r["py"]) for r in truth], [float(r["pz"]) for r in truth],
               color="gray", lw=0.8, ls=":", label="truth")
        a.plot(*zip(*p), color="k", lw=1.0, label="positions")
        length = 25.0
        for r, x in zip(rows, p):
            q = (float(r["qw"]), float(r["qx"]), float(r["qy"]), float(r["qz"]))
            for axis, colour in (((length, 0, 0), "C3"), ((0, length, 0), "C0")):
                d = rotate(q, axis)
                a.plot([x[0], x[0] + d[0]], [x[1], x[1] + d[1]], [x[2], x[2] + d[2]], color=colour, lw=0.7)
        a.set_title(title, fontsize=10)
        a.set_xlabel("x (mm)")
        a.set_ylabel("y (mm)")
        a.set_zlabel("z (mm)")
        if k == 0:
            a.legend(fontsize=8, loc="upper left")
    save(fig, out, "fairing-motion.png")


if __name__ == "__main__":
    main()
