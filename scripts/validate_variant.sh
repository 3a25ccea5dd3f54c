#!/bin/sh
# Run `rktsph validate` on a copy of cases/ with keys overridden, to reproduce the variant
# comparisons of docs/VALIDATION.md (validate has no --set: its cases read their own files).
#
#   scripts/validate_variant.sh [--only GLOB] [--add] OUT TABLE.KEY=VALUE... -- [validate options] CASES...
#
# Every thesis and example case file matching GLOB (default: all) that has the [TABLE] header
# gets `KEY = VALUE` as the first line of that table (with --add, given after --only, a file
# without the table gets it appended); a line setting KEY anywhere else in the file is removed
# (so KEY must name one key of the file only: true of the keys used below). The report goes to
# OUT/report. Example, the odd-even filter at half strength on the V3 cases:
#
#   scripts/validate_variant.sh --only '1[3-7]_*' /tmp/half solver.pressure_odd_even_filter=0.5 -- 13 14 15 16 17
#   scripts/validate_variant.sh --only '16_*' /tmp/c05 time.cfl=0.5 -- --full 16
set -eu
# RKTSPH names the binary (default build/rktsph), e.g. a copy kept while build/ is rebuilt.
cd "$(dirname "$0")/.."
only='*'
if [ "${1:-}" = "--only" ]; then
  only=$2
  shift 2
fi
add=0
if [ "${1:-}" = "--add" ]; then
  add=1
  shift
fi
[ $# -ge 2 ] || { echo "usage: $0 [--only GLOB] [--add] OUT TABLE.KEY=VALUE... -- [validate options] CASES..." >&2; exit 2; }
out=$1
shift
rm -rf "$out/cases"
mkdir -p "$out/cases"
cp -r cases/thesis cases/examples "$out/cases/"
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  table=${1%%.*}
  rest=${1#*.}
  key=${rest%%=*}
  value=${rest#*=}
  [ "$table" != "$1" ] && [ "$key" != "$rest" ] || { echo "$0: '$1' is not TABLE.KEY=VALUE" >&2; exit 2; }
  found=0
  for f in "$out"/cases/thesis/$only.toml "$out"/cases/examples/$only.toml; do
    [ -f "$f" ] || continue
    if ! grep -q "^\[$table\]" "$f"; then
      [ "$add" -eq 1 ] || continue
      printf '\n[%s]\n' "$table" >>"$f"
    fi
    sed -i "/^$key *=/d; s|^\[$table\]\$|[$table]\n$key = $value|" "$f"
    found=$((found + 1))
  done
  [ "$found" -gt 0 ] || { echo "$0: no case file matching '$only' has a [$table] table" >&2; exit 2; }
  echo "$table.$key = $value in $found case files"
  shift
done
[ "${1:-}" = "--" ] && shift
exec "${RKTSPH:-build/rktsph}" validate --no-plots --cases-dir "$out/cases/thesis" -o "$out/report" "$@"
