#!/usr/bin/python3
"""Check a smooth rigid strip footing on weightless c-phi soil against Prandtl-Reissner.

Cases: cases/examples/strip_footing_cphi{20,30}_2d.toml (issue 16, item 5(a)). The exact
bearing capacity of a smooth strip on a weightless Mohr-Coulomb soil with associated flow and
a surcharge q_s is q_u = c N_c + q_s N_q, N_q = exp(pi tan phi) tan^2(45 deg + phi/2),
N_c = (N_q - 1) cot phi.

The script runs the case (unless --no-run) with one probe per footing node for the spacing in
effect, then reads probes.csv:

* footing force per metre from the vertical equilibrium of the soil above a horizontal section
  (a row of nodes B/2 below the footing; the soil is weightless and loaded slowly):
  F = -sum_j w_j sigma_yy,j - q_s (L - B/2), w_j the nodes' tributary widths (dx/2 at the two
  ends), L the model's width; the surcharge acts through the elastic cover on L - B/2;
* footing pressure q = F / (B/2) (the "section" pressure, the one checked);
* for comparison, the footing nodes' own sigma_yy (a reaction, singular at the edge), summed
  over their segments (dx/2 at the centre and at the edge, whose other half is under the cover);
* settlement s = -u_y of the centre node (all footing nodes move together);
* plateau: the mean of q over the last quarter of the settlement (s >= 0.75 s_end); its
  flatness is reported as the change of q across that window relative to q_u and its range.

It prints the plateau, the exact value and the error, draws q/q_u against s/B
(footing_cphi.png in the output folder), and exits with status 1 when the error is outside
-3/+8 % (--low/--high), 0 otherwise.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import time
import tomllib

MARKER = "# --- footing probes"


def prandtl_reissner(c, phi_deg, q_s):
    phi = math.radians(phi_deg)
    n_q = math.exp(math.pi * math.tan(phi)) * math.tan(math.pi / 4 + phi / 2) ** 2
    n_c = (n_q - 1.0) / math.tan(phi)
    return n_q, n_c, c * n_c + q_s * n_q


def prandtl_extent(b, phi_deg):
    """Surface reach (from the centre) and depth of the smooth-footing Prandtl mechanism."""
    phi = math.radians(phi_deg)
    a0 = math.pi / 4 + phi / 2
    r0 = b / math.cos(a0)
    depth = max(r0 * math.exp(t * math.tan(phi)) * math.sin(a0 + t)
                for t in [k * (math.pi / 2) / 1000 for k in range(1001)])
    r1 = r0 * math.exp(math.pi / 2 * math.tan(phi))
    reach = b + 2.0 * r1 * math.cos(math.pi / 4 - phi / 2)
    return reach, depth


def find_boundary(case, name):
    for entry in case.get("boundary", []):
        if entry.get("name") == name:
            return entry
    sys.exit(f"check_footing_cphi: the case has no [[boundary]] named '{name}'")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case")
    ap.add_argument("--spacing", type=float, help="geometry.spacing (m); default: the case file's")
    ap.add_argument("--out", help="output folder (default out/<case>[-dx<spacing>])")
    ap.add_argument("--rktsph", default="build/rktsph")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--set", action="append", default=[], help="extra --set key=value for the run")
    ap.add_argument("--row-depth", type=float, help="depth of the section row below the footing (m); default B/2")
    ap.add_argument("--no-run", action="store_true", help="only read an existing output folder")
    ap.add_argument("--low", type=float, default=-0.03, help="lower tolerance on the error (default -0.03)")
    ap.add_argument("--high", type=float, default=0.08, help="upper tolerance on the error (default +0.08)")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--hold", type=float, metavar="T",
                    help="stop the footing at T s (over 0.1 s) and hold it to time.end: reports the pressure "
                         "just before the stop and its decay while held (a rate-independent soil keeps it)")
    args = ap.parse_args()

    with open(args.case, "rb") as f:
        case = tomllib.load(f)
    with open(args.case, encoding="utf-8") as f:
        text = f.read()
    dx = args.spacing if args.spacing else float(case["geometry"]["spacing"])
    mat = case["material"] if "material" in case else case["materials"]["soil"]
    c, phi, psi = float(mat["cohesion"]), float(mat["friction_angle"]), float(mat.get("dilatancy", 0.0))
    footing = find_boundary(case, "footing")
    surcharge = find_boundary(case, "surcharge")
    b = float(footing["x"][1])
    top = float(footing["y"][0])
    q_s = -float(surcharge["stress"]["yy"])
    soil = [blk for blk in case["geometry"]["block"] if blk.get("material", "soil") == "soil"][-1]
    width = float(soil["max"][0])
    depth = top - float(soil["min"][1])
    n_q, n_c, q_u = prandtl_reissner(c, phi, q_s)
    reach, fan_depth = prandtl_extent(b, phi)
    name = os.path.splitext(os.path.basename(args.case))[0]
    out = args.out or os.path.join("out", name if args.spacing is None else f"{name}-dx{dx:g}")

    row_y = top - (args.row_depth if args.row_depth is not None else b)
    n_row = int(round(width / dx)) + 1
    n_nodes = int(round(b / dx)) + 1
    if abs((n_nodes - 1) * dx - b) > 1e-9 * b:
        sys.exit(f"check_footing_cphi: B/2 = {b} m is not a multiple of the spacing {dx} m")

    print(f"case {args.case}: c = {c:.4g} Pa, phi = {phi:g} deg, psi = {psi:g} deg, q_s = {q_s:.4g} Pa, "
          f"B/2 = {b:g} m, dx = {dx:g} m (B/{2 * b / dx:g})")
    print(f"Prandtl-Reissner: N_q = {n_q:.3f}, N_c = {n_c:.3f}, q_u = {q_u / 1e3:.2f} kPa")
    print(f"mechanism: surface reach {reach:.2f} m of {width:g} m, depth {fan_depth:.2f} m of {depth:g} m")
    if psi != phi:
        print("note: non-associated flow; Prandtl-Reissner is exact only for psi = phi")

    if not args.no_run:
        cut = text.find(MARKER)
        base = text if cut < 0 else text[:cut]
        if args.hold is not None:
            # The footing's ramp becomes ramp - hold - stop: a table with the same rise.
            start = base.index("[functions.push]")
            stop = base.index("\n[", start + 1)
            rise = float(case["functions"]["push"]["duration"])
            if not rise < args.hold:
                sys.exit(f"check_footing_cphi: --hold {args.hold} s must come after the {rise} s ramp")
            base = (base[:start] + "[functions.push]\ntype = \"table\"\n"
                    f"times = [0.0, {rise}, {args.hold}, {args.hold + 0.1}]\nvalues = [0.0, 1.0, 1.0, 0.0]\n"
                    + base[stop:])
        probes = "".join(
            f'\n[[probe]]\nname = "p{i:02d}"\nposition = [{i * dx:.6f}, {top}]\nfields = ["uy", "syy"]\n'
            for i in range(n_nodes))
        probes += "".join(
            f'\n[[probe]]\nname = "r{j:03d}"\nposition = [{j * dx:.6f}, {row_y}]\nfields = ["syy"]\n'
            for j in range(n_row))
        os.makedirs(out, exist_ok=True)
        derived = os.path.join(out, f"{name}.footing.toml")
        with open(derived, "w", encoding="utf-8") as f:
            f.write(base + f"{MARKER} for dx = {dx:g} m (written by check_footing_cphi.py)\n" + probes)
        cmd = [args.rktsph, "run", derived, "--out", os.path.join(out, "run"), "--threads", str(args.threads),
               "--quiet", "--set", f"geometry.spacing={dx}"]
        for s in args.set:
            cmd += ["--set", s]
        print("running:", " ".join(cmd), flush=True)
        t0 = time.time()
        rc = subprocess.call(cmd)
        print(f"run: exit status {rc}, {time.time() - t0:.0f} s wall")
        if rc != 0:
            sys.exit(rc)

    run_dir = os.path.join(out, "run")
    with open(os.path.join(run_dir, "probes.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    weights = [0.5 * dx] + [dx] * (n_nodes - 2) + [0.5 * dx]
    row_weights = [0.5 * dx] + [dx] * (n_row - 2) + [0.5 * dx]
    settle, press, press_nodes = [], [], []
    for r in rows:
        force_nodes = sum(w * -float(r[f"p{i:02d}.syy"]) for i, w in enumerate(weights))
        force = sum(w * -float(r[f"r{j:03d}.syy"]) for j, w in enumerate(row_weights)) - q_s * (width - b)
        settle.append(-float(r["centre.uy"]))
        press.append(force / b)
        press_nodes.append(force_nodes / b)
    if args.hold is not None:
        times = [float(r["t"]) for r in rows]
        def mean_q(t0, t1):
            qs = [q for t, q in zip(times, press) if t0 <= t <= t1]
            return sum(qs) / len(qs) if qs else float("nan")
        moving = mean_q(args.hold - 0.2, args.hold)
        print(f"hold at {args.hold:g} s: q moving (mean over the last 0.2 s) = {moving / q_u:.4f} q_u; held: "
              f"{mean_q(args.hold + 0.4, args.hold + 0.6) / q_u:.4f} q_u after 0.5 s, "
              f"{press[-1] / q_u:.4f} q_u at {times[-1]:g} s")
        marks = [args.hold + 0.5 * k for k in range(1, int((times[-1] - args.hold) / 0.5) + 1)]
        print("held q/q_u (means over 0.1 s) at " + ", ".join(
            f"{t - args.hold:g} s: {mean_q(t - 0.05, t + 0.05) / q_u:.4f}" for t in marks))
        sys.exit(0)
    s_end = settle[-1]
    window = [(s, q) for s, q in zip(settle, press) if s >= 0.75 * s_end]
    plateau = sum(q for _, q in window) / len(window)
    plateau_nodes = sum(q for s, q in zip(settle, press_nodes) if s >= 0.75 * s_end) / len(window)
    drift = (window[-1][1] - window[0][1]) / q_u
    error = plateau / q_u - 1.0
    spread = max(abs(float(r[f"p{i:02d}.uy"]) - float(r["centre.uy"])) for r in rows[-1:] for i in range(n_nodes))
    print(f"run: {summary.get('nodes')} nodes, {summary.get('steps')} steps, dt = {summary.get('dt'):.3e} s, "
          f"time loop {summary.get('wall_seconds', 0):.0f} s, status {summary.get('status')}")
    print(f"settlement at the end {s_end:.4f} m = {s_end / (2 * b):.4f} B "
          f"(footing nodes' u_y spread {spread:.2e} m)")
    print(f"plateau (mean q over s >= 0.75 s_end, {len(window)} rows) = {plateau / 1e3:.2f} kPa; "
          f"exact q_u = {q_u / 1e3:.2f} kPa; error {100 * error:+.2f} % "
          f"(tolerance {100 * args.low:+.0f}/{100 * args.high:+.0f} %); "
          f"change across the window {100 * drift:+.2f} % of q_u, range "
          f"{min(q for _, q in window) / q_u:.3f}-{max(q for _, q in window) / q_u:.3f} q_u")
    print(f"footing nodes' own sigma_yy over the same window: {plateau_nodes / 1e3:.2f} kPa, "
          f"{100 * (plateau_nodes / q_u - 1):+.2f} %")
    ok = args.low <= error <= args.high
    print("PASS" if ok else "NOT MET")

    if not args.no_plot:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("matplotlib not available: no plot")
        else:
            fig, ax = plt.subplots(figsize=(6.4, 4.2))
            ax.plot([s / (2 * b) for s in settle], [q / q_u for q in press], label=f"rktsph, dx = B/{2 * b / dx:g}, section")
            ax.plot([s / (2 * b) for s in settle], [q / q_u for q in press_nodes], lw=0.8, ls="--",
                    label="footing nodes' σ_yy")
            ax.axhline(1.0, color="k", lw=0.8, label="Prandtl–Reissner $q_u$")
            ax.axhspan(1 + args.low, 1 + args.high, color="0.85", label="−3/+8 %")
            ax.axvline(0.75 * s_end / (2 * b), color="0.5", ls=":", lw=0.8, label="plateau window")
            ax.set_xlabel("settlement / B")
            ax.set_ylabel("footing pressure / $q_u$")
            ax.set_title(f"smooth strip, c = {c / 1e3:g} kPa, φ = ψ = {phi:g}°, $q_s$ = {q_s / 1e3:g} kPa: "
                         f"{100 * error:+.1f} %", fontsize=9)
            ax.set_ylim(0, 1.2)
            ax.legend(loc="lower right", fontsize=8)
            fig.tight_layout()
            png = os.path.join(out, "footing_cphi.png")
            fig.savefig(png, dpi=120)
            print("plot:", png)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
