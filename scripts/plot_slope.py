#!/usr/bin/python3
"""Plots of the polygon slope check (cases/examples/slope_elastic_2d.toml) from the CSV files the
unit test writes with RKTSPH_SLOPE_OUT=DIR:

  RKTSPH_SLOPE_OUT=DIR build/tests/rktsph_unit_tests --gtest_filter=PolygonSlope.*
  /usr/bin/python3 scripts/plot_slope.py DIR

Writes DIR/slope_face_residual.png (|sigma.n| / (rho g H) along the inclined face, and the
tangential stress) and DIR/slope_stress.png (sigma_yy and sigma_xx over the body).
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from plot_common import read  # noqa: E402


def main(d):
    d = Path(d)
    f = read(d / "slope_face.csv")
    order = sorted(range(len(f["s"])), key=lambda i: f["s"][i])
    s = [f["s"][i] for i in order]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    axes[0].semilogy(s, [max(f["interp_residual"][i], 1e-17) for i in order], "o-", ms=3,
                     label="stress points interpolated to the face nodes")
    axes[0].semilogy(s, [max(f["node_residual"][i], 1e-17) for i in order], "x", ms=3,
                     label="nodal stress (the imposed condition)")
    axes[0].axhline(0.02, color="k", ls="--", label="acceptance 2 %")
    for x0 in (2.0, (20.0**2 + 10.0**2) ** 0.5 - 2.0):
        axes[0].axvline(x0, color="grey", ls=":")
    axes[0].set_xlabel("distance along the face from the toe (m); dotted: 2 m from the ends")
    axes[0].set_ylabel("|σ·n| / (ρ g H)")
    axes[0].legend(fontsize=8)
    axes[0].grid(alpha=0.3, which="both")
    axes[1].plot(s, [f["interp_stt"][i] for i in order], "o-", ms=3)
    axes[1].set_xlabel("distance along the face from the toe (m)")
    axes[1].set_ylabel("σ_tt / (ρ g H) (tension positive)")
    axes[1].grid(alpha=0.3)
    fig.suptitle("Elastic 2:1 slope, H = 10 m, Δx = 0.5 m, V1 at rest: traction on the inclined face")
    fig.tight_layout()
    fig.savefig(d / "slope_face_residual.png", dpi=110)
    plt.close(fig)

    n = read(d / "slope_nodes.csv")
    fig, axes = plt.subplots(2, 1, figsize=(11, 7))
    for ax, comp, name in ((axes[0], "syy", "σ_yy"), (axes[1], "sxx", "σ_xx")):
        sc = ax.scatter(n["x"], n["y"], c=[v / 1e3 for v in n[comp]], s=6, cmap="viridis")
        fig.colorbar(sc, ax=ax, label=f"{name} (kPa)")
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
    fig.suptitle("Elastic 2:1 slope at rest: nodal stresses")
    fig.tight_layout()
    fig.savefig(d / "slope_stress.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
