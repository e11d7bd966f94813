#!/usr/bin/env bash
# tests/host_sim/test_rfseek_map.sh BIN - rfseek-map on a real map and on bad input.
# Reference values: the cell counts of scenarios/maps/README.md's source (intel: 29 942
# occupied, 192 948 free, 113 509 unknown) and the PGM header written for 579 x 581.
set -u
bin=${1:?usage: test_rfseek_map.sh path/to/rfseek-map}
maps=${RFS_MAPS_DIR:-scenarios/maps}
bad=tests/data/maps_bad
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/../lib/checks.sh"

"$bin" --help | grep -q '^usage: rfseek-map'; check_rc help $?

out=$("$bin" "$maps/intel.yaml" --res 0.1 --pgm "$tmp/intel.pgm")
rc=$?
check_rc intel-exit $rc
echo "$out" | grep -q 'image cells  free 192948, occupied 29942, unknown 113509'; check_rc intel-counts $?
echo "$out" | grep -q 'core cells   free 192948, wall 29942,'; check_rc intel-core-counts $?
echo "$out" | grep -q "core bytes   $((581 * ((579 + 7) / 8))) per bit grid"; check_rc intel-bytes $?
head -c 100 "$tmp/intel.pgm" | grep -aq '^579 581$'; check_rc intel-pgm-header $?
[ ! -e "$tmp/intel.pgm.tmp" ]; check_rc intel-pgm-no-temp $?
size=$(stat -c %s "$tmp/intel.pgm"); hdr=$(head -c 100 "$tmp/intel.pgm" | grep -ac '')
[ $((size - 579 * 581)) -gt 0 ] && [ $((size - 579 * 581)) -lt 120 ]; check_rc intel-pgm-size $?

# Bad input: one line naming the file, exit 1; bad options exit 2.
err=$("$bin" "$bad/res_zero.yaml" 2>&1 >/dev/null); rc=$?
[ $rc = 1 ] && [ "$(echo "$err" | wc -l)" = 1 ] && echo "$err" | grep -q "res_zero.yaml: resolution: must be > 0"; check_rc bad-res $?
err=$("$bin" "$bad/image_truncated.yaml" 2>&1 >/dev/null); rc=$?
[ $rc = 1 ] && [ "$(echo "$err" | wc -l)" = 1 ] && echo "$err" | grep -q "truncated.pgm: truncated"; check_rc bad-pgm $?
err=$("$bin" "$bad/ok.yaml" --res abc 2>&1 >/dev/null); rc=$?
[ $rc = 2 ] && echo "$err" | grep -q -- "--res: a non-negative number"; check_rc bad-option $?
err=$("$bin" 2>&1 >/dev/null); rc=$?
[ $rc = 2 ]; check_rc no-map $?
"$bin" "$bad/thresh_order.yaml" --pgm "$tmp/no.pgm" >/dev/null 2>&1
[ ! -e "$tmp/no.pgm" ] && [ ! -e "$tmp/no.pgm.tmp" ]; check_rc bad-no-output $?

# A line break in an option, an option name or a file name still gives one error line
# (shown as '?'), and no output is written.
# one_err NAME RC TEXT ARGS...: exit RC, exactly one stderr line holding TEXT, no tmp/nl*.
one_err() {
    local name=$1 want=$2 text=$3
    shift 3
    "$bin" "$@" >/dev/null 2>"$tmp/err"
    local rc=$?
    if [ $rc != "$want" ]; then fail "$name" "exit $rc"
    elif [ "$(wc -l <"$tmp/err")" != 1 ]; then fail "$name" "$(wc -l <"$tmp/err") stderr lines: $(head -c 200 "$tmp/err")"
    elif ! grep -qF -- "$text" "$tmp/err"; then fail "$name" "stderr '$(cat "$tmp/err")' lacks '$text'"
    elif compgen -G "$tmp/nl*" >/dev/null; then fail "$name" "left $(ls "$tmp"/nl*)"
    else pass "$name"; fi
    rm -rf "$tmp"/nl*
}
one_err newline-res 2 "--res: a non-negative number of metres expected, got '1?2'" \
    "$bad/ok.yaml" --res $'1\n2' --pgm "$tmp/nl.pgm"
one_err res-zero-names-it 2 "rfseek-map: --res: must be > 0 metres" "$bad/ok.yaml" --res 0 --pgm "$tmp/nl.pgm"
one_err grid-zero-names-it 2 "rfseek-map: --grid: must be > 0 metres" "$bad/ok.yaml" --grid 0 --pgm "$tmp/nl.pgm"
one_err newline-bench 2 "--bench: a count 1..1000000 expected, got '5?6'" \
    "$bad/ok.yaml" --bench $'5\n6' --pgm "$tmp/nl.pgm"
one_err newline-option 2 "--x?y: unknown option" "$bad/ok.yaml" $'--x\ny' --pgm "$tmp/nl.pgm"
one_err newline-second-map 2 "a?b: only one map expected" "$bad/ok.yaml" $'a\nb' --pgm "$tmp/nl.pgm"
one_err newline-map-name 1 "nl?map.yaml" "$tmp/"$'nl\nmap.yaml' --pgm "$tmp/nl.pgm"
# A resolution outside 1 mm .. 10 m: one line at once (1e-10 hung in the resampling).
one_err res-tiny 1 "res_tiny.yaml: resolution: 1e-10 m out of range (0.001 .. 10 m per pixel)" \
    "$bad/res_tiny.yaml" --pgm "$tmp/nl.pgm"
# Options that would wrap in Q16.16 (65536.25 m reads as 0.25 m) are refused by range.
one_err clearance-range 2 "--clearance: 65536.25 m out of range (0 .. 64 m)" \
    "$bad/ok.yaml" --clearance 65536.25 --pgm "$tmp/nl.pgm"
one_err grid-range 2 "--grid: 65536.25 m out of range (0 .. 1000 m)" \
    "$bad/ok.yaml" --grid 65536.25 --pgm "$tmp/nl.pgm"
one_err res-range 2 "--res: 1e300 m out of range (0 .. 1000 m)" \
    "$bad/ok.yaml" --res 1e300 --pgm "$tmp/nl.pgm"
one_err newline-pgm 1 "nl/a?b.pgm: No such file or directory" "$bad/ok.yaml" --pgm "$tmp/nl/a"$'\n'"b.pgm"
[ $fails = 0 ]
