#!/usr/bin/env bash
# bit_identical.sh BUILD - issue 6: the same recorded input stream fed to the host build
# of the application loop and to the Cortex-M4 image under qemu gives identical output
# streams, byte for byte. The stream is a simulated mission (scenarios/default.yaml, the
# firmware loop as the controller, inputs as CAN frames) with injected faults: inputs
# stopping, bus-off and a watchdog reset. Also: the live closed-loop outputs equal the
# replay, the outputs are not trivial, and malformed streams fail cleanly on both sides.
set -uo pipefail
B=${1:-build}
. "$(dirname "$0")/../lib/fw_stream.sh"

if ! "$bin/rfseek-record" scenarios/default.yaml -o "$tmp/in.rfsr" --live-out "$tmp/live.rfso" \
        --max-time 120 --drop 20:22 --bus-off 35:36 --reset 50 --fit-budget 2500 >"$tmp/record.txt"; then
    fail record "rfseek-record failed"; exit 1
fi
"$bin/rfseek-replay" "$tmp/in.rfsr" -o "$tmp/host.rfso" && cmp -s "$tmp/live.rfso" "$tmp/host.rfso" \
    && pass "host replay equals the live run" || fail "host replay equals the live run"
if qemu in.rfsr qemu.rfso; then pass "qemu image exits 0"; else fail "qemu image exits 0" "status $?"; fi
if cmp "$tmp/host.rfso" "$tmp/qemu.rfso"; then
    pass "bit-identical: host and Cortex-M4 (qemu) outputs, $(stat -c %s "$tmp/host.rfso") bytes"
else
    fail "bit-identical: host and Cortex-M4 (qemu) outputs"
fi
"$bin/rfseek-replay" --print "$tmp/qemu.rfso" >"$tmp/qemu.txt"
nd=$(grep -c '^DECISION' "$tmp/qemu.txt"); nm=$(awk '$1 == "OUT" && ($3 != "left=0" || $4 != "right=0")' "$tmp/qemu.txt" | wc -l)
nrel=$(grep '^DECISION' "$tmp/qemu.txt" | grep -c 'relearned=1'); ntx=$(grep -c '^CAN_TX' "$tmp/qemu.txt")
[ "$nd" -ge 5 ] && [ "$nm" -ge 100 ] && [ "$nrel" -ge 1 ] && [ "$ntx" -ge 1000 ] \
    && pass "outputs are not trivial ($nd decisions, $nrel relearned, $nm moving steps, $ntx frames)" \
    || fail "outputs are not trivial" "$nd decisions, $nrel relearned, $nm moving steps, $ntx frames"

# A second, fault-free mission to the end (reached, distance or time limit), in the
# faithful configuration (the fit in one period).
if "$bin/rfseek-record" scenarios/default.yaml -o "$tmp/m.rfsr" --seed 7 >"$tmp/m.txt" \
        && "$bin/rfseek-replay" "$tmp/m.rfsr" -o "$tmp/m_host.rfso" && qemu m.rfsr m_qemu.rfso \
        && cmp "$tmp/m_host.rfso" "$tmp/m_qemu.rfso"; then
    pass "bit-identical on a whole mission, seed 7 ($(cat "$tmp/m.txt"))"
else
    fail "bit-identical on a whole mission, seed 7"
fi

# Malformed streams: one clear error, non-zero exit, nothing left behind (host); the
# image reports the reason on the semihosting console and exits non-zero.
head -c 5000 "$tmp/in.rfsr" >"$tmp/trunc.rfsr"
printf 'RFSR\001\000\000\000\377\000' >"$tmp/badtype.rfsr"
printf 'XXXX\001\000\000\000' >"$tmp/badmagic.rfsr"
for f in trunc badtype badmagic; do
    if "$bin/rfseek-replay" "$tmp/$f.rfsr" -o "$tmp/$f.out" 2>"$tmp/$f.err"; then
        fail "host rejects $f stream" "exit 0"
    elif [ -e "$tmp/$f.out" ] || [ "$(wc -l <"$tmp/$f.err")" -ne 1 ] || ! grep -q "$f.rfsr" "$tmp/$f.err"; then
        fail "host rejects $f stream" "$(cat "$tmp/$f.err")"
    else
        pass "host rejects $f stream: $(cat "$tmp/$f.err")"
    fi
    if qemu "$f.rfsr" "$f.qout" 2>"$tmp/$f.qerr"; then
        fail "qemu image rejects $f stream" "exit 0"
    elif ! grep -q 'rfseek-qemu: ' "$tmp/$f.qerr"; then
        fail "qemu image rejects $f stream" "no message"
    else
        pass "qemu image rejects $f stream: $(cat "$tmp/$f.qerr")"
    fi
done
exit $((fails > 0))
