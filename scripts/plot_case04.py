#!/usr/bin/python3
"""Plots for thesis case 4 (elastic vertical cut) from the CSV files written by `rktsph validate`.

Usage: /usr/bin/python3 scripts/plot_case04.py DIR   (DIR = validation/case04)
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402



def dx_of(p, prefix):
    return p.stem[len(prefix):]


def main(d):
    d = Path(d)
    finals = sorted(d.glob("a_final_dx*.csv"), key=lambda p: -float(dx_of(p, "a_final_dx")))
    # (a) sigma_yy and sigma_xx along x = 0, 5 and the column next to the face
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    styles = ["-", "--"]
    for si, p in enumerate(finals):
        dx = float(dx_of(p, "a_final_dx"))
        s = read(p)
        xface = max(s["x"]) - (0.0 if dx <= 0.1 else 0.0)
        for xc, col in ((0.0, "C0"), (5.0, "C1"), (xface, "C2")):
            idx = sorted([i for i in range(len(s["x"])) if abs(s["x"][i] - xc) < 1e-6], key=lambda i: s["y"][i])
            y = [s["y"][i] for i in idx]
            axes[0].plot([s["syy"][i] / 1e3 for i in idx], y, styles[si % 2], color=col,
                         label=f"RKT-SPH x = {xc:g} m, dx = {dx:g} m")
            axes[1].plot([s["sxx"][i] / 1e3 for i in idx], y, styles[si % 2], color=col,
                         label=f"RKT-SPH x = {xc:g} m, dx = {dx:g} m")
    pts = read(sorted(d.glob("a_points_dx*.csv"))[0])
    for comp, ax in (("syy", axes[0]), ("sxx", axes[1])):
        xs = [pts["reference_kPa"][i] for i in range(len(pts["x"])) if pts["component"][i] == comp]
        ys = [pts["y"][i] for i in range(len(pts["x"])) if pts["component"][i] == comp]
        lab = [f"({pts['x'][i]:g}, {pts['y'][i]:g})" for i in range(len(pts["x"])) if pts["component"][i] == comp]
        ax.plot(xs, ys, "k*", ms=11, label="FE reference points " + ", ".join(lab))
    yy = [0.0, 10.0]
    axes[0].plot([-2000 * 9.81 * 10 / 1e3, 0.0], yy, "k:", label="1-D column $-\\gamma (H-y)$")
    axes[0].set_xlabel("$\\sigma_{yy}$ (kPa, tension positive)")
    axes[1].set_xlabel("$\\sigma_{xx}$ (kPa, tension positive)")
    for ax in axes:
        ax.set_ylabel("y (m)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Case 4(a): stresses along vertical lines at t = 2 s (the face column is x = 10 m; the "
                 "reference point is at x = 9.9 m)")
    fig.tight_layout()
    fig.savefig(d / "a_stress_profiles.png", dpi=110)
    plt.close(fig)

    # (a) section resultants
    fig, ax = plt.subplots(figsize=(6.5, 5))
    for p in sorted(d.glob("a_sections_dx*.csv"), key=lambda p: -float(dx_of(p, "a_sections_dx"))):
        s = read(p)
        ax.plot(s["resultant_kN"], s["y"], "o-", ms=3, label=f"RKT-SPH, dx = {dx_of(p, 'a_sections_dx')} m")
    ax.plot(s["exact_kN"], s["y"], "k--", label="exact: $-\\rho g W (H-y)$")
    ax.set_xlabel("section resultant $\\int_0^W \\sigma_{yy}\\,dx$ (kN/m)")
    ax.set_ylabel("y (m)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Case 4(a): vertical equilibrium of horizontal sections")
    fig.tight_layout()
    fig.savefig(d / "a_sections.png", dpi=110)
    plt.close(fig)

    # (a) deformed shape (displacements magnified)
    fig, ax = plt.subplots(figsize=(6.5, 6))
    s = read(finals[0])
    scale = 100.0
    ax.plot(s["x"], s["y"], ".", color="0.8", ms=3, label="undeformed nodes")
    ax.plot([x + scale * u for x, u in zip(s["x"], s["ux"])], [y + scale * v for y, v in zip(s["y"], s["uy"])], ".",
            color="C0", ms=3, label=f"deformed, displacements x {scale:g} (dx = {dx_of(finals[0], 'a_final_dx')} m)")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.legend(fontsize=8, loc="lower left")
    ax.set_title("Case 4(a): deformed shape at t = 2 s")
    fig.tight_layout()
    fig.savefig(d / "a_deformed.png", dpi=110)
    plt.close(fig)

    # (b) histories
    hist = sorted(d.glob("b_history_dx*.csv"), key=lambda p: -float(dx_of(p, "b_history_dx")))
    fig, ax = plt.subplots(figsize=(10, 4.5))
    for p in hist:
        h = read(p)
        for key, col in (("syy_x1", "C0"), ("syy_x5", "C1"), ("syy_x9.75", "C2")):
            if dx_of(p, "b_history_dx") != dx_of(hist[-1], "b_history_dx") and key != "syy_x5":
                continue
            ax.plot(h["t"], [v / 1e3 for v in h[key]], color=col, lw=1,
                    alpha=1.0 if p == hist[-1] else 0.4,
                    label=f"RKT-SPH x = {key[5:]} m, dx = {dx_of(p, 'b_history_dx')} m")
    ax.plot(h["t"], [v / 1e3 for v in h["syy_exact"]], "k--", label="closed form")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("base $\\sigma_{yy}$ (kPa)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title("Case 4(b): base stress under sudden gravity")
    fig.tight_layout()
    fig.savefig(d / "b_base_stress.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(10, 4.5))
    for p in hist:
        h = read(p)
        ax.plot(h["t"], [1e3 * v for v in h["uy_x5"]], lw=1, label=f"RKT-SPH top x = 5 m, dx = {dx_of(p, 'b_history_dx')} m")
    ax.plot(h["t"], [1e3 * v for v in h["uy_exact"]], "k--", label="closed form")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("top $u_y$ (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Case 4(b): top displacement")
    fig.tight_layout()
    fig.savefig(d / "b_top_uy.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(10, 4.5))
    for p in hist:
        h = read(p)
        ax.plot(h["t"], [1e3 * v for v in h["ux_face_max"]], lw=1, label=f"RKT-SPH, dx = {dx_of(p, 'b_history_dx')} m")
    ax.axhline(0.0, color="k", ls="--", label="closed form: $u_x$ = 0")
    ax.axhline(1e3 * 0.02 * 2 * 2000 * 9.81 * 100 / 8e7, color="r", ls=":", label="tolerance 2 % of max|$u_y$|")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("max |$u_x$| on the face (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Case 4(b): spurious horizontal displacement of the face")
    fig.tight_layout()
    fig.savefig(d / "b_face_ux.png", dpi=110)
    plt.close(fig)

    # (b) in 3D: the base stress at the centre and at the edge where two free faces meet, the
    # finest 2D block beside it, and the closed form.
    hist3 = sorted(d.glob("b3d_history_dx*.csv"), key=lambda p: -float(dx_of(p, "b3d_history_dx")))
    if hist3:
        fig, ax = plt.subplots(figsize=(10, 4.5))
        for p in hist3:
            h = read(p)
            finest = p == hist3[-1]
            for key, col, where in (("szz_x5", "C1", "(5, 5)"), ("szz_x9.75", "C2", "(9.75, 9.75)")):
                if not finest and key != "szz_x5":
                    continue
                ax.plot(h["t"], [v / 1e3 for v in h[key]], color=col, lw=1, alpha=1.0 if finest else 0.4,
                        label=f"3D {where} m, dx = {dx_of(p, 'b3d_history_dx')} m")
        if hist:
            h2 = read(hist[-1])
            ax.plot(h2["t"], [v / 1e3 for v in h2["syy_x5"]], color="C0", lw=1, ls=":",
                    label=f"2D x = 5 m, dx = {dx_of(hist[-1], 'b_history_dx')} m")
        ax.plot(h["t"], [v / 1e3 for v in h["szz_exact"]], "k--", label="closed form")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("base $\\sigma_{zz}$ (kPa)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
        ax.set_title("Case 4(b) in 3D: base stress of the cube under sudden gravity")
        fig.tight_layout()
        fig.savefig(d / "b3d_base_stress.png", dpi=110)
        plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
    import toe_scaling  # noqa: E402  (scripts/ is on the path: this script's folder)

    toe_scaling.plot(sys.argv[1])  # a_face_residual.png: the face residual against the toe singularity
