#!/usr/bin/python3
"""Bishop's simplified method on circular slip surfaces for a slope of several soils: an
independent check of `rktsph lem` (src/lem/) written from the textbook formula, not from its
code (docs/fos.md, "Acceptance"; docs/VALIDATION.md, "Factor of safety").

The soil is read from a case file: its [[geometry.polygon]] bodies, each with its
[materials.NAME] (cohesion, friction_angle in degrees, density; von Mises: c = cohesion or
yield_stress / sqrt(3), phi = 0) and the gravity [0, -g]. A slice's weight sums each body's unit
weight over the length of that body on the slice's centre line above its base; its base has
the c and phi of the body the base lies in (Bishop 1955; e.g. Duncan & Wright 2005, Soil
Strength and Slope Stability, ch. 6):

    F = sum_i (c_i b + W_i tan(phi_i)) / m_i  /  sum_i W_i sin(alpha_i),
    m_i = cos(alpha_i) + sin(alpha_i) tan(phi_i) / F,

with m_i raised to 0.2 on the toe side (alpha < 0) where it would fall below (Whitman & Bailey
1967, as rktsph lem does). The rigid base is the soil's lowest level (a circle may touch it within the
soil, not cross it); a circle must enter and leave the soil through its top surface, left of any vertical
side of the body (the rollers of the slope cases). The search: a grid of centres, at each the
least F over the radii, then a Nelder-Mead refinement of (x_c, y_c, R) from the best circles.

Usage: /usr/bin/python3 scripts/bishop_layered.py CASE.toml [--slices 200] [--grid 21]
Prints F, the circle and its entry and exit; --json FILE writes them.
"""
import argparse
import json
import math
import sys
import tomllib

import numpy as np
from scipy.optimize import minimize


def read_case(path):
    with open(path, "rb") as f:
        case = tomllib.load(f)
    g = -case["body_force"]["gravity"][1]
    materials = case.get("materials", {})
    if "material" in case:
        materials = {"material": case["material"]}
    bodies = []
    for poly in case["geometry"]["polygon"]:
        name = poly.get("material", "material" if "material" in case else None)
        m = materials[name]
        if m["model"] == "perzyna_von_mises":
            c = m.get("cohesion", m.get("yield_stress", 0.0) / math.sqrt(3.0))
            phi = 0.0
        else:
            c = m["cohesion"]
            phi = math.radians(m["friction_angle"])
        pts = [tuple(p) for p in poly["vertices"]]
        if pts[0] == pts[-1]:
            pts = pts[:-1]
        bodies.append({"name": name, "pts": np.array(pts, float), "c": c, "tan_phi": math.tan(phi),
                       "gamma": m["density"] * g})
    return bodies


def sections(body, x):
    """For each x, the (lo, hi) intervals of the body on the vertical at x (even-odd rule)."""
    p = body["pts"]
    a, b = p, np.roll(p, -1, axis=0)
    xa, xb = a[:, 0][None, :], b[:, 0][None, :]
    X = x[:, None]
    cross = ((xa <= X) & (X < xb)) | ((xb <= X) & (X < xa))
    with np.errstate(invalid="ignore", divide="ignore"):
        h = a[:, 1][None, :] + (X - xa) * (b[:, 1] - a[:, 1])[None, :] / (xb - xa)
    h = np.where(cross, h, np.inf)
    h.sort(axis=1)
    return h  # row k: heights sorted, pairs (0,1), (2,3), ... are the sections; inf beyond


class Slope:
    def __init__(self, bodies):
        self.bodies = bodies
        allp = np.vstack([b["pts"] for b in bodies])
        self.x_lo, self.y_lo = allp.min(axis=0)
        self.x_hi, self.y_hi = allp.max(axis=0)
        self.H = self.y_hi - self.y_lo

    def top(self, x):
        t = np.full(x.shape, -np.inf)
        for b in self.bodies:
            h = sections(b, x)
            finite = np.where(np.isfinite(h), h, -np.inf)
            t = np.maximum(t, finite.max(axis=1))
        return t

    def columns(self, x, y_base):
        """Weight per unit width above y_base at each x, and the c, tan(phi) at the base."""
        w = np.zeros(x.shape)
        c = np.full(x.shape, np.nan)
        tp = np.full(x.shape, np.nan)
        for b in self.bodies:
            h = sections(b, x)
            for k in range(0, h.shape[1] - 1, 2):
                lo, hi = h[:, k], h[:, k + 1]
                ok = np.isfinite(lo) & np.isfinite(hi)
                with np.errstate(invalid="ignore"):
                    seg = np.where(ok, np.clip(hi - np.maximum(lo, y_base), 0.0, None), 0.0)
                w += b["gamma"] * seg
                inside = ok & (lo <= y_base + 1e-9) & (y_base < hi)
                c = np.where(inside, b["c"], c)
                tp = np.where(inside, b["tan_phi"], tp)
        return w, c, tp


