#!/usr/bin/env bash
# bench-feed: frames/s extracting one MAC's RSSI from a 1,000,000-frame capture written by
# our writer, rfseek-feed side by side with the tshark command of docs/FEEDER.md (median of
# 3; the outputs must be equal) and with COUNT, a loop that only reads and counts the
# records (feed_count.c; 11 runs each, alternating with rfseek-feed, medians of wall time
# and of CPU time, user + system: the ratio by CPU time holds under load).
# usage: bench_feed.sh FEED WRITEGEN DIR COUNT [FRAMES]
set -euo pipefail
feed=$1 writegen=$2 dir=$3 count=$4 frames=${5:-1000000}
mkdir -p "$dir"
cap=$dir/bench-$frames.pcap
if [ ! -f "$cap" ]; then "$writegen" "$cap" "$frames" > "$cap.macs"; fi
mac=$(head -1 "$cap.macs")
now() { date +%s.%N; }
median() { printf '%s\n' "$@" | sort -g | sed -n "$(( ($# + 1) / 2 ))p"; }
echo "bench-feed: load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
ours=() floor=() theirs=() ours_cpu=() floor_cpu=()
TIMEFORMAT='%3R %3U %3S'
# "wall cpu" of one run of "$@" (its stdout into $out)
timed() { local t; t=$( { time "$@" > "$out"; } 2>&1 ); awk '{printf "%s %.3f", $1, $2 + $3}' <<< "$t"; }
for i in 1 2 3 4 5 6 7 8 9 10 11; do
    out=$dir/ours.tsv; read -r w c <<< "$(timed "$feed" "$cap" --mac "$mac" --format tsv)"
    ours+=("$w") ours_cpu+=("$c")
    out=$dir/count.txt; read -r w c <<< "$(timed "$count" "$cap")"
    floor+=("$w") floor_cpu+=("$c")
    [ "$(cat "$out")" = "$frames" ] || { echo "bench-feed: $count read $(cat "$out") records, not $frames"; exit 1; }
done
for i in 1 2 3; do
    t0=$(now)
    tshark -r "$cap" -Y "wlan.sa == $mac" -T fields -e frame.time_epoch -e wlan.sa \
        -e radiotap.dbm_antsignal -E occurrence=f > "$dir/tshark.tsv" 2>/dev/null
    t1=$(now)
    theirs+=("$(echo "$t1 - $t0" | bc -l)")
done
cmp -s "$dir/ours.tsv" "$dir/tshark.tsv" || { echo "bench-feed: outputs differ from tshark's"; exit 1; }
mo=$(median "${ours[@]}") mc=$(median "${floor[@]}") mt=$(median "${theirs[@]}")
co=$(median "${ours_cpu[@]}") cc=$(median "${floor_cpu[@]}")
lines=$(wc -l < "$dir/ours.tsv")
printf 'bench-feed: %d frames, %d lines for %s (outputs equal)\n' "$frames" "$lines" "$mac"
printf 'bench-feed: rfseek-feed %.3f s wall, %.3f s cpu, medians of 11 = %.0f frames/s\n' "$mo" "$co" "$(echo "$frames / $mo" | bc -l)"
printf 'bench-feed: count only  %.3f s wall, %.3f s cpu, medians of 11 = %.0f frames/s\n' "$mc" "$cc" "$(echo "$frames / $mc" | bc -l)"
printf 'bench-feed: tshark      %.3f s median (%s) = %.0f frames/s\n' "$mt" "${theirs[*]}" "$(echo "$frames / $mt" | bc -l)"
printf 'bench-feed: %.1fx tshark (target >= 20x)\n' "$(echo "$mt / $mo" | bc -l)"
printf 'bench-feed: %.2fx the count-only loop by wall time, %.2fx by cpu time (target <= 1.5x)\n' \
    "$(echo "$mo / $mc" | bc -l)" "$(echo "$co / $cc" | bc -l)"
echo "bench-feed: load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
