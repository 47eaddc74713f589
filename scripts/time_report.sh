#!/usr/bin/env bash
# The time `make report` takes on the committed store: builds `ugl` first (not timed), then
# renders the report ROUNDS times into a temporary directory with the built binary and prints
# each wall time and the median. Run it on an otherwise idle machine (never while a build runs),
# after `make test` (the same build). Checks that every render is byte-identical to
# report/out, so a faster report is still the same report.
#
#   scripts/time_report.sh [rounds]        (default 5)
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-5}
exe=$(cargo build --quiet --bin ugl --message-format=json-render-diagnostics |
  sed -n 's/.*"executable":"\([^"]*\/ugl\)".*/\1/p' | tail -n 1)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
times=()
for r in $(seq "$rounds"); do
  t0=$(date +%s.%N)
  "$exe" report --results data/results --out "$out/report" --main paper >/dev/null 2>&1
  t1=$(date +%s.%N)
  t=$(awk "BEGIN {print $t1 - $t0}")
  times+=("$t")
  printf 'round %d: %.2f s\n' "$r" "$t"
  diff -rq report/out "$out/report" >/dev/null || { echo "the render differs from report/out" >&2; exit 1; }
done
printf '%s\n' "${times[@]}" | sort -n | awk '{a[NR]=$1} END {printf "median of %d: %.2f s\n", NR, a[int((NR+1)/2)]}'
