#!/usr/bin/python3
"""Plot of a limit-equilibrium analysis (rktsph lem): the soil's outline, the critical circle
with its slices, and the least factor of safety over the radii at each centre of the first
search grid (contours), with the critical centre.

Usage: /usr/bin/python3 scripts/plot_lem.py lem.json lem.png
"""
import argparse
import json
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("json")
    ap.add_argument("png")
    a = ap.parse_args()
    with open(a.json) as f:
        j = json.load(f)
    fig, ax = plt.subplots(figsize=(10, 6))
    xs, ys = [], []
    for b in j["bodies"]:
        ax.add_patch(Polygon(b["outer"], closed=True, facecolor="#e8d9b5", edgecolor="k", lw=1.2))
        for h in b["holes"]:
            ax.add_patch(Polygon(h, closed=True, facecolor="w", edgecolor="k", lw=1.0))
        xs += [p[0] for p in b["outer"]]
        ys += [p[1] for p in b["outer"]]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    for r in j["rigid_regions"]:
        rx = [x0 if r["x"][0] is None else max(r["x"][0], x0), x1 if r["x"][1] is None else min(r["x"][1], x1)]
        ry = [y0 if r["y"][0] is None else max(r["y"][0], y0), y1 if r["y"][1] is None else min(r["y"][1], y1)]
        ax.plot([rx[0], rx[1], rx[1], rx[0], rx[0]], [ry[0], ry[0], ry[1], ry[1], ry[0]], "-", color="0.3", lw=3,
                alpha=0.6)
    # Contours of the least F per centre (first grid).
    g = [p for p in j["first_grid"] if p[2] is not None]
    F = j.get("factor_of_safety")
    if len(g) >= 3:
        gx, gy, gf = [p[0] for p in g], [p[1] for p in g], [p[2] for p in g]
        cap = (F or min(gf)) * 2.5
        levels = sorted(set([round(F * k, 3) for k in (1.02, 1.05, 1.1, 1.2, 1.35, 1.5, 1.75, 2.0)])) if F else 8
        try:
            cs = ax.tricontour(gx, gy, [min(v, cap) for v in gf], levels=levels, colors="tab:blue", linewidths=0.7)
            ax.clabel(cs, fmt="%.3g", fontsize=7)
        except (ValueError, RuntimeError):
            pass
    if F is not None:
        (xc, yc), R = j["circle"]["centre"], j["circle"]["radius"]
        ex, en = j["exit"], j["entry"]
        a0 = math.atan2(ex[1] - yc, ex[0] - xc)
        a1 = math.atan2(en[1] - yc, en[0] - xc)
        if a0 > 0:
            a0 -= 2 * math.pi
        if a1 > 0:
            a1 -= 2 * math.pi
        n = 200
        arc = [a0 + (a1 - a0) * k / n for k in range(n + 1)]
        ax.plot([xc + R * math.cos(t) for t in arc], [yc + R * math.sin(t) for t in arc], "r-", lw=2,
                label=f"critical circle, F = {F:.3f}")
        for s in j["slices"][:: max(1, len(j["slices"]) // 25)]:
            ax.plot([s["x"], s["x"]], [s["base_y"], s["base_y"] + s["height"]], "-", color="tab:red", lw=0.5,
                    alpha=0.6)
        ax.plot([xc], [yc], "r+", ms=10)
        ax.plot([xc, ex[0]], [yc, ex[1]], "r:", lw=0.8)
        ax.plot([xc, en[0]], [yc, en[1]], "r:", lw=0.8)
    s = j["soil"]
    if j.get("layered"):
        ax.set_title(f"Bishop simplified, {len(j['bodies'])} bodies of their own soils; contours: least F per centre",
                     fontsize=10)
    else:
        ax.set_title(f"Bishop simplified: c = {s['cohesion_Pa'] / 1e3:.4g} kPa, φ = {s['friction_angle_deg']:.4g}°, "
                     f"γ = {s['unit_weight_N_per_m3'] / 1e3:.4g} kN/m³; contours: least F per centre", fontsize=10)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    bx, by = j["search"]["first_box"]["x"], j["search"]["first_box"]["y"]
    ax.set_xlim(min(x0, bx[0]) - 1, max(x1, bx[1]) + 1)
    ax.set_ylim(y0 - 1, max(y1, by[1]) + 1)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)


if __name__ == "__main__":
    main()
