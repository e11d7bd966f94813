#!/usr/bin/env bash
# heartbeat_replay.sh BUILD - the receiver heartbeat through the firmware's
# wire paths: a simulated mission that starts in a radio dead zone (the office, the
# receiver's sensitivity at -45 dBm with a hard edge and no shadowing, fading or noise:
# packets arrive only within about 7 m of the source, the robot starts 20 m away),
# recorded by rfseek-record with the heartbeat as RX_STATUS CAN frames (0x121), as
# RECEIVER replay records, and not at all. Checks:
#   - each recording replayed on the host equals its live run, byte for byte;
#   - the CAN and the RECEIVER encodings give identical output streams;
#   - without the heartbeat the robot never moves; with it, it drives and decides;
#   - the Cortex-M4 image under qemu gives the host's bytes for both encodings;
#   - an old stream (no heartbeat at all) still plays: the "off" recording is one;
#   - a RECEIVER record of the wrong length is one error line naming the file;
#   - a bad --heartbeat value is one error line, exit status non-zero, no recording.
set -uo pipefail
B=${1:?usage: heartbeat_replay.sh BUILD}
. "$(dirname "$0")/../lib/fw_stream.sh"
sed -e "s|^map: maps/office.yaml|map: $PWD/scenarios/maps/office.yaml|" \
    -e 's|^  shadowing:.*|  shadowing: {enabled: false}|' -e 's|^  fading:.*|  fading: {enabled: false}|' \
    -e 's|^  noise:.*|  noise: {enabled: false}|' \
    -e 's|sensitivity_dbm: -95, loss_width_db: 1.5|sensitivity_dbm: -45, loss_width_db: 0.01|' \
    scenarios/default.yaml > "$tmp/dead.yaml"
grep -q 'sensitivity_dbm: -45' "$tmp/dead.yaml" || { fail "dead-zone scenario" "scenarios/default.yaml changed"; exit 1; }

# A bad --heartbeat value: one error line naming the option, exit 1, no recording left.
"$bin/rfseek-record" "$tmp/dead.yaml" -o "$tmp/bad.rfsr" --heartbeat sometimes > /dev/null 2> "$tmp/bad.err"
rc=$?
[ "$rc" -ne 0 ] && [ "$(wc -l < "$tmp/bad.err")" -eq 1 ] && grep -q -- '--heartbeat' "$tmp/bad.err" \
    && [ ! -e "$tmp/bad.rfsr" ] && pass "record --heartbeat sometimes: one error line, nothing written" \
    || fail "record --heartbeat sometimes" "exit $rc: $(head -c 200 "$tmp/bad.err")"

moving() { "$bin/rfseek-replay" --print "$1" | awk '$1 == "OUT" && ($3 != "left=0" || $4 != "right=0")' | wc -l; }
for m in can record off; do
    if ! "$bin/rfseek-record" "$tmp/dead.yaml" -o "$tmp/$m.rfsr" --live-out "$tmp/$m.live" --max-time 120 \
            --heartbeat $m > "$tmp/$m.txt"; then
        fail "record --heartbeat $m"; continue
    fi
    "$bin/rfseek-replay" "$tmp/$m.rfsr" -o "$tmp/$m.host" && cmp -s "$tmp/$m.live" "$tmp/$m.host" \
        && pass "heartbeat $m: host replay equals the live run" || fail "heartbeat $m: host replay equals the live run"
done
n_can=$("$bin/rfseek-replay" --print "$tmp/can.rfsr" | awk '$1 == "CAN" && $3 == "id=121"' | wc -l)
n_rec=$("$bin/rfseek-replay" --print "$tmp/record.rfsr" | grep -c '^RECEIVER')
n_off=$("$bin/rfseek-replay" --print "$tmp/off.rfsr" | grep -cE '^RECEIVER|id=121')
[ "$n_can" -eq 2400 ] && [ "$n_rec" -eq 2400 ] && [ "$n_off" -eq 0 ] \
    && pass "heartbeats recorded: $n_can RX_STATUS frames, $n_rec RECEIVER records, none when off (2400 steps)" \
    || fail "heartbeats recorded" "can $n_can, record $n_rec, off $n_off"
cmp -s "$tmp/can.live" "$tmp/record.live" \
    && pass "RX_STATUS frames and RECEIVER records give identical outputs" \
    || fail "RX_STATUS frames and RECEIVER records give identical outputs"
m_on=$(moving "$tmp/can.live"); m_off=$(moving "$tmp/off.live")
d_on=$("$bin/rfseek-replay" --print "$tmp/can.live" | grep -c '^DECISION')
d_off=$("$bin/rfseek-replay" --print "$tmp/off.live" | grep -c '^DECISION')
[ "$m_off" -eq 0 ] && [ "$d_off" -eq 0 ] && [ "$m_on" -ge 1000 ] && [ "$d_on" -ge 5 ] \
    && pass "dead zone: without the heartbeat 0 moving steps, with it $m_on of 2400 and $d_on decisions" \
    || fail "dead zone drives only with the heartbeat" "off: $m_off moving, $d_off decisions; on: $m_on, $d_on"
for m in can record; do
    if qemu $m.rfsr $m.qemu 2> "$tmp/$m.qemu.err" && cmp -s "$tmp/$m.host" "$tmp/$m.qemu"; then
        pass "heartbeat $m: Cortex-M4 (qemu) output equals the host's ($(stat -c %s "$tmp/$m.qemu") bytes)"
    else
        fail "heartbeat $m: Cortex-M4 (qemu) output equals the host's"
    fi
done
# A RECEIVER record one byte short: one line naming the file, exit 1, no output file.
printf 'RFSR\001\000\000\000\023\017' > "$tmp/bad.rfsr"; head -c 15 /dev/zero >> "$tmp/bad.rfsr"
if "$bin/rfseek-replay" "$tmp/bad.rfsr" -o "$tmp/bad.out" 2> "$tmp/bad.err"; then
    fail "short RECEIVER record rejected" "exit 0"
elif [ -e "$tmp/bad.out" ] || [ "$(wc -l < "$tmp/bad.err")" -ne 1 ] || ! grep -q "bad.rfsr.*wrong record length" "$tmp/bad.err"; then
    fail "short RECEIVER record rejected" "$(cat "$tmp/bad.err")"
else
    pass "short RECEIVER record rejected: $(cat "$tmp/bad.err")"
fi
exit $((fails > 0))
