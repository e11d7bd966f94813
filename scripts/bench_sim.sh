#!/usr/bin/env bash
# bench_sim.sh - simulator figures for docs/PERFORMANCE.md (make bench-sim).
#   scripts/bench_sim.sh build/bin/rfseek-sim
# 1. Real-time factor of one robot with one 200 pkt/s source, the core in-process, on one
#    core: the default scenario, seeds 1..20 run one after another in one process
#    (three repetitions; the median of the three overall factors is reported).
# 2. Wall time of a 200-seed batch of the default scenario on 2 cores (--jobs 2).
# 3. Real-time factors by CPU time of meta + ridge and meta-path + pathloss on the default
#    office and the Intel lab (seeds 1..5, one process each, median of three), with BASE
#    (another build's rfseek-sim) side by side, the two runs alternating:
#   scripts/bench_sim.sh build/bin/rfseek-sim [BASE]
# 4. With BENCH_SIM_ALL=1 instead: the same factors for every strategy x {ridge, pathloss}
#    on every shipped floor (FLOORS narrows them), one table row each, then stop
#    (BENCH_SIM_REPS=1: one run each instead of the median of three).
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
SIM=${1:?usage: bench_sim.sh path/to/rfseek-sim [BASE]}
BASE=${2:-}
echo "bench-sim: load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
# cpu-time factor of one run: SIM SCENARIO STRATEGY MODEL
rtf() { "$1" "scenarios/$2.yaml" --strategy "$3" --model "$4" --seeds 1..5 --bench |
        sed -nE 's/.*by cpu time: ([0-9]+)x.*/\1/p'; }
med3() { printf '%s\n' "$@" | sort -n | sed -n "$((($# + 1) / 2))p"; }
# The factors of SCENARIO STRATEGY MODEL, median of three, with BASE's alternating.
compare() {
    local new=() old=() line
    for rep in $(seq "${BENCH_SIM_REPS:-3}"); do
        new+=("$(rtf "$SIM" "$1" "$2" "$3")")
        if [ -n "$BASE" ]; then old+=("$(rtf "$BASE" "$1" "$2" "$3")"); fi
    done
    line="bench-sim: $1, $2 + $3, seeds 1..5, by cpu time: median ${new[*]} -> $(med3 "${new[@]}")x"
    if [ -n "$BASE" ]; then line="$line; base ${old[*]} -> $(med3 "${old[@]}")x"; fi
    echo "$line"
}
if [ -n "${BENCH_SIM_ALL:-}" ]; then
    for sc in ${FLOORS:-default intel willow 3ne gdc2 gdc4 house lshape open bookstore warehouse}; do
        for st in meta meta-global fd-gradient plane-gradient chemotaxis meta-path; do
            for model in ridge pathloss; do compare "$sc" "$st" "$model"; done
        done
    done
    echo "bench-sim: load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
    exit 0
fi
rtfs=() cpus=()
for rep in 1 2 3; do
    out=$("$SIM" scenarios/default.yaml --seeds 1..20 --bench)
    echo "$out" | sed "s/^/bench-sim: rep $rep: /"
    rtfs+=("$(echo "$out" | sed -nE 's/.*overall ([0-9]+)x.*/\1/p')")
    cpus+=("$(echo "$out" | sed -nE 's/.*by cpu time: ([0-9]+)x.*/\1/p')")
done
med=$(printf '%s\n' "${rtfs[@]}" | sort -n | sed -n 2p)
medc=$(printf '%s\n' "${cpus[@]}" | sort -n | sed -n 2p)
echo "bench-sim: real-time factor (default scenario, 1 robot, 1 x 200 pkt/s, 1 core): median ${med}x by wall time, ${medc}x by cpu time"
start=$(date +%s.%N)
"$SIM" scenarios/default.yaml --seeds 1..200 --jobs 2 --quiet >/dev/null
end=$(date +%s.%N)
echo "bench-sim: 200-seed batch of the default scenario on 2 cores: $(awk "BEGIN{printf \"%.1f\", $end - $start}") s wall"
echo "bench-sim: load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
for sc in default intel; do
    for sm in "meta ridge" "meta-path pathloss"; do
        set -- $sm
        compare "$sc" "$1" "$2"
    done
done
echo "bench-sim: load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
