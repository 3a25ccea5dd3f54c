#!/usr/bin/python3
"""Run a V2 case with a driven rigid body (`rktsph run`) and check the body's mean pressure over
the last part of the run against a reference interval (the CTest entry v2_cphi_footing_plateau;
docs/VALIDATION.md, "V2 with a rigid footing"). The pressure is |F_y| of the body's records in
bodies.csv over --width (the loaded width, m), averaged over the records with t >= --from; it
passes when the run reaches its end and pressure / --reference lies in [low, high].

Usage: /usr/bin/python3 scripts/check_body_plateau.py --binary build/rktsph --case CASE.toml \
           --out DIR --body footing --width 1.0 --from 3.06 --reference 212.34e3 \
           --low 0.97 --high 1.08 [-- extra rktsph run arguments]
"""
import csv
import json
import os
import sys

from check_common import parser, run, split_extra


def main():
    argv, extra = split_extra()
    p = parser(__doc__)
    p.add_argument("--body", required=True, help="the body's name in bodies.csv")
    p.add_argument("--width", type=float, required=True, help="m: the loaded width the force acts over")
    p.add_argument("--from", dest="t_from", type=float, required=True, help="s: the plateau's first record")
    p.add_argument("--reference", type=float, required=True, help="Pa: the exact limit pressure")
    a = p.parse_args(argv)
    run([a.binary, "run", a.case, "-o", a.out] + extra, "run")
    with open(os.path.join(a.out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(a.out, "bodies.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["body"] == a.body]
    if not rows:
        sys.exit("{}: no records of body '{}'".format(os.path.join(a.out, "bodies.csv"), a.body))
    plateau = [abs(float(r["Fy"])) / a.width for r in rows if float(r["t"]) >= a.t_from]
    if not plateau:
        sys.exit("no record of body '{}' at t >= {} s (the last at {} s)".format(a.body, a.t_from, rows[-1]["t"]))
    ratio = sum(plateau) / len(plateau) / a.reference
    # The run reached its end time (a run that stopped on a diagnosis exits non-zero as well).
    reached = summary["status"] == "completed" and summary["steps"] >= summary["steps_planned"]
    inside = a.low <= ratio <= a.high
    print("{}: mean pressure over {} records from t = {} s: {:.4f} of {:.6g} Pa (expected in [{}, {}]); "
          "run {} at {:.4f} s: {}".format(a.body, len(plateau), a.t_from, ratio, a.reference, a.low, a.high,
                                          summary["status"], summary["time"],
                                          "pass" if inside and reached else "FAIL"))
    sys.exit(0 if inside and reached else 1)


if __name__ == "__main__":
    main()
