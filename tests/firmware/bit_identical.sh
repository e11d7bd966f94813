#!/usr/bin/env bash
# bit_identical.sh BUILD - the same recorded input stream fed to the host build
# of the application loop and to the Cortex-M4 image under qemu gives identical output
# streams, byte for byte. The stream is a simulated mission (scenarios/default.yaml, the
# firmware loop as the controller, inputs as CAN frames) with injected faults: inputs
# stopping, bus-off and a watchdog reset; then a whole mission, and one of meta-path +
# pathloss (the improvement the image holds beside the paper's), also with the STM32
# configuration's fit_early; and senders in an epoch of their own. Also: the live
# closed-loop outputs equal the replay, the outputs are not trivial, and malformed streams
# fail cleanly on both sides.
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

# Senders stamping in an epoch of their own, 3 h ahead of the controller's clock (docs/CAN.md,
# "Time on the bus"): the image follows it, so the mission above, reset included, gives the
# shared clock's outputs byte for byte, live, on the host and on the image.
if "$bin/rfseek-record" scenarios/default.yaml -o "$tmp/ep.rfsr" --live-out "$tmp/ep_live.rfso" \
        --max-time 120 --drop 20:22 --bus-off 35:36 --reset 50 --fit-budget 2500 --sender-ahead 10800 >/dev/null \
        && ! cmp -s "$tmp/ep.rfsr" "$tmp/in.rfsr" && cmp -s "$tmp/ep_live.rfso" "$tmp/live.rfso" \
        && "$bin/rfseek-replay" "$tmp/ep.rfsr" -o "$tmp/ep_host.rfso" && cmp -s "$tmp/ep_host.rfso" "$tmp/live.rfso" \
        && qemu ep.rfsr ep_qemu.rfso && cmp -s "$tmp/ep_qemu.rfso" "$tmp/live.rfso"; then
    pass "senders 3 h ahead: the shared clock's outputs, live, host and qemu"
else
    fail "senders 3 h ahead: the shared clock's outputs, live, host and qemu"
fi

# A second, fault-free mission to the end (reached, distance or time limit), in the
# faithful configuration (the fit in one period).
if "$bin/rfseek-record" scenarios/default.yaml -o "$tmp/m.rfsr" --seed 7 >"$tmp/m.txt" \
        && "$bin/rfseek-replay" "$tmp/m.rfsr" -o "$tmp/m_host.rfso" && qemu m.rfsr m_qemu.rfso \
        && cmp "$tmp/m_host.rfso" "$tmp/m_qemu.rfso"; then
    pass "bit-identical on a whole mission, seed 7 ($(cat "$tmp/m.txt"))"
else
    fail "bit-identical on a whole mission, seed 7"
fi

# The improvement the STM32 image holds beside the paper's: meta-path + pathloss, chosen
# by the CFG record as by a CONFIG frame (strategy, P0 floor -40 dBm), its relearns sliced
# at the path-loss model's MCU budget (600 wall counts a period), inputs stopping and a
# watchdog reset on the way.
if "$bin/rfseek-record" scenarios/default.yaml -o "$tmp/mp.rfsr" --seed 3 --model pathloss \
        --strategy meta-path --p0-min -40 --fit-budget 600 --drop 20:21 --reset 30 >"$tmp/mp.txt" \
        && "$bin/rfseek-replay" "$tmp/mp.rfsr" -o "$tmp/mp_host.rfso" && qemu mp.rfsr mp_qemu.rfso \
        && cmp "$tmp/mp_host.rfso" "$tmp/mp_qemu.rfso"; then
    pass "bit-identical on a meta-path + pathloss mission, seed 3 ($(cat "$tmp/mp.txt"))"
else
    fail "bit-identical on a meta-path + pathloss mission, seed 3"
fi
"$bin/rfseek-replay" --print "$tmp/mp.rfsr" | head -1 >"$tmp/mp_cfg.txt"
"$bin/rfseek-replay" --print "$tmp/mp_qemu.rfso" >"$tmp/mp_qemu.txt"
nl=$(awk '$1 == "OUT" && $5 == "state=2"' "$tmp/mp_qemu.txt" | wc -l)
nrel=$(grep '^DECISION' "$tmp/mp_qemu.txt" | grep -c 'relearned=1')
# -40 dBm is -5120 in the CONFIG frame's 1/128 dBm.
if grep -q $'model=pathloss\tstrategy=meta-path\tp0_min=-5120' "$tmp/mp_cfg.txt" && [ "$nrel" -ge 3 ] \
        && [ "$nl" -ge 10 ]; then
    pass "the mission ran meta-path + pathloss ($nrel relearns, $nl learning periods)"
