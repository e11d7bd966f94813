#!/usr/bin/env bash
# Instruction counts of the data path (docs/PERFORMANCE.md, "data"): callgrind counts
# exactly the calls inside CALLGRIND_TOGGLE_COLLECT pairs in bench/bench_ridge.c; per-item figures
# are marginal (difference of two sizes / difference of counts), so set-up cost cancels.
#   scripts/bench_data.sh [BUILD]      (default build)
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
build=${1:-build}
bin=$build/bin/bench_ridge
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ir() { # ir ARGS... -> instructions counted between START and STOP
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" --collect-atstart=no \
        "$bin" "$@" >/dev/null 2>"$tmp/vg.log"
    callgrind_annotate "$tmp/cg.out" 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",","",$1); print $1}'
}
per() { awk -v a="$1" -v b="$2" -v n="$3" 'BEGIN{printf "%.1f", (b - a) / n}'; }
f0=$(ir fit 0); f10=$(ir fit 10000); f20=$(ir fit 20000)
o10=$(ir fit 10000 16000) # spread +-160 m: nearly every sample outside the 5 m radius
p0=$(ir predict 0); p12=$(ir predict 12800)
# instructions inside ridge_predict alone (all its lines, inlined helpers included)
pf=$(callgrind_annotate --auto=no "$tmp/cg.out" 2>/dev/null | awk '/:ridge_predict( |$)/ && $1 ~ /^[0-9,]+$/ {gsub(",","",$1); s += $1} END {print s + 0}')
w0=$(ir row 0); w12=$(ir row 12800)
r1=$(ir rssi 1000); r5=$(ir rssi 5000)
s1=$(ir store 1000); s5=$(ir store 5000)
echo "data path, host x86-64 instructions (callgrind, exact):"
echo "  ridge fit, 10,000 samples all within 5 m: $f10 ($(per 0 "$f10" 10000) per sample incl. solve; marginal $(per "$f10" "$f20" 10000) per sample; empty fit $f0)"
echo "  ridge fit, 10,000 samples mostly outside the radius: $o10 ($(per 0 "$o10" 10000) per sample)"
echo "  ridge predict: $(per 0 "$pf" 12800) per point inside ridge_predict; $(per "$p0" "$p12" 12800) with the caller's loop (12,800-point grid)"
echo "  ridge predict_row: $(per "$w0" "$w12" 12800) per point in rows of 160 (12,800-point grid: $((w12 - w0)))"
echo "  rssi push + mean at 400 packets/s: $(per "$r1" "$r5" 4000) per packet"
echo "  store add_value (+ a pose every 40): $(per "$s1" "$s5" 4000) per measurement"
arm=$build/arm/lib/librfs_core.a
if [ -f "$arm" ]; then
    echo "  arm-none-eabi-size (Cortex-M4, -Os) of the data modules, text bytes:"
    arm-none-eabi-size "$arm" 2>/dev/null | awk '/rfs_(fix|rssi|store|ridge|target)\.o/ {printf "    %s %s\n", $6, $1}'
fi
