#!/usr/bin/env bash
# rfseekd: command line errors, malformed LCM input, stale inputs stop the wheels,
# deterministic replay, logs readable by lcm-logplayer; then the two-process run (udpm in
# a private network namespace) when this user may create one.
# usage: tests/wire/rfseekd_test.sh BUILD
set -uo pipefail
build=${1:?usage: rfseekd_test.sh BUILD}
d=$build/bin/rfseekd tool=$build/tests/wire/lcm_tool
map=scenarios/maps/office.yaml
w=$build/tests/wire/rfseekd
rm -rf "$w" && mkdir -p "$w"
. "$(dirname "$0")/../lib/checks.sh"
# expect_err NAME WANT_RC PATTERN ARGS...: one error line matching PATTERN, that exit code
# (rfseekd; expect_err_of BIN NAME ... for another program)
expect_err_of() {
    local bin=$1 name=$2 want=$3 pat=$4; shift 4
    "$bin" "$@" > "$w/out" 2> "$w/err"; local rc=$?
    if [ $rc -eq "$want" ] && [ "$(wc -l < "$w/err")" -eq 1 ] && grep -q -- "$pat" "$w/err"; then pass "$name"
    else fail "$name (rc $rc, stderr: $(head -3 "$w/err"))"; fi
}
expect_err() { expect_err_of "$d" "$@"; }

"$d" --help > "$w/help" && grep -q -- '--can-over-lcm' "$w/help" && grep -q -- '--fit-early on|off' "$w/help" \
    && grep -q 'whole fits ignore it' "$w/help" && pass rfseekd-help || fail rfseekd-help
expect_err rfseekd-bad-fit-early 2 "--fit-early: expected on or off, got yes" --map $map --fit-early yes
expect_err rfseekd-bad-fit-budget 2 "--fit-budget: expected work units in \[0, 100000\], got -1" --map $map --fit-budget -1
expect_err rfseekd-missing-fit-early 2 "missing value for option --fit-early" --map $map --fit-early
expect_err rfseekd-unknown-option 2 "unknown option (see --help): --bogus" --bogus
# "" as a file, URL or interface: refused before any work (it ran, then failed to rename
# the output to ""; --lcm "" was liblcm's default provider)
expect_err rfseekd-empty-decisions 2 "empty value for option --decisions" --map $map --lcm memq:// --decisions ""
expect_err rfseekd-empty-lcm 2 "empty value for option --lcm" --map $map --lcm ""
expect_err rfseekd-map-required 2 "--map MAP.yaml is required" --lcm memq://
expect_err rfseekd-missing-map 1 "nope.yaml" --map "$w/nope.yaml" --lcm memq://
expect_err rfseekd-bad-seed 2 "--seed: expected a non-negative integer, got x" --map $map --seed x
expect_err rfseekd-can-exclusive 2 "exclude each other" --map $map --can vcan0 --can-over-lcm
expect_err rfseekd-missing-iface 1 "can: rfsnope0: no such interface" --map $map --lcm memq:// --can rfsnope0
expect_err rfseekd-missing-log 1 "$w/none.lcmlog" --map $map --replay "$w/none.lcmlog"
"$d" --map $map --lcm memq:// --log "$w/sub/x.lcmlog" > /dev/null 2> "$w/err"
[ $? -eq 1 ] && grep -qx "rfseekd: $w/sub/x.lcmlog: No such file or directory" "$w/err" && [ ! -e "$w/sub/x.lcmlog" ] \
    && pass rfseekd-unwritable-log || fail "rfseekd-unwritable-log ($(cat "$w/err"))"
