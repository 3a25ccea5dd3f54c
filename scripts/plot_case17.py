#!/usr/bin/python3
"""Plots for thesis case 17 (saturated vertical cut) from the CSV files written by
`rktsph validate`.

Usage: /usr/bin/python3 scripts/plot_case17.py DIR   (DIR = validation/case17)
"""
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read, style_crest_history  # noqa: E402

RUNS = [("N3.4_k1e-05", "N = 3.4, k = 1e-5 m/s"), ("N3.4_k1e-07", "N = 3.4, k = 1e-7 m/s"),
        ("N4.2_k1e-05", "N = 4.2, k = 1e-5 m/s"), ("N4.2_k1e-07", "N = 4.2, k = 1e-7 m/s")]


def main(d):
    d = Path(d)
    meta = read(d / "meta.csv")
    dx, H, W = meta["dx"][0], meta["H"][0], meta["W"][0]

    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8))
    for tag, lab in RUNS:
        p = d / f"history_{tag}.csv"
        if not p.exists():
            continue
        h = read(p)
        ls = "-" if "k1e-05" in tag else "--"
        axes[0].plot(h["t"], h["uc"], ls, label=lab)
        axes[1].semilogy(h["t"], [max(k, 1e-12) for k in h["kinetic"]], ls, label=lab)
    style_crest_history(axes, H, [(3.0, "--", "end of the gravity ramp"), (6.0, ":", "t = 6 s (u_c compared between k)")])
    fig.suptitle(f"Case 17: saturated cut, crest displacement and kinetic energy (dx = {dx:g} m)")
    fig.tight_layout()
    fig.savefig(d / "histories.png", dpi=110)
    plt.close(fig)

    # p_w at the end of the ramp and after 3 s of hold, N = 3.4, both k; mean total stress for reference
    fig, axes = plt.subplots(3, 2, figsize=(13, 10))
    for c, tag in enumerate(["N3.4_k1e-05", "N3.4_k1e-07"]):
        for r, (stem, when) in enumerate([("ramp", "end of ramp (3 s)"), ("hold", "after 3 s of hold (6 s)")]):
            p = d / f"{stem}_{tag}.csv"
            ax = axes[r][c]
            if not p.exists():
                ax.set_title(f"{tag}: no {stem} state")
                continue
            s = read(p)
            sc = ax.scatter(s["x"], s["y"], c=[v / 1e3 for v in s["pw"]], s=6, marker="s", cmap="viridis",
                            vmin=0, vmax=200)
            fig.colorbar(sc, ax=ax, label="$p_w$ (kPa)")
            ax.set_title(f"{dict(RUNS)[tag]}: $p_w$, {when}", fontsize=9)
        p = d / f"ramp_{tag}.csv"
        ax = axes[2][c]
        if p.exists():
            s = read(p)
            sc = ax.scatter(s["x"], s["y"], c=[v / 1e3 for v in s["p_total"]], s=6, marker="s", cmap="viridis",
                            vmin=0, vmax=200)
            fig.colorbar(sc, ax=ax, label="mean total stress (kPa)")
            ax.add_patch(plt.Rectangle((0, 0), W - 0.5 * H, 0.5 * H, fill=False, ec="r", lw=1.2,
                                       label="region of the p_w / total stress check"))
            ax.legend(fontsize=7, loc="upper left")
            ax.set_title(f"{dict(RUNS)[tag]}: mean total stress $-$tr$\\sigma$/3, end of ramp", fontsize=9)
    for row in axes:
        for ax in row:
            ax.set_aspect("equal")
            ax.set_xlabel("x (m)")
            ax.set_ylabel("y (m)")
    fig.suptitle("Case 17: pore pressure (excess over hydrostatic) in the saturated cut")
    fig.tight_layout()
    fig.savefig(d / "pw_maps.png", dpi=110)
    plt.close(fig)

    em = read(d / "emergence.csv") if (d / "emergence.csv").exists() else None
    fig, axes = plt.subplots(2, 1, figsize=(11, 10))
    from matplotlib.colors import LogNorm
    for ax, tag in zip(axes, ["N4.2_k1e-05", "N4.2_k1e-07"]):
        p = d / f"final_{tag}.csv"
        if not p.exists():
            continue
        s = read(p)
        top = max(s["eps_vp_eq"]) or 1.0
        vals = [max(e, 1e-3 * top) for e in s["eps_vp_eq"]]
        sc = ax.tripcolor(s["x"], s["y"], vals, shading="gouraud", cmap="viridis", norm=LogNorm(vmin=1e-3 * top, vmax=top))
        plt.colorbar(sc, ax=ax, label="accumulated plastic strain $\\bar\\varepsilon^{vp}$ (-, log scale)")
        cx, cy, R = W + 1.41 * H, 2.21 * H, 2.62 * H
        xs, ys = [], []
        for k in range(400):
            a = math.pi + k * (math.pi / 2) / 399
            x, y = cx + R * math.cos(a), cy + R * math.sin(a)
            if 0 <= y <= H and x <= W:
                xs.append(x)
                ys.append(y)
        ax.plot(xs, ys, "r--", label="limit-analysis circular mechanism (0.91H)")
        ax.axvspan(W - 1.15 * H, W - 0.7 * H, ymin=0.9, color="orange", alpha=0.3, label="accepted emergence 0.7H-1.15H")
        if em is not None and tag in em["label"]:
            e = em["emergence"][em["label"].index(tag)]
            ax.plot([W - e], [H], "wv", ms=10, mec="k", label=f"measured emergence ({e:.2f} m behind the crest)")
        ax.set_title(f"{dict(RUNS)[tag]}: end of run", fontsize=9)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_aspect("equal")
        ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(d / "eps_maps.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
