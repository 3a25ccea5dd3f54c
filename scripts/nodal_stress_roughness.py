#!/usr/bin/env python3
"""The nodal stress mode of a V2 run (docs/VALIDATION.md, Case 9, "The nodal stress mode";
method-notes eq. (2.3.3)): for every written frame of an output folder, how far the nodal mean
stress p = -(sxx + syy + szz)/3 departs from the mean of its nodal neighbours within 1.5 dx
(over the nodes with at least 4 such neighbours), and where the largest departure is.

    /usr/bin/python3 scripts/nodal_stress_roughness.py OUTPUT_DIR --dx 0.25 [--around X,Y [--radius R]]

Prints per frame: t, the RMS of p - neighbours' mean (kPa), the largest |p| and the largest
|p - neighbours' mean| (kPa) with its node's position. With --around, also lists the nodes within
R (default 0.6 m) of (X, Y): position, free-surface flag, velocity, sxx / syy / sxy (kPa).
Reads nodes.pvd (rktsph run ... with output.times or output.interval as needed).
"""
import argparse
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_builds import read_vtu  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder")
    ap.add_argument("--dx", type=float, required=True)
    ap.add_argument("--around", help="X,Y: list the nodes near this point in every frame")
    ap.add_argument("--radius", type=float, default=0.6)
    a = ap.parse_args()
    text = open(os.path.join(a.folder, "nodes.pvd")).read()
    for t, f in re.findall(r'timestep="([^"]+)" part="0" file="([^"]+)"', text):
        n = read_vtu(os.path.join(a.folder, f))
        x = n["Points"][:, :2]
        sxx, syy, szz, sxy = (n["PointData/" + k].ravel() for k in ("sxx", "syy", "szz", "sxy"))
        p = -(sxx + syy + szz) / 3.0
        d2 = ((x[:, None] - x[None]) ** 2).sum(axis=2)
        near = (d2 < (1.5 * a.dx) ** 2) & (d2 > 0.0)
        count = near.sum(axis=1)
        ok = count >= 4
        departure = p - (near * p[None]).sum(axis=1) / np.maximum(count, 1)
        k = int(np.argmax(np.where(ok, np.abs(departure), -1.0)))
        print(f"t={float(t):7.2f} s  rms(p - neighbours) = {np.sqrt((departure[ok] ** 2).mean()) / 1e3:8.2f} kPa  "
              f"max|p| = {np.abs(p).max() / 1e3:8.1f} kPa  max|p - neighbours| = {abs(departure[k]) / 1e3:8.1f} kPa "
              f"at ({x[k, 0]:.2f}, {x[k, 1]:.2f})")
        if a.around:
            c = np.array([float(v) for v in a.around.split(",")])
            v = n["PointData/velocity"][:, :2]
            flag = n["PointData/free_surface"].ravel()
            for i in np.where(((x - c) ** 2).sum(axis=1) < a.radius ** 2)[0]:
                print(f"    node {i:5d} ({x[i, 0]:6.2f}, {x[i, 1]:6.2f}) surface {int(flag[i])} "
                      f"v = ({v[i, 0]:7.2f}, {v[i, 1]:7.2f}) m/s  "
                      f"sxx / syy / sxy = {sxx[i] / 1e3:8.1f} / {syy[i] / 1e3:8.1f} / {sxy[i] / 1e3:8.1f} kPa")


if __name__ == "__main__":
    main()
