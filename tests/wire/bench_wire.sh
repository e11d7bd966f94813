#!/usr/bin/env bash
# Figures of the wire part (docs/PERFORMANCE.md, "## wire"):
#  1. instructions per frame of the CAN codec (encode + decode), host x86-64, callgrind,
#     exact (1000 calls per function, lazy binding off);
#  2. wall time of the default scenario in-process vs two processes (rfseek-sim-lcm +
#     rfseekd over udpm:// in a private network namespace), medians of 5, side by side.
# usage: tests/wire/bench_wire.sh BUILD
set -uo pipefail
build=${1:?usage: bench_wire.sh BUILD}
w=$build/bench/wire
mkdir -p "$w"
LD_BIND_NOW=1 valgrind --tool=callgrind --callgrind-out-file="$w/cg.out" --toggle-collect='bench_*' \
    "$build/tests/wire/bench_can" > /dev/null 2>&1 || { echo "bench_can failed"; exit 1; }
echo "CAN codec, instructions per message (encode with rfs_can_tx_* + decode with rfs_can_rx_frame):"
callgrind_annotate --inclusive=yes "$w/cg.out" 2>/dev/null | awk '
    /bench_can\.c:bench_/ {
        gsub(",", "", $1); n = $1; name = $0; sub(/.*bench_can\.c:bench_/, "", name); sub(/ .*/, "", name); sub(/\..*/, "", name);
        printf "  %-12s %8.1f\n", name, n / 1000 }' | sort
echo "  (pose = two frames; crc_* = one 8-byte frame checksum: table vs bit by bit)"

ns=rfswbench$$
ip netns add "$ns" || { echo "cannot create a network namespace"; exit 1; }
trap 'ip netns del "$ns" 2>/dev/null' EXIT
ip netns exec "$ns" ip link set lo up && ip netns exec "$ns" ip route add 224.0.0.0/4 dev lo
url='udpm://239.255.76.67:7667?ttl=0'
map=scenarios/maps/office.yaml
ns_now() { date +%s%N; }
inproc=() twoproc=()
for i in 1 2 3 4 5; do
    t0=$(ns_now)
    "$build/bin/rfseek-sim" scenarios/default.yaml --quiet > /dev/null 2>&1
    t1=$(ns_now)
    ip netns exec "$ns" "$build/bin/rfseekd" --map $map --lcm "$url" --can-over-lcm --clock-lcm --idle-exit 1500 \
        2> "$w/d.err" &
    dpid=$!
    sleep 0.3
    t2=$(ns_now)
    ip netns exec "$ns" "$build/bin/rfseek-sim-lcm" scenarios/default.yaml --lcm "$url" > "$w/summary.json" 2>/dev/null
    t3=$(ns_now)
    wait $dpid
    inproc+=($(( (t1 - t0) / 1000 ))) twoproc+=($(( (t3 - t2) / 1000 )))
done
steps=$(sed -n 's/^rfseekd: \([0-9]*\) steps.*/\1/p' "$w/d.err")
med() { printf '%s\n' "$@" | sort -n | sed -n 3p; }
mi=$(med "${inproc[@]}") mt=$(med "${twoproc[@]}")
echo "default scenario, wall time (median of 5, microseconds): in-process $mi, two processes $mt"
echo "  two-process / in-process: $(echo "scale=1; $mt / $mi" | bc)x; $steps lock-step control steps:" \
     "$(echo "scale=1; ($mt - $mi) / $steps" | bc) us extra per step (clock out, wheel frame + status back)"
grep -q '"reached": true' "$w/summary.json" && echo "  two-process run reached the source" || echo "  two-process run did NOT reach the source"
