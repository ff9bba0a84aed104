#!/usr/bin/python3
"""Plots for docs/splines.md: geometric C^k splines (k = 1, 2, 3) through a decimated real
orientation stream, their angular velocity against the gyroscope, and their angular
acceleration.

    /usr/bin/python3 tools/plot_splines.py build/tools/posefair docs/img

Data: BROAD trial 07 (fast rotation; Laidig et al. 2021, CC BY 4.0). The script writes every
10th optical sample of a 3 s stretch (28.6 Hz knots) to a CSV, runs
`posefair resample --rate 1000 --order k --derivatives` on it for k = 1, 2, 3 (the C++ code
writes the body-frame angular velocity and acceleration CSV), and plots those against the
trial's own 285.7 Hz gyroscope. Needs python3-matplotlib.

    build/tools/posefair reproduce rodrigues-figure6 -o build/rodrigues-figure6.csv
    /usr/bin/python3 tools/plot_splines.py --figure6 build/rodrigues-figure6.csv docs/img

draws the paper's Figure 6 (docs/img/splines-figure6.png) from that command's curves instead.
"""
import csv
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The full trial, not part of the repository: in $POSEFAIR_DATA, else in ../shared/data beside the project.
DATA_DIR = Path(os.environ.get("POSEFAIR_DATA") or Path(__file__).resolve().parent.parent.parent / "shared/data")
DATA = DATA_DIR / "broad/07_undisturbed_fast_rotation_B.csv"
START, LENGTH, DECIMATE = 30.0, 3.0, 10


def plot_figure6(path, out_dir):
    """The segment s_i of Figure 6 on S² for k = 1, 2, 3 (corrected v_{i+1}), the step-1 curves
    l, c, r it blends, and the velocities at both ends."""
    curves = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            curves.setdefault(r["curve"], []).append((float(r["x"]), float(r["y"]), float(r["z"])))
    fig = plt.figure(figsize=(7, 6.5))
    a = fig.add_subplot(projection="3d")
    import math
    n = 24
    for i in range(n + 1):  # a wire sphere: meridians and parallels
        th = math.pi * i / n
        a.plot([math.sin(th) * math.cos(2 * math.pi * j / 96) for j in range(97)],
               [math.sin(th) * math.sin(2 * math.pi * j / 96) for j in range(97)], [math.cos(th)] * 97,
               color="0.85", lw=0.4)
    for i in range(n):
        ph = 2 * math.pi * i / n
        a.plot([math.sin(math.pi * j / 48) * math.cos(ph) for j in range(49)],
               [math.sin(math.pi * j / 48) * math.sin(ph) for j in range(49)], [math.cos(math.pi * j / 48) for j in range(49)],
               color="0.85", lw=0.4)
    styles = {"l": ("C7", ":", "l (geodesic from p_i, v_i)"), "c": ("C7", "--", "c (great arc p_i to p_i+1)"),
              "r": ("C7", "-.", "r (geodesic into p_i+1, v_i+1)"),
              "s-k1": ("C0", "-", "s_i, k = 1"), "s-k2": ("C3", "-", "s_i, k = 2 (the paper's natural spline)"),
              "s-k3": ("C2", "-", "s_i, k = 3"), "s-k2-printed-v": ("C1", (0, (1, 1)), "k = 2, printed v_i+1 projected")}
    for name, (colour, ls, label) in styles.items():
        pts = curves[name]
        a.plot(*zip(*pts), color=colour, ls=ls, lw=1.8 if name.startswith("s-") else 1.0, label=label)
    p0, p1 = curves["s-k2"][0], curves["s-k2"][-1]
    r3 = 3 ** 0.5
    for p, v in ((p0, (0.5, r3, 3 - r3)), (p1, (-0.1, 1.8, (9 * r3 - 1) / 15))):
        a.quiver(*p, *[0.3 * c for c in v], color="k", arrow_length_ratio=0.15)
    a.scatter(*zip(p0, p1), color="k", s=20)
    a.text(*p0, "  p_i", fontsize=9)
    a.text(*p1, "  p_i+1", fontsize=9)
    a.set_box_aspect((1, 1, 1))
    a.view_init(elev=20, azim=20)
    a.set_title("Figure 6: segment s_i on S² (v_i+1 with first component −1/10, ERRATA 3)", fontsize=10)
    a.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(Path(out_dir) / "splines-figure6.png", dpi=110)
    plt.close(fig)
    print("wrote", Path(out_dir) / "splines-figure6.png")


