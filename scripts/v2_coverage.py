#!/usr/bin/env python3
"""Stress-point coverage of the nodes of a V2 run's frames (docs/method-notes.md §4.5,
"Where the V2 run-outs go unstable"): for every written frame of an output folder, the nodes
with few stress points within the kernel support 2h, and the fastest node with its count.

    scripts/v2_coverage.py OUTPUT_DIR --dx 0.25 [--h-over-dx 1.2] [--few 3]

Reads nodes.pvd and elements.pvd (rktsph run ... with output.interval small enough to see the
onset). Prints, per frame: t, the nodes with <= 4 and <= 2 stress points in 2h, the fastest
node's |v| and its count, and the nodes with <= `few` (index, position, free-surface flag).
"""
import argparse
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_builds import read_vtu  # noqa: E402


def frames(folder, pvd):
    text = open(os.path.join(folder, pvd)).read()
    return [(float(t), os.path.join(folder, f))
            for t, f in re.findall(r'timestep="([^"]+)" part="0" file="([^"]+)"', text)]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder")
    ap.add_argument("--dx", type=float, required=True)
    ap.add_argument("--h-over-dx", type=float, default=1.2)
    ap.add_argument("--few", type=int, default=3)
    a = ap.parse_args()
    radius = 2.0 * a.h_over_dx * a.dx
    for (t, fn), (_, fe) in zip(frames(a.folder, "nodes.pvd"), frames(a.folder, "elements.pvd")):
        n = read_vtu(fn)
        x = n["Points"][:, :2]
        sp = read_vtu(fe)["Points"][:, :2]
        d2 = ((x[:, None, :] - sp[None, :, :]) ** 2).sum(axis=2)
        count = (d2 < radius * radius).sum(axis=1)
        speed = np.linalg.norm(n["PointData/velocity"][:, :2], axis=1)
        flag = n["PointData/free_surface"].ravel()
        k = int(np.argmax(speed))
        few = np.where(count <= a.few)[0]
        e = read_vtu(fe)
        nodes_of = (d2 < radius * radius).sum(axis=0)  # nodes within 2h of each stress point
        sp_speed = np.linalg.norm(e["PointData/velocity"][:, :2], axis=1)
        ke = int(np.argmax(sp_speed))
        print(f"t={t:.3f} nodes<=4: {(count <= 4).sum()} <=2: {(count <= 2).sum()} "
              f"max|v|={speed[k]:.2f} (node {k} at ({x[k, 0]:.2f},{x[k, 1]:.2f}), {count[k]} stress points) "
              f"SP max|v|={sp_speed[ke]:.2f} (SP {ke}, {nodes_of[ke]} nodes); SPs with <=4 nodes: "
              f"{(nodes_of <= 4).sum()} few: " +
              " ".join(f"{i}({x[i, 0]:.2f},{x[i, 1]:.2f};{count[i]};fs{int(flag[i])})" for i in few))


if __name__ == "__main__":
    main()
