#!/usr/bin/env bash
# path_opts.sh - a path-valued option given an option for its value (`rfseek-record -o --seed
# ...` wrote a file named "--seed"): every program refuses it in one line naming the
# option (lx_err_path_opt), exits non-zero and writes nothing; "./-x" still names a file.
#   tests/linux/path_opts.sh BUILD        (from the repository root)
set -uo pipefail
build=$(cd "${1:?usage: path_opts.sh BUILD}" && pwd)
root=$PWD
w=$(mktemp -d /tmp/rfs_path_opts.XXXXXX)
trap 'rm -rf -- "$w"' EXIT
. "$(dirname "$0")/../lib/checks.sh"
scn=$root/scenarios/default.yaml map=$root/scenarios/maps/office.yaml
# refused NAME OPT VALUE PROGRAM ARGS...: run in an empty folder; one stderr line
# "PROGRAM: OPT: 'VALUE' is an option, not a file name ...", exit status not 0, no file.
refused() {
    local name=$1 opt=$2 val=$3 prog=$4; shift 4
    rm -rf "$w/run" && mkdir "$w/run"
    (cd "$w/run" && "$build/bin/$prog" "$@" > "$w/out" 2> "$w/err"); local rc=$?
    if [ $rc -ne 0 ] && [ "$(wc -l < "$w/err")" -eq 1 ] \
        && grep -qxF -- "$prog: $opt: '$val' is an option, not a file name (./$val for a file)" "$w/err" \
        && [ -z "$(ls -A "$w/run")" ]; then
        pass "$name"
    else
        fail "$name" "rc $rc, stderr: $(head -2 "$w/err" | tr '\n' '|'), files: $(ls -A "$w/run" | tr '\n' ' ')"
    fi
}
refused record-out -o/--out --seed rfseek-record -o --seed "$scn"
refused record-out-long -o/--out --seed rfseek-record --out --seed 3 "$scn"
refused record-out-equals -o/--out --max-time rfseek-record "--out=--max-time" "$scn"
refused record-live-out --live-out -x rfseek-record -o a.rfsr --live-out -x "$scn"
refused record-candump --candump --seed rfseek-record -o a.rfsr --candump --seed 1 "$scn"
refused sim-out --out --seed rfseek-sim "$scn" --out --seed 1
refused sim-pcap --pcap --quiet rfseek-sim "$scn" --pcap --quiet
refused sim-lcm-log --log --seed rfseek-sim-lcm "$scn" --lcm memq:// --log --seed 1
refused rfseekd-map --map --lcm rfseekd --map --lcm memq://
for o in --replay --log --decisions --candump; do
    refused "rfseekd-${o#--}" "$o" --seed rfseekd --map "$map" "$o" --seed 1
done
for o in --output --pose --scenario --out; do
    refused "feed-${o#--}" "$o" --stats rfseek-feed x.pcap --mac aa:bb:cc:dd:ee:ff "$o" --stats
done
refused replay-out -o --print rfseek-replay in.rfsr -o --print
refused replay-map --map -o rfseek-replay in.rfsr --map -o a.rfso
for o in --pgm --png --crop; do
    refused "map-${o#--}" "$o" --mcu rfseek-map "$map" "$o" --mcu
done
# A file whose name begins with '-' is still written when named ./-x.
rm -rf "$w/run" && mkdir "$w/run"
(cd "$w/run" && "$build/bin/rfseek-record" -o ./--x.rfsr --max-time 1 "$scn" > "$w/out" 2> "$w/err"); rc=$?
[ $rc -eq 0 ] && [ -s "$w/run/--x.rfsr" ] && pass record-dot-slash-dash-file \
    || fail record-dot-slash-dash-file "rc $rc: $(head -2 "$w/err")"
exit $((fails > 0))
