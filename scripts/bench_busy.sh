#!/bin/sh
# Default threads against one thread on a busy machine (issue 14: "a run with the default
# threads is never slower than one thread when another process keeps cores busy").
#
# Usage:
#   scripts/bench_busy.sh [REPS=5] [BIN=build/rktsph]
#
# Starts BUSY (default 1) busy loops (`sh -c 'while :; do :; done'`, killed at the end, also on
# Ctrl-C), then runs each case REPS times in each mode, the modes of a repetition back to back
# and their order reversed from one repetition to the next (default, one, one, default, ...), so
# that slow drifts of the machine hit the modes alike:
#   v1: bench/cases/elastic_block_2d.toml --set time.end=0.164 (the V1 benchmark block, 1e5
#       nodes, run 5 times as long as the file says: 215 steps, ~2 s on one thread, so that a
#       run averages over many scheduler time slices)
#   v3: cases/thesis/15_strip_foundation_saturated.toml --set time.end=1.0 (V3, 2601 nodes,
#       1401 steps, a PCG solve every step: many short parallel loops)
# Modes (MODES, default "default one"):
#   default  no --threads: every CPU, each loop on all of them or on one thread, whichever it
#            measures faster (adaptive), and the wait policy rktsph sets (OMP_WAIT_POLICY=passive)
#   one      --threads 1
#   all      --threads N, N = the CPUs available: every loop on all threads (not adaptive), with
#            the passive wait policy; for reference (what the wait policy alone gives)
#   spin     OMP_NUM_THREADS=N and GOMP_SPINCOUNT=300000: every loop on all threads, waiting
#            threads spinning (libgomp's own default; rktsph then leaves the policy alone): the
#            default before issue 14; for reference
# Every run is `BIN run CASE --out TMP --quiet`; the figure is node_steps_per_second of its
# summary.json (node-steps over the time loop's wall time).
#
# Output: bench/results/busy-<date>-<revision>/ holding runs.tsv (case, mode, repetition, exit
# status, node-steps/s, loop seconds, threads, wait policy), host.txt, and summary.md /
# summary.json: per case and mode the median node-steps/s and its range, and per case the
# ratio default / one of each repetition (paired: the two runs back to back) with the median,
# minimum and maximum. The summary is also printed.
#
# Exit status: 0 when every run completed and, for each case, the median paired ratio
# default / one is >= 1 and no repetition's is below 0.9 (back-to-back runs on a shared machine
# differ by 10 % and more: the spread of the one-thread figures is in the summary); 1 otherwise;
# 2 on bad arguments.
set -eu

REPS=${1:-5}
BIN=${2:-build/rktsph}
BUSY=${BUSY:-1}
MODES=${MODES:-default one}
case $REPS in '' | *[!0-9]* | 0) echo "REPS must be a positive integer, not '$REPS'" >&2; exit 2 ;; esac
case $BUSY in '' | *[!0-9]*) echo "BUSY must be a non-negative integer, not '$BUSY'" >&2; exit 2 ;; esac
[ -x "$BIN" ] || { echo "not an executable: $BIN (build first: scripts/build.sh)" >&2; exit 2; }
for m in $MODES; do
  case $m in default | one | all | spin) ;; *) echo "unknown mode '$m' (default, one, all, spin)" >&2; exit 2 ;; esac
done

here=$(cd "$(dirname "$0")" && pwd)
repo=$(dirname "$here")
rev=$(git -C "$repo" rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
dir="$repo/bench/results/busy-$(date +%Y%m%d-%H%M%S)-$rev"
mkdir -p "$dir"
tmp=$(mktemp -d)
busy_pids=""
cleanup() {
  for p in $busy_pids; do kill "$p" 2>/dev/null || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

{
  echo "binary: $BIN ($("$BIN" --version 2>/dev/null || echo '?'))"
  echo "revision: $rev"
  echo "host: $(uname -n), $(nproc) CPUs available, $(grep -c ^processor /proc/cpuinfo) online"
  echo "cpu: $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)"
  echo "busy loops: $BUSY; repetitions: $REPS; modes: $MODES"
  echo "load average before: $(cat /proc/loadavg)"
  echo "environment: OMP_WAIT_POLICY=${OMP_WAIT_POLICY-unset} GOMP_SPINCOUNT=${GOMP_SPINCOUNT-unset} OMP_NUM_THREADS=${OMP_NUM_THREADS-unset}"
} > "$dir/host.txt"
cat "$dir/host.txt" >&2

i=0
while [ "$i" -lt "$BUSY" ]; do
  sh -c 'while :; do :; done' &
  busy_pids="$busy_pids $!"
  i=$((i + 1))
done
sleep 1

run_one() {  # case mode rep
  c=$1
  mode=$2
  rep=$3
  case $c in
    v1) set -- "$repo/bench/cases/elastic_block_2d.toml" --set time.end=0.164 ;;
    v3) set -- "$repo/cases/thesis/15_strip_foundation_saturated.toml" --set time.end=1.0 ;;
  esac
  out="$tmp/$c-$mode"
  rm -rf "$out"
  rc=0
  case $mode in
    default) "$BIN" run "$@" --out "$out" --quiet > "$tmp/log" 2>&1 || rc=$? ;;
    one) "$BIN" run "$@" --out "$out" --quiet --threads 1 > "$tmp/log" 2>&1 || rc=$? ;;
    all) "$BIN" run "$@" --out "$out" --quiet --threads "$(nproc)" > "$tmp/log" 2>&1 || rc=$? ;;
    spin) GOMP_SPINCOUNT=300000 OMP_NUM_THREADS="$(nproc)" "$BIN" run "$@" --out "$out" --quiet > "$tmp/log" 2>&1 \
      || rc=$? ;;
  esac
  fig=$(/usr/bin/python3 -c '
import json, sys
try:
    d = json.load(open(sys.argv[1]))
    f = (d["node_steps_per_second"], d["wall_seconds"], d["threads"], d.get("omp_wait_policy", "?"),
         d.get("threads_adaptive", "?"), d.get("team_call_share", "nan"))
except Exception:
    f = ("nan", "nan", "nan", "?", "?", "nan")
print("\t".join(str(x) for x in f))
' "$out/summary.json")
  printf '%s\t%s\t%s\t%s\t%s\n' "$c" "$mode" "$rep" "$rc" "$fig" >> "$dir/runs.tsv"
  echo "  $c $mode rep $rep: exit $rc, node-steps/s, loop s, threads, policy: $fig" >&2
  [ "$rc" -eq 0 ] || cat "$tmp/log" >&2
}

