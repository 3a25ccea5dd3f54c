#!/usr/bin/python3
"""Plots for thesis case 3 (2D Cam-Clay plane-strain compression) from the CSV files written
by `rktsph validate`.

Usage: /usr/bin/python3 scripts/plot_case03.py DIR   (DIR = validation/case03)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402



def main(d):
    d = Path(d)
    dx = open(d / "plot_input.txt").read().strip()
    cf = read(d / "closed_form.csv")

    fig, axes = plt.subplots(1, 2, figsize=(13, 4.2))
    for p in sorted(d.glob("history_dx*.csv")):
        h = read(p)
        lab = p.stem[len("history_"):].replace("dx", "dx = ") + " m"
        e = [100 * s for s in h["strain"]]
        axes[0].plot(e, [q / 1e3 for q in h["q"]], label=f"RKT-SPH, {lab}")
        axes[1].plot(e, [q / 1e3 for q in h["p"]], label=f"RKT-SPH, {lab}")
    ce = [100 * s for s in cf["strain"]]
    axes[0].plot(ce, [q / 1e3 for q in cf["q"]], "k--", label="closed-form elastic path")
    axes[1].plot(ce, [q / 1e3 for q in cf["p"]], "k--", label="closed-form elastic path")
    axes[0].plot([ce[-1]], [cf["q"][-1] / 1e3], "r*", ms=12, label="first yield (q$_y$ = 236.3 kPa)")
    axes[1].plot([ce[-1]], [cf["p"][-1] / 1e3], "r*", ms=12, label="first yield (p'$_y$ = 165.2 kPa)")
    axes[0].set_ylabel("q of the average stress (kPa)")
    axes[1].set_ylabel("p' of the average stress (kPa)")
    for ax in axes:
        ax.set_xlabel("axial strain $\\varepsilon_a$ (%)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Case 3: Cam-Clay plane-strain compression, sample response")
    fig.tight_layout()
    fig.savefig(d / "response.png", dpi=110)
    plt.close(fig)

    s = read(d / f"snapshots_dx{dx}.csv")
    strains = sorted(set(s["strain"]))
    fig, axes = plt.subplots(1, len(strains), figsize=(4.2 * len(strains), 6.5))
    if len(strains) == 1:
        axes = [axes]
    for ax, st in zip(axes, strains):
        idx = [i for i, v in enumerate(s["strain"]) if v == st]
        sc = ax.scatter([s["x"][i] for i in idx], [s["y"][i] for i in idx], c=[s["eps_vp_eq"][i] for i in idx],
                        s=6, cmap="viridis")
        ax.set_aspect("equal")
        ax.set_title(f"$\\varepsilon_a$ = {100 * st:.1f} %")
        ax.set_xlabel("x (m)")
        fig.colorbar(sc, ax=ax, label="$\\bar\\varepsilon^{vp}$ (-)", shrink=0.8)
    axes[0].set_ylabel("y (m)")
    fig.suptitle(f"Case 3: accumulated deviatoric viscoplastic strain, dx = {dx} m")
    fig.tight_layout()
    fig.savefig(d / "eps_vp_maps.png", dpi=110)
    plt.close(fig)

    st = strains[-1]
    idx = [i for i, v in enumerate(s["strain"]) if v == st]
    fig, ax = plt.subplots(figsize=(5.5, 8))
    vx = [s["vx"][i] for i in idx]
    vy = [s["vy"][i] for i in idx]
    speed = [(a * a + b * b) ** 0.5 * 1e3 for a, b in zip(vx, vy)]
    step = max(1, int(round(0.04 / float(dx))))
    keep = [k for k, i in enumerate(idx) if round(s["x"][i] / float(dx)) % step == 0 and round(s["y"][i] / float(dx)) % step == 0]
    q = ax.quiver([s["x"][idx[k]] for k in keep], [s["y"][idx[k]] for k in keep], [vx[k] for k in keep],
                  [vy[k] for k in keep], [speed[k] for k in keep], cmap="plasma")
    fig.colorbar(q, ax=ax, label="|v| (mm/s)", shrink=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"Case 3: particle velocity at $\\varepsilon_a$ = {100 * st:.1f} %")
    fig.tight_layout()
    fig.savefig(d / "velocity.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
