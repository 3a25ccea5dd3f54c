#!/usr/bin/python3
"""Plot the trials of `rktsph fos` (docs/fos.md): u_c(t) / L of every trial, coloured by its
outcome, and the kinetic energy against time; writes fos_uc.png in the search's folder.

Usage: /usr/bin/python3 scripts/plot_fos.py OUT_DIR   (the folder holding fos.json)
"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"stable": "tab:green", "collapse": "tab:red", "undecided": "tab:orange", "unstable": "tab:purple"}


def read_history(path):
    t, u, ke = [], [], []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            t.append(float(row["t"]))
            u.append(float(row["u_c"]))
            ke.append(float(row["kinetic"]))
    return t, u, ke


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    with open(os.path.join(out, "fos.json")) as f:
        fos = json.load(f)
    length = fos["monitor"]["length"]
    window = fos["monitor"]["window"]
    fig, (ax_u, ax_k) = plt.subplots(1, 2, figsize=(12, 4.8))
    t_end = 0.0
    for trial in fos["trials"]:
        path = os.path.join(out, trial["history"])
        if trial["outcome"] == "failed" or not os.path.exists(path):
            continue
        t, u, ke = read_history(path)
        if not t:
            continue
        t_end = max(t_end, t[-1])
        colour = COLOURS.get(trial["outcome"], "tab:gray")
        style = "-" if trial["used"] else ":"
        label = "F = {:.4f} {}{}".format(trial["factor"], trial["outcome"], "" if trial["used"] else " (speculative)")
        ax_u.plot(t, [v / length for v in u], style, color=colour, lw=1.2, label=label)
        peak = max(ke) if max(ke) > 0 else 1.0
        ax_k.semilogy(t, [max(k / peak, 1e-12) for k in ke], style, color=colour, lw=1.0)
    ax_u.axhline(0.05, color="k", lw=0.8, ls="--", label="collapse: u_c = 0.05 L")
    # Collapsing trials run far past the threshold: keep the region around it readable.
    low, high = ax_u.get_ylim()
    ax_u.set_ylim(max(min(low, -0.005), -0.02), min(high, 0.2))
    if t_end > 0:
        ax_u.axvspan(t_end - window, t_end, color="0.9", zorder=0, label="classification window")
        ax_k.axvspan(t_end - window, t_end, color="0.9", zorder=0)
    ax_k.axhline(1e-2, color="k", lw=0.8, ls="--", label="stable: below 1e-2 of the peak")
    ax_u.set_xlabel("t (s)")
    ax_u.set_ylabel("u_c / L (L = {:g} m)".format(length))
    ax_k.set_ylim(1e-6, 2.0)
    ax_k.set_xlabel("t (s)")
    ax_k.set_ylabel("kinetic energy / its peak")
    f = fos.get("factor", fos.get("factor_of_safety"))
    lo, hi = fos["bracket"]
    name = "load factor" if fos.get("mode") == "load" else "F"
    title = "{} = {:.4f}, bracket [{}, {}]".format(name, f, lo, hi) if f is not None else "no factor: " + fos["status"]
    ax_u.set_title(title)
    ax_k.set_title(os.path.basename(fos["case"]))
    ax_u.legend(fontsize=7, loc="upper left")
    ax_k.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fos_uc.png"), dpi=120)


if __name__ == "__main__":
    main()
