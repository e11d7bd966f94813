#!/usr/bin/env bash
# bench_modes.sh BUILD - every bench program's quick modes run to the end (exit 0), so a
# change that breaks a benchmark's own self-check (bench_core's "the iteration was not
# the worst case", bench_models' equal maxima) fails `make test`, not `make bench`.
set -u
build=${1:?usage: bench_modes.sh BUILD}
bin=$build/bin
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/../lib/checks.sh"

"$bin/bench_core" iter >"$tmp/o" 2>"$tmp/e"
check bench-core-iter '[ $? -eq 0 ] && grep -q "^periods [12]$" "$tmp/o"'
"$bin/bench_core" time 3 >"$tmp/o" 2>"$tmp/e"
check bench-core-time '[ $? -eq 0 ] && grep -Eq "^[0-9]+\.[0-9]$" "$tmp/o"'
"$bin/bench_core" dump "$tmp/samples.txt" 2>"$tmp/e"
check bench-core-dump '[ $? -eq 0 ] && [ "$(grep -vc "^#" "$tmp/samples.txt")" -eq 10000 ]'
"$bin/bench_ridge" fit 10000 >/dev/null 2>"$tmp/e"
check bench-ridge-fit '[ $? -eq 0 ]'
for m in ridge mlp knn radius pathloss; do
    "$bin/bench_models" search "$m" >/dev/null 2>"$tmp/e"
    check "bench-models-search-$m" '[ $? -eq 0 ]'
    "$bin/bench_models" slice "$m" 600 >/dev/null 2>"$tmp/e"
    check "bench-models-slice-$m" '[ $? -eq 0 ]'
done
"$bin/bench_pathloss" scenarios/maps/office.yaml slice 1000 2000 >/dev/null 2>"$tmp/e"
check bench-pathloss-slice '[ $? -eq 0 ]'
"$bin/bench_pathloss" scenarios/maps/office.yaml predict 1000 >/dev/null 2>"$tmp/e"
check bench-pathloss-predict '[ $? -eq 0 ]'
[ "$fails" -eq 0 ]
