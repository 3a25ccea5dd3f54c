#!/usr/bin/python3
"""Plots for thesis case 10 (cohesive vertical slope, failure and post-failure, V2) from the CSV
files written by `rktsph validate 10`: u_c(t), the kinetic energy and the scarp position (reference
X of the top row's eps_vp_eq peak, behind the crest) against time for N = 3.4 and 4.5; eps_vp_eq
maps of the N = 4.5 run at the onset (u_c > 0.1 m) and at the end; the final geometry of both.

Usage: /usr/bin/python3 scripts/plot_case10.py DIR   (DIR = validation/case10)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read, style_crest_history  # noqa: E402

H = 10.0


def main(d):
    d = Path(d)
    fig, ax = plt.subplots(1, 3, figsize=(15, 4))
    for label in ("N3.4", "N4.5"):
        h = read(d / f"history_{label}.csv")
        ax[0].plot(h["t"], h["uc"], label=label)
        ax[1].semilogy(h["t"], [max(v, 1e-30) for v in h["kinetic"]], label=label)
        t = read(d / f"track_{label}.csv")
        ax[2].plot(t["t"], [v / H for v in t["scarp"]], label=label)
    style_crest_history(ax[:2], H, [(3.0, "--", "end of ramp")])
    ax[2].axhspan(0.7, 1.15, color="0.9", label="0.7-1.15 H")
    ax[2].axhline(0.91, color="k", ls="--", lw=0.8, label="circular mechanism 0.91 H")
    ax[2].set_ylabel("scarp behind the crest / H")
    ax[2].set_xlabel("t (s)")
    ax[2].grid(alpha=0.3)
    ax[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(d / "histories.png", dpi=130)

    fig, ax = plt.subplots(2, 1, figsize=(12, 7))
    for a, name, title in ((ax[0], "onset_N4.5.csv", "N = 4.5 at the onset (u_c > 0.1 m)"),
                           (ax[1], "final_N4.5.csv", "N = 4.5 at the end")):
        if not (d / name).exists():
            a.set_title(title + ": not reached")
            continue
        s = read(d / name)
        sc = a.scatter(s["x"], s["y"], c=s["eps_vp_eq"], s=4, cmap="magma_r",
                       vmax=max(1e-6, sorted(s["eps_vp_eq"])[int(0.995 * len(s["eps_vp_eq"]))]))
        fig.colorbar(sc, ax=a, label=r"$\bar\varepsilon$", fraction=0.02)
        a.set_aspect("equal")
        a.set_title(title, fontsize=9)
        a.set_ylabel("y (m)")
    ax[1].set_xlabel("x (m)")
    fig.tight_layout()
    fig.savefig(d / "eps_maps.png", dpi=130)

    fig, ax = plt.subplots(figsize=(12, 4))
    for label, c in (("N3.4", "C0"), ("N4.5", "C1")):
        s = read(d / f"final_{label}.csv")
        ax.plot(s["x"], s["y"], ".", ms=1.5, color=c, label=f"{label} final")
    ax.plot([0, 20, 20], [10, 10, 0], "k--", lw=0.8, label="initial cut")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(d / "geometry.png", dpi=130)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "validation/case10")
