#!/usr/bin/env bash
# bench-feed: frames/s extracting one MAC's RSSI from a 1,000,000-frame capture written by
# our writer, rfseek-feed side by side with the tshark command of docs/FEEDER.md on the same file.
# Median of 3 runs each, output to files on the same disk (also compared: must be equal).
# usage: bench_feed.sh FEED WRITEGEN DIR [FRAMES]
set -euo pipefail
feed=$1 writegen=$2 dir=$3 frames=${4:-1000000}
mkdir -p "$dir"
cap=$dir/bench-$frames.pcap
if [ ! -f "$cap" ]; then "$writegen" "$cap" "$frames" > "$cap.macs"; fi
mac=$(head -1 "$cap.macs")
now() { date +%s.%N; }
median() { printf '%s\n' "$@" | sort -g | sed -n 2p; }
ours=() theirs=()
for i in 1 2 3; do
    t0=$(now); "$feed" "$cap" --mac "$mac" --format tsv > "$dir/ours.tsv"; t1=$(now)
    ours+=("$(echo "$t1 - $t0" | bc -l)")
done
for i in 1 2 3; do
    t0=$(now)
    tshark -r "$cap" -Y "wlan.sa == $mac" -T fields -e frame.time_epoch -e wlan.sa \
        -e radiotap.dbm_antsignal -E occurrence=f > "$dir/tshark.tsv" 2>/dev/null
    t1=$(now)
    theirs+=("$(echo "$t1 - $t0" | bc -l)")
done
cmp -s "$dir/ours.tsv" "$dir/tshark.tsv" || { echo "bench-feed: outputs differ from tshark's"; exit 1; }
mo=$(median "${ours[@]}") mt=$(median "${theirs[@]}")
lines=$(wc -l < "$dir/ours.tsv")
printf 'bench-feed: %d frames, %d lines for %s (outputs equal)\n' "$frames" "$lines" "$mac"
printf 'bench-feed: rfseek-feed %.3f s median (%s) = %.0f frames/s\n' "$mo" "${ours[*]}" "$(echo "$frames / $mo" | bc -l)"
printf 'bench-feed: tshark     %.3f s median (%s) = %.0f frames/s\n' "$mt" "${theirs[*]}" "$(echo "$frames / $mt" | bc -l)"
printf 'bench-feed: ratio %.1fx (target >= 20x)\n' "$(echo "$mt / $mo" | bc -l)"
