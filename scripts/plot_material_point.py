#!/usr/bin/python3
"""Stress-path plot of a material-point run (rktsph material-point): q-p' and q-strain.

Usage: /usr/bin/python3 scripts/plot_material_point.py path.csv path.png [--strain yy]
The strain component is plotted compression-positive for normal components (-e, %) and as the
engineering shear strain 2 e (%) for shear components.
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("png")
    ap.add_argument("--strain", default="yy", choices=["xx", "yy", "zz", "xy"])
    a = ap.parse_args()
    with open(a.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    p = [float(r["p"]) / 1e3 for r in rows]
    q = [float(r["q"]) / 1e3 for r in rows]
    e = [float(r["e" + a.strain]) for r in rows]
    if a.strain == "xy":
        x = [200.0 * v for v in e]
        xlabel = "engineering shear strain 2ε_xy (%)"
    else:
        x = [-100.0 * v for v in e]
        xlabel = f"strain −ε_{a.strain} (%, compression positive)"
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4.2))
    ax1.plot(p, q, "-", lw=1.5)
    ax1.plot(p[:1], q[:1], "o", label="start")
    ax1.set_xlabel("mean effective stress p' (kPa)")
    ax1.set_ylabel("deviator stress q (kPa)")
    ax1.set_title("stress path")
    ax1.grid(True, alpha=0.3)
    ax1.legend()
    ax2.plot(x, q, "-", lw=1.5)
    ax2.set_xlabel(xlabel)
    ax2.set_ylabel("deviator stress q (kPa)")
    ax2.set_title("q against strain")
    ax2.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)


if __name__ == "__main__":
    main()
