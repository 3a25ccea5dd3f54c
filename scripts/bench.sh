#!/bin/sh
# Run the benchmark suite (build/bench/rktsph_bench) and write its table to stdout and its
# figures to bench/results/<date>-<revision>.json. Extra arguments go to the benchmark, e.g.
#   scripts/bench.sh --benchmark_filter=V1Step --benchmark_repetitions=3
# Timings on a shared machine are noisy: compare repetitions (real and CPU time are both in the
# JSON), and prefer the byte counts, which are exact.
set -eu
cd "$(dirname "$0")/.."
rev=$(git rev-parse --short=12 HEAD 2>/dev/null || echo unknown)
mkdir -p bench/results
out="bench/results/$(date +%Y%m%d-%H%M%S)-$rev.json"
build/bench/rktsph_bench --benchmark_counters_tabular=true \
  --benchmark_out="$out" --benchmark_out_format=json "$@"
echo "figures: $out"