def main():
    if sys.argv[1] == "--figure6":
        plot_figure6(sys.argv[2], sys.argv[3])
        return
    posefair, out_dir = Path(sys.argv[1]), Path(sys.argv[2])
    data = sys.argv[3] if len(sys.argv) > 3 else DATA
    if not Path(data).exists():
        sys.exit(f"plot_splines.py: {data} not found; it comes from BROAD (Laidig et al., Data 6(7):72, 2021, "
                 "doi:10.3390/data6070072, CC BY 4.0). Set POSEFAIR_DATA to the folder with broad/, or put it in "
                 "../shared/data beside the project (docs/benchmarks.md).")
    rows = []
    with open(data, newline="") as f:
        for r in csv.DictReader(f):
            t = float(r["t_s"])
            if START <= t <= START + LENGTH and r["gt_qw"] != "nan":
                rows.append(r)
    knots = rows[::DECIMATE]
    gyro_t = [float(r["t_s"]) for r in rows]
    gyro = [sum(float(r[f"gyr_{a}_rads"]) ** 2 for a in "xyz") ** 0.5 for r in rows]
    curves, vectors = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        knot_file = Path(tmp) / "knots.csv"
        with open(knot_file, "w") as f:
            f.write("t,qw,qx,qy,qz\n")
            for r in knots:
                f.write(",".join([r["t_s"], r["gt_qw"], r["gt_qx"], r["gt_qy"], r["gt_qz"]]) + "\n")
        for k in (1, 2, 3):
            deriv = Path(tmp) / f"k{k}.csv"
            subprocess.run([str(posefair), "resample", str(knot_file), "-o", str(Path(tmp) / f"out{k}.csv"),
                            "--rate", "1000", "--order", str(k), "--derivatives", str(deriv), "-q"], check=True)
            with open(deriv, newline="") as f:
                d = list(csv.DictReader(f))
            curves[k] = ([float(r["t"]) for r in d], [float(r["w_norm"]) for r in d], [float(r["a_norm"]) for r in d])
            vectors[k] = [[float(r[f"w{a}"]) for a in "xyz"] for r in d]
    knot_t = [float(r["t_s"]) for r in knots]
    # Body-frame angular velocity against the gyroscope (same body frame), at the gyro's
    # samples inside the knots' range (the 1 kHz spline output, nearest sample).
    for k, (t, _, _) in curves.items():
        err2, n = 0.0, 0
        for r in rows:
            tg = float(r["t_s"])
            if not t[0] <= tg <= t[-1]:
                continue
            j = min(range(max(0, int((tg - t[0]) * 1000) - 1), min(len(t), int((tg - t[0]) * 1000) + 2)),
                    key=lambda i: abs(t[i] - tg))
            g = [float(r[f"gyr_{a}_rads"]) for a in "xyz"]
            err2 += sum((vectors[k][j][c] - g[c]) ** 2 for c in range(3))
            n += 1
        print(f"k={k}: RMS |w_spline - w_gyro| = {(err2 / n) ** 0.5:.3f} rad/s over {n} gyro samples")
    fig, (ax_w, ax_a) = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    ax_w.plot(gyro_t, gyro, color="0.6", lw=2.5, label="gyroscope (285.7 Hz)")
    colors = {1: "tab:blue", 2: "tab:orange", 3: "tab:green"}
    for k, (t, w, a) in curves.items():
        ax_w.plot(t, w, color=colors[k], lw=1, label=f"spline k={k}")
        ax_a.plot(t, a, color=colors[k], lw=1, label=f"spline k={k}")
    for t in knot_t:
        ax_w.axvline(t, color="0.85", lw=0.5, zorder=0)
        ax_a.axvline(t, color="0.85", lw=0.5, zorder=0)
    ax_w.set_ylabel("|angular velocity| (rad/s)")
    ax_a.set_ylabel("|angular acceleration| (rad/s²)")
    ax_a.set_xlabel("time (s); grey lines: knots (every 10th optical sample, 28.6 Hz)")
    ax_w.set_title("Geometric splines on S³ through BROAD trial 07 optical orientation (bessel knot velocities)")
    ax_w.legend(loc="upper right", fontsize=8)
    ax_a.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    out_dir.mkdir(parents=True, exist_ok=True)
    fig.savefig(out_dir / "splines-k123.png", dpi=110)
    # A close-up of one second.
    ax_w.set_xlim(START + 1.0, START + 2.0)
    fig.savefig(out_dir / "splines-k123-zoom.png", dpi=110)
    print(f"wrote {out_dir / 'splines-k123.png'} and {out_dir / 'splines-k123-zoom.png'}")


if __name__ == "__main__":
    main()