else
    fail "the mission ran meta-path + pathloss" "$(cat "$tmp/mp_cfg.txt"); $nrel relearns, $nl learning periods"
fi
# The STM32 configuration's fit_early (docs/FIRMWARE.md, "Learning between periods") in the
# CFG record: the same mission with it on is live, host and image alike; `--fit-early off`
# records mp.rfsr's very bytes; with it on the relearns begin while the base brakes, so
# the decisions differ and fewer periods wait for a fit.
fea=(scenarios/default.yaml --seed 3 --model pathloss --strategy meta-path --p0-min -40 --fit-budget 600 --drop 20:21 --reset 30)
if "$bin/rfseek-record" "${fea[@]}" --fit-early on -o "$tmp/fe.rfsr" --live-out "$tmp/fe.rfso" >"$tmp/fe.txt" \
        && "$bin/rfseek-record" "${fea[@]}" --fit-early off -o "$tmp/fe0.rfsr" >/dev/null && cmp "$tmp/mp.rfsr" "$tmp/fe0.rfsr" \
        && "$bin/rfseek-replay" "$tmp/fe.rfsr" -o "$tmp/fe_host.rfso" && cmp "$tmp/fe.rfso" "$tmp/fe_host.rfso" \
        && qemu fe.rfsr fe_qemu.rfso && cmp "$tmp/fe_host.rfso" "$tmp/fe_qemu.rfso"; then
    pass "bit-identical on a meta-path + pathloss mission with fit_early, seed 3 ($(cat "$tmp/fe.txt"))"
else
    fail "bit-identical on a meta-path + pathloss mission with fit_early, seed 3"
fi
"$bin/rfseek-replay" --print "$tmp/fe_qemu.rfso" >"$tmp/fe_qemu.txt"
fl=$(awk '$1 == "OUT" && $5 == "state=2"' "$tmp/fe_qemu.txt" | wc -l)
frel=$(grep '^DECISION' "$tmp/fe_qemu.txt" | grep -c 'relearned=1')
"$bin/rfseek-replay" --print "$tmp/fe.rfsr" | head -1 >"$tmp/fe_cfg.txt"
if grep -q $'node=1\tfit_early=1\tmodel=pathloss' "$tmp/fe_cfg.txt" && [ "$frel" -ge 3 ] && [ "$fl" -lt "$nl" ] \
        && ! cmp -s <(grep '^DECISION' "$tmp/fe_qemu.txt") <(grep '^DECISION' "$tmp/mp_qemu.txt"); then
    pass "fit_early relearns early: decisions differ, $frel relearns, $fl learning periods (off: $nl)"
else
    fail "fit_early relearns early" "$(cat "$tmp/fe_cfg.txt"); $frel relearns, $fl learning periods (off: $nl)"
fi

# The same choice as a CONFIG frame on the bus before any input (the operator's, docs/CAN.md):
# the outputs equal the CFG choice's but for STATUS's Configured bit (bit 15, set in every
# STATUS of the CONFIG run, and so its checksum; no reset here: a reset returns to the
# defaults), byte for byte between the host and the image; its candump log passes canmatrix.
same_but_configured() {
    /usr/bin/python3 - "$1" "$2" <<'PY'
import sys
a = open(sys.argv[1]).read().splitlines()
c = open(sys.argv[2]).read().splitlines()
n = 0
ok = len(a) == len(c)
for x, y in zip(a, c):
    if x == y:
        continue
    fx, fy = x.split("\t"), y.split("\t")
    if fx[:4] != fy[:4] or fx[2] != "id=180" or not fx[4].startswith("data="):
        ok = False
        break
    dx, dy = bytes.fromhex(fx[4][5:]), bytes.fromhex(fy[4][5:])
    ok = ok and dx[1] & 0x80 == 0 and dy[1] == dx[1] | 0x80 and dx[0] == dy[0] and dx[2:7] == dy[2:7]
    n += 1
status = sum(1 for y in c if "\tid=180\t" in y)
sys.exit(0 if ok and n == status and n > 0 else 1)
PY
}
mp2=(scenarios/default.yaml --seed 3 --model pathloss --strategy meta-path --p0-min -40 --fit-budget 600 --drop 20:21)
if "$bin/rfseek-record" "${mp2[@]}" -o "$tmp/mpa.rfsr" --live-out "$tmp/mpa.rfso" >/dev/null \
        && "$bin/rfseek-record" "${mp2[@]}" --config-frame -o "$tmp/mpc.rfsr" --live-out "$tmp/mpc.rfso" \
            --candump "$tmp/mpc.log" >/dev/null \
        && "$bin/rfseek-replay" "$tmp/mpc.rfsr" -o "$tmp/mpc_host.rfso" && qemu mpc.rfsr mpc_qemu.rfso \
        && "$bin/rfseek-replay" --print "$tmp/mpa.rfso" >"$tmp/mpa.txt" \
        && "$bin/rfseek-replay" --print "$tmp/mpc.rfso" >"$tmp/mpc.txt" \
        && same_but_configured "$tmp/mpa.txt" "$tmp/mpc.txt" && cmp "$tmp/mpc.rfso" "$tmp/mpc_host.rfso" \
        && cmp "$tmp/mpc_host.rfso" "$tmp/mpc_qemu.rfso" && head -1 "$tmp/mpc.log" | grep -q ' can0 130#004500EC030000A7$' \
        && /usr/bin/python3 scripts/check_candump.py can/rfseek.dbc "$tmp/mpc.log" --sim >"$tmp/mpc_check.txt"; then
    pass "a CONFIG frame chooses what the CFG does: outputs equal but STATUS Configured, host and qemu ($(stat -c %s "$tmp/mpc.rfso") bytes)"
