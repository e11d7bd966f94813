#!/usr/bin/env bash
# Cross-check rfseek-feed against tshark, line for line.
# usage: cross_check.sh FEED_BIN CAPTURE...
# For each CAPTURE: the transmitters are CAPTURE.macs when it exists (generated files),
# otherwise every wlan.sa tshark finds. Compared: one run with all of them (our repeated
# --mac against tshark's `wlan.sa == A || wlan.sa == B ...`) and one run per address
# (the exact command of the issue; for generated files the first two addresses, to keep
# make test short). Only frames with a signal are lines.
set -uo pipefail
feed=$1; shift
fail=0
tshark_lines() { # FILE FILTER
    tshark -r "$1" -Y "$2" -T fields -e frame.time_epoch -e wlan.sa -e radiotap.dbm_antsignal \
        -E occurrence=f 2>/dev/null | awk -F'\t' '$3 != ""'
}
for f in "$@"; do
    name=$(basename "$f")
    if [ -f "$f.macs" ]; then
        mapfile -t macs < "$f.macs"
    else
        mapfile -t macs < <(tshark -r "$f" -T fields -e wlan.sa -E occurrence=f 2>/dev/null | grep . | sort -u)
    fi
    if [ ${#macs[@]} -eq 0 ]; then echo "FAIL $name: no transmitter addresses to check"; fail=1; continue; fi
    filter="" args=()
    for m in "${macs[@]}"; do
        filter+="${filter:+ || }wlan.sa == $m"; args+=(--mac "$m")
    done
    want=$(tshark_lines "$f" "$filter")
    got=$("$feed" "$f" "${args[@]}" --format tsv)
    rc=$?
    nwant=$(printf '%s' "$want" | grep -c .)
    if [ $rc -ne 0 ]; then
        echo "FAIL $name: rfseek-feed exit $rc"; fail=1
    elif [ "$nwant" -eq 0 ]; then
        echo "FAIL $name: tshark finds no frame with a signal: nothing compared"; fail=1
    elif [ "$got" == "$want" ]; then
        echo "PASS $name: ${#macs[@]} addresses together, $nwant lines equal tshark's"
    else
        echo "FAIL $name: ${#macs[@]} addresses together differ from tshark (< ours, > tshark):"
        diff <(printf '%s\n' "$got") <(printf '%s\n' "$want") | head -10; fail=1
    fi
    singles=("${macs[@]}")
    if [ -f "$f.macs" ]; then singles=("${macs[@]:0:2}"); fi
    for m in "${singles[@]}"; do
        want=$(tshark_lines "$f" "wlan.sa == $m")
        got=$("$feed" "$f" --mac "$m" --format tsv)
        if [ "$got" == "$want" ]; then
            echo "PASS $name $m: $(printf '%s' "$want" | grep -c .) lines equal tshark's"
        else
            echo "FAIL $name $m differs from tshark (< ours, > tshark):"
            diff <(printf '%s\n' "$got") <(printf '%s\n' "$want") | head -10; fail=1
        fi
    done
done
exit $fail
