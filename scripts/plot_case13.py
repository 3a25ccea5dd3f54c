#!/usr/bin/python3
"""Plots for thesis case 13 (consolidation of a saturated column) from the CSV files written by
`rktsph validate`: isochrones p_w/p0 against Terzaghi (Biot c_v), p_w(t) at z/H = 0.25, 0.5,
1.0, the degree of consolidation and the settlement, and e2 against dx.

Usage: /usr/bin/python3 scripts/plot_case13.py DIR   (DIR = validation/case13)
"""
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402

TV = ["0.05", "0.1", "0.2", "0.5", "1"]



def spacing(p, prefix):
    return float(p.stem[len(prefix):])


def main():
    d = Path(sys.argv[1])
    isos = sorted(d.glob("isochrones_dx*.csv"), key=lambda p: spacing(p, "isochrones_dx"))
    hists = sorted(d.glob("history_dx*.csv"), key=lambda p: spacing(p, "history_dx"))
    base = next((p for p in isos if abs(spacing(p, "isochrones_dx") - 0.1) < 1e-9), isos[0])

    fig, ax = plt.subplots(1, 2, figsize=(11, 5))
    data = read(base)
    for i, tv in enumerate(TV):
        c = f"C{i}"
        ax[0].plot(data["ref_Tv" + tv], data["z_over_H"], "-", color=c, label=f"exact, T_v = {tv}")
        ax[0].plot(data["num_Tv" + tv], data["z_over_H"], "o", ms=2.5, color=c)
    ax[0].invert_yaxis()
    ax[0].set_xlabel("p_w / p0")
    ax[0].set_ylabel("z / H (depth from the drained top)")
    ax[0].set_title(f"isochrones, dx = {spacing(base, 'isochrones_dx')} m (dots: rktsph)")
    ax[0].legend(fontsize=8)
    dxs, e2 = [], []
    for p in isos:
        r = read(p)
        num = sum((r["num_Tv" + t][k] - r["ref_Tv" + t][k]) ** 2 for t in TV[2:] for k in range(len(r["z_over_H"])))
        den = sum(r["ref_Tv" + t][k] ** 2 for t in TV[2:] for k in range(len(r["z_over_H"])))
        dxs.append(spacing(p, "isochrones_dx"))
        e2.append(math.sqrt(num / den))
    ax[1].loglog(dxs, e2, "o-", label="e2 over T_v >= 0.2")
    if len(dxs) > 1:
        ax[1].loglog(dxs, [e2[-1] * (x / dxs[-1]) for x in dxs], "k--", label="order 1")
    ax[1].set_xlabel("dx (m)")
    ax[1].set_ylabel("e2")
    ax[1].legend()
    ax[1].set_title("convergence")
    fig.tight_layout()
    fig.savefig(d / "isochrones.png", dpi=120)

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.5))
    for p in hists:
        h = read(p)
        dx = spacing(p, "history_dx")
        for j, key in enumerate(["p25", "p50", "p100"]):
            ax[0].plot(h["t"], h[key + "_num"], color=f"C{j}", lw=0.8, alpha=0.5 + 0.5 * (dx < 0.15))
        ax[1].plot(h["t"], h["U_num"], lw=0.8, label=f"dx = {dx}")
        ax[2].plot(h["t"], [1e3 * s for s in h["S_num"]], lw=0.8, label=f"dx = {dx}")
    h = read(hists[0])
    for j, (key, z) in enumerate([("p25", 0.25), ("p50", 0.5), ("p100", 1.0)]):
        ax[0].plot(h["t"], h[key + "_ref"], "k--", lw=0.8)
        ax[0].plot([], [], color=f"C{j}", label=f"z/H = {z}")
    ax[0].set_xlabel("t (s)")
    ax[0].set_ylabel("p_w / p0")
    ax[0].legend()
    ax[0].set_title("pore pressure (dashed: exact)")
    ax[1].plot(h["t"], h["U_ref"], "k--", label="exact")
    ax[1].set_xlabel("t (s)")
    ax[1].set_ylabel("U")
    ax[1].legend()
    ax[1].set_title("degree of consolidation")
    ax[2].plot(h["t"], [1e3 * s for s in h["S_ref"]], "k--", label="exact")
    ax[2].set_xlabel("t (s)")
    ax[2].set_ylabel("settlement (mm)")
    ax[2].legend()
    ax[2].set_title("settlement")
    fig.tight_layout()
    fig.savefig(d / "histories.png", dpi=120)


if __name__ == "__main__":
    main()
