#!/usr/bin/env bash
# run_tests.sh - run the test jobs of JOBFILE (written by `make test` / `make check`: one
# line per job, tab-separated NAME, KIND (bin: a CMocka program; script: a command that
# prints PASS/FAIL lines), SERIAL ("serial": run alone, after the others) and COMMAND).
# Jobs run TEST_JOBS at a time (default: nproc), longest first by the last run's times;
# each job's output goes to BUILD/test-logs/NAME.log. A job with no passed and no failed
# check fails (unless it printed a "SKIP " line). Prints one PASS/FAIL line per job in
# the file's order, then the closing "tests: N passed, N failed" line, last. Exits
# non-zero when anything failed.
#   scripts/run_tests.sh JOBFILE [--only NAME]    (--only: that job alone, its log shown)
set -uo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
jobfile=${1:?usage: run_tests.sh JOBFILE [--only NAME]}
only=
[ "${2:-}" = --only ] && only=${3:?--only needs a NAME}
logdir=${BUILD:-build}/test-logs
mkdir -p "$logdir"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
par=${TEST_JOBS:-$(nproc)}

names=() kinds=() serial=() cmds=()
while IFS=$'\t' read -r n k s c; do
    n=${n#"${n%%[![:space:]]*}"}
    [ -n "$n" ] || continue
    [ -z "$only" ] || [ "$n" = "$only" ] || continue
    names+=("$n"); kinds+=("$k"); serial+=("$s"); cmds+=("$c")
done < "$jobfile"
[ ${#names[@]} -gt 0 ] || { echo "run_tests.sh: no test named '$only'" >&2; exit 2; }

slug() { echo "$1" | tr '/ ' '__'; }

# Run job $1: its output to NAME.log, "rc ok bad seconds" to NAME.res.
run_job() {
    local i=$1 s log start rc ok bad
    s=$(slug "${names[$i]}")
    log=$logdir/$s.log
    start=$(date +%s.%N)
    if [ "${kinds[$i]}" = bin ]; then
        ${cmds[$i]} >"$log" 2>&1
        rc=$?
        ok=$(grep -c '^\[       OK \]' "$log")
        bad=$(grep -E '^\[  (FAILED|ERROR)   \] [A-Za-z_]' "$log" | grep -v 'test(s)' | sort -u | wc -l)
        # A case filter (RFS_TEST_CASE, make check CASE=) that matches nothing is a mistake.
        if [ -n "${RFS_TEST_CASE:-}" ] && [ "$ok" -eq 0 ] && [ "$bad" -eq 0 ]; then
            echo "FAIL no case of ${names[$i]} matches RFS_TEST_CASE='$RFS_TEST_CASE'" >>"$log"; bad=1
        fi
    else
        bash -c "${cmds[$i]}" >"$log" 2>&1
        rc=$?
        ok=$(grep -c '^PASS ' "$log")
        bad=$(grep -c '^FAIL ' "$log")
    fi
    # A job that reports no check passed and none failed tested nothing (an empty glob, a
    # loop that never ran): a failure, unless it says why it skipped (a "SKIP " line).
    if [ "$ok" -eq 0 ] && [ "$bad" -eq 0 ] && ! grep -q '^SKIP ' "$log"; then
        echo "FAIL ${names[$i]}: no PASS or FAIL line (nothing was checked)" >>"$log"; bad=1
    fi
    if [ $rc -ne 0 ] && [ "$bad" -eq 0 ]; then bad=1; fi
    echo "$rc $ok $bad $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {printf "%.1f", b - a}')" >"$logdir/$s.res"
}

# Longest first (the last run's seconds), so the long jobs do not finish the run alone.
times=$logdir/times.tsv
par_idx=() ser_idx=()
for i in "${!names[@]}"; do
    rm -f "$logdir/$(slug "${names[$i]}").res"
    if [ "${serial[$i]}" = serial ]; then ser_idx+=("$i"); else par_idx+=("$i"); fi
done
if [ -s "$times" ] && [ ${#par_idx[@]} -gt 1 ]; then
    mapfile -t par_idx < <(for i in "${par_idx[@]}"; do
        t=$(awk -F'\t' -v n="${names[$i]}" '$1 == n {t = $2} END {print t + 0}' "$times")
        echo "$t $i"; done | sort -k1,1nr -k2,2n | awk '{print $2}')
fi

for i in "${par_idx[@]}"; do
    while [ "$(jobs -rp | wc -l)" -ge "$par" ]; do wait -n; done
    run_job "$i" &
done
wait
for i in "${ser_idx[@]}"; do run_job "$i"; done

passed=0 failed=0
# A private temporary file: a `make check` beside a `make test` rewrites times.tsv too.
new_times=$(mktemp "$times.XXXXXX")
for i in "${!names[@]}"; do
    n=${names[$i]} s=$(slug "${names[$i]}")
    read -r rc ok bad secs <"$logdir/$s.res" || { rc=1 ok=0 bad=1 secs=0; }
    printf '%s\t%s\n' "$n" "$secs" >>"$new_times"
    passed=$((passed + ok)); failed=$((failed + bad))
    unit=checks; [ "${kinds[$i]}" = bin ] && unit=tests
    if [ "$rc" -eq 0 ] && [ "$bad" -eq 0 ]; then
        echo "PASS $n ($ok $unit, ${secs} s)"
    else
        echo "FAIL $n (exit $rc; log $logdir/$s.log)"
        if [ "${kinds[$i]}" = bin ]; then
            grep -E '^FAIL |FAILED|ERROR|error|Sanitizer|runtime error' "$logdir/$s.log" | head -20
        else
            grep -E '^FAIL|rror' "$logdir/$s.log" | head -20
        fi
    fi
done
[ -n "$only" ] && { echo "--- $logdir/$(slug "$only").log"; cat "$logdir/$(slug "$only").log"; echo "---"; }
# Keep the times of jobs this run did not include (make check runs one).
[ -s "$times" ] && awk -F'\t' 'NR == FNR {seen[$1] = 1; next} !($1 in seen)' "$new_times" "$times" >>"$new_times"
mv "$new_times" "$times"
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
