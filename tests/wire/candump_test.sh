#!/usr/bin/env bash
# candump_test.sh BUILD - CAN logs in the can-utils format (docs/CAN.md, "CAN logs"):
# a simulated mission's bus (rfseek-record --candump) and rfseekd's frames (--candump)
# are accepted by log2asc and decode frame by frame with canmatrix from can/rfseek.dbc
# (scripts/check_candump.py: checksums, ranges, enums, counters, cycle times, ECUs, value
# tables); the log and the .rfsr of one recording replay to the same output; lines written
# by asc2log (can-utils' own writer) read as ours; a bad line is one error line with its
# number, exit 1 and no output.
set -uo pipefail
B=${1:?usage: candump_test.sh BUILD}
bin=$B/bin map=scenarios/maps/office.yaml dbc=can/rfseek.dbc
w=$(mktemp -d /tmp/rfs_candump.XXXXXX)
trap 'rm -rf -- "$w"' EXIT
. "$(dirname "$0")/../lib/checks.sh"
py() { /usr/bin/python3 scripts/check_candump.py "$@"; }
shift_us=4294967296 # a log from a clock that starts at 0 is shifted by 2^32 us (lx_candump.h)

# --- a recorded mission: log2asc and canmatrix -----------------------------------------------
"$bin/rfseek-record" scenarios/default.yaml -o "$w/m.rfsr" --live-out "$w/m.live" --candump "$w/m.log" \
    --max-time 60 --seed 3 >/dev/null || fail record-candump
log2asc -I "$w/m.log" can0 >"$w/m.asc"; check_rc log2asc-accepts-mission $?
py $dbc "$w/m.log" --sim --asc "$w/m.asc" || fail "candump-decode-mission"
# The checker can fail: a flipped data nibble, and the DBC with space-separated receivers.
sed '100s/#\(...\)./#\1F/' "$w/m.log" >"$w/bad.log"
py $dbc "$w/bad.log" >/dev/null && fail candump-negative-byte || pass candump-negative-byte
sed 's/MOTOR,LOC,RADIO/MOTOR LOC RADIO/' $dbc >"$w/spaces.dbc"
py "$w/spaces.dbc" "$w/m.log" >"$w/spaces.out"
grep -q "^FAIL dbc-ecus" "$w/spaces.out" && pass dbc-negative-receivers || fail dbc-negative-receivers

# --- the log and the stream replay to the same output ----------------------------------------
"$bin/rfseek-replay" "$w/m.rfsr" -o "$w/s.rfso" && cmp -s "$w/s.rfso" "$w/m.live" || fail replay-stream
"$bin/rfseek-replay" "$w/m.log" --map $map --seed 3 -o "$w/l.rfso"; check_rc replay-candump $?
unshift() { awk -F'\t' -v s=$shift_us 'BEGIN {OFS = "\t"} $1 != "END" {$2 = $2 - s} {print}'; }
"$bin/rfseek-replay" --print "$w/s.rfso" >"$w/s.txt"
"$bin/rfseek-replay" --print "$w/l.rfso" | unshift >"$w/l.txt"
n_dec=$(grep -c '^DECISION' "$w/s.txt")
if [ "$n_dec" -ge 3 ] && cmp -s "$w/s.txt" "$w/l.txt"; then
    pass "replay-log-equals-stream ($(wc -l <"$w/s.txt") output records, $n_dec decisions, times 2^32 us apart)"
else
    fail replay-log-equals-stream "$n_dec decisions; $(diff "$w/s.txt" "$w/l.txt" | head -3 | tr '\n' '|')"
