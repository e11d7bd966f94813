#!/usr/bin/env bash
# Instruction counts of the internal models (docs/PERFORMANCE.md, "Models"): callgrind,
# host x86-64, exact. Usage: scripts/bench_models.sh BUILD_DIR
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
build=${1:-build}
bin=$build/bin/bench_models
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ir() { # ir OUTNAME ARGS...: instructions inside the instrumented region
    local name=$1; shift
    valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file="$tmp/$name.cg" \
        "$bin" "$@" >"$tmp/$name.out" 2>"$tmp/$name.log"
    callgrind_annotate "$tmp/$name.cg" 2>/dev/null | awk '/PROGRAM TOTALS/ {gsub(",","",$1); print $1}'
}
echo "models: 10,000 samples over 40 x 20 m; grid search = 12,800 lattice points (0.25 m)"
echo "  host x86-64 instructions (callgrind, exact)"
echo "  predict all: a prediction at every point; full scan: rfs_gridmax_scan();"
echo "  search: rfs_gridmax_find() (row shortcut for ridge, branch and bound for mlp/knn/radius)"
printf "  %-7s %13s %13s %9s %13s %13s %7s\n" model "full relearn" "predict all" "/point" \
    "full scan" "search" "ratio"
for m in ridge mlp knn radius; do
    r=$(ir "r_$m" relearn "$m")
    g=$(ir "g_$m" grid "$m")
    sc=$(ir "sc_$m" scan "$m")
    se=$(ir "se_$m" search "$m")
    # the three searches must agree on the maximum
    if ! cmp -s <(grep '^max' "$tmp/sc_$m.out") <(grep '^max' "$tmp/se_$m.out"); then
        echo "bench_models: $m: search and full scan disagree" >&2
        exit 1
    fi
    printf "  %-7s %13s %13s %9s %13s %13s %7s\n" "$m" "$r" "$g" \
        "$(awk -v g="$g" 'BEGIN{printf "%.0f", g/12800}')" "$sc" "$se" \
        "$(awk -v a="$sc" -v b="$se" 'BEGIN{printf "%.1fx", a/b}')"
done
echo "  the same 10,000 samples along a robot path (dense, noisy, whole dB: bench/bench_models.c)"
printf "  %-7s %13s %13s %7s\n" model "full scan" "search" "ratio"
for m in knn radius; do
    sc=$(ir "pc_$m" scan "$m" path)
    se=$(ir "pe_$m" search "$m" path)
    if ! cmp -s <(grep '^max' "$tmp/pc_$m.out") <(grep '^max' "$tmp/pe_$m.out")
    then
        echo "bench_models: $m on a path: search and full scan disagree" >&2
        exit 1
    fi
    printf "  %-7s %13s %13s %7s\n" "$m" "$sc" "$se" \
        "$(awk -v a="$sc" -v b="$se" 'BEGIN{printf "%.1fx", a/b}')"
done
for b in 100 1000; do
    s=$(ir "s_mlp_$b" slice mlp "$b")
    calls=$(awk '/^calls/ {print $2}' "$tmp/s_mlp_$b.out")
    echo "  mlp first slice of budget $b sample-updates: $s instructions; whole fit in $calls calls"
done
s=$(ir s_knn slice knn 2000)
calls=$(awk '/^calls/ {print $2}' "$tmp/s_knn.out")
echo "  knn first slice of budget 2000 units: $s instructions; whole fit in $calls calls"
