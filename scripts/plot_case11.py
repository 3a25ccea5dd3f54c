#!/usr/bin/python3
"""Plots for thesis case 11 (strip footing at the crest of a weightless vertical cut, V2) from the
CSV files written by `rktsph validate 11`: the mean footing pressure against settlement/B with
2c; the eps_vp_eq maps at settlement/B = 0.02, 0.05 and 0.1 (finest resolution), with the band
cloud fitted at 0.05 and the exact 45-degree line from the inner footing edge to the face.

Usage: /usr/bin/python3 scripts/plot_case11.py DIR   (DIR = validation/case11)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402

W, H, B, C = 20.0, 10.0, 5.0, 50e3


def main(d):
    d = Path(d)
    runs = read(d / "runs.csv")
    n = len(runs["file"])
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k in range(n):
        f = read(d / f"force_{runs['file'][k]}.csv")
        ax.plot([s / B for s in f["settlement"]], [q / 1e3 for q in f["pressure"]],
                label=f"$\\Delta x$ = {runs['dx'][k]:g} m (plateau {runs['plateau'][k] / 1e3:.1f} kPa)")
    ax.axhline(2 * C / 1e3, color="k", lw=0.8, label="2c = 100 kPa")
    ax.axhspan(0.97 * 2 * C / 1e3, 1.08 * 2 * C / 1e3, color="0.9", label="acceptance band")
    ax.axvspan(0.02, 0.05, color="y", alpha=0.15, label="plateau window")
    ax.set_xlabel("settlement / B")
    ax.set_ylabel("mean footing pressure (kPa)")
    ax.set_ylim(0, 130)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(d / "pressure.png", dpi=110)

    k = min(range(n), key=lambda j: runs["dx"][j])
    m = read(d / f"maps_{runs['file'][k]}.csv")
    band = read(d / f"band_{runs['file'][k]}.csv")["in_band"]
    maps = sorted(set(m["map"]))
    fig, axes = plt.subplots(1, len(maps), figsize=(5.2 * len(maps), 4.6), squeeze=False)
    for a, j in zip(axes[0], maps):
        idx = [i for i, v in enumerate(m["map"]) if v == j]
        sc = a.scatter([m["x"][i] for i in idx], [m["y"][i] for i in idx], c=[m["eps_vp_eq"][i] for i in idx], s=3,
                       cmap="viridis")
        fig.colorbar(sc, ax=a)
        if j == 1 and band:
            bi = [i for i, v in zip(idx, band) if v > 0]
            a.scatter([m["x"][i] for i in bi], [m["y"][i] for i in bi], s=5, facecolors="none", edgecolors="r",
                      lw=0.3, label=f"band cloud: {runs['angle'][k]:.1f} deg, emerges at {runs['emergence'][k]:.2f} m")
            a.legend(fontsize=7, loc="lower left")
        a.plot([W - B, W], [H, H - B], "w--", lw=0.8)
        a.set_title(f"$\\Delta x$ = {runs['dx'][k]:g} m: $\\bar\\varepsilon$ at settlement/B = "
                    f"{m['settlement'][idx[0]] / B:.2f}", fontsize=9)
        a.set_aspect("equal")
        a.set_xlim(W - 1.6 * B, W + 1.0)
        a.set_ylim(H - 1.6 * B, H + 0.5)
    fig.tight_layout()
    fig.savefig(d / "eps_maps.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
