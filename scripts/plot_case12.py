#!/usr/bin/python3
"""Plots for thesis case 12 (strip footing on a weightless Tresca soil, Prandtl, V2) from the CSV
files written by `rktsph validate 12`: q/c against settlement/B for the smooth and the rough
footing at each resolution, with (2 + pi); the eps_vp_eq and velocity fields at settlement/B =
0.05 (finest resolution); and the surface heave at settlement/B = 0.05.

Usage: /usr/bin/python3 scripts/plot_case12.py DIR   (DIR = validation/case12)
"""
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402

B, C, H = 2.0, 50e3, 4.0
QU = 2 + math.pi


def main(d):
    d = Path(d)
    runs = read(d / "runs.csv")
    n = len(runs["file"])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k in range(n):
        f = read(d / f"force_{runs['file'][k]}.csv")
        ls = "-" if runs["contact"][k] == "smooth" else "--"
        ax.plot([s / B for s in f["settlement"]], [q / C for q in f["pressure"]], ls,
                label=f"{runs['contact'][k]}, $\\Delta x$ = {runs['dx'][k]:g} m")
    ax.axhline(QU, color="k", lw=0.8, label="$(2+\\pi)$ (Prandtl)")
    ax.axhspan(0.97 * QU, 1.08 * QU, color="0.9", label="acceptance band")
    ax.axvspan(0.03, 0.06, color="y", alpha=0.15, label="plateau window")
    ax.set_xlabel("settlement / B")
    ax.set_ylabel("q / c (footing reaction / (B/2) / c)")
    ax.set_ylim(0, 1.3 * QU)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(d / "pressure.png", dpi=110)

    # Fields at settlement/B = 0.05 (map 1) of the finest smooth and rough runs.
    finest = min(runs["dx"])
    sel = [k for k in range(n) if runs["dx"][k] == finest]
    fig, axes = plt.subplots(len(sel), 2, figsize=(13, 3.6 * len(sel)), squeeze=False)
    for row, k in enumerate(sel):
        m = read(d / f"maps_{runs['file'][k]}.csv")
        idx = [i for i, v in enumerate(m["map"]) if v == 1]
        x = [m["x"][i] for i in idx]
        y = [m["y"][i] for i in idx]
        a = axes[row][0]
        sc = a.scatter(x, y, c=[m["eps_vp_eq"][i] for i in idx], s=2, cmap="viridis")
        fig.colorbar(sc, ax=a)
        a.set_title(f"{runs['contact'][k]}, $\\Delta x$ = {finest:g} m: $\\bar\\varepsilon$ at settlement/B = 0.05",
                    fontsize=9)
        a = axes[row][1]
        sp = [math.hypot(m["vx"][i], m["vy"][i]) for i in idx]
        sc = a.scatter(x, y, c=sp, s=2, cmap="magma_r")
        fig.colorbar(sc, ax=a, label="|v| (m/s)")
        step = max(1, len(idx) // 600)
        a.quiver(x[::step], y[::step], [m["vx"][i] for i in idx][::step], [m["vy"][i] for i in idx][::step],
                 scale=0.6, width=0.002)
        a.set_title("velocity field (plastic-zone depth {:.2f} B)".format(runs["zone_depth"][k] / B), fontsize=9)
        for a in axes[row]:
            a.set_aspect("equal")
            a.set_xlim(0, 4)
            a.set_ylim(1, 4.3)
            a.axvline(1.0, color="w", lw=0.5, ls=":")
    fig.tight_layout()
    fig.savefig(d / "fields.png", dpi=110)

    fig, ax = plt.subplots(figsize=(7, 4))
    for k in range(n):
        m = read(d / f"maps_{runs['file'][k]}.csv")
        pts = sorted((m["X"][i], m["uy"][i]) for i, v in enumerate(m["map"]) if v == 1 and abs(m["Y"][i] - H) < 1e-9)
        ls = "-" if runs["contact"][k] == "smooth" else "--"
        ax.plot([(p[0] - 1.0) / B for p in pts], [1e3 * p[1] for p in pts], ls,
                label=f"{runs['contact'][k]}, $\\Delta x$ = {runs['dx'][k]:g} m")
    ax.axvline(0.0, color="k", lw=0.8)
    ax.axvline(1.0, color="0.5", ls=":", label="Prandtl: B beyond the edge")
    ax.axvline(1.2, color="r", ls=":", label="acceptance 1.2 B")
    ax.set_xlabel("(x - B/2) / B (distance from the footing edge)")
    ax.set_ylabel("surface $u_y$ at settlement/B = 0.05 (mm)")
    ax.set_xlim(-0.5, 2.5)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(d / "heave.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