else
    fail "a CONFIG frame chooses what the CFG does" "$(grep FAIL "$tmp/mpc_check.txt" 2>/dev/null | head -3)"
fi

# A choice the image does not hold (meta-path + pathloss under the bridging target: one
# fit per node, two path-loss states): the recorder (its player) refuses it, one line, no
# file left; a stream with it (mp.rfsr with its CFG's target byte, at offset 18, made
# bridge) stops the
# host and the image with the same reason.
"$bin/rfseek-record" scenarios/bridge.yaml -o "$tmp/br.rfsr" --model pathloss --strategy meta-path \
    --max-time 5 >/dev/null 2>"$tmp/br_rec.err"; rrc=$?
{ head -c 18 "$tmp/mp.rfsr"; printf '\001'; tail -c +20 "$tmp/mp.rfsr"; } >"$tmp/br.rfsr"
"$bin/rfseek-replay" "$tmp/br.rfsr" -o "$tmp/br.rfso" 2>"$tmp/br.err"; hrc=$?
qemu br.rfsr br_q.rfso 2>"$tmp/br_q.err"; qrc=$?
why='CFG chooses a strategy, model and target the image does not hold'
if [ $rrc -eq 1 ] && [ $hrc -eq 1 ] && [ $qrc -ne 0 ] && [ "$(wc -l <"$tmp/br_rec.err")" -eq 1 ] \
        && grep -qF "$why" "$tmp/br_rec.err" && grep -qF "$why" "$tmp/br.err" && grep -qF "$why" "$tmp/br_q.err" \
        && ! compgen -G "$tmp/br.rfsr.tmp*" >/dev/null && [ ! -e "$tmp/br.rfso" ]; then
    pass "bridge + pathloss refused by the recorder, the host and the image: $why"
else
    fail "bridge + pathloss refused" "record $rrc $(cat "$tmp/br_rec.err"); host $hrc $(cat "$tmp/br.err"); qemu $qrc $(cat "$tmp/br_q.err")"
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

# A line break in an option, its value or a file name: one error line (shown as '?'),
# exit 2 for options / 1 for files, and no output or temporary file left (tmp/nl*).
# one_err NAME PROG RC TEXT ARGS...
one_err() {
    local name=$1 prog=$2 want=$3 text=$4
    shift 4
    "$bin/$prog" "$@" >/dev/null 2>"$tmp/nl_err.txt"
    local rc=$? lines
    lines=$(wc -l <"$tmp/nl_err.txt")
    mv "$tmp/nl_err.txt" "$tmp/err.txt"
    if [ $rc -ne "$want" ]; then fail "$name" "exit $rc"
    elif [ "$lines" -ne 1 ]; then fail "$name" "$lines stderr lines: $(head -c 200 "$tmp/err.txt")"
    elif ! grep -qF -- "$text" "$tmp/err.txt"; then fail "$name" "stderr '$(cat "$tmp/err.txt")' lacks '$text'"
    elif compgen -G "$tmp/nl*" >/dev/null; then fail "$name" "left $(ls -d "$tmp"/nl*)"
    else pass "$name"; fi
    rm -rf "$tmp"/nl*
}
nl=$'\n' scn=scenarios/default.yaml
one_err record-newline-option rfseek-record 2 "unknown option '--x?y'" $scn -o "$tmp/nl.rfsr" "--x${nl}y"
one_err record-newline-missing-value rfseek-record 2 "missing value for '--drop'" $scn -o "$tmp/nl.rfsr" --drop
one_err record-newline-max-time rfseek-record 2 "--max-time: bad value '1?2'" $scn -o "$tmp/nl.rfsr" --max-time "1${nl}2"
one_err record-newline-drop rfseek-record 2 "--drop: bad value '1:2?'" $scn -o "$tmp/nl.rfsr" --drop "1:2${nl}"
"$bin/rfseek-record" --help | grep -q -- '--fit-early on|off' && pass record-help-fit-early || fail record-help-fit-early
one_err record-sender-ahead-value rfseek-record 2 "--sender-ahead (seconds in [-1e6, 1e6]): bad value '2e6'" $scn -o "$tmp/nl.rfsr" --sender-ahead 2e6
one_err record-fit-early-value rfseek-record 2 "--fit-early (on or off): bad value 'yes'" $scn -o "$tmp/nl.rfsr" --fit-early yes
one_err record-newline-model rfseek-record 2 "--model: unknown 'a?b'" $scn -o "$tmp/nl.rfsr" --model "a${nl}b"
one_err record-newline-scenario rfseek-record 1 "nl?s.yaml" "$tmp/nl${nl}s.yaml" -o "$tmp/nl.rfsr"
one_err record-newline-out rfseek-record 1 "nl/a?b.rfsr" $scn -o "$tmp/nl/a${nl}b.rfsr" --max-time 1
one_err record-newline-live-out rfseek-record 1 "nl/a?b.rfso" $scn -o "$tmp/nl.rfsr" \
    --live-out "$tmp/nl/a${nl}b.rfso" --max-time 1
