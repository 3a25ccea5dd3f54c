#!/usr/bin/python3
"""Plot the trials of `rktsph fos` (docs/fos.md): u_c(t) / L of every trial, coloured by its
outcome, and beside it, for strength reduction, the monitor's speed |du_c/dt| with the hold's
two halves (whose drifts the classification compares), for the load factor the kinetic energy
against time; writes fos_uc.png in the search's folder.

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


def speed(t, u, bins):
    """|du/dt| as the least-squares slope over consecutive bins of equal time (as the rule takes
    its drifts: a ringing averages out), at the bins' centres."""
    if len(t) < 2:
        return [], []
    tc, v = [], []
    width = (t[-1] - t[0]) / bins
    for k in range(bins):
        a = t[0] + k * width
        pts = [(x, y) for x, y in zip(t, u) if a <= x < a + width]
        if len(pts) < 3:
            continue
        n = len(pts)
        mt = sum(x for x, _ in pts) / n
        mu = sum(y for _, y in pts) / n
        stt = sum((x - mt) ** 2 for x, _ in pts)
        if stt > 0:
            tc.append(mt)
            v.append(abs(sum((x - mt) * (y - mu) for x, y in pts) / stt))
    return tc, v


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    with open(os.path.join(out, "fos.json")) as f:
        fos = json.load(f)
    monitor = fos["monitor"]
    length = monitor["length"]
    by_hold = fos.get("mode") != "load"
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
        if by_hold:
            tc, v = speed(t, u, 40)
            ax_k.semilogy(tc, [max(x, 1e-12) for x in v], style, color=colour, lw=1.0)
        else:
            peak = max(ke) if max(ke) > 0 else 1.0
            ax_k.semilogy(t, [max(k / peak, 1e-12) for k in ke], style, color=colour, lw=1.0)
    ax_u.axhline(0.05, color="k", lw=0.8, ls="--", label="collapse: u_c = 0.05 L")
    # Collapsing trials run far past the threshold: keep the region around it readable.
    low, high = ax_u.get_ylim()
    ax_u.set_ylim(max(min(low, -0.005), -0.02), min(high, 0.2))
    if by_hold:
        start, hold = monitor["hold_start"], monitor["hold"]
        for ax in (ax_u, ax_k):
            ax.axvspan(start, start + 0.5 * hold, color="0.93", zorder=0)
            ax.axvspan(start + 0.5 * hold, start + hold, color="0.85", zorder=0)
        ax_k.set_ylabel("|du_c/dt| (m/s); the hold's halves shaded")
        ax_k.set_ylim(bottom=1e-8)
    elif t_end > 0:
        window = monitor["window"]
        ax_u.axvspan(t_end - window, t_end, color="0.9", zorder=0, label="classification window")
        ax_k.axvspan(t_end - window, t_end, color="0.9", zorder=0)
        ax_k.axhline(1e-2, color="k", lw=0.8, ls="--", label="stable: below 1e-2 of the peak")
        ax_k.set_ylim(1e-6, 2.0)
        ax_k.set_ylabel("kinetic energy / its peak")
        ax_k.legend(fontsize=7, loc="lower left")
    ax_u.set_xlabel("t (s)")
    ax_u.set_ylabel("u_c / L (L = {:g} m)".format(length))
    ax_k.set_xlabel("t (s)")
    f = fos.get("factor", fos.get("factor_of_safety"))
    lo, hi = fos["bracket"]
    name = "load factor" if fos.get("mode") == "load" else "F"
    title = "{} = {:.4f}, bracket [{}, {}]".format(name, f, lo, hi) if f is not None else "no factor: " + fos["status"]
    ax_u.set_title(title)
    ax_k.set_title(os.path.basename(fos["case"]))
    ax_u.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fos_uc.png"), dpi=120)


if __name__ == "__main__":
    main()