# A line break in an option, its value or a file name: still one line (shown as '?'),
# liblcm's own complaint about a bad URL folded into it, and nothing written (tmp/nl*).
nl=$'\n'
expect_err rfseekd-newline-option 2 "unknown option (see --help): --x?y" "--x${nl}y"
expect_err rfseekd-newline-target 2 "--target: expected rssi or bridge, got a?b" --map $map --target "a${nl}b"
expect_err rfseekd-newline-res 2 "--res: expected metres in \[0.01, 1\], got 1?2" --map $map --res "1${nl}2"
expect_err rfseekd-newline-seed 2 "--seed: expected a non-negative integer, got 1?2" --map $map --seed "1${nl}2"
expect_err rfseekd-newline-map 1 "nl?map.yaml" --map "$w/nl${nl}map.yaml" --lcm memq://
expect_err rfseekd-newline-lcm-url 1 "lcm: udpm://?q: cannot open this provider.*liblcm: .*?q" \
    --map $map --lcm "udpm://${nl}q" --decisions "$w/nl-dec.txt"
expect_err rfseekd-bad-provider 1 "lcm: foo://: cannot open this provider.*liblcm: .*foo" \
    --map $map --lcm foo:// --decisions "$w/nl-dec.txt"
expect_err rfseekd-newline-can 1 "can: rfsno?q" --map $map --lcm memq:// --can "rfsno${nl}q"
expect_err rfseekd-newline-decisions 1 "nl/a?b: No such file or directory" --map $map --lcm memq:// --decisions "$w/nl/a${nl}b"
expect_err rfseekd-newline-log 1 "nl/a?b: No such file or directory" --map $map --lcm memq:// --log "$w/nl/a${nl}b"
expect_err rfseekd-newline-replay 1 "nl?none.lcmlog" --map $map --replay "$w/nl${nl}none.lcmlog"
compgen -G "$w/nl*" > /dev/null && fail "rfseekd-newline-nothing-written ($(ls -d "$w"/nl*))" \
    || pass rfseekd-newline-nothing-written