one_err record-no-out rfseek-record 2 "rfseek-record: " $scn
one_err replay-newline-option rfseek-replay 2 "--x?y: unknown option" "$tmp/in.rfsr" -o "$tmp/nl.rfso" "--x${nl}y"
one_err replay-newline-in rfseek-replay 1 "nl?none.rfsr: No such file" "$tmp/nl${nl}none.rfsr" -o "$tmp/nl.rfso"
one_err replay-newline-out rfseek-replay 1 "nl/a?b.rfso" "$tmp/in.rfsr" -o "$tmp/nl/a${nl}b.rfso"
one_err replay-newline-second-input rfseek-replay 2 "a?b" "$tmp/in.rfsr" "a${nl}b" -o "$tmp/nl.rfso"
one_err replay-missing-value rfseek-replay 2 "-o: missing value" "$tmp/in.rfsr" -o
# Values that once passed: a negative seed (wrapped), NaN times, empty file names (the -o
# stream was written, then the rename to "" failed); seeds are decimal ("010" is 10).
one_err record-seed-negative rfseek-record 2 "--seed: bad value '-1'" $scn -o "$tmp/nl.rfsr" --seed -1
one_err record-drop-nan rfseek-record 2 "--drop: bad value 'nan:1'" $scn -o "$tmp/nl.rfsr" --drop nan:1
one_err record-reset-nan rfseek-record 2 "--reset: bad value 'nan'" $scn -o "$tmp/nl.rfsr" --reset nan
one_err record-empty-out rfseek-record 2 "-o/--out: bad value ''" $scn -o ""
one_err record-empty-live-out rfseek-record 2 "--live-out: bad value ''" $scn -o "$tmp/nl.rfsr" --live-out ""
one_err record-empty-candump rfseek-record 2 "--candump: bad value ''" $scn -o "$tmp/nl.rfsr" --candump ""
# getopt_long's prefixes ("--se" for --seed) are not options: --help lists whole names.
one_err record-prefix-option rfseek-record 2 "unknown option '--se'" $scn -o "$tmp/nl.rfsr" --se 1
one_err record-prefix-flag rfseek-record 2 "unknown option '--config'" $scn -o "$tmp/nl.rfsr" --config --max-time 0.5
one_err replay-fit-budget-units rfseek-replay 2 "--fit-budget: expected work units in [0, 100000], got '5x'" "$tmp/in.rfsr" --fit-budget 5x -o "$tmp/nl.rfso"
one_err replay-empty-out rfseek-replay 2 "-o: empty value" "$tmp/in.rfsr" -o ""
one_err replay-empty-map rfseek-replay 2 "--map: empty value" "$tmp/in.rfsr" --map "" -o "$tmp/nl.rfso"
"$bin/rfseek-record" $scn -o "$tmp/s010.rfsr" --seed 010 --max-time 0.5 >/dev/null 2>&1
"$bin/rfseek-record" $scn -o "$tmp/s10.rfsr" --seed 10 --max-time 0.5 >/dev/null 2>&1
check record-seed-decimal 'cmp -s "$tmp/s010.rfsr" "$tmp/s10.rfsr"'
exit $((fails > 0))
