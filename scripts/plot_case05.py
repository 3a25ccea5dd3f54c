#!/usr/bin/python3
"""Plots for thesis case 5 (viscoplastic vertical cut) from the CSV files written by
`rktsph validate`.

Usage: /usr/bin/python3 scripts/plot_case05.py DIR   (DIR = validation/case05)
"""
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read, style_crest_history  # noqa: E402



def histories(d, fig_path, title, pattern_labels, H=10.0):
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8))
    for pattern, label in pattern_labels:
        for p in sorted(d.glob(pattern)):
            h = read(p)
            dx = p.stem.split("_dx")[-1]
            axes[0].plot(h["t"], h["uc"], label=f"{label}, dx = {dx} m")
            axes[1].semilogy(h["t"], [max(k, 1e-12) for k in h["kinetic"]], label=f"{label}, dx = {dx} m")
    style_crest_history(axes, H, [(3.0, "--", "end of the gravity ramp"), (5.0, ":", "damping off at the latest (damping.until)")])
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(fig_path, dpi=110)
    plt.close(fig)


def eps_map(ax, s, title):
    from matplotlib.colors import LogNorm
    top = max(s["eps_vp_eq"])
    vals = [max(e, 1e-3 * top) for e in s["eps_vp_eq"]]
    sc = ax.tripcolor(s["x"], s["y"], vals, shading="gouraud", cmap="viridis", norm=LogNorm(vmin=1e-3 * top, vmax=top))
    plt.colorbar(sc, ax=ax, label="accumulated plastic strain $\\bar\\varepsilon^{vp}$ (-, log scale)")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)


def main(d):
    d = Path(d)
    histories(d, d / "histories.png", "Case 5: crest displacement and kinetic energy",
              [("history_N3.4_dx*.csv", "N = 3.4 (expected stable)"),
               ("history_N4.2_dx*.csv", "N = 4.2 (expected collapse)")])
    meta = read(d / "meta.csv")
    W, H, em = meta["W"][0], meta["H"][0], meta["emergence"][0]
    s = read(d / "final_N4.2.csv")
    fig, ax = plt.subplots(figsize=(11, 5.5))
    eps_map(ax, s, f"Case 5, N = 4.2, end of run (dx = {meta['dx'][0]:g} m)")
    # Reference mechanism: circle through the toe, centre (+1.41H, +2.21H) from the toe, radius 2.62H
    cx, cy, R = W + 1.41 * H, 2.21 * H, 2.62 * H
    xs, ys = [], []
    for k in range(400):
        a = math.pi + k * (math.pi / 2) / 399
        x, y = cx + R * math.cos(a), cy + R * math.sin(a)
        if 0 <= y <= H and x <= W:
            xs.append(x)
            ys.append(y)
    ax.plot(xs, ys, "r--", label="limit-analysis circular mechanism (emerges 0.91H behind the crest)")
    ax.axvspan(W - 1.15 * H, W - 0.7 * H, ymin=0.9, color="orange", alpha=0.3, label="accepted emergence 0.7H-1.15H")
    ax.plot([W - em], [H], "wv", ms=10, mec="k", label=f"measured emergence ({em:.2f} m behind the crest)")
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(d / "eps_N4.2.png", dpi=110)
    plt.close(fig)

    p = d / "onset_N4.2.csv"
    fig, ax = plt.subplots(figsize=(11, 5.5))
    if p.exists():
        s = read(p)
        v = [math.hypot(a, b) for a, b in zip(s["vx"], s["vy"])]
        step = max(1, int(round(len(s["x"]) / 1500)))
        sc = ax.scatter(s["x"], s["y"], c=v, s=4, cmap="magma_r", marker="s")
        plt.colorbar(sc, ax=ax, label="|v| (m/s)")
        ax.quiver(s["x"][::step], s["y"][::step], s["vx"][::step], s["vy"][::step], color="C0", width=0.002)
        ax.set_title("Case 5, N = 4.2: velocity at the onset of collapse ($u_c$ first > 0.01 H)", fontsize=9)
    else:
        ax.set_title("Case 5, N = 4.2: no onset snapshot ($u_c$ never exceeded 0.01 H)")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(d / "velocity_onset_N4.2.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
