#!/bin/sh
# Side-by-side speed of two builds: V1 and V3 steps at 1e5 nodes on one and two threads.
#
# Usage:
#   scripts/bench_compare.sh OLD_BENCH NEW_BENCH [REPS=3] [-- extra benchmark arguments]
#   e.g. scripts/bench_compare.sh /work/baseline/build/bench/rktsph_bench build/bench/rktsph_bench
#
# Runs the two benchmark binaries alternately, REPS times each (old, new, old, new, ...), every
# run with
#   --benchmark_filter='^BM_V1Step/100000/[12]/real_time$|^BM_V3Step/100000/[12]/1/0/real_time$'
# (BM_V1Step/nodes/threads and BM_V3Step/nodes/threads/filter/implicit_faces of bench/bench_step.cpp: the V1
# step and the V3 step with the pressure filter, 1e5 nodes, 1 and 2 threads), so slow drifts of
# the machine hit both binaries alike. Override the filter with BENCH_FILTER=regex; arguments
# after `--` go to every run (e.g. -- --benchmark_min_time=2
# for longer measurements: this Google Benchmark takes seconds as a plain number).
#
# Output: bench/results/compare-<date>-<oldrev>-<newrev>/ of this repository, holding the raw
# JSON of every run (old-1.json, new-1.json, ...), its console table (old-1.txt, ...), runs.tsv
# (side, repetition, exit status, wall seconds), revisions.txt, and summary.md/summary.json from
# scripts/bench_compare.py: per benchmark the old and new median node-steps/s, their spread
# (min-max), the ratio new/old, bytes per node old/new (state, operator, traffic counters of
# BM_V1Step; BM_V3Step reports none), and pairs/node, nodes, pcg_iter/step and the number of
# timed steps old/new as a check that both do the same work. The revision of a binary is the hash in `rktsph --version` of the
# rktsph next to it (BIN/../rktsph), else the name of its build folder's parent.
#
# Exit status: 0 when every run completed and no bytes-per-node counter is higher in new;
# 1 otherwise; 2 on bad arguments. Speed does not set it: read the ratio against the spread.
# Time: one run of the four benchmarks takes ~17 s on the 2-core development machine, so the
# default REPS=3 takes ~2 min. V3 at 1e5 nodes dominates (~8 s for one thread, ~9 s for two):
# its step is ~80 ms (one thread) / ~46 ms (two), but Google Benchmark calls the function
# several times while it picks the iteration count, each time with the set-up and 20 warm-up
# steps, and then times only 8-16 steps; V1 takes ~1 s per variant.
set -eu

usage() {
  sed -n '2,/^set -eu/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//' >&2
  exit 2
}
[ $# -ge 2 ] || usage
OLD=$1
NEW=$2
shift 2
REPS=3
if [ $# -gt 0 ] && [ "$1" != "--" ]; then
  REPS=$1
  shift
fi
[ $# -gt 0 ] && [ "$1" = "--" ] && shift
case $REPS in '' | *[!0-9]* | 0) echo "REPS must be a positive integer, not '$REPS'" >&2; exit 2 ;; esac
for b in "$OLD" "$NEW"; do
  [ -x "$b" ] || { echo "not an executable: $b" >&2; exit 2; }
done
FILTER=${BENCH_FILTER:-'^BM_V1Step/100000/[12]/real_time$|^BM_V3Step/100000/[12]/1/0/real_time$'}

here=$(cd "$(dirname "$0")" && pwd)
repo=$(dirname "$here")

# The revision of a benchmark binary: `rktsph --version` next to it, else its build folder's name.
rev_of() {
  d=$(cd "$(dirname "$1")" && pwd)
  r=""
  for c in "$d/../rktsph" "$d/rktsph"; do
    if [ -x "$c" ] && [ -f "$c" ]; then
      r=$("$c" --version 2>/dev/null | sed -n 's/.*(\([^)]*\)).*/\1/p' | head -n 1)
      break
    fi
  done
  [ -n "$r" ] || r=$(basename "$(dirname "$d")")
  printf '%s' "$r" | tr -c 'A-Za-z0-9._-' '_'
}
oldrev=$(rev_of "$OLD")
newrev=$(rev_of "$NEW")
dir="$repo/bench/results/compare-$(date +%Y%m%d-%H%M%S)-$oldrev-$newrev"
mkdir -p "$dir"
{
  echo "old: $OLD ($oldrev)"
  echo "new: $NEW ($newrev)"
  echo "filter: $FILTER"
  echo "extra arguments: $*"
  echo "host: $(uname -n), $(nproc) cores"
} > "$dir/revisions.txt"
: > "$dir/runs.tsv"
echo "writing $dir" >&2

status=0
i=1
while [ "$i" -le "$REPS" ]; do
  for side in old new; do
    if [ $side = old ]; then bin=$OLD; else bin=$NEW; fi
    t0=$(date +%s)
    rc=0
    "$bin" --benchmark_filter="$FILTER" --benchmark_counters_tabular=true \
      --benchmark_out="$dir/$side-$i.json" --benchmark_out_format=json "$@" \
      > "$dir/$side-$i.txt" 2>&1 || rc=$?
    t1=$(date +%s)
    printf '%s\t%s\t%s\t%s\n' "$side" "$i" "$rc" "$((t1 - t0))" >> "$dir/runs.tsv"
    echo "  $side run $i/$REPS: exit $rc, $((t1 - t0)) s" >&2
    [ "$rc" -eq 0 ] || status=1
  done
  i=$((i + 1))
done

/usr/bin/python3 "$here/bench_compare.py" "$dir" || status=1
echo "results: $dir"
exit $status
