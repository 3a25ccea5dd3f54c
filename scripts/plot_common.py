"""Shared by the plot scripts: reading the CSV files that `rktsph validate` writes, and the
crest-history axes of the cut cases (5, 17)."""
import csv


def read(path):
    """Columns of a CSV file by header name: floats, or strings where a column is not numeric."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    out = {}
    for k in rows[0]:
        try:
            out[k] = [float(r[k]) for r in rows]
        except ValueError:
            out[k] = [r[k] for r in rows]
    return out


def style_crest_history(axes, height, marks):
    """Axes of a cut's crest displacement (axes[0]) and kinetic energy (axes[1], log) against t:
    the collapse threshold 0.05 H of docs/cases.md §1.3, labels, and vertical lines at the times of
    `marks`, a list of (t, line style, label)."""
    top = max(max(line.get_ydata()) for line in axes[1].get_lines())
    axes[1].set_ylim(bottom=1e-6 * top)
    axes[0].axhline(0.05 * height, color="r", ls=":", label="collapse threshold 0.05 H")
    axes[0].set_ylabel("crest horizontal displacement $u_c$ (m, outward +)")
    axes[0].set_yscale("symlog", linthresh=1e-3)
    axes[1].set_ylabel("kinetic energy (J/m)")
    for ax in axes:
        for t, ls, label in marks:
            ax.axvline(t, color="0.5", ls=ls, lw=0.8, label=label)
        ax.set_xlabel("t (s)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