def circle_factor(slope, xc, yc, R, n, want=False):
    """Bishop's F of one circle, or inf if it is not admissible."""
    if R <= 0 or xc - R >= slope.x_hi or xc + R <= slope.x_lo:
        return math.inf
    # The crossings with the top surface: the lower circle below the top between them, and
    # soil on both sides of each crossing's sample (not a vertical side of the body).
    xs = np.linspace(xc - R, xc + R, 801)
    yb = yc - np.sqrt(np.maximum(R * R - (xs - xc) ** 2, 0.0))
    top = slope.top(xs)
    f = top - yb  # > 0 where the circle is inside the soil
    inside = f > 0
    if inside.sum() < 3:
        return math.inf
    idx = np.nonzero(inside)[0]
    if np.any(np.diff(idx) != 1):
        return math.inf  # leaves and re-enters
    i0, i1 = idx[0], idx[-1]
    if yb[i0:i1 + 1].min() < slope.y_lo - 1e-9:
        return math.inf  # below the rigid base within the soil (outside it, e.g. beyond the toe, it may dip)
    if i0 == 0 or i1 == len(xs) - 1 or not (np.isfinite(top[i0 - 1]) and np.isfinite(top[i1 + 1])):
        return math.inf  # it crosses a vertical side of the soil (the rollers)

    def root(i, j):
        a, b = xs[i], xs[j]
        for _ in range(50):
            m = 0.5 * (a + b)
            fm = slope.top(np.array([m]))[0] - (yc - math.sqrt(max(R * R - (m - xc) ** 2, 0.0)))
            if (fm > 0) == (f[j] > 0):
                b = m
            else:
                a = m
        return 0.5 * (a + b)

    xa, xb = root(i0 - 1, i0), root(i1 + 1, i1)
    if yc < max(slope.top(np.array([xa, xb]))):
        return math.inf  # the slip surface would reach above the centre
    b = (xb - xa) / n
    x = xa + (np.arange(n) + 0.5) * b
    y = yc - np.sqrt(np.maximum(R * R - (x - xc) ** 2, 0.0))
    w, c, tp = slope.columns(x, y)
    W = w * b  # the slices' weights, N/m
    if np.any(np.isnan(c)):
        return math.inf
    moment = np.sum(W * (x - xc))
    s = 1.0 if moment > 0 else -1.0  # > 0: the mass turns clockwise, sliding towards -x
    sin_a = s * (x - xc) / R
    cos_a = np.sqrt(np.maximum(1.0 - sin_a * sin_a, 0.0))
    driving = np.sum(W * sin_a)
    if driving <= 0:
        return math.inf
    F = np.sum(c * b / cos_a + W * cos_a * tp) / driving  # the ordinary method to start
    for _ in range(200):
        m = cos_a + sin_a * tp / F
        m = np.where((sin_a < 0) & (m < 0.2), 0.2, m)
        Fn = np.sum((c * b + W * tp) / m) / driving
        if abs(Fn - F) <= 1e-9 * Fn:
            F = Fn
            break
        F = Fn
    if want:
        return F, (xa, float(slope.top(np.array([xa]))[0])), (xb, float(slope.top(np.array([xb]))[0]))
    return F


def search(slope, n, grid):
    H = slope.H
    best = []
    for xc in np.linspace(slope.x_lo - H, slope.x_hi, grid):
        for yc in np.linspace(slope.y_lo + 0.5 * H, slope.y_hi + 2.5 * H, grid):
            rmax = math.hypot(max(abs(xc - slope.x_lo), abs(xc - slope.x_hi)), yc - slope.y_lo)
            Fs = [(circle_factor(slope, xc, yc, R, n // 4), R) for R in np.linspace(0.05 * H, rmax, 40)]
            F, R = min(Fs)
            if math.isfinite(F):
                best.append((F, xc, yc, R))
    best.sort()
    results = []
    for F0, xc, yc, R in best[:6]:
        r = minimize(lambda p: circle_factor(slope, p[0], p[1], p[2], n), [xc, yc, R], method="Nelder-Mead",
                     options={"xatol": 1e-4, "fatol": 1e-7, "maxiter": 2000, "initial_simplex": [
                         [xc, yc, R], [xc + 0.05 * H, yc, R], [xc, yc + 0.05 * H, R], [xc, yc, R + 0.05 * H]]})
        results.append((r.fun, tuple(r.x)))
    return min(results)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("case")
    p.add_argument("--slices", type=int, default=200)
    p.add_argument("--grid", type=int, default=21)
    p.add_argument("--json")
    a = p.parse_args()
    slope = Slope(read_case(a.case))
    F, (xc, yc, R) = search(slope, a.slices, a.grid)
    F, entry, exit_ = circle_factor(slope, xc, yc, R, a.slices, want=True)
    print("Bishop (independent script): F = {:.4f}; circle centre ({:.3f}, {:.3f}) m, radius {:.3f} m; "
          "crossings ({:.3f}, {:.3f}) and ({:.3f}, {:.3f})".format(F, xc, yc, R, *entry, *exit_))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"factor_of_safety": F, "centre": [xc, yc], "radius": R, "crossings": [entry, exit_]}, f,
                      indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
