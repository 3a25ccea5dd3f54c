#!/usr/bin/python3
"""Plots for thesis case 14 (harmonic loading of a saturated column) from the CSV files written
by `rktsph validate`: envelopes max|p_w|/q0 against the exact steady state, p_w(t) at z/L = 0.1
and 1.0, and the top displacement.

Usage: /usr/bin/python3 scripts/plot_case14.py DIR   (DIR = validation/case14)
"""
import re
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402



def key(p):
    m = re.search(r"_T([0-9.]+)_dx([0-9.]+)\.csv$", p.name)
    return float(m.group(1)), float(m.group(2))


def main():
    d = Path(sys.argv[1])
    envs = sorted(d.glob("envelope_T*_dx*.csv"), key=key)
    periods = sorted({key(p)[0] for p in envs})
    fig, ax = plt.subplots(1, len(periods), figsize=(4.2 * len(periods), 5), squeeze=False)
    for i, T in enumerate(periods):
        a = ax[0][i]
        first = True
        for p in envs:
            t, dx = key(p)
            if t != T:
                continue
            e = read(p)
            if first:
                a.plot(e["reference"], e["z_over_L"], "k-", label="exact")
                first = False
            a.plot(e["envelope"], e["z_over_L"], "o", ms=2, label=f"dx = {dx}")
        a.invert_yaxis()
        a.set_xlabel("max |p_w| / q0")
        a.set_ylabel("z / L")
        a.set_title(f"T = {T} s")
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(d / "envelopes.png", dpi=120)

    hists = [p for p in sorted(d.glob("history_T*_dx*.csv"), key=key) if abs(key(p)[1] - 0.1) < 1e-9]
    fig, ax = plt.subplots(len(hists), 2, figsize=(12, 2.8 * len(hists)), squeeze=False)
    for i, p in enumerate(hists):
        T, dx = key(p)
        h = read(p)
        ax[i][0].plot(h["t"], h["p_z01"], lw=0.7, label="z/L = 0.1")
        ax[i][0].plot(h["t"], h["p_base"], lw=0.7, label="z/L = 1 (base)")
        ax[i][0].set_ylabel("p_w / q0")
        ax[i][0].set_title(f"T = {T} s, dx = {dx}")
        ax[i][0].legend(fontsize=8)
        ax[i][1].plot(h["t"], [1e3 * u for u in h["u_top"]], lw=0.7)
        ax[i][1].set_ylabel("top settlement (mm)")
        ax[i][1].set_title(f"T = {T} s")
    for a in ax[-1]:
        a.set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(d / "histories.png", dpi=120)


if __name__ == "__main__":
    main()