fi
"$bin/rfseek-replay" --print "$w/m.rfsr" | grep -E '^(CAN|STEP|END)' >"$w/si.txt"
"$bin/rfseek-replay" --print "$w/m.log" | unshift >"$w/li.txt"
check replay-log-inputs-equal-stream 'cmp -s "$w/si.txt" "$w/li.txt"'
# The controller's frames in the log are the replay's CAN_TX records.
awk -F'\t' '$1 == "CAN_TX" {print $2, $3, $5}' "$w/s.txt" | sed 's/id=//; s/data=//' >"$w/tx_out.txt"
sed -n 's/^(\([0-9]*\)\.\([0-9]*\)) can0 \(100\|180\)#\(.*\)/\1 \2 \3 \4/p' "$w/m.log" \
    | awk -v s=$shift_us '{print $1 * 1000000 + $2 - s, $3, $4}' >"$w/tx_log.txt"
check candump-tx-equals-can-tx '[ -s "$w/tx_log.txt" ] && cmp -s "$w/tx_out.txt" "$w/tx_log.txt"'

# A robot's log of the STM32 configuration (meta-path + pathloss chosen by a CONFIG frame,
# fit budget 600, fit_early on): the log with `--fit-early on` replays to the stream's
# output; with it off the decisions part.
"$bin/rfseek-record" scenarios/default.yaml -o "$w/fe.rfsr" --candump "$w/fe.log" --seed 3 --max-time 60 \
    --model pathloss --strategy meta-path --p0-min -40 --fit-budget 600 --fit-early on --config-frame >/dev/null \
    && "$bin/rfseek-replay" "$w/fe.rfsr" -o "$w/fe_s.rfso" || fail record-fit-early
for fe in on off; do
    "$bin/rfseek-replay" "$w/fe.log" --map $map --seed 3 --fit-budget 600 --fit-early $fe -o "$w/fe_$fe.rfso" \
        || fail "replay-candump-fit-early-$fe"
    "$bin/rfseek-replay" --print "$w/fe_$fe.rfso" | unshift >"$w/fe_$fe.txt"
done
"$bin/rfseek-replay" --print "$w/fe_s.rfso" >"$w/fe_s.txt"
check replay-log-fit-early-equals-stream '[ "$(grep -c ^DECISION "$w/fe_s.txt")" -ge 3 ] && cmp -s "$w/fe_s.txt" "$w/fe_on.txt" && ! cmp -s "$w/fe_s.txt" "$w/fe_off.txt"'
# The CONFIG frame's FitEarly (bits 6..7, docs/CAN.md; re-sealed with scripts/check_dbc.py's
# CRC) outranks the replay's own setting: 2 (on) plays as --fit-early on, 1 (off) as off.
fe_config() { # LOG_IN FIT_EARLY LOG_OUT: the log with its CONFIG frame's FitEarly set
    /usr/bin/python3 -c 'import re, sys; sys.path.insert(0, "scripts"); from check_dbc import crc8_j1850
def fix(m):
    d = bytearray.fromhex(m.group(2)); d[0] = (d[0] & 0x3F) | (int(sys.argv[2]) << 6)
    d[7] = crc8_j1850(bytes([0x30, 0x01]) + bytes(d[:7])); return m.group(1) + d.hex().upper()
out = [re.sub(r"^(.* 130#)([0-9A-F]{16})$", fix, l) for l in open(sys.argv[1]).read().splitlines()]
open(sys.argv[3], "w").write("\n".join(out) + "\n")' "$@"
}
fe_config "$w/fe.log" 2 "$w/fe_c2.log" && fe_config "$w/fe.log" 1 "$w/fe_c1.log" || fail fe-config-log
grep -q ' can0 130#8' "$w/fe_c2.log" && grep -q ' can0 130#4' "$w/fe_c1.log" || fail fe-config-log-rewritten
for c in 1 2; do
    "$bin/rfseek-replay" "$w/fe_c$c.log" --map $map --seed 3 --fit-budget 600 --fit-early $([ $c = 2 ] && echo off || echo on) \
        -o "$w/fe_c$c.rfso" && "$bin/rfseek-replay" --print "$w/fe_c$c.rfso" | unshift >"$w/fe_c$c.txt" \
        || fail "replay-candump-config-fit-early-$c"
done
check replay-config-frame-fit-early '[ -s "$w/fe_c2.txt" ] && cmp -s "$w/fe_c2.txt" "$w/fe_on.txt" && cmp -s "$w/fe_c1.txt" "$w/fe_off.txt"'

