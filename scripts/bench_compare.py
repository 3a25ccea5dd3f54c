#!/usr/bin/python3
"""Summarise the alternating old/new benchmark runs of scripts/bench_compare.sh.

Usage:
  /usr/bin/python3 scripts/bench_compare.py DIR

DIR holds old-1.json, new-1.json, old-2.json, ... (Google Benchmark --benchmark_out JSON, one
entry per benchmark and run) and optionally runs.tsv (side, repetition, exit status, seconds,
as written by bench_compare.sh) and revisions.txt. Per benchmark it reports, for old and new:
the median of node_steps/s over the runs, the spread (min-max), the ratio of the medians
new/old, and the per-node memory counters (state_B/node, operator_B/node, traffic_B/node of
BM_V1Step; the V3 benchmark reports none), plus pairs/node, nodes, pcg_iter/step and the
number of timed steps (iterations), which show whether both binaries do the same work
(pcg_iter/step is a mean over the timed steps, so it only has to agree when their numbers do). A benchmark is "slower"/"faster" only when the two
spreads do not overlap, else "within noise".

Writes DIR/summary.md and DIR/summary.json and prints the table.
Exit status: 0 when every run has every benchmark and exited 0; 1 otherwise (missing or failed
run, a benchmark that errored); 2 on bad arguments. Speed never sets the exit status (timings
on a shared machine are noisy; read the spread). Bytes per node higher in new: reported as
"HIGHER" in the table, and the exit status is 1.
"""
import json
import re
import statistics
import sys
from pathlib import Path

RATE = "node_steps/s"
BYTES = ["state_B/node", "operator_B/node", "traffic_B/node"]
WORK = ["pairs/node", "pcg_iter/step", "nodes", "iterations"]


def load(path):
    with open(path) as f:
        d = json.load(f)
    out = {}
    for b in d.get("benchmarks", []):
        if b.get("run_type", "iteration") != "iteration":
            continue
        name = b.get("run_name", b["name"])
        out.setdefault(name, []).append(b)
    return d.get("context", {}), out


def fmt(x):
    """Rates in millions (0.8254M), other counters with 5 significant digits."""
    if x is None:
        return "—"
    return f"{x / 1e6:.4g}M" if abs(x) >= 1e5 else f"{x:.5g}"


def show(v):
    """A counter that was the same in every run, or the range over the runs."""
    if isinstance(v, list):
        return f"{fmt(min(v))}–{fmt(max(v))}"
    return fmt(v)


