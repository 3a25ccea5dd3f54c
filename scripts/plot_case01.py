#!/usr/bin/python3
"""Plots for thesis case 1 (1D elastic bar) from the CSV files written by `rktsph validate`.

Usage: /usr/bin/python3 scripts/plot_case01.py DIR   (DIR = validation/case01)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402



def main(d):
    d = Path(d)
    # Stress profiles, smooth load, at the snapshots, three resolutions.
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), sharey=True)
    for n, style in ((100, "o"), (200, "s"), (400, "-")):
        data = read(d / f"smooth_N{n}.csv")
        for ax, snap in zip(axes, (0.5, 1.5, 3.5)):
            idx = [i for i, s in enumerate(data["snapshot_LC"]) if abs(s - snap) < 0.02]
            x = [data["x"][i] for i in idx]
            s = [data["sigma"][i] / 1e3 for i in idx]
            if style == "-":
                ax.plot(x, s, "-", color="tab:blue", label=f"RKT-SPH N = {n}")
                ax.plot(x, [data["sigma_exact"][i] / 1e3 for i in idx], "k--", label="exact")
            else:
                ax.plot(x[::2], s[::2], style, ms=3, mfc="none", label=f"RKT-SPH N = {n}")
            ax.set_title(f"t = {snap} L/c")
            ax.set_xlabel("x (m)")
            ax.grid(alpha=0.3)
    axes[0].set_ylabel("axial stress $\\sigma_{xx}$ (kPa)")
    axes[0].legend(fontsize=8)
    fig.suptitle("Case 1, smooth load: stress profiles against the exact solution")
    fig.tight_layout()
    fig.savefig(d / "profiles_smooth.png", dpi=110)
    plt.close(fig)

    # Histories of the step-load runs: v at the loaded end and sigma at the fixed end.
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    h = read(d / "step_tension_N100_C0.5.csv")
    h4 = read(d / "step_tension_N400_C0.5.csv")
    axes[0].plot(h["t_LC"], h["v_loaded"], label="N = 100")
    axes[0].plot(h4["t_LC"], h4["v_loaded"], label="N = 400", lw=0.8)
    axes[0].plot(h["t_LC"], h["v_loaded_exact"], "k--", label="exact")
    axes[0].set_ylabel("v at x = L (m/s)")
    axes[0].legend(fontsize=8, loc="upper right")
    axes[1].plot(h["t_LC"], [s / 1e3 for s in h["sigma_fixed"]], label="N = 100")
    axes[1].plot(h4["t_LC"], [s / 1e3 for s in h4["sigma_fixed"]], label="N = 400", lw=0.8)
    axes[1].plot(h["t_LC"], [s / 1e3 for s in h["sigma_fixed_exact"]], "k--", label="exact")
    axes[1].set_ylabel("$\\sigma_{xx}$ at x = 0 (kPa)")
    axes[1].set_xlabel("time (L/c)")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle("Case 1, step load in tension (C = 0.5) over 20 transits")
    fig.tight_layout()
    fig.savefig(d / "histories_step.png", dpi=110)
    plt.close(fig)

    # Energy balance and L1 error against time, C = 0.5 and C = 1.2.
    fig, axes = plt.subplots(1, 2, figsize=(12, 3.8))
    for n in (100, 400):
        for c in ("0.5", "1.2"):
            f = d / f"step_tension_N{n}_C{c}.csv"
            if f.exists():
                h = read(f)
                axes[0].plot(h["t_LC"], [100 * e for e in h["energy_error"]], label=f"N = {n}, C = {c}")
                axes[1].plot(h["t_LC"], h["e1"], label=f"N = {n}, C = {c}")
    col = d / "collocated_step_tension_N100_C0.5.csv"
    if col.exists():
        h = read(col)
        axes[0].plot(h["t_LC"], [100 * e for e in h["energy_error"]], "k:", label="single set, N = 100")
        axes[1].plot(h["t_LC"], h["e1"], "k:", label="single set, N = 100")
    axes[0].set_ylabel("energy balance error (% of $\\sigma_0 \\cdot 2\\sigma_0 L/E$)")
    axes[1].set_ylabel("$e_1(\\sigma)$, L1 relative error")
    for ax in axes:
        ax.set_xlabel("time (L/c)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Case 1, step load: energy balance and error against time")
    fig.tight_layout()
    fig.savefig(d / "energy_error.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "validation/case01")
