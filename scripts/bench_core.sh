#!/usr/bin/env bash
# Figures of the core's worst-case iteration (docs/PERFORMANCE.md, "Core"): callgrind
# instructions (exact, with cell sums and without), then ROUNDS interleaved rounds of wall time, the core's median of
# 101 iterations then the scikit-learn twin's median of 101, and their ratio per round.
#   scripts/bench_core.sh [BUILD] [ROUNDS]
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
build=${1:-build}
rounds=${2:-5}
bin=$build/bin/bench_core
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" --collect-atstart=no \
    "$bin" iter >/dev/null 2>"$tmp/vg.log" || { grep -v '^==' "$tmp/vg.log" >&2; exit 1; }
total=$(callgrind_annotate "$tmp/cg.out" 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",","",$1); print $1}')
valgrind --tool=callgrind --callgrind-out-file="$tmp/scan.out" --collect-atstart=no \
    "$bin" --scan iter >/dev/null 2>"$tmp/vg.log" || { grep -v '^==' "$tmp/vg.log" >&2; exit 1; }
scan=$(callgrind_annotate "$tmp/scan.out" 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",","",$1); print $1}')
"$bin" dump "$tmp/samples.txt"
echo "core worst-case iteration (10,000 samples in radius, relearn, 12,800-point grid search):"
echo "  host x86-64 instructions (callgrind, exact): $total with cell sums, $scan visiting every sample (the STM32 image's pass)"
for r in $(seq 1 "$rounds"); do
    c_us=$("$bin" time 101)
    py_us=$(/usr/bin/python3 bench/sklearn_iteration.py "$tmp/samples.txt" 101)
    echo "$c_us $py_us" >>"$tmp/rounds"
    echo "  round $r: core median of 101 ${c_us} us; scikit-learn twin ${py_us} us;" \
         "ratio $(awk -v a="$py_us" -v b="$c_us" 'BEGIN{printf "%.0f", a/b}')x"
done
med() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
c_med=$(cut -d' ' -f1 "$tmp/rounds" | med)
p_med=$(cut -d' ' -f2 "$tmp/rounds" | med)
awk '{ print $2 / $1 }' "$tmp/rounds" | sort -g >"$tmp/ratios"
echo "  over $rounds rounds: core median ${c_med} us, scikit-learn ${p_med} us;" \
     "ratio median $(med <"$tmp/ratios" | xargs printf '%.0f')x," \
     "worst round $(head -1 "$tmp/ratios" | xargs printf '%.0f')x (target 200x)"
