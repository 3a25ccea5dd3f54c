"""Shared by the plot scripts: reading the CSV files that `rktsph validate` writes."""
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
