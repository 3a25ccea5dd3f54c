#!/usr/bin/env python3
"""When does a run stop? A case run at several Courant numbers, in parallel, one thread each.

    /usr/bin/python3 scripts/stop_times.py CASE [--cfl 0.4 0.45 0.5 0.55] [--parallel 2]
        [--binary build/rktsph] [--out DIR] [--set KEY=VALUE ...]

For comparing variants of a solver on a run that goes unstable (docs/VALIDATION.md Case 9): the
time at which the growth guard stops a run scatters with the time step by a factor of two or
more, so one run says little; the spread over a few steps says more. For each Courant number the
case is run with `--set time.cfl=C --set 'output.times=[]'` and the extra `--set`s; the line
gives the last time in `energy.csv`, the exit status (0: reached time.end; 3: stopped unstable)
and, for a stopped run, where the fastest node was. Then the median and the mean of the times.
Exit status 0 whatever the runs did; 2 if the binary or the case is missing.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor


def run_one(binary, case, out, cfl, sets):
    folder = os.path.join(out, f"cfl{cfl:g}")
    cmd = [binary, "run", case, "-q", "-j1", "-o", folder, "--set", f"time.cfl={cfl}", "--set", "output.times=[]"]
    for s in sets:
        cmd += ["--set", s]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    last = float("nan")
    try:
        with open(os.path.join(folder, "energy.csv")) as f:
            rows = [line for line in f.read().splitlines() if line and not line.startswith("t")]
        if rows:
            last = float(rows[-1].split(",")[0])
    except OSError:
        pass
    where = ""
    m = re.search(r"The fastest node is at x = \[([^\]]*)\] \(at \[([^\]]*)\] in the body as made\), \|v\| = (\S+) m/s",
                  proc.stderr)
    if m:
        where = f"fastest node at ({m.group(1)}), made at ({m.group(2)}), |v| = {m.group(3)} m/s"
    elif proc.returncode not in (0, 3):
        where = (proc.stderr.strip().splitlines() or ["(no message)"])[-1][:160]
    return cfl, last, proc.returncode, where


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case")
    ap.add_argument("--cfl", type=float, nargs="+", default=[0.4, 0.45, 0.5, 0.55])
    ap.add_argument("--parallel", type=int, default=2, help="runs at once (default 2)")
    ap.add_argument("--binary", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "rktsph"))
    ap.add_argument("--out", default=None, help="folder for the runs' output (default: a temporary folder)")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE")
    a = ap.parse_args()
    if not os.path.isfile(a.binary):
        print(f"error: no binary at {a.binary} (build first, or give --binary)", file=sys.stderr)
        return 2
    if not os.path.isfile(a.case):
        print(f"error: no case file at {a.case}", file=sys.stderr)
        return 2
    out = a.out or tempfile.mkdtemp(prefix="stop_times_")
    with ThreadPoolExecutor(max_workers=max(1, a.parallel)) as pool:
        results = list(pool.map(lambda c: run_one(a.binary, a.case, out, c, a.sets), a.cfl))
    print(f"{a.case} {' '.join('--set ' + s for s in a.sets)}  (output in {out})")
    for cfl, last, rc, where in results:
        state = {0: "completed", 3: "stopped"}.get(rc, f"exit {rc}")
        print(f"  C = {cfl:<5g} t = {last:9.4f} s  {state:9s} {where}")
    times = [r[1] for r in results if r[1] == r[1]]
    if times:
        print(f"  median {statistics.median(times):.3f} s, mean {statistics.fmean(times):.3f} s over {len(times)} runs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
