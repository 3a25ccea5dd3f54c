#!/usr/bin/python3
"""Plots for thesis case 9 (collapse and run-out of a low-cohesion vertical slope, V2) from the CSV
files written by `rktsph validate 09`: snapshots of the particles (coloured by eps_vp_eq) at
t = 1, 2, 4 s and at the end, with the detected free surface and, at the end, the alpha-shape
boundary; the final surface profile against the Nye profile h = sqrt(2 c (x_f - x) / (rho g));
the front position and the kinetic energy against time.

Usage: /usr/bin/python3 scripts/plot_case09.py DIR   (DIR = validation/case09)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402


def main(d):
    d = Path(d)
    meta = read(d / "meta.csv")
    h0, xf = meta["h0"][0], meta["xf"][0]
    fr = read(d / "frames.csv")
    times = sorted(set(fr["t"]))
    fig, axes = plt.subplots(len(times), 1, figsize=(12, 2.4 * len(times) + 0.5))
    if len(times) == 1:
        axes = [axes]
    emax = max(fr["eps_vp_eq"]) or 1.0
    for ax, t in zip(axes, times):
        idx = [i for i, v in enumerate(fr["t"]) if v == t]
        x = [fr["x"][i] for i in idx]
        y = [fr["y"][i] for i in idx]
        e = [min(fr["eps_vp_eq"][i], 5.0) for i in idx]
        sc = ax.scatter(x, y, c=e, s=2, cmap="viridis", vmin=0, vmax=min(emax, 5.0))
        fs = [i for i in idx if fr["free_surface"][i] != 0]
        ax.plot([fr["x"][i] for i in fs], [fr["y"][i] for i in fs], "r.", ms=2, label="detected free surface")
        vb = [i for i in idx if fr["visual_boundary"][i] == 1]
        if vb:
            ax.plot([fr["x"][i] for i in vb], [fr["y"][i] for i in vb], "o", mfc="none", mec="k", ms=3.5, mew=0.4,
                    label="alpha-shape boundary (r = 1.5 dx)")
        ax.set_aspect("equal")
        ax.set_ylim(-0.3, 10.5)
        ax.set_title(f"t = {t:.2f} s", fontsize=9)
        ax.set_ylabel("y (m)")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("x (m)")
    for ax in axes:
        ax.set_xlim(-0.3, max(30.0, max(fr["x"]) + 0.5))
    fig.colorbar(sc, ax=list(axes), label=r"$\bar\varepsilon$ (clipped at 5)", fraction=0.015, pad=0.01)
    fig.savefig(d / "snapshots.png", dpi=130, bbox_inches="tight")

    p = read(d / "profile.csv")
    fig, ax = plt.subplots(figsize=(11, 3.8))
    ax.step(p["x"], p["h"], where="mid", label="final deposit (highest node per column)")
    ax.plot(p["x"], p["h_nye"], "k--", label=f"Nye: $h_0$ = {h0:.3f} m, $x_f$ = {xf:.2f} m")
    ax.axhline(1.10 * h0, color="r", ls=":", lw=0.8, label="1.10 $h_0$ (wall-height tolerance)")
    ax.axvline(0.90 * xf, color="r", ls="-.", lw=0.8, label="0.90 $x_f$ (run-out tolerance)")
    ax.set_xlim(0, max(30.0, max(x for x, h in zip(p["x"], p["h"]) if h > 0) + 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("h (m)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(d / "profile.png", dpi=130)

    h = read(d / "history.csv")
    fig, ax = plt.subplots(1, 3, figsize=(14, 3.8))
    ax[0].plot(h["t"], h["front"])
    ax[0].axhline(xf, color="k", ls="--", lw=0.8, label="Nye $x_f$")
    ax[0].set_ylabel("front (m)")
    ax[1].semilogy(h["t"], h["kinetic"])
    ax[1].axhline(1e-4 * max(h["kinetic"]), color="r", ls=":", lw=0.8, label="1e-4 of the peak")
    ax[1].set_ylabel("kinetic energy (J/m)")
    ax[2].plot(h["t"], h["nn_cv"], label="cv of nearest-neighbour distance")
    ax[2].plot(h["t"], h["nn_max"], label="max nearest-neighbour distance / dx")
    ax[2].plot(h["t"], h["nn_min"], label="min nearest-neighbour distance / dx")
    for a in ax:
        a.set_xlabel("t (s)")
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(d / "history.png", dpi=130)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "validation/case09")
