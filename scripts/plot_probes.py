#!/usr/bin/python3
"""Plot the probe histories of a run (probes.csv) to probes.png in the same folder.

Usage: /usr/bin/python3 scripts/plot_probes.py OUTPUT_DIR
One panel per field kind (velocity, displacement, stress, ...), one line per probe.
"""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

UNITS = {"v": ("velocity", "m/s", 1.0), "u": ("displacement", "m", 1.0),
         "s": ("stress", "kPa", 1e-3), "p": ("mean pressure p", "kPa", 1e-3),
         "q": ("deviatoric stress q", "kPa", 1e-3)}


def kind(field):
    if field in ("p", "q"):
        return field
    if field[0] in "vus" and len(field) <= 3:
        return field[0]
    return "state:" + field


def main(out_dir):
    out = Path(out_dir)
    with open(out / "probes.csv") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]
    t = [float(r[0]) for r in data]
    groups = {}
    for j, name in enumerate(header[1:], start=1):
        probe, field = name.rsplit(".", 1)
        groups.setdefault(kind(field), []).append((probe, field, j))
    fig, axes = plt.subplots(len(groups), 1, figsize=(9, 2.8 * len(groups)), sharex=True, squeeze=False)
    for ax, (k, series) in zip(axes[:, 0], groups.items()):
        label, unit, scale = UNITS.get(k, (k.split(":", 1)[-1], "", 1.0))
        for probe, field, j in series:
            ax.plot(t, [float(r[j]) * scale for r in data], label=f"{probe}: {field}")
        ax.set_ylabel(f"{label} ({unit})" if unit else label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    axes[-1, 0].set_xlabel("time (s)")
    fig.suptitle(f"Probe histories: {out.name}")
    fig.tight_layout()
    fig.savefig(out / "probes.png", dpi=110)
    print(f"wrote {out / 'probes.png'}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
