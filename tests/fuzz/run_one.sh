#!/usr/bin/env bash
# Run one libFuzzer target over its corpus plus a short burst of new inputs. New inputs and
# crash artifacts go to SCRATCH (a build directory), never into the committed corpus.
# usage: run_one.sh FUZZER SCRATCH CORPUS RUNS   (the target is named after FUZZER's file)
set -uo pipefail
[ $# -eq 4 ] || { echo "usage: run_one.sh FUZZER SCRATCH CORPUS RUNS" >&2; exit 2; }
fuzzer=$1 scratch=$2 corpus=$3 runs=$4
name=$(basename "$fuzzer")
mkdir -p "$scratch"
log=$(mktemp); trap 'rm -f "$log"' EXIT
n=$(ls "$corpus" | wc -l)
if "$fuzzer" -artifact_prefix="$scratch/" -runs="$runs" -seed=1 -max_len=4096 -timeout=10 "$scratch" "$corpus" >"$log" 2>&1; then
    echo "PASS $name: $n corpus inputs + $runs runs, $(grep -oE 'cov: [0-9]+' "$log" | tail -1)"
else
    echo "FAIL $name: crash or sanitizer report"; grep -E 'ERROR|runtime error|SUMMARY' "$log" | head -10
    exit 1
fi
