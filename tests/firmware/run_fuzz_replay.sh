#!/usr/bin/env bash
# run_fuzz_replay.sh FUZZER SCRATCH CORPUS RUNS - the libFuzzer target over the recorded
# stream parser and player, over its corpus plus RUNS new inputs. New inputs go to SCRATCH
# (a build directory), never into the committed corpus.
set -uo pipefail
fuzzer=$1 scratch=$2 corpus=$3 runs=$4
mkdir -p "$scratch"
log=$(mktemp); trap 'rm -f "$log"' EXIT
n=$(ls "$corpus" | wc -l)
if "$fuzzer" -artifact_prefix="$scratch/" -runs="$runs" -seed=1 -max_len=4096 -timeout=10 "$scratch" "$corpus" >"$log" 2>&1; then
    echo "PASS fuzz_replay: $n corpus inputs + $runs runs, $(grep -oE 'cov: [0-9]+' "$log" | tail -1)"
else
    echo "FAIL fuzz_replay: crash or sanitizer report"; grep -E 'ERROR|runtime error|SUMMARY' "$log" | head -10
    exit 1
fi