# The real-time clock stepped back an hour 0.5 s into a live run (an LD_PRELOAD shim): the
# steps go on at 20 Hz (scheduled on the monotonic clock; they stopped until the clock had
# caught up), and the run, ended by SIGINT after 2 s, ends on a zero command with Stop.
if cc -shared -fPIC -o "$w/clock_back.so" tests/wire/clock_back.c -ldl 2> "$w/cc.err"; then
    RFS_CLOCK_AFTER_MS=500 RFS_CLOCK_BACK_S=3600 LD_PRELOAD="$w/clock_back.so" timeout -s INT 2 \
        "$d" --map $map --lcm memq:// --can-over-lcm --log "$w/back.lcmlog" > /dev/null 2> "$w/back.err"
    n=$(/usr/bin/python3 -c 'import sys; sys.path.insert(0, "tests/host_sim")
from status_est_check import events
print(sum(1 for _t, ch, _b in events(sys.argv[1]) if ch == "RFS_WHEEL_CMD"))' "$w/back.lcmlog" 2>&1)
    [ "${n:-0}" -ge 30 ] 2>/dev/null && pass "rfseekd-clock-stepped-back ($n wheel commands in 2 s)" \
        || fail "rfseekd-clock-stepped-back ($n wheel commands in 2 s, want >= 30: $(head -2 "$w/back.err"))"
    /usr/bin/python3 tests/host_sim/wheel_stop_check.py "$w/back.lcmlog" live | sed 's/ wheel_stop/ rfseekd-clock-back-wheel_stop/'
else fail "rfseekd-clock-stepped-back: cannot build the shim ($(head -1 "$w/cc.err"))"; fi
# rfseek-sim-lcm: the same rule (it writes only summary.json, to stdout: none on error).
sl=$build/bin/rfseek-sim-lcm scn=scenarios/default.yaml
expect_err_of "$sl" sim-lcm-newline-option 2 "unknown option '--x?y'" $scn "--x${nl}y" 1
expect_err_of "$sl" sim-lcm-newline-unknown-last 2 "unknown option '--x?y'" $scn "--x${nl}y"
expect_err_of "$sl" sim-lcm-missing-value 2 "missing value for --seed" $scn --seed
expect_err_of "$sl" sim-lcm-second-scenario 2 "unexpected argument 'b.yaml' (one SCENARIO only)" $scn b.yaml
# "": not seed 0, not liblcm's default provider (udpm)
expect_err_of "$sl" sim-lcm-empty-seed 2 "empty value for --seed" $scn --seed "" --lcm memq://
expect_err_of "$sl" sim-lcm-empty-lcm 2 "empty value for --lcm" $scn --lcm ""
expect_err_of "$sl" sim-lcm-newline-seed 2 "--seed: '1?2' is not" $scn --seed "1${nl}2"
expect_err_of "$sl" sim-lcm-newline-max-time 2 "--max-time: '1?2' is not" $scn --max-time "1${nl}2"
expect_err_of "$sl" sim-lcm-newline-timeout 2 "--timeout-ms: '1?2' is not" $scn --timeout-ms "1${nl}2"
expect_err_of "$sl" sim-lcm-newline-scenario 1 "nl?s.yaml" "$w/nl${nl}s.yaml" --lcm memq://
expect_err_of "$sl" sim-lcm-newline-lcm-url 1 "lcm: udpm://?q: cannot open this provider.*liblcm: .*?q" \
    $scn --lcm "udpm://${nl}q" --max-time 1
expect_err_of "$sl" sim-lcm-newline-can 1 "can: rfsno?q" $scn --lcm memq:// --can "rfsno${nl}q" --max-time 1
[ ! -s "$w/out" ] && pass sim-lcm-newline-no-summary || fail sim-lcm-newline-no-summary
# --log: checked before any work (its folder, not the scenario itself).
expect_err_of "$sl" sim-lcm-log-no-folder 1 "$w/nope/l.tsv: No such file or directory" $scn --lcm memq:// --log "$w/nope/l.tsv"
expect_err_of "$sl" sim-lcm-log-is-scenario 1 "is the input" $scn --lcm memq:// --log $scn
# liblcm's own stderr is folded by lx_lcm_open (firmware/port/linux/lx_lcm.c): its two lines
# for a bad option of a missing log (lcm_logprov.c) become part of one error line, and a
# warning on a provider that does open is one line before the end-of-run summary.
expect_err rfseekd-liblcm-two-lines 1 "cannot open this provider.*(liblcm: Warning: Invalid value for speed?Error: Failed to open $PWD/$w/none.lcmlog: No such file or directory)\$" \
    --map $map --lcm "file://$PWD/$w/none.lcmlog?speed=abc"
"$d" --map $map --lcm "file://$PWD/$w/warn.lcmlog?mode=w&foo=1" --duration 1 > "$w/out" 2> "$w/err"; rc=$?
[ $rc -eq 0 ] && [ "$(wc -l < "$w/err")" -eq 2 ] \
    && [ "$(head -1 "$w/err")" = "rfseekd: lcm: file://$PWD/$w/warn.lcmlog?mode=w&foo=1: liblcm: Warning: unrecognized option: [foo]" ] \
    && grep -q "^rfseekd: [0-9]* steps, " "$w/err" && pass rfseekd-liblcm-warning-one-line \
    || fail "rfseekd-liblcm-warning-one-line (rc $rc: $(tr '\n' '|' < "$w/err"))"
# SIGTERM ends a live run cleanly, wherever it lands (liblcm's wait interrupted is no LCM
# error): the summary line, exit 0, the log renamed into place.
"$d" --map $map --lcm memq:// --log "$w/term.lcmlog" > /dev/null 2> "$w/err" &
pid=$!
sleep 1
kill -TERM $pid; wait $pid; rc=$?
[ $rc -eq 0 ] && [ -s "$w/term.lcmlog" ] && [ ! -e "$w/term.lcmlog.tmp" ] && [ "$(wc -l < "$w/err")" -eq 1 ]     && grep -q "^rfseekd: [0-9]* steps, " "$w/err" && pass "rfseekd-sigterm-clean-exit ($(cut -d, -f1 "$w/err"))" \
    || fail "rfseekd-sigterm-clean-exit (rc $rc: $(tr '\n' '|' < "$w/err"))"
expect_err_of "$sl" sim-lcm-liblcm-two-lines 1 "^rfseek-sim-lcm: lcm: file://.*(liblcm: Warning: Invalid value for speed?Error: Failed to open" \
    $scn --lcm "file://$PWD/$w/none.lcmlog?speed=abc" --max-time 1
# hs_ctrl_lcm's own lines carry the name of the program using it: a malformed
# RFS_SEEKER_STATUS (5 bytes; the log written here with LCM's documented event layout:
# magic, event number, time, channel length, data length, channel, data) is dropped with
# one line, then the first unanswered step and their count are reported (exit 1).
printf '\xed\xa1\xda\x01\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x11\0\0\0\x05RFS_SEEKER_STATUS\x01\x02\x03\x04\x05' \
    > "$w/bad-status.lcmlog"
"$sl" $scn --lcm "file://$PWD/$w/bad-status.lcmlog?speed=0" --timeout-ms 50 --max-time 0.5 > "$w/out" 2> "$w/err"; rc=$?
[ $rc -eq 1 ] && [ "$(wc -l < "$w/err")" -eq 3 ] && ! grep -qv "^rfseek-sim-lcm: " "$w/err" \
    && grep -qxF "rfseek-sim-lcm: dropped LCM message: RFS_SEEKER_STATUS: truncated, oversized or not an rfseek.seeker_status_t (5 bytes)" "$w/err" \
    && grep -q "^rfseek-sim-lcm: no answer from the controller for step t=[0-9]* us within 50 ms; wheels stopped\$" "$w/err" \
    && pass sim-lcm-ctrl-lines-name-the-program \
    || fail "sim-lcm-ctrl-lines-name-the-program (rc $rc: $(tr '\n' '|' < "$w/err"))"

# A crafted input log: malformed messages are dropped with one line each, the controller
# keeps running, and the wheels stop within 200 ms of the inputs stopping at 3 s.
"$tool" mklog "$w/in.lcmlog" || fail lcm-mklog
for i in 1 2; do
    "$d" --map $map --replay "$w/in.lcmlog" --clock-lcm --lcm memq:// --log "$w/out$i.lcmlog" \
        > "$w/dec$i.txt" 2> "$w/err$i.txt" || fail "rfseekd-replay-run-$i"
    "$tool" dump "$w/out$i.lcmlog" > "$w/status$i.txt" || fail "lcm-dump-$i"
done
for pat in "RFS_POSE: truncated, oversized or not an rfseek.pose_t (37 bytes)" \
           "RFS_POSE: x or y is not a finite position" "RFS_RSSI: source 99 out of range 0..15" \
           "RFS_POSE: truncated, oversized or not an rfseek.pose_t (16 bytes)" \
           "RFS_RSSI: truncated, oversized or not an rfseek.rssi_t (5 bytes)" \
           "RFS_CLOCK: time 1000000 not after 2000000"; do
    grep -qF "$pat" "$w/err1.txt" && pass "rfseekd-bad-input: $pat" || fail "rfseekd-bad-input: $pat"
done
# 81 clock ticks (0..4 s at 20 Hz; the backwards one is dropped), the 5 malformed
# messages, and the one out-of-order pose rejected by the seeker.
grep -qE "^rfseekd: 81 steps, [0-9]+ decisions, 5 bad messages, 0 CAN send failures, 0 receiver heartbeats, seeker rejected 1 inputs" "$w/err1.txt" \
    && pass rfseekd-bad-input-counted || fail "rfseekd-bad-input-counted ($(tail -1 "$w/err1.txt"))"
# STATUS t state left right faults decided
awk '$2 < 3000000 && ($4 != 0 || $5 != 0) {moving++}
     $2 >= 3000000 && ($4 != 0 || $5 != 0) {last_moving = $2}
     $2 >= 3200000 {after++} $2 >= 3200000 && ($4 != 0 || $5 != 0) {late++}
     END {exit !(moving > 10 && after >= 10 && late == 0)}' "$w/status1.txt" \
    && pass "rfseekd-stale-inputs-stop-wheels (<= 200 ms after the last input)" \
    || fail "rfseekd-stale-inputs-stop-wheels ($(awk '$2 >= 2900000' "$w/status1.txt" | head -8 | tr '\n' ';'))"
awk '$2 >= 3200000 {n++} $2 >= 3200000 && (int($6 / 256) % 4) != 3 {bad++} END {exit n < 10 || bad > 0}' "$w/status1.txt" \
    && pass rfseekd-stale-faults-reported || fail rfseekd-stale-faults-reported
cmp -s "$w/dec1.txt" "$w/dec2.txt" && cmp -s "$w/status1.txt" "$w/status2.txt" && [ -s "$w/status1.txt" ] \
    && pass "rfseekd-replay-deterministic ($(wc -l < "$w/status1.txt") steps)" || fail rfseekd-replay-deterministic
# The same malformed input under ASan+UBSan (leaks included; the build is a prerequisite).
if [ ! -x "$build/asan/bin/rfseekd" ]; then
    fail "rfseekd-bad-input-under-asan-ubsan ($build/asan/bin/rfseekd missing)"
else
    ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1 "$build/asan/bin/rfseekd" --map $map \
        --replay "$w/in.lcmlog" --clock-lcm --lcm memq:// --log "$w/out-asan.lcmlog" > "$w/dec-asan.txt" 2> "$w/err-asan.txt"
    rc=$?
    if [ $rc -eq 0 ] && ! grep -qE "Sanitizer|runtime error" "$w/err-asan.txt" && cmp -s "$w/dec1.txt" "$w/dec-asan.txt"; then
        pass rfseekd-bad-input-under-asan-ubsan
    else
        fail "rfseekd-bad-input-under-asan-ubsan (rc $rc: $(grep -m3 -E 'Sanitizer|runtime error' "$w/err-asan.txt"))"
    fi
fi
# A radio dead zone: packets stop at 1 s, poses go on. Without the receiver
# heartbeat (RFS_RSSI_STATUS) the wheels stop within 200 ms and stay stopped; with it
# every one of the 81 heartbeats reaches the application (counted by rfseekd) and the
# robot drives on to 4 s; the garbage heartbeat is dropped with one line.
for hb in off on; do
    "$tool" mkdeadzone "$w/dz-$hb.lcmlog" $hb || fail "lcm-mkdeadzone-$hb"
    "$d" --map $map --replay "$w/dz-$hb.lcmlog" --clock-lcm --lcm memq:// --log "$w/dz-out-$hb.lcmlog" \
        > /dev/null 2> "$w/dz-err-$hb.txt" || fail "rfseekd-dead-zone-run-$hb"
    "$tool" dump "$w/dz-out-$hb.lcmlog" > "$w/dz-status-$hb.txt" || fail "lcm-dump-dead-zone-$hb"
done
# moving steps before 1 s, from 1.2 s to 4 s
dz() { awk '($4 != 0 || $5 != 0) && $2 < 1000000 {a++} ($4 != 0 || $5 != 0) && $2 >= 1200000 {b++}
            END {printf "%d %d\n", a, b}' "$1"; }
read -r off_before off_after <<<"$(dz "$w/dz-status-off.txt")"
read -r on_before on_after <<<"$(dz "$w/dz-status-on.txt")"
[ "$off_before" -gt 5 ] && [ "$off_after" -eq 0 ] \
    && pass "rfseekd-dead-zone-without-heartbeat-stops ($off_before moving steps before 1 s, none from 1.2 s)" \
    || fail "rfseekd-dead-zone-without-heartbeat-stops ($off_before before, $off_after after)"
[ "$on_before" -eq "$off_before" ] && [ "$on_after" -ge 50 ] \
    && pass "rfseekd-dead-zone-heartbeat-drives-on ($on_after of 57 steps from 1.2 s move)" \
    || fail "rfseekd-dead-zone-heartbeat-drives-on ($on_before before, $on_after after)"
grep -qE "^rfseekd: 81 steps, [0-9]+ decisions, 1 bad messages, 0 CAN send failures, 81 receiver heartbeats, seeker rejected 0 inputs" \
    "$w/dz-err-on.txt" && grep -qF "RFS_RSSI_STATUS: truncated, oversized or not an rfseek.rssi_status_t (5 bytes)" "$w/dz-err-on.txt" \
    && pass "rfseekd-heartbeats-reach-the-app (81 of 81, the garbage one dropped)" \
    || fail "rfseekd-heartbeats-reach-the-app ($(cat "$w/dz-err-on.txt" | tr '\n' ';'))"

timeout 60 lcm-logplayer -l memq:// -s 1000 "$w/out1.lcmlog" > /dev/null 2>&1 \
    && pass rfseekd-log-plays-in-lcm-logplayer || fail rfseekd-log-plays-in-lcm-logplayer

# Two processes over udpm://, only inside a network namespace we create and delete.
# two_process TAG RFSEEKD-ARGS...: rfseekd (with the args) and rfseek-sim-lcm on the default
# office in a fresh namespace (the simulator with the options in sim_args); rfseekd's stderr
# in $w/d-TAG.err, the simulator's summary in $w/summary-TAG.json, its log.tsv in
# $w/log-TAG.tsv and stderr in $w/sim-TAG.err; sets src and drc. Returns 2 when no
# namespace can be made.
sim_args=()
url='udpm://239.255.76.67:7667?ttl=0'
two_process() {
    local tag=$1
    shift
    ns=rfswire$tag$$
    ip netns add "$ns" 2>/dev/null || return 2
    trap 'ip netns del "$ns" 2>/dev/null' EXIT
    ip netns exec "$ns" ip link set lo up && ip netns exec "$ns" ip route add 224.0.0.0/4 dev lo \
        || { fail "netns setup ($tag)"; exit 1; }
    ip netns exec "$ns" timeout 300 "$d" --map $map --lcm "$url" --can-over-lcm --clock-lcm \
        --idle-exit 3000 "$@" 2> "$w/d-$tag.err" > /dev/null &
    local dpid=$!
    sleep 0.5
    ip netns exec "$ns" timeout 300 "$build/bin/rfseek-sim-lcm" scenarios/default.yaml --lcm "$url" \
        --log "$w/log-$tag.tsv" "${sim_args[@]}" > "$w/summary-$tag.json" 2> "$w/sim-$tag.err"
    src=$?
    wait $dpid
    drc=$?
    ip netns del "$ns"; trap - EXIT
    ip netns list | grep -q "^$ns" && fail "netns $ns left behind"
    return 0
}
two_process paper --log "$w/run.lcmlog" --decisions "$w/live.txt"
if [ $? -eq 2 ]; then
    echo "SKIP two-process run: cannot create a network namespace (needs root)"
    exit $((fails > 0))
fi
if [ $src -eq 0 ] && [ $drc -eq 0 ] && grep -q '"reached": true' "$w/summary-paper.json"; then
    pass "two-process-run-reaches-source ($(grep -E '"(sim_time_s|iterations)"' "$w/summary-paper.json" | tr -d ' \n'))"
else
    fail "two-process-run-reaches-source (sim rc $src, rfseekd rc $drc: $(cat "$w/sim-paper.err" "$w/d-paper.err" | head -5))"
fi
# The decision flags and plan_wait cross LCM: rfseek-sim-lcm's log.tsv and summary as
# rfseekd's own --decisions lines give them (tests/wire/decision_flags.py).
out=$(/usr/bin/python3 tests/wire/decision_flags.py "$w/live.txt" "$w/log-paper.tsv" "$w/summary-paper.json" 2>&1) \
    && pass "two-process-plan-wait ($out)" || fail "two-process-plan-wait ($out)"
"$d" --map $map --replay "$w/run.lcmlog" --clock-lcm > "$w/replay1.txt" 2>/dev/null
"$d" --map $map --replay "$w/run.lcmlog" --clock-lcm > "$w/replay2.txt" 2>/dev/null
if [ -s "$w/live.txt" ] && cmp -s "$w/live.txt" "$w/replay1.txt" && cmp -s "$w/replay1.txt" "$w/replay2.txt"; then
    pass "two-process-replay-same-decisions ($(wc -l < "$w/live.txt") decisions, live = replay = replay)"
else
    fail two-process-replay-same-decisions
fi
"$d" --map $map --lcm "file://$PWD/$w/run.lcmlog?speed=0" --clock-lcm --decisions "$w/replay3.txt" \
    --idle-exit 2000 2>/dev/null
cmp -s "$w/live.txt" "$w/replay3.txt" && pass "two-process-replay-through-lcm-file-provider" \
    || fail two-process-replay-through-lcm-file-provider

# The map-aware improvement on the Linux port: meta-path with the pathloss model.
two_process path --model pathloss --strategy meta-path --log "$w/path.lcmlog"
if [ $src -eq 0 ] && [ $drc -eq 0 ] && grep -q '"reached": true' "$w/summary-path.json" \
    && grep -q "(strategy meta-path, model pathloss, fit budget 0, fit_early off)\$" "$w/d-path.err"; then
    pass "two-process-meta-path-pathloss-reaches-source ($(grep -E '"(distance_travelled_m|iterations)"' "$w/summary-path.json" | tr -d ' \n'))"
else
    fail "two-process-meta-path-pathloss-reaches-source (sim rc $src, rfseekd rc $drc: $(cat "$w/sim-path.err" "$w/d-path.err" | tail -3))"
fi
# Simulator seed 8 with meta-path + pathloss: epsilon goals drawn from the model (sampled),
# argmaxes ruled out (refuted) and decisions waiting a period for their tree (plan_wait).
sim_args=(--seed 8)
two_process flags --model pathloss --strategy meta-path --decisions "$w/flags.txt"
sim_args=()
out=$(/usr/bin/python3 tests/wire/decision_flags.py "$w/flags.txt" "$w/log-flags.tsv" "$w/summary-flags.json" 2>&1)
if [ $? -eq 0 ] && [ $src -eq 0 ] && [ $drc -eq 0 ] && [[ $out == *"sampled "[1-9]* ]] \
    && [[ $out == *"refuted "[1-9]* ]] && [[ $out == *"plan_wait_max "[1-9]* ]]; then
    pass "two-process-decision-flags ($out)"
else
    fail "two-process-decision-flags (sim rc $src, rfseekd rc $drc: $out)"
fi
# The path-loss estimate crosses LCM: rfseek-sim-lcm's summary holds the one the last status
# in rfseekd's log carried (decoded by scripts/lcm_log.py).
est_log=$(/usr/bin/python3 scripts/lcm_log.py "$w/path.lcmlog" --channel RFS_SEEKER_STATUS | tail -1 \
    | /usr/bin/python3 -c 'import json, sys; m = json.loads(sys.stdin.read())["msg"]
print("%.3f %.3f" % (m["est_x"], m["est_y"]) if m["est_valid"] else "none")')
est_sum=$(/usr/bin/python3 -c 'import json, sys; s = json.load(open(sys.argv[1]))
print("none" if s["est_src_x_m"] is None else "%.3f %.3f" % (s["est_src_x_m"], s["est_src_y_m"]))' \
    "$w/summary-path.json")
[ "$est_log" != none ] && [ "$est_log" = "$est_sum" ] && pass "two-process-estimate-in-summary ($est_sum)" \
    || fail "two-process-estimate-in-summary (log: $est_log, summary: $est_sum)"
# --fit-early reaches the seeker with a fit budget (the path-loss model's MCU one, 150) and
# changes the decisions made on the same inputs; whole fits ignore it.
for fe in on off; do
    for fb in 0 150; do
        "$d" --map $map --replay "$w/path.lcmlog" --clock-lcm --model pathloss --strategy meta-path \
            --fit-budget $fb --fit-early $fe > "$w/fe-$fb-$fe.txt" 2> "$w/fe-$fb-$fe.err" \
            || fail "rfseekd-fit-early-replay-$fb-$fe"
    done
done
if grep -q "(strategy meta-path, model pathloss, fit budget 150, fit_early on)\$" "$w/fe-150-on.err" \
    && [ "$(wc -l < "$w/fe-150-on.txt")" -ge 3 ] && ! cmp -s "$w/fe-150-on.txt" "$w/fe-150-off.txt" \
    && cmp -s "$w/fe-0-on.txt" "$w/fe-0-off.txt"; then
    pass "rfseekd-fit-early-with-a-fit-budget ($(wc -l < "$w/fe-150-on.txt") / $(wc -l < "$w/fe-150-off.txt") decisions; whole fits alike)"
else
    fail "rfseekd-fit-early-with-a-fit-budget ($(tail -1 "$w/fe-150-on.err"))"
fi
# The baselines on the Linux port: their decision kinds name themselves, every status
# message they publish decodes (one a step, none dropped as out of range), and their CAN
# STATUS frames carry docs/CAN.md's Kind codes (decoded in Python from --candump).
for st in chemotaxis plane-gradient fd-gradient; do
    "$d" --map $map --replay "$w/path.lcmlog" --clock-lcm --strategy $st --lcm memq:// \
        --log "$w/bl-$st.lcmlog" --candump "$w/bl-$st.candump" > "$w/bl-$st.txt" 2> "$w/bl-$st.err" \
        || fail "rfseekd-baseline-$st-run"
    if out=$(/usr/bin/python3 tests/wire/status_kinds.py "$w/bl-$st.candump" "$w/bl-$st.txt"); then
        pass "rfseekd-baseline-$st-can-status-kinds ($out)"
    else
        fail "rfseekd-baseline-$st-can-status-kinds ($(echo "$out" | tr '\n' ' '))"
    fi
    "$tool" dump "$w/bl-$st.lcmlog" > "$w/bl-$st.dump" 2> "$w/bl-$st.dump.err"
    steps=$(sed -n 's/^rfseekd: \([0-9]*\) steps.*/\1/p' "$w/bl-$st.err")
    case $st in chemotaxis) kinds="run tumble" ;; fd-gradient) kinds="probe" ;; *) kinds="gradient" ;; esac
    ok=1
    for k in $kinds; do grep -q " kind=$k " "$w/bl-$st.txt" || ok=0; done
    if [ $ok -eq 1 ] && [ -n "$steps" ] && [ "$(grep -c '^STATUS ' "$w/bl-$st.dump")" -eq "$steps" ] \
        && [ ! -s "$w/bl-$st.dump.err" ]; then
        pass "rfseekd-baseline-$st-kinds-and-status ($steps steps, kinds: $(sed -n 's/.* kind=\([a-z]*\) .*/\1/p' "$w/bl-$st.txt" | sort -u | tr '\n' ' '))"
    else
        fail "rfseekd-baseline-$st-kinds-and-status ($(head -2 "$w/bl-$st.dump.err"))"
    fi
done
exit $((fails > 0))
