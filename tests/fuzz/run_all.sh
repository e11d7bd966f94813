#!/usr/bin/env bash
# run_all.sh - run libFuzzer targets over their committed corpora.
#   tests/fuzz/run_all.sh BUILD --runs N    NAME...   corpus + N new inputs each (make test)
#   tests/fuzz/run_all.sh BUILD --seconds S NAME...   S seconds each (make fuzz)
# NAME is can, lcm, map, png, scenario, pcap, poses, candump (BUILD/fuzz/fuzz_NAME), radiotap (BUILD/feed/) or replay
# (BUILD/firmware/). New inputs go to BUILD/fuzz/corpus-NAME and crashes to
# BUILD/fuzz/artifacts/, never into tests/fuzz/corpus. Prints one PASS/FAIL line per
# target with executions, wall time, executions/s and coverage (cov: edges, ft: features);
# a FAIL names the finding and its input. Exits non-zero on any FAIL.
set -uo pipefail
usage() { echo "usage: run_all.sh BUILD (--runs N | --seconds S) NAME..." >&2; exit 2; }
[ "${1:-}" = --help ] && { sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0; }
[ $# -ge 4 ] || usage
build=$1 mode=$2 amount=$3; shift 3
case $mode in
    --runs) limit=(-runs="$amount") ;;
    --seconds) limit=(-max_total_time="$amount") ;;
    *) usage ;;
esac
[[ $amount =~ ^[0-9]+$ ]] || { echo "run_all.sh: $mode: expected a whole number, got '$amount'" >&2; exit 2; }
art=$build/fuzz/artifacts
mkdir -p "$art"
rc=0
for name in "$@"; do
    case $name in
        radiotap) bin=$build/feed/fuzz_radiotap ;;
        replay) bin=$build/firmware/fuzz_replay ;;
        *) bin=$build/fuzz/fuzz_$name ;;
    esac
    corpus=tests/fuzz/corpus/$name scratch=$build/fuzz/corpus-$name
    if [ ! -x "$bin" ] || [ ! -d "$corpus" ]; then
        echo "FAIL fuzz_$name: $bin or $corpus missing"; rc=1; continue
    fi
    mkdir -p "$scratch"
    log=$build/fuzz/fuzz_$name.log
    n=$(ls "$corpus" | wc -l)
    start=$(date +%s.%N)
    # -seed=1 makes make-test bursts repeatable; -rss_limit_mb bounds memory (2 cores, shared).
    "$bin" "${limit[@]}" -seed=1 -max_len=4096 -timeout=10 -rss_limit_mb=1024 -print_final_stats=1 \
        -artifact_prefix="$art/$name-" "$scratch" "$corpus" >"$log" 2>&1
    status=$?
    end=$(date +%s.%N)
    execs=$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+).*/\1/p' "$log" | tail -1)
    cov=$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -1)
    wall=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.0f", b - a }')
    rate=$(awk -v e="${execs:-0}" -v a="$start" -v b="$end" 'BEGIN { printf "%.0f", e / (b - a) }')
    if [ $status -eq 0 ]; then
        echo "PASS fuzz_$name: $n corpus inputs, ${execs:-?} executions, $wall s, $rate exec/s, ${cov:-cov: ?}"
    else
        finding=$(grep -m1 -oE 'ERROR: (AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|libFuzzer): [a-z-]+( [a-z-]+)*|runtime error: .*' "$log")
        echo "FAIL fuzz_$name: ${finding:-crash, leak or sanitizer report} after ${execs:-?} executions, $wall s (log $log, input in $art/)"
        grep -E 'ERROR|runtime error|SUMMARY|Test unit written' "$log" | head -10
        rc=1
    fi
done
exit $rc
