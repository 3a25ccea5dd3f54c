#!/usr/bin/python3
"""Mandel's problem (rktsph validate mandel): centre pore pressure and plate settlement against
the exact series, for each resolution. Usage: plot_mandel.py DIR (the history_dx*.csv files)."""
import csv
import glob
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def main(folder):
    files = sorted(glob.glob(os.path.join(folder, "history_dx*.csv")), reverse=True)
    fig, (ax_p, ax_u) = plt.subplots(1, 2, figsize=(11, 4.2))
    exact = None
    for path in files:
        d = read(path)
        dx = os.path.basename(path)[len("history_dx"):-len(".csv")]
        ax_p.plot(d["tc_over_a2"], d["p_over_p0"], lw=1.2, label=f"rktsph, dx = {dx} m")
        ax_u.plot(d["tc_over_a2"], [1e3 * u for u in d["settlement"]], lw=1.2, label=f"rktsph, dx = {dx} m")
        exact = d
    if exact is not None:
        ax_p.plot(exact["tc_over_a2"], exact["p_exact_over_p0"], "k--", lw=1.0, label="exact (Mandel)")
        ax_u.plot(exact["tc_over_a2"], [1e3 * u for u in exact["settlement_exact"]], "k--", lw=1.0,
                  label="exact (Mandel)")
    ax_p.axhline(1.0, color="0.6", lw=0.6)
    ax_p.set_ylabel("centre $p_w$ / $p_0$")
    ax_p.set_title("Mandel–Cryer effect at the centre")
    ax_u.set_ylabel("plate settlement (mm)")
    ax_u.set_title("Rigid plate under a constant force")
    for ax in (ax_p, ax_u):
        ax.set_xscale("log")
        ax.set_xlim(left=1e-3)
        ax.set_xlabel("t c / a$^2$")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "mandel.png"), dpi=130)


if __name__ == "__main__":
    main(sys.argv[1])
