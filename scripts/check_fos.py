#!/usr/bin/python3
"""Run `rktsph fos` and check its factor against a reference interval (the CTest entry fos_quick;
docs/fos.md). Passes when the search converges, its bracket is within the tolerance it reports,
and scale * F lies in [low, high] (e.g. scale 3.4 turns F into gamma H / c_F for Case 5).

Usage: /usr/bin/python3 scripts/check_fos.py --binary build/rktsph --case CASE.toml --out DIR \
           --scale 3.4 --low 3.64 --high 4.00 [-- extra rktsph fos arguments]
"""
import json
import os
import sys

from check_common import parser, run, split_extra


def main():
    argv, extra = split_extra()
    p = parser(__doc__)
    p.add_argument("--scale", type=float, default=1.0)
    a = p.parse_args(argv)
    run([a.binary, "fos", a.case, "--out", a.out, "--no-plot"] + extra, "fos")
    with open(os.path.join(a.out, "fos.json")) as f:
        fos = json.load(f)
    lo, hi = fos["bracket"]
    f_value = fos.get("factor", fos.get("factor_of_safety"))
    ok = fos["status"] == "converged" and hi - lo <= fos["tolerance"] * lo * (1 + 1e-12)
    value = a.scale * f_value
    inside = a.low <= value <= a.high
    print("F = {:.5f}, bracket [{:.5f}, {:.5f}], tolerance {}, {} trials used, {} run, {:.1f} s; "
          "{} x F = {:.4f} (expected in [{}, {}]): {}".format(
              f_value, lo, hi, fos["tolerance"], fos["trials_used"], fos["trials_run"], fos["wall_seconds"],
              a.scale, value, a.low, a.high, "pass" if ok and inside else "FAIL"))
    sys.exit(0 if ok and inside else 1)


if __name__ == "__main__":
    main()
