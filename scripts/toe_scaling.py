#!/usr/bin/python3
"""Case 4(a) face-traction residual against the toe singularity, from `rktsph validate 04` output.

Reads DIR/a_face_residual_dx*.csv (one row per stress-point row next to the face x = W: its
height y and the extrapolated face tractions s_n = sigma_xx, s_t = sigma_xy over rho g H) and
prints, per dx: the whole-face maximum, the toe-row value, the RMS over the face, the maxima for
y >= 2 dx and y >= 0.1 H, with the observed rates between successive spacings next to those of
a corner field r^(lam - 1) (lam from scripts/williams_corner.py: clamped base, free face, right
angle, plane strain).  A fixed stress-point row k sits at r ~ (k - 1/2) dx from the toe, so a
singular field makes its residual grow as dx^(lam - 1); the RMS over the face should fall as
dx^(lam - 1/2); the maximum over a zone of fixed physical size (y >= 0.1 H) should converge.
With --plot it writes DIR/a_face_residual.png (per-row residual against y, and the rows
rescaled by dx^(1 - lam), which collapse onto one curve if the toe residual is the corner field).

Usage: /usr/bin/python3 scripts/toe_scaling.py DIR [--plot] [--nu 0.3] [--H 10]
"""
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import williams_corner as wc  # noqa: E402


def load(d):
    out = {}
    for p in Path(d).glob("a_face_residual_dx*.csv"):
        dx = float(p.stem[len("a_face_residual_dx"):])
        a = np.genfromtxt(p, delimiter=",", names=True)
        out[dx] = a
    return dict(sorted(out.items(), reverse=True))


def corner_lambda(nu):
    kappa = 3 - 4 * nu
    return wc.roots(lambda z: wc.det(z, math.pi / 2, kappa, "free-clamped"))[0].real


def measures(a, dx, H):
    y, sn, st = a["y"], a["sn_over_rhogH"], a["st_over_rhogH"]
    m = np.maximum(abs(sn), abs(st))
    return {
        "whole-face max": m.max(),
        "toe row (y = dx/2)": m[np.argmin(y)],
        "RMS": math.sqrt(np.mean(sn**2 + st**2)),
        "max y >= 2 dx": m[y >= 2 * dx - 1e-9 * dx].max(),
        "max y >= 0.1 H": m[y >= 0.1 * H].max(),
    }


def main():
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        sys.exit(2)
    d = Path(args[0])
    nu = float(args[args.index("--nu") + 1]) if "--nu" in args else 0.3
    H = float(args[args.index("--H") + 1]) if "--H" in args else 10.0
    data = load(d)
    if not data:
        sys.exit(f"no a_face_residual_dx*.csv in {d}")
    lam = corner_lambda(nu)
    dxs = list(data)
    ms = {dx: measures(data[dx], dx, H) for dx in dxs}
    keys = list(ms[dxs[0]])
    print(f"lam = {lam:.4f} (stress ~ r^{lam - 1:.4f}); all values % of rho g H")
    print(f"{'measure':22s}" + "".join(f"  dx={dx:<7g}" for dx in dxs) + "  rates p (value ~ dx^p)")
    for k in keys:
        vals = [ms[dx][k] for dx in dxs]
        rates = [math.log(vals[i] / vals[i + 1]) / math.log(dxs[i] / dxs[i + 1]) for i in range(len(dxs) - 1)]
        print(f"{k:22s}" + "".join(f"  {100 * v:<10.3f}" for v in vals) + "  " + ", ".join(f"{p:+.2f}" for p in rates))
    print(f"singular corner field: fixed row p = lam - 1 = {lam - 1:+.3f}; RMS p = lam - 1/2 = {lam - 0.5:+.3f}")
    print("\nper-row residual max(|s_n|, |s_t|) (%), rows k = 1, 2, ... from the toe, and rescaled by dx^(1 - lam):")
    for k in range(5):
        raw = [100 * np.maximum(abs(data[dx]["sn_over_rhogH"]), abs(data[dx]["st_over_rhogH"]))[k] for dx in dxs]
        sc = [r * dx ** (1 - lam) for r, dx in zip(raw, dxs)]
        print(f"  k = {k + 1}: " + "  ".join(f"{r:6.3f}" for r in raw) + "   rescaled: " + "  ".join(f"{s:6.3f}" for s in sc))
    if "--plot" in args:
        plot(d, data, lam)


def plot(d, data=None, lam=None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = data or load(d)
    lam = lam if lam is not None else corner_lambda(0.3)
    if not data:
        return
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    for dx, a in data.items():
        m = np.maximum(abs(a["sn_over_rhogH"]), abs(a["st_over_rhogH"]))
        axes[0].loglog(a["y"], 100 * m, "o-", ms=3, label=f"dx = {dx:g} m")
        k = np.arange(1, len(m) + 1)
        axes[1].loglog(k, 100 * m * dx ** (1 - lam), "o-", ms=3, label=f"dx = {dx:g} m")
    # The toe rows (y = dx/2) of the successive spacings: on a line of slope lam - 1 if singular.
    dx_f = min(data)
    a_f = data[dx_f]
    toe_f = 100 * max(abs(a_f["sn_over_rhogH"][0]), abs(a_f["st_over_rhogH"][0]))
    y = np.geomspace(0.5 * dx_f * 0.7, 0.5 * max(data) * 1.4, 20)
    axes[0].loglog(y, toe_f * (y / (0.5 * dx_f)) ** (lam - 1), "k--", lw=1,
                   label=f"toe rows: $\\propto dx^{{\\lambda-1}}$, $\\lambda-1$ = {lam - 1:.3f}")
    axes[0].axhline(2.0, color="r", ls=":", label="2 % of $\\rho g H$")
    axes[0].set_xlabel("height of the stress-point row above the toe, y (m)")
    axes[0].set_ylabel("face traction residual max(|$s_n$|, |$s_t$|) (% of $\\rho g H$)")
    axes[0].set_title("Case 4(a): face residual per row")
    axes[1].set_xlabel("row index k from the toe (y = (k - 1/2) dx)")
    axes[1].set_ylabel("residual x $dx^{1-\\lambda}$ (% of $\\rho g H$, dx in m)")
    axes[1].set_title("rows rescaled by the corner exponent: a collapse = singular field")
    for ax in axes:
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(Path(d) / "a_face_residual.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
