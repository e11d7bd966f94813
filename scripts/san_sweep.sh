#!/usr/bin/env bash
# san_sweep.sh - run the ASan+UBSan build of rfseek-sim over seeds 1..N of each scenario and
# require zero sanitizer reports (make sweep, docs/RELIABILITY.md).
#   scripts/san_sweep.sh ASAN_SIM N SCENARIO...
# Every report (ASan, UBSan, LeakSanitizer) goes to its own file through log_path; a run
# that aborts on a report also ends its worker, which rfseek-sim reports. One PASS/FAIL
# line per scenario, with the seeds run, the seeds that reached the source and the time.
set -uo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
if [ $# -lt 3 ]; then
    echo "usage: san_sweep.sh ASAN_SIM N SCENARIO... (see --help)" >&2
    exit 2
fi
sim=$1 n=$2; shift 2
[[ $n =~ ^[1-9][0-9]*$ ]] || { echo "san_sweep.sh: N: expected a positive whole number, got '$n'" >&2; exit 2; }
[ -x "$sim" ] || { echo "san_sweep.sh: $sim: not an executable" >&2; exit 2; }
work=$(mktemp -d /tmp/rfs_sweep.XXXXXX)
trap 'rm -rf -- "$work"' EXIT
rc=0
for scn in "$@"; do
    name=$(basename "$scn" .yaml)
    mkdir -p "$work/$name/logs"
    start=$(date +%s.%N)
    ASAN_OPTIONS="log_path=$work/$name/logs/asan:detect_leaks=1:abort_on_error=0" \
    UBSAN_OPTIONS="log_path=$work/$name/logs/ubsan:print_stacktrace=1" \
        "$sim" "$scn" --seeds "1..$n" --jobs 2 --quiet --out "$work/$name/out" >"$work/$name/stdout" 2>"$work/$name/stderr"
    status=$?
    secs=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.0f", b - a }')
    reports=$(find "$work/$name/logs" -type f | wc -l)
    table=$work/$name/out/runs.tsv
    rows=0 reached=0
    if [ -f "$table" ]; then
        rows=$(($(wc -l <"$table") - 1))
        col=$(head -1 "$table" | tr '\t' '\n' | grep -nx reached | cut -d: -f1)
        if [ -n "$col" ]; then
            reached=$(awk -F'\t' -v c="$col" 'NR > 1 && ($c == 1 || $c == "true" || $c == "yes") { k++ } END { print k + 0 }' "$table")
        fi
    fi
    if [ $status -eq 0 ] && [ "$reports" -eq 0 ] && [ "$rows" -eq "$n" ]; then
        echo "PASS san_sweep $name: $n seeds under ASan+UBSan, 0 reports, $reached reached, ${secs} s"
    else
        echo "FAIL san_sweep $name: exit $status, $reports sanitizer reports, $rows of $n seeds in the table"
        for f in $(find "$work/$name/logs" -type f | head -3); do grep -E 'ERROR|runtime error|SUMMARY' "$f" | head -3; done
        head -3 "$work/$name/stderr"
        rc=1
    fi
done
exit $rc
