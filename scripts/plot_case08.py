#!/usr/bin/python3
"""Plots for thesis case 8 (von Mises bar in plane-strain tension, V2) from the CSV files written
by `rktsph validate 08`: the grip force and the neck width against the elongation, with the exact
limit force 2 c_min B; the eps_vp_eq maps at 10, 20 and 30 % elongation (or the last good state)
with the nodes flagged as free surface; and the plastic strain of the 0.1 s at the first band.

Usage: /usr/bin/python3 scripts/plot_case08.py DIR   (DIR = validation/case08)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402

LIMIT_FORCE = 2 * 49.5e3 * 1.0  # N/m


def main(d):
    d = Path(d)
    f = read(d / "force.csv")
    e = [100 * v for v in f["elongation"]]
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2))
    ax[0].plot(e, [v / 1e3 for v in f["force_cut"]], "-", label="section cuts (two slabs)")
    ax[0].plot(e, [v / 1e3 for v in f["force_work"]], ":", label="from the grips' power")
    ax[0].axhline(LIMIT_FORCE / 1e3, color="k", ls="--", lw=0.8, label="$2 c_{min} B$ = 99.0 kN/m")
    ax[0].axhspan(0.98 * LIMIT_FORCE / 1e3, 1.05 * LIMIT_FORCE / 1e3, color="0.9", label="acceptance band of the peak")
    ax[0].set_xlabel("elongation (%)")
    ax[0].set_ylabel("grip force (kN/m)")
    ax[0].legend(fontsize=8)
    ax[0].grid(alpha=0.3)
    ax[1].plot(e, f["neck_width"], "-")
    ax[1].plot(e, [1.0 / (1.0 + v / 100) for v in e], "k--", lw=0.8, label="uniform thinning 1 / (1 + e)")
    ax[1].set_xlabel("elongation (%)")
    ax[1].set_ylabel("neck width (m)")
    ax[1].legend(fontsize=8)
    ax[1].grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(d / "force.png", dpi=110)

    m = read(d / "maps.csv")
    times = sorted(set(m["t"]))
    b = read(d / "band.csv")
    fig, axes = plt.subplots(len(times) + 1, 1, figsize=(11, 2.6 * (len(times) + 1)))
    for ax, t in zip(axes, times):
        idx = [i for i, s in enumerate(m["t"]) if s == t]
        x = [m["x"][i] for i in idx]
        y = [m["y"][i] for i in idx]
        sc = ax.scatter(x, y, c=[m["eps_vp_eq"][i] for i in idx], s=3, cmap="viridis")
        fx = [m["x"][i] for i in idx if m["free_surface"][i] > 0]
        fy = [m["y"][i] for i in idx if m["free_surface"][i] > 0]
        ax.scatter(fx, fy, s=6, facecolors="none", edgecolors="r", lw=0.4, label="free surface")
        ax.set_title(f"$\\bar\\varepsilon^{{vp}}$ at t = {t:.2f} s, {100 * m['elongation'][idx[0]]:.1f} % elongation",
                     fontsize=9)
        ax.set_aspect("equal")
        ax.legend(fontsize=7, loc="upper right")
        fig.colorbar(sc, ax=ax)
    ax = axes[-1]
    if b["x"]:
        sc = ax.scatter(b["x"], b["y"], c=b["deps"], s=3, cmap="magma")
        cx = [b["x"][i] for i in range(len(b["x"])) if b["in_cloud"][i] > 0]
        cy = [b["y"][i] for i in range(len(b["x"])) if b["in_cloud"][i] > 0]
        ax.scatter(cx, cy, s=6, facecolors="none", edgecolors="c", lw=0.4, label="band cloud (>= 50 % of max)")
        ax.set_title("plastic strain of the last 0.1 s at the first band", fontsize=9)
        ax.set_aspect("equal")
        ax.legend(fontsize=7, loc="upper right")
        fig.colorbar(sc, ax=ax)
    fig.tight_layout()
    fig.savefig(d / "maps.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