# --- can-utils' own writer: asc2log's lines read as ours -------------------------------------
asc2log -I "$w/m.asc" -O "$w/a2l.log" 2>/dev/null
cut -d' ' -f2,3 "$w/a2l.log" >"$w/a2l.frames"; cut -d' ' -f2- "$w/m.log" >"$w/m.frames"
"$bin/rfseek-replay" --print "$w/a2l.log" | cut -f1,3- >"$w/a2l.txt"; check_rc asc2log-lines-read $?
check asc2log-frames-equal '[ -s "$w/m.frames" ] && cmp -s "$w/a2l.frames" "$w/m.frames" && cut -f1,3- "$w/li.txt" | cmp -s - "$w/a2l.txt"'

# --- rfseekd --candump: the frames it sends -----------------------------------------------
"$B/tests/wire/lcm_tool" mklog "$w/in.lcmlog" || fail lcm-mklog
"$bin/rfseekd" --map $map --replay "$w/in.lcmlog" --clock-lcm --lcm memq:// --log "$w/out.lcmlog" \
    --candump "$w/d.log" >/dev/null 2>"$w/d.err"; check_rc rfseekd-candump $?
log2asc -I "$w/d.log" can0 >"$w/d.asc"; check_rc log2asc-accepts-rfseekd $?
py $dbc "$w/d.log" --asc "$w/d.asc" --decode >"$w/d.dec" || { grep FAIL "$w/d.dec"; fail candump-decode-rfseekd; }
grep "^PASS" "$w/d.dec"
steps=$(sed -n 's/^rfseekd: \([0-9]*\) steps.*/\1/p' "$w/d.err")
check "rfseekd-candump-two-frames-per-step ($steps steps)" '[ "$steps" -gt 0 ] && [ "$(wc -l <"$w/d.log")" -eq $((2 * steps)) ]'
# The wheel speeds canmatrix decodes equal the LCM log's status (time, left, right).
awk -F'\t' '$2 == "WHEEL_CMD" {sub("LeftSpeed=", "", $5); sub("RightSpeed=", "", $6); print $1 - s, $5, $6}' \
    s=$shift_us "$w/d.dec" >"$w/wheel_can.txt"
"$B/tests/wire/lcm_tool" dump "$w/out.lcmlog" | awk '$1 == "STATUS" {print $2, $4, $5}' >"$w/wheel_lcm.txt"
check rfseekd-candump-wheels-equal-lcm '[ -s "$w/wheel_can.txt" ] && cmp -s "$w/wheel_can.txt" "$w/wheel_lcm.txt"'

