#!/usr/bin/python3
"""Plots for thesis case 16 (saturated Cam-Clay plane-strain compression) from the CSV files
written by `rktsph validate`.

Usage: /usr/bin/python3 scripts/plot_case16.py DIR   (DIR = validation/case16)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402

RUNS = [("k1e-09", "k = 1e-9 m/s (undrained)"), ("k1e-06", "k = 1e-6 m/s (local drainage)")]


def main(d):
    d = Path(d)
    dx = open(d / "plot_input.txt").read().strip()
    cf = read(d / "closed_form.csv")
    meta = read(d / "meta.csv")
    q_y, p_y, pw_y, e_y = meta["q_y"][0], meta["p_y"][0], meta["dpw_y"][0], meta["eps_y"][0]
    p_f, q_f = meta["p_f"][0], meta["q_f"][0]

    fig, axes = plt.subplots(1, 4, figsize=(22, 4.6))
    for tag, lab in RUNS:
        p = d / f"history_{tag}.csv"
        if not p.exists():
            continue
        h = read(p)
        e = [100 * s for s in h["strain"]]
        axes[0].plot(e, [v / 1e3 for v in h["q"]], label=f"RKT-SPH V3, {lab}")
        axes[1].plot(e, [v / 1e3 for v in h["p"]], label=f"RKT-SPH V3, {lab}")
        axes[2].plot(e, [v / 1e3 for v in h["dpw"]], label=f"RKT-SPH V3, {lab}")
        if "eps_vp_eq_cov" in h:
            axes[3].plot(e, h["eps_vp_eq_cov"], label=f"RKT-SPH V3, {lab}")
    ce = [100 * s for s in cf["strain"]]
    for ax, key, yv in ((axes[0], "q", q_y), (axes[1], "p", p_y), (axes[2], "dpw", pw_y)):
        ax.plot(ce, [v / 1e3 for v in cf[key]], "k--", label="closed-form undrained elastic path")
        ax.plot([100 * e_y], [yv / 1e3], "r*", ms=12, label="closed-form first yield")
    axes[0].axhline(q_f / 1e3, color="C2", ls=":", label=f"undrained critical state q_f = {q_f / 1e3:.1f} kPa")
    axes[1].axhline(p_f / 1e3, color="C2", ls=":", label=f"undrained critical state p'_f = {p_f / 1e3:.1f} kPa")
    axes[0].set_ylabel("q of the average stress (kPa)")
    axes[1].set_ylabel("p' of the average effective stress (kPa)")
    axes[2].set_ylabel("mean excess pore pressure $\\Delta p_w$ (kPa)")
    axes[3].axhline(0.2, color="r", ls=":", label="docs/cases.md no-band limit at 8 % (k = 1e-9)")
    axes[3].set_ylabel("coefficient of variation of $\\bar\\varepsilon^{vp}$ (-)")
    axes[3].set_ylim(0, 2)
    for ax in axes:
        ax.set_xlabel("axial strain $\\varepsilon_a$ (%)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"Case 16: saturated Cam-Clay sample, response (dx = {dx} m)")
    fig.tight_layout()
    fig.savefig(d / "response.png", dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(1, 4, figsize=(17, 7.5))
    col = 0
    for tag, lab in RUNS:
        p = d / f"snapshots_{tag}.csv"
        if not p.exists():
            continue
        s = read(p)
        st = max(s["strain"])
        idx = [i for i, v in enumerate(s["strain"]) if v == st]
        x = [s["x"][i] for i in idx]
        y = [s["y"][i] for i in idx]
        ax = axes[col]
        sc = ax.scatter(x, y, c=[s["eps_vp_eq"][i] for i in idx], s=8, marker="s", cmap="viridis")
        fig.colorbar(sc, ax=ax, label="$\\bar\\varepsilon^{vp}$ (-)", shrink=0.7)
        band = [i for i in idx if s["in_band"][i] > 0.5]
        if band and tag == "k1e-06":
            ax.plot([s["x"][i] for i in band], [s["y"][i] for i in band], "r.", ms=2, label="band cloud (50 % of the largest outside the imperfection)")
            ax.legend(fontsize=7, loc="lower right")
        ax.set_title(f"{lab}\n$\\bar\\varepsilon^{{vp}}$ at $\\varepsilon_a$ = {100 * st:.1f} %", fontsize=9)
        ax = axes[col + 1]
        pw = [s["pw"][i] / 1e3 for i in idx]
        sc = ax.scatter(x, y, c=pw, s=8, marker="s", cmap="coolwarm")
        fig.colorbar(sc, ax=ax, label="$p_w$ (kPa)", shrink=0.7)
        ax.set_title(f"{lab}\n$p_w$ at $\\varepsilon_a$ = {100 * st:.1f} %", fontsize=9)
        col += 2
    for ax in axes:
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
    axes[0].set_ylabel("y (m)")
    fig.suptitle(f"Case 16: accumulated deviatoric viscoplastic strain and pore pressure, dx = {dx} m")
    fig.tight_layout()
    fig.savefig(d / "maps.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
