#!/usr/bin/python3
"""Plots for Case 18 (the collapse of a frictional column of aspect ratio 0.5, V2) from the CSV
files written by `rktsph validate 18`: snapshots of the particles (coloured by eps_vp_eq) at
t = 0.1, 0.2, 0.4 s and at rest, with the initial column and, at rest, the detected free surface
and the alpha-shape boundary; the final surface profiles with the line of slope tan(phi); the
front position and the kinetic energy against time, at both spacings.

Usage: /usr/bin/python3 scripts/plot_case18.py DIR   (DIR = validation/case18)
"""
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402

L0, H0, PHI = 0.2, 0.1, 19.8


def suffixes(d):
    return sorted((p.name[len("frames"):-len(".csv")] for p in d.glob("frames_dx*.csv")),
                  key=lambda s: -float(s[3:-2]))


def main(d):
    d = Path(d)
    tags = suffixes(d)
    fine = tags[-1]
    fr = read(d / f"frames{fine}.csv")
    times = sorted(set(fr["t"]))
    fig, axes = plt.subplots(len(times), 1, figsize=(10, 1.9 * len(times) + 0.6))
    if len(times) == 1:
        axes = [axes]
    for ax, t in zip(axes, times):
        idx = [i for i, v in enumerate(fr["t"]) if v == t]
        e = [min(fr["eps_vp_eq"][i], 1.0) for i in idx]
        sc = ax.scatter([fr["x"][i] for i in idx], [fr["y"][i] for i in idx], c=e, s=1.5, cmap="viridis", vmin=0,
                        vmax=1.0)
        ax.plot([0, L0, L0], [H0, H0, 0], "k--", lw=0.7, label="initial column")
        vb = [i for i in idx if fr["visual_boundary"][i] == 1]
        if vb:
            fs = [i for i in idx if fr["free_surface"][i] != 0]
            ax.plot([fr["x"][i] for i in fs], [fr["y"][i] for i in fs], "r.", ms=2, label="detected free surface")
            ax.plot([fr["x"][i] for i in vb], [fr["y"][i] for i in vb], "o", mfc="none", mec="k", ms=3, mew=0.4,
                    label="alpha-shape boundary")
        ax.set_aspect("equal")
        ax.set_xlim(-0.01, 0.45)
        ax.set_ylim(-0.005, 0.11)
        ax.set_title(f"t = {t:.3f} s", fontsize=9)
        ax.set_ylabel("y (m)")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("x (m)")
    fig.colorbar(sc, ax=list(axes), label=r"$\bar\varepsilon$ (clipped at 1)", fraction=0.02, pad=0.01)
    fig.savefig(d / "snapshots.png", dpi=130, bbox_inches="tight")

    fig, ax = plt.subplots(figsize=(10, 3.4))
    for tag in tags:
        p = read(d / f"profile{tag}.csv")
        ax.step(p["x"], p["h"], where="mid", label=f"at rest, {tag[1:]}")
    front = max(x for x, h in zip(p["x"], p["h"]) if h > 0)
    ax.plot([front, front - H0 / math.tan(math.radians(PHI))], [0, H0], "k--", lw=0.8,
            label=r"slope $\tan\varphi$ from the front")
    ax.axhline(0.97 * H0, color="r", ls=":", lw=0.8, label="0.97 $H_0$")
    ax.axvspan(1.45 * L0, 1.75 * L0, color="g", alpha=0.12, label=r"$L_\infty$ in [1.45, 1.75] $L_0$")
    ax.set_xlim(0, 0.45)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("h (m)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(d / "profile.png", dpi=130)

    fig, ax = plt.subplots(1, 2, figsize=(12, 3.6))
    for tag in tags:
        h = read(d / f"history{tag}.csv")
        ax[0].plot(h["t"], [f / L0 for f in h["front"]], label=tag[1:])
        ax[1].semilogy(h["t"], [max(k, 1e-30) for k in h["kinetic"]], label=tag[1:])
    ax[0].set_ylabel(r"front / $L_0$")
    ax[1].set_ylabel("kinetic energy (J/m)")
    for a in ax:
        a.set_xlabel("t (s)")
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(d / "history.png", dpi=130)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "validation/case18")
