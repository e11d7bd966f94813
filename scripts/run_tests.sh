#!/usr/bin/env bash
# Run CMocka binaries (before --) and test scripts (after --); print each result and a
# closing "N passed, N failed" line. Exit non-zero when anything failed.
set -uo pipefail
bins=() scripts=()
seen_sep=0
for a in "$@"; do
    if [ "$a" = "--" ]; then seen_sep=1; continue; fi
    if [ $seen_sep -eq 0 ]; then bins+=("$a"); else scripts+=("$a"); fi
done
passed=0 failed=0
logdir=${BUILD:-build}/test-logs
mkdir -p "$logdir"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
for b in "${bins[@]}"; do
    log="$logdir/$(echo "$b" | tr '/' '_').log"
    "$b" >"$log" 2>&1
    rc=$?
    ok=$(grep -c '^\[       OK \]' "$log")
    bad=$(grep -E '^\[  (FAILED|ERROR)   \] [A-Za-z_]' "$log" | grep -v 'test(s)' | sort -u | wc -l)
    if [ $rc -ne 0 ] && [ "$bad" -eq 0 ]; then bad=1; fi
    passed=$((passed + ok)); failed=$((failed + bad))
    if [ $rc -eq 0 ]; then echo "PASS $b ($ok tests)"; else echo "FAIL $b (exit $rc; log $log)"; sed -n '1,200p' "$log" | grep -E 'FAILED|ERROR|error|Sanitizer|runtime error' | head -20; fi
done
for s in "${scripts[@]}"; do
    log="$logdir/$(echo "$s" | tr '/ ' '__').log"
    bash -c "$s" >"$log" 2>&1
    rc=$?
    ok=$(grep -c '^PASS ' "$log")
    bad=$(grep -c '^FAIL ' "$log")
    if [ $rc -ne 0 ] && [ "$bad" -eq 0 ]; then bad=1; fi
    passed=$((passed + ok)); failed=$((failed + bad))
    if [ $rc -eq 0 ] && [ "$bad" -eq 0 ]; then echo "PASS $s ($ok checks)"; else echo "FAIL $s (exit $rc; log $log)"; grep -E '^FAIL|rror' "$log" | head -20; fi
done
echo "tests: $passed passed, $failed failed"
[ $failed -eq 0 ]