printf 'case\tmode\trep\texit\tnode_steps_per_second\tloop_seconds\tthreads\twait_policy\tadaptive\tteam_call_share\n' > "$dir/runs.tsv"
rep=1
while [ "$rep" -le "$REPS" ]; do
  order=$MODES
  if [ $((rep % 2)) -eq 0 ]; then
    order=""
    for m in $MODES; do order="$m $order"; done
  fi
  for c in v1 v3; do
    for m in $order; do run_one "$c" "$m" "$rep"; done
  done
  rep=$((rep + 1))
done
echo "load average after: $(cat /proc/loadavg)" >> "$dir/host.txt"

status=0
/usr/bin/python3 - "$dir" <<'EOF' || status=1
import json, math, statistics, sys
from pathlib import Path

d = Path(sys.argv[1])
rows = [l.split("\t") for l in (d / "runs.tsv").read_text().splitlines()[1:]]
runs = {}
failed = 0
for c, mode, rep, rc, nsps, secs, threads, policy, adaptive, share in rows:
    if rc != "0":
        failed += 1
    runs.setdefault(c, {}).setdefault(mode, {})[int(rep)] = (float(nsps), float(secs), threads, policy,
                                                              adaptive, float(share))
host = (d / "host.txt").read_text()
summary = {"host": host, "cases": {}}
lines = ["# Default threads against one thread, busy machine", "", "```", host.rstrip(), "```", ""]
lines += ["| case | mode | threads | adaptive | wait policy | node-steps/s median | range | loop s median | "
          "loop calls on all threads |",
          "|---|---|---|---|---|---|---|---|---|"]
ok = failed == 0
names = {"v1": "V1 block (1e5 nodes, 215 steps)", "v3": "V3 case 15 (2601 nodes, 1401 steps)"}
for c, modes in runs.items():
    summary["cases"][c] = {"modes": {}}
    for mode, reps in modes.items():
        v = [x[0] for x in reps.values()]
        s = [x[1] for x in reps.values()]
        some = next(iter(reps.values()))
        share = [x[5] for x in reps.values()]
        summary["cases"][c]["modes"][mode] = {"node_steps_per_second": v, "median": statistics.median(v),
                                              "min": min(v), "max": max(v), "loop_seconds": s,
                                              "threads": some[2], "wait_policy": some[3],
                                              "adaptive": some[4], "team_call_share": share}
        share_text = "-" if some[4] != "True" else ", ".join(f"{x:.2f}" for x in share)
        lines.append(f"| {names.get(c, c)} | {mode} | {some[2]} | {some[4]} | {some[3]} | "
                     f"{statistics.median(v):.3g} | {min(v):.3g} - {max(v):.3g} | {statistics.median(s):.3g} | "
                     f"{share_text} |")
lines += ["", "| case | ratio | per repetition | median | min | max |", "|---|---|---|---|---|---|"]
for c, modes in runs.items():
    for other in ("one", "all", "spin"):
        if "default" not in modes or other not in modes or other == "default":
            continue
        pairs = sorted(set(modes["default"]) & set(modes[other]))
        r = [modes["default"][k][0] / modes[other][k][0] for k in pairs]
        r = [x for x in r if math.isfinite(x)]
        if not r:
            ok = False
            continue
        summary["cases"][c][f"default_over_{other}"] = {"per_repetition": r, "median": statistics.median(r),
                                                         "min": min(r), "max": max(r)}
        lines.append(f"| {names.get(c, c)} | default / {other} | {', '.join(f'{x:.2f}' for x in r)} | "
                     f"{statistics.median(r):.2f} | {min(r):.2f} | {max(r):.2f} |")
        if other == "one" and (statistics.median(r) < 1.0 or min(r) < 0.9):
            ok = False
verdict = ("default not slower than one thread: median ratio >= 1, no repetition below 0.9" if ok
           else "NOT met: a run failed, or default / one has a median below 1 or a repetition below 0.9")
summary["never_slower"] = ok
summary["failed_runs"] = failed
lines += ["", f"Verdict: {verdict}.", ""]
(d / "summary.md").write_text("\n".join(lines))
(d / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
print("\n".join(lines))
sys.exit(0 if ok else 1)
EOF
echo "results: $dir"
exit $status
