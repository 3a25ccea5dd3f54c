#!/usr/bin/python3
"""Run the clamped elastic plate of cases/examples/plate_bending_v2_2d.toml (or another case with
a probe `tip` recording uy and no external work) and check the scheme's energy budget (the CTest
entry v2_plate_energy; docs/VALIDATION.md, "V2's default step"):

* the total energy (kinetic + strain, energy.csv) never exceeds its initial value by more than
  --growth (relative; 1e-3);
* from one maximum of the tip's deflection to the next (one period) the energy falls by at most
  --loss (relative; 0.02);
* the period between maxima against --period (s, the Euler-Bernoulli value), printed; it is not
  a pass criterion here (docs/VALIDATION.md says what it is and what it should be).

Usage: /usr/bin/python3 scripts/check_plate_energy.py --binary build/rktsph --case CASE.toml \
           --out DIR --period 1.181 [--growth 1e-3] [--loss 0.02] [--reuse] [-- extra rktsph run arguments]
"""
import argparse
import csv
import os
import sys

from check_common import run, split_extra


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def main():
    argv, extra = split_extra()
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--binary", required=True)
    p.add_argument("--case", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--period", type=float, required=True, help="s: the reference period")
    p.add_argument("--growth", type=float, default=1e-3)
    p.add_argument("--loss", type=float, default=0.02)
    p.add_argument("--reuse", action="store_true", help="check the run already in --out instead of running")
    a = p.parse_args(argv)
    if not a.reuse:
        run([a.binary, "run", a.case, "-o", a.out] + extra, "run")
    energy = read(os.path.join(a.out, "energy.csv"))
    t_e = [float(r["t"]) for r in energy]
    total = [float(r["kinetic"]) + float(r["strain"]) for r in energy]
    e0 = total[0] if total[0] > 0.0 else total[1]
    growth = max(total) / e0 - 1.0
    probes = read(os.path.join(a.out, "probes.csv"))
    t_p = [float(r["t"]) for r in probes]
    uy = [float(r["tip.uy"]) for r in probes]
    # Maxima of the tip's upward deflection (the mode starts moving up): above half the largest,
    # and at least half a reference period apart (a finer plate carries higher-mode ripple).
    top = max(uy)
    peaks = []
    for i in range(1, len(uy) - 1):
        if uy[i] > 0.5 * top and uy[i] > uy[i - 1] and uy[i] >= uy[i + 1]:
            if peaks and t_p[i] - peaks[-1] < 0.5 * a.period:
                continue
            peaks.append(t_p[i])
    if len(peaks) < 2:
        sys.exit("fewer than two maxima of the tip's deflection in {} s: no period to measure".format(t_p[-1]))

    def energy_at(t):
        return total[min(range(len(t_e)), key=lambda k: abs(t_e[k] - t))]

    losses = [1.0 - energy_at(peaks[k + 1]) / energy_at(peaks[k]) for k in range(len(peaks) - 1)]
    periods = [peaks[k + 1] - peaks[k] for k in range(len(peaks) - 1)]
    mean_period = sum(periods) / len(periods)
    print("initial energy {:.6g} J/m; largest growth above it {:.3e} (<= {:g})".format(e0, growth, a.growth))
    print("energy lost per period: {} (each <= {:g})".format(", ".join("{:.4f}".format(x) for x in losses), a.loss))
    print("period {:.4f} s against {:.4f} s: {:+.2f} % (reported)".format(mean_period, a.period,
                                                                            100.0 * (mean_period / a.period - 1.0)))
    ok = growth <= a.growth and all(x <= a.loss for x in losses)
    print("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
