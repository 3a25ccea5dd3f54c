#!/usr/bin/python3
"""Plots for thesis case 2 (1D viscoplastic bar with softening) from the CSV files written by
`rktsph validate`.

Usage: /usr/bin/python3 scripts/plot_case02.py DIR   (DIR = validation/case02)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402

L_OVER_C = 10.0 / (1.0e7 / 2000.0) ** 0.5
# docs/cases.md Case 2, Variant B reference at t_end = 1.8 L/c.
EPS_X = [0.0, 0.05, 0.10, 0.20, 0.30, 0.50, 1.0]
EPS_REF = [0.0475, 0.0321, 0.0234, 0.0132, 0.0079, 0.0034, 0.0007]
SIG_X = [1.0, 2.0, 3.0, 5.0, 7.0, 9.5]
SIG_REF = [18.8, 19.6, 20.0, 20.0, 20.0, 15.0]



def spacing(p, prefix):
    return float(p.stem[len(prefix):])


def main(d):
    d = Path(d)
    profiles = sorted(d.glob("profile_dx*.csv"), key=lambda p: -spacing(p, "profile_dx"))
    histories = sorted(d.glob("history_dx*.csv"), key=lambda p: -spacing(p, "history_dx"))

    fig, axes = plt.subplots(1, 2, figsize=(13, 4.2))
    for p in profiles:
        dx = spacing(p, "profile_dx")
        r = read(p)
        axes[0].plot(r["x"], r["eps_vp_eq"], "-", label=f"RKT-SPH dx = {dx} m")
        axes[1].plot(r["x"], [s / 1e3 for s in r["sigma"]], "-", lw=1, label=f"RKT-SPH dx = {dx} m")
    for p in sorted(d.glob("profile_gamma1e4_dx*.csv")):
        r = read(p)
        dx = spacing(p, "profile_gamma1e4_dx")
        axes[0].plot(r["x"], r["eps_vp_eq"], ":", label=f"diagnostic $\\gamma_f$ = 1e4 1/s, dx = {dx} m")
    axes[0].plot(EPS_X, EPS_REF, "ko", mfc="none", label="reference (docs/cases.md, Variant B)")
    axes[0].axhline(0.0475 / 2, color="grey", lw=0.6, ls="--")
    axes[0].set_xlim(0, 1.0)
    axes[0].set_xlabel("x (m)")
    axes[0].set_ylabel("accumulated viscoplastic strain $\\bar\\varepsilon^{vp}$ (-)")
    axes[0].set_title("$\\bar\\varepsilon^{vp}$ near the fixed end, t = 1.8 L/c")
    axes[1].plot(SIG_X, SIG_REF, "ko", mfc="none", label="reference (docs/cases.md, Variant B)")
    axes[1].set_xlabel("x (m)")
    axes[1].set_ylabel("axial stress $\\sigma$ (kPa)")
    axes[1].set_title("$\\sigma$ along the bar, t = 1.8 L/c")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(d / "profiles.png", dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(13, 4.0))
    for p in histories:
        dx = spacing(p, "history_dx")
        h = read(p)
        t = [x / L_OVER_C for x in h["t"]]
        axes[0].plot(t, [s / 1e3 for s in h["sigma_x0"]], label=f"dx = {dx} m")
        axes[1].plot(t, [v * 1e3 for v in h["integral_eps"]], label=f"dx = {dx} m")
    axes[0].axhline(20.0, color="grey", ls="--", lw=0.8, label="$\\sigma_{Y0}$")
    axes[0].set_ylabel("$\\sigma$ at x = 0 (kPa)")
    axes[1].plot([1.8], [8.27], "ko", mfc="none", label="reference at t$_{end}$")
    axes[1].set_ylabel("$\\int_0^L \\bar\\varepsilon^{vp} dx$ (mm)")
    for ax in axes:
        ax.set_xlabel("time (L/c)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(d / "histories.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
