#!/usr/bin/env bash
# Figures of the core's worst-case iteration (docs/PERFORMANCE.md, "Core").
set -euo pipefail
build=${1:-build}
bin=$build/bin/bench_core
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" --collect-atstart=no \
    "$bin" iter >/dev/null 2>"$tmp/vg.log" || { grep -v '^==' "$tmp/vg.log" >&2; exit 1; }
total=$(callgrind_annotate "$tmp/cg.out" 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",","",$1); print $1}')
"$bin" dump "$tmp/samples.txt"
c_us=$("$bin" time 101)
py_us=$(/usr/bin/python3 bench/sklearn_iteration.py "$tmp/samples.txt" 101)
echo "core worst-case iteration (10,000 samples in radius, relearn, 12,800-point grid search):"
echo "  host x86-64 instructions (callgrind, exact): $total"
echo "  host wall time median of 101: ${c_us} us; scikit-learn twin median of 101: ${py_us} us"
echo "  ratio sklearn / core: $(awk -v a="$py_us" -v b="$c_us" 'BEGIN{printf "%.0f", a/b}')x"
