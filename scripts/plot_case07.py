#!/usr/bin/python3
"""Plots for thesis case 7 (1D elastic bar in large deformation) from the CSV files written by
`rktsph validate 07`: sigma, lambda and v against X at 0.06 and 0.12 s for the push (a shock)
and the pull (a rarefaction fan), with the exact solution and V1's small-strain push; and the
particle trajectories x(X, t).

Usage: /usr/bin/python3 scripts/plot_case07.py DIR   (DIR = validation/case07)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402


def at(data, t, key):
    idx = [i for i, s in enumerate(data["t"]) if abs(s - t) < 1e-3]
    return [data["X"][i] for i in idx], [data[key][i] for i in idx]


def main(d):
    d = Path(d)
    fig, axes = plt.subplots(3, 2, figsize=(12, 9), sharex=True)
    for col, run in enumerate(("push", "pull")):
        fine = read(d / f"{run}_dx0.025.csv")
        coarse = read(d / f"{run}_dx0.05.csv")
        small = read(d / "push_small_strain_dx0.05.csv") if run == "push" else None
        for row, (key, scale, label) in enumerate(
            (("sigma", 1e-6, "$\\sigma_{xx}$ (MPa)"), ("lambda", 1.0, "stretch $\\lambda = \\partial x/\\partial X$"),
             ("v", 1.0, "velocity $v$ (m/s)"))
        ):
            ax = axes[row][col]
            for t, color in ((0.06, "tab:blue"), (0.12, "tab:orange")):
                X, y = at(coarse, t, key)
                ax.plot(X, [v * scale for v in y], "o", ms=2, color=color, mfc="none", label=f"dx 0.05 m, t = {t} s")
                X, y = at(fine, t, key)
                ax.plot(X, [v * scale for v in y], "-", lw=1, color=color, label=f"dx 0.025 m, t = {t} s")
                X, y = at(fine, t, key + "_exact")
                ax.plot(X, [v * scale for v in y], "k--", lw=0.8, label="exact" if t == 0.06 else None)
                if small is not None and key == "sigma":
                    X, y = at(small, t, key)
                    ax.plot(X, [v * scale for v in y], ":", color="0.4", lw=1,
                            label="V1 small strain" if t == 0.06 else None)
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
            if row == 0:
                ax.set_title("push: one shock" if run == "push" else "pull: a rarefaction fan")
                ax.legend(fontsize=7)
        axes[2][col].set_xlabel("reference position X (m)")
    fig.suptitle("Case 7: V2 (moving particles, Jaumann rate, simple second step) against the exact solution")
    fig.tight_layout()
    fig.savefig(d / "profiles.png", dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    for ax, run in zip(axes, ("push", "pull")):
        tracks = read(d / f"{run}_tracks_dx0.05.csv")
        for key in tracks:
            if key == "t":
                continue
            ax.plot(tracks[key], tracks["t"], lw=0.6, color="tab:blue")
        ax.set_xlabel("current position x (m)")
        ax.set_title(f"{run}: particle trajectories x(X, t), every 10th node")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("t (s)")
    fig.tight_layout()
    fig.savefig(d / "tracks.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