# --- bad input ------------------------------------------------------------------------------
# err NAME RC TEXT ARGS...: rfseek-replay exits RC with exactly one stderr line holding TEXT
# and leaves no output.
err() {
    local name=$1 want=$2 text=$3; shift 3
    rm -f "$w/x.rfso"
    "$bin/rfseek-replay" "$@" >/dev/null 2>"$w/err"; local rc=$?
    if [ $rc -ne "$want" ]; then fail "$name" "exit $rc: $(head -c 300 "$w/err")"
    elif [ "$(wc -l <"$w/err")" -ne 1 ] || ! grep -qF -- "$text" "$w/err"; then fail "$name" "stderr: $(head -c 300 "$w/err")"
    elif compgen -G "$w/x.rfso*" >/dev/null; then fail "$name" "an output was left"
    else pass "$name"; fi
}
err candump-fit-early-value 2 "--fit-early: expected on or off, got 'yes'" "$w/m.log" --map $map --fit-early yes -o "$w/x.rfso"
head -3 "$w/m.log" >"$w/ok3"
bad_line() { # NAME TEXT LINE: LINE as the 4th line of a log
    { cat "$w/ok3"; printf '%s\n' "$3"; tail -n +4 "$w/m.log"; } >"$w/b.log"
    err "candump-bad-$1" 1 "b.log:4: $2" "$w/b.log" --map $map -o "$w/x.rfso"
}
bad_line time-digits "timestamp: '.', 6 digits of microseconds" "(0000004295.00000) can0 100#1000000000A2"
bad_line no-paren "no '(' opening" "0000004295.000000 can0 100#1000000000A2"
bad_line no-iface "interface name and frame expected" "(0000004295.000000) can0"
bad_line id-digits "identifier: 3 hex digits (11-bit) or 8" "(0000004295.000000) can0 1000#00"
bad_line id-range "identifier: an 11-bit one is at most 7FF" "(0000004295.000000) can0 800#00"
bad_line odd-hex "data: hex digits in pairs" "(0000004295.000000) can0 100#100"
bad_line nine-bytes "data: more than 8 bytes" "(0000004295.000000) can0 100#112233445566778899"
bad_line fd "CAN FD" "(0000004295.000000) can0 100##1112233"
bad_line trailing "unexpected text after the frame" "(0000004295.000000) can0 100#11 X"
bad_line second-bus "interface can1 after can0" "(0000004295.000000) can1 100#1000000000A2"
bad_line tab "data: hex digits in pairs" "$(printf '(0000004295.000000) can0 100#1\t')"
{ cat "$w/ok3"; printf '(0000004295.000000) can0 100#1\0002\n'; } >"$w/b.log"
err candump-bad-nul 1 "b.log:4: data: hex digits in pairs" "$w/b.log" --map $map -o "$w/x.rfso"
grep -v ' 100#' "$w/m.log" >"$w/nostep.log"
err candump-no-step 1 "no WHEEL_CMD (100) frame" "$w/nostep.log" --map $map -o "$w/x.rfso"
err candump-needs-map 2 "is played with --map" "$w/m.log" -o "$w/x.rfso"
err candump-map-not-for-stream 2 "--map: only for playing a candump -L log" "$w/m.rfsr" --map $map -o "$w/x.rfso"
err candump-map-not-for-print 2 "--seed: only for playing" --print "$w/m.log" --seed 2
err candump-bad-seed 2 "--seed: expected a non-negative integer" "$w/m.log" --map $map --seed -1 -o "$w/x.rfso"
err candump-map-missing 1 "none.yaml" "$w/m.log" --map "$w/none.yaml" -o "$w/x.rfso"
# Lines candump -x and several interfaces write: a direction letter, right-aligned names.
printf '(0000004295.000000)  can0 100#1000000000A2 T\n(0000004295.000001)  can0 7FF#R\n(0000004295.000002)  can0 20000004#0004000000000000\n(0000004295.000003)  can0 12345678#00\n' >"$w/x.log"
check candump-extras-parse '[ "$("$bin/rfseek-replay" --print "$w/x.log" | cut -f1 | tr "\n" " ")" = "STEP END " ]'
# The writer's errors: a candump log next to a missing folder, or named as the stream.
"$bin/rfseek-record" scenarios/default.yaml -o "$w/r.rfsr" --candump "$w/no/r.log" --max-time 1 >/dev/null 2>"$w/err"
check record-candump-dir-missing '[ $? -eq 1 ] && grep -q "no/r.log: No such file" "$w/err" && [ ! -e "$w/r.rfsr" ]'
"$bin/rfseek-record" scenarios/default.yaml -o "$w/r.rfsr" --candump "$w/./r.rfsr" --max-time 1 >/dev/null 2>"$w/err"
check record-candump-is-out '[ $? -eq 1 ] && grep -q "is also written as" "$w/err" && [ ! -e "$w/r.rfsr" ]'
"$bin/rfseekd" --map $map --replay "$w/in.lcmlog" --clock-lcm --lcm memq:// --log "$w/o.lcmlog" --candump "$w/o.lcmlog" \
    >/dev/null 2>"$w/err"
check rfseekd-candump-is-log '[ $? -eq 1 ] && grep -q "is also written as" "$w/err" && [ ! -e "$w/o.lcmlog" ]'
exit $((fails > 0))
