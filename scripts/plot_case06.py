#!/usr/bin/python3
"""Plots for thesis case 6 (vertical cut with softening) from the CSV files written by
`rktsph validate`.

Usage: /usr/bin/python3 scripts/plot_case06.py DIR   (DIR = validation/case06)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from plot_case05 import eps_map, histories, read  # noqa: E402


def main(d):
    d = Path(d)
    histories(d, d / "histories.png", "Case 6 (softening): crest displacement and kinetic energy",
              [("history_N2.2_dx*.csv", "N0 = 2.2 (expected stable)"),
               ("history_N3.4_dx*.csv", "N0 = 3.4 (not predicted)"),
               ("history_N3.9_dx*.csv", "N0 = 3.9 (expected collapse)"),
               ("history_case5_N3.4_dx*.csv", "case 5, N = 3.4 (no softening)")])
    finals = sorted(d.glob("final_N3.9_dx*.csv"), key=lambda p: -float(p.stem.split("_dx")[-1]))
    fig, axes = plt.subplots(len(finals), 1, figsize=(11, 5 * len(finals)), squeeze=False)
    for ax, p in zip(axes[:, 0], finals):
        eps_map(ax, read(p), f"Case 6, N0 = 3.9, end of run, dx = {p.stem.split('_dx')[-1]} m")
        ax.axhline(5.0, color="w", ls=":", lw=0.8)
    fig.tight_layout()
    fig.savefig(d / "eps_maps.png", dpi=100)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(9, 4.8))
    for p in sorted(d.glob("profile_*.csv")):
        s = read(p)
        name = p.stem[len("profile_"):]
        lab = ("case 5 N = 4.2 (no softening)" if name.startswith("case5") else "case 6 N0 = 3.9") + \
            f", dx = {name.split('_dx')[-1]} m"
        ax.plot(s["x"], s["eps_vp_eq"], "o-", ms=2, label=lab)
    ax.set_xlabel("x (m) along y = H/2")
    ax.set_ylabel("accumulated plastic strain $\\bar\\varepsilon^{vp}$ (-)")
    ax.set_yscale("log")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Profiles across the band at mid-height when $u_c$ first exceeds 0.05 H (band width = FWHM)")
    fig.tight_layout()
    fig.savefig(d / "band_profiles.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