def main():
    if len(sys.argv) != 2 or not Path(sys.argv[1]).is_dir():
        print(__doc__, file=sys.stderr)
        return 2
    d = Path(sys.argv[1])
    problems = []
    runs = {"old": [], "new": []}
    for p in sorted(d.glob("*.json")):
        m = re.fullmatch(r"(old|new)-(\d+)\.json", p.name)
        if not m:
            continue
        try:
            ctx, benches = load(p)
        except (OSError, ValueError) as e:
            problems.append(f"{p.name}: unreadable ({e})")
            continue
        runs[m.group(1)].append((int(m.group(2)), ctx, benches))
    for side in runs:
        runs[side].sort(key=lambda r: r[0])
    tsv = {}
    if (d / "runs.tsv").exists():
        for line in (d / "runs.tsv").read_text().splitlines():
            f = line.split("\t")
            if len(f) >= 4 and f[0] in ("old", "new"):
                tsv[(f[0], int(f[1]))] = (int(f[2]), float(f[3]))
                if int(f[2]) != 0:
                    problems.append(f"{f[0]} run {f[1]} exited {f[2]}")
    names = []
    for side in ("old", "new"):
        for _, _, benches in runs[side]:
            for n in benches:
                if n not in names:
                    names.append(n)
    if not runs["old"] or not runs["new"]:
        problems.append("no runs of " + " and ".join(s for s in runs if not runs[s]))

    result, rows = [], []
    for name in names:
        entry = {"benchmark": name}
        stats = {}
        for side in ("old", "new"):
            vals, extra = [], {}
            for rep, _, benches in runs[side]:
                bs = benches.get(name)
                if not bs:
                    problems.append(f"{side} run {rep}: {name} missing")
                    continue
                b = bs[0]
                if b.get("error_occurred"):
                    problems.append(f"{side} run {rep}: {name}: {b.get('error_message', 'error')}")
                    continue
                if RATE in b:
                    vals.append(float(b[RATE]))
                for k in BYTES + WORK:
                    if k in b:
                        extra.setdefault(k, []).append(float(b[k]))
            s = {"node_steps_per_s": vals,
                 "median": statistics.median(vals) if vals else None,
                 "min": min(vals) if vals else None, "max": max(vals) if vals else None}
            for k, v in extra.items():
                s[k] = v[0] if len(set(v)) == 1 else v
            stats[side] = s
            entry[side] = s
        o, n = stats["old"], stats["new"]
        ratio = n["median"] / o["median"] if o["median"] and n["median"] else None
        if ratio is None:
            verdict = "no data"
        elif min(len(o["node_steps_per_s"]), len(n["node_steps_per_s"])) < 2:
            verdict = "one run: no spread"
        elif n["min"] > o["max"]:
            verdict = "faster"
        elif n["max"] < o["min"]:
            verdict = "slower"
        else:
            verdict = "within noise"
        entry["ratio_new_old"] = ratio
        entry["verdict"] = verdict
        mem = []
        for k in BYTES:
            if k in o or k in n:
                a, b = o.get(k), n.get(k)
                flag = ""
                if a is not None and b is not None and max(a if isinstance(a, list) else [a]) < max(b if isinstance(b, list) else [b]):
                    flag = " HIGHER"
                    problems.append(f"{name}: {k} higher in new ({a:g} -> {b:g})")
                mem.append(f"{k.split('_B')[0]} {show(a)}/{show(b)}{flag}")
        work = []
        for k in WORK:
            if k in o or k in n:
                a, b = o.get(k), n.get(k)
                # pcg_iter/step is a mean over the timed steps, whose number the benchmark
                # chooses per run (iterations): it need not agree when the step counts differ
                same = "" if a == b or k == "iterations" or (k == "pcg_iter/step" and o.get("iterations") != n.get("iterations")) else " DIFFERS"
                k = "steps" if k == "iterations" else k
                work.append(f"{k} {show(a)}/{show(b)}{same}")
        rows.append((name.replace("/real_time", ""), fmt(o["median"]), f"{fmt(o['min'])}–{fmt(o['max'])}",
                     fmt(n["median"]), f"{fmt(n['min'])}–{fmt(n['max'])}",
                     f"{ratio:.3f}" if ratio else "—", verdict, "; ".join(mem) or "—", "; ".join(work) or "—"))
        result.append(entry)

    nrep = max(len(runs["old"]), len(runs["new"]))
    lines = ["| benchmark | old median node-steps/s | old min–max | new median | new min–max | new/old | "
             "verdict | bytes/node old/new | work old/new |",
             "|---|---|---|---|---|---|---|---|---|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    head = [f"# bench_compare: {d.name}", ""]
    if (d / "revisions.txt").exists():
        head += ["```", (d / "revisions.txt").read_text().rstrip(), "```", ""]
    head += [f"{nrep} alternating run(s) of each binary (old, new, old, new, ...); node-steps/s per run "
             "from the benchmark's own timing (real time).", ""]
    order = []
    for rep in range(1, nrep + 1):
        for side in ("old", "new"):
            r = next((x for x in runs[side] if x[0] == rep), None)
            if r is None:
                continue
            la = r[1].get("load_avg")
            secs = tsv.get((side, rep), (None, None))[1]
            order.append(f"- {side} run {rep}: {r[1].get('date', '?')}, load average at start "
                         f"{', '.join(f'{x:.2f}' for x in la) if la else '?'}"
                         f"{f', {secs:.0f} s wall' if secs is not None else ''}")
    tail = ["", "Runs:", ""] + order
    if problems:
        tail += ["", "Problems:", ""] + [f"- {p}" for p in problems]
    text = "\n".join(head + lines + tail) + "\n"
    (d / "summary.md").write_text(text)
    (d / "summary.json").write_text(json.dumps({"benchmarks": result, "problems": problems}, indent=1) + "\n")
    print(text, end="")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
