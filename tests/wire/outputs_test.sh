#!/usr/bin/env bash
# outputs_test.sh BUILD - the Linux programs' outputs under stress: an output that is the
# input (refused before any work, the input intact), stdout on /dev/full (exit 1, one
# line), a full disk for rfseekd --log (a 200 KB tmpfs: no PATH.tmp left), rfseekd
# --replay and rfseek-sim-lcm's file:// of logs that are not LCM logs, and replay streams
# cut before their END record.
set -uo pipefail
B=${1:?usage: outputs_test.sh BUILD}
bin=$B/bin map=scenarios/maps/office.yaml
w=$(mktemp -d /tmp/rfs_outputs.XXXXXX)
ns=rfsout$$
trap 'mountpoint -q "$w/full" && umount "$w/full"; ip netns del "$ns" 2>/dev/null; rm -rf -- "$w"' EXIT
. "$(dirname "$0")/../lib/checks.sh"
# err NAME RC TEXT PROG ARGS...: exit RC, exactly one stderr line containing TEXT.
err() {
    local name=$1 want=$2 text=$3 p=$4; shift 4
    "$bin/$p" "$@" >"$w/out" 2>"$w/err"; local rc=$?
    if [ $rc -ne "$want" ]; then fail "$name" "exit $rc: $(head -c 300 "$w/err")"
    elif [ "$(wc -l <"$w/err")" -ne 1 ]; then fail "$name" "$(wc -l <"$w/err") stderr lines: $(head -c 300 "$w/err")"
    elif ! grep -qF -- "$text" "$w/err"; then fail "$name" "stderr '$(cat "$w/err")' lacks '$text'"
    else pass "$name"; fi
}
full=$'No space left on device'

# --- inputs --------------------------------------------------------------------------------
"$B/tests/wire/lcm_tool" mklog "$w/bad.lcmlog" || fail lcm-mklog
# a log of well-formed messages only: what rfseekd records of the crafted one
"$bin/rfseekd" --map $map --clock-lcm --lcm memq:// --replay "$w/bad.lcmlog" --log "$w/in.lcmlog" >/dev/null 2>&1 || fail lcm-clean-log
"$bin/rfseek-record" scenarios/default.yaml -o "$w/in.rfsr" --max-time 3 >/dev/null || fail record
"$bin/rfseek-replay" "$w/in.rfsr" -o "$w/out.rfso" || fail replay

# --- row: output = input -------------------------------------------------------------------
cp "$w/in.rfsr" "$w/same.rfsr"; ln -s same.rfsr "$w/link.rfsr"
err replay-out-is-in 1 "is the input" rfseek-replay "$w/same.rfsr" -o "$w/link.rfsr"
check replay-out-is-in-intact 'cmp -s "$w/same.rfsr" "$w/in.rfsr" && ! compgen -G "$w/same.rfsr.tmp*" >/dev/null'
cp "$w/in.lcmlog" "$w/same.lcmlog"
err rfseekd-log-is-replay 1 "is the input" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/same.lcmlog" --log "$w/same.lcmlog"
err rfseekd-decisions-is-replay 1 "is the input" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/same.lcmlog" --decisions "$w/same.lcmlog"
err rfseekd-log-is-decisions 1 "is also written as" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/in.lcmlog" --log "$w/new.lcmlog" --decisions "$w/./new.lcmlog"
check rfseekd-log-is-decisions-nothing 'test ! -e "$w/new.lcmlog"'
check rfseekd-out-is-in-intact 'cmp -s "$w/same.lcmlog" "$w/in.lcmlog"'
err rfseekd-log-dir-missing 1 "$w/no/out.lcmlog: No such file or directory" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/in.lcmlog" --log "$w/no/out.lcmlog"
cap=$(ls tests/data/captures/*.pcap | head -1)
cp "$cap" "$w/same.pcap"
err feed-output-is-capture 1 "is the input" rfseek-feed "$w/same.pcap" --mac 02:00:00:00:00:01 --output "$w/same.pcap"
check feed-output-is-capture-intact 'cmp -s "$w/same.pcap" "$cap"'
err feed-output-dir-missing 1 "No such file or directory" rfseek-feed "$w/same.pcap" --mac 02:00:00:00:00:01 --output "$w/no/x.tsv"
printf 't_us,x_m,y_m,theta_rad\n1700000000000000,8,6,0\n1700000001000000,9,6,0\n' >"$w/p.csv"
mkdir "$w/exists"
err feed-out-exists 1 "$w/exists: already exists" rfseek-feed "$cap" --pose "$w/p.csv" --scenario scenarios/default.yaml --out "$w/exists"
check feed-out-exists-untouched '[ -z "$(ls -A "$w/exists")" ] && ! compgen -G "$w/exists.tmp*" >/dev/null'
# An output that is a directory or a FIFO: refused before any work (renamed into place, a
# directory failed after the work and a device or FIFO node would have been replaced).
mkfifo "$w/fifo"
for o in exists fifo; do
    want=$([ $o = exists ] && echo "Is a directory" || echo "not a regular file")
    err "replay-out-$o" 1 "$w/$o: $want" rfseek-replay "$w/in.rfsr" -o "$w/$o"
    err "rfseekd-log-$o" 1 "$w/$o: $want" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/in.lcmlog" --log "$w/$o"
    err "rfseekd-decisions-$o" 1 "$w/$o: $want" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/in.lcmlog" --decisions "$w/$o"
    err "feed-output-$o" 1 "$w/$o: $want" rfseek-feed "$cap" --mac 02:00:00:00:00:01 --output "$w/$o"
    err "map-pgm-$o" 1 "$w/$o: $want" rfseek-map $map --pgm "$w/$o"
    err "record-out-$o" 1 "$w/$o: $want" rfseek-record scenarios/default.yaml -o "$w/$o" --max-time 3
    err "sim-pcap-$o" 1 "$w/$o: $want" rfseek-sim scenarios/default.yaml --seed 1 --pcap "$w/$o"
done
check outputs-dir-fifo-untouched '[ -z "$(ls -A "$w/exists")" ] && [ -p "$w/fifo" ] && ! compgen -G "$w/fifo.tmp*" >/dev/null'
cp scenarios/maps/office.yaml "$w/office.yaml"; sed -i "s|^image: *|image: $PWD/scenarios/maps/|" "$w/office.yaml"
err map-pgm-is-yaml 1 "is the input" rfseek-map "$w/office.yaml" --pgm "$w/office.yaml"
cp scenarios/default.yaml "$w/scn.yaml"; sed -i "s|^map: *|map: $PWD/scenarios/|" "$w/scn.yaml"
cp "$w/scn.yaml" "$w/scn.orig"
err record-out-is-scenario 1 "is the input" rfseek-record "$w/scn.yaml" -o "$w/scn.yaml" --max-time 3
err record-live-is-scenario 1 "is the input" rfseek-record "$w/scn.yaml" -o "$w/r.rfsr" --live-out "$w/scn.yaml" --max-time 3
err record-live-is-out 1 "is also written as" rfseek-record "$w/scn.yaml" -o "$w/r.rfsr" --live-out "$w/r.rfsr" --max-time 3
check record-scenario-intact 'cmp -s "$w/scn.yaml" "$w/scn.orig" && [ ! -e "$w/r.rfsr" ]'
err record-out-dir-missing 1 "$w/no/r.rfsr: No such file or directory" rfseek-record "$w/scn.yaml" -o "$w/no/r.rfsr" --max-time 3

# --- row: stdout on /dev/full --------------------------------------------------------------
exec 3>&1
for c in "rfseek-map $map" "rfseek-replay --print $w/out.rfso" "rfseekd --map $map --clock-lcm --lcm memq:// --replay $w/bad.lcmlog" \
         "rfseek-feed $cap --mac 90:a4:de:c0:46:11"; do
    # shellcheck disable=SC2086
    "$bin"/$c >/dev/full 2>"$w/err"; rc=$?
    name="stdout-full-${c%% *}"
    [ $rc -eq 1 ] && [ "$(grep -c . "$w/err" | head -1)" -ge 1 ] && grep -qF "${c%% *}: stdout: $full" "$w/err" \
        && [ "$(grep -vc -e '^rfseekd: dropped LCM message' -e '(dropped, counted)$' -e '^rfseekd: [0-9]* steps, ' "$w/err")" -eq 1 ] && pass "$name" || fail "$name" "rc $rc: $(head -c 300 "$w/err")"
done

# --help to /dev/full: the text lost, exit 1 (every program returns through its stdout).
for p in rfseek-map rfseek-replay rfseekd rfseek-feed rfseek-record rfseek-sim rfseek-sim-lcm; do
    "$bin/$p" --help >/dev/full 2>"$w/err"; rc=$?
    [ $rc -eq 1 ] && [ "$(cat "$w/err")" = "$p: stdout: $full" ] && pass "help-full-$p" || fail "help-full-$p" "rc $rc: $(head -c 200 "$w/err")"
done

# rfseek-record prints its summary to stdout.
"$bin/rfseek-record" "$w/scn.yaml" -o "$w/r2.rfsr" --max-time 3 >/dev/full 2>"$w/err"; rc=$?
[ $rc -eq 1 ] && [ "$(wc -l <"$w/err")" -eq 1 ] && grep -qF "rfseek-record: stdout: $full" "$w/err" \
    && pass stdout-full-rfseek-record || fail stdout-full-rfseek-record "rc $rc: $(head -c 300 "$w/err")"

# rfseek-sim-lcm prints summary.json; its controller is rfseekd in another process, over
# udpm:// inside a private network namespace (memq:// does not cross processes), as in
# tests/wire/rfseekd_test.sh. sim_lcm OUT: one 2 s run, stdout to OUT; sets rc.
url='udpm://239.255.76.67:7667?ttl=0'
sim_lcm() {
    ip netns exec "$ns" timeout 60 "$bin/rfseekd" --map $map --lcm "$url" --can-over-lcm --clock-lcm \
        --idle-exit 1000 >/dev/null 2>"$w/d.err" &
    local dpid=$!
    sleep 0.5
    ip netns exec "$ns" timeout 60 "$bin/rfseek-sim-lcm" scenarios/default.yaml --lcm "$url" --max-time 2 \
        >"$1" 2>"$w/err"
    rc=$?
    wait $dpid
}
if ip netns add "$ns" 2>/dev/null && ip netns exec "$ns" ip link set lo up \
    && ip netns exec "$ns" ip route add 224.0.0.0/4 dev lo; then
    sim_lcm "$w/summary.json"
    check stdout-file-rfseek-sim-lcm '[ $rc -eq 0 ] && [ ! -s "$w/err" ] && grep -q "\"sim_time_s\"" "$w/summary.json"'
    sim_lcm /dev/full
    [ $rc -eq 1 ] && [ "$(cat "$w/err")" = "rfseek-sim-lcm: stdout: $full" ] \
        && pass stdout-full-rfseek-sim-lcm || fail stdout-full-rfseek-sim-lcm "rc $rc: $(head -c 300 "$w/err")"
    ip netns del "$ns"
else
    echo "SKIP stdout-full-rfseek-sim-lcm: cannot create a network namespace (needs root)"
fi

# --- row: full disk, rfseekd --log leaves no temporary -------------------------------------
mkdir -p "$w/full"
if mount -t tmpfs -o size=200k tmpfs "$w/full" 2>/dev/null; then
    head -c 300000 /dev/zero >"$w/full/fill" 2>/dev/null
    "$bin/rfseekd" --map $map --clock-lcm --lcm memq:// --replay "$w/bad.lcmlog" --log "$w/full/out.lcmlog" >/dev/null 2>"$w/err"
    check rfseekd-log-disk-full '[ $? -eq 1 ] && [ "$(grep -v -e "^rfseekd: dropped LCM message" -e "(dropped, counted)$" -e "^rfseekd: [0-9]* steps, " "$w/err")" = "rfseekd: $w/full/out.lcmlog: could not finish the log (write failed)" ]' 
    check rfseekd-log-disk-full-no-tmp '[ ! -e "$w/full/out.lcmlog.tmp" ] && [ ! -e "$w/full/out.lcmlog" ]'
    "$bin/rfseekd" --map $map --clock-lcm --lcm memq:// --replay "$w/bad.lcmlog" --decisions "$w/full/d.txt" >/dev/null 2>"$w/err"
    check rfseekd-decisions-disk-full '[ $? -eq 1 ] && [ "$(grep -v -e "^rfseekd: dropped LCM message" -e "(dropped, counted)$" -e "^rfseekd: [0-9]* steps, " "$w/err")" = "rfseekd: $w/full/d.txt: write failed" ] && [ "$(ls "$w/full")" = fill ]'
    # The other programs' files on the full disk: one line naming the file, nothing left.
    for c in "record:rfseek-record scenarios/default.yaml -o $w/full/r.rfsr --max-time 3" \
             "replay:rfseek-replay $w/in.rfsr -o $w/full/o.rfso" \
             "feed:rfseek-feed $cap --mac 90:a4:de:c0:46:11 --output $w/full/x.tsv" \
             "feed-pose:rfseek-feed $cap --pose $w/p.csv --scenario scenarios/default.yaml --out $w/full/d" \
             "map:rfseek-map $map --pgm $w/full/m.pgm" \
             "record-live:rfseek-record scenarios/default.yaml -o $w/r3.rfsr --live-out $w/full/l.rfso --max-time 3"; do
        # shellcheck disable=SC2086
        "$bin"/${c#*:} >/dev/null 2>"$w/err"; rc=$?
        [ $rc -eq 1 ] && [ "$(wc -l <"$w/err")" -eq 1 ] && grep -qF "$w/full/" "$w/err" && [ "$(ls "$w/full")" = fill ] \
            && pass "disk-full-${c%%:*}" || fail "disk-full-${c%%:*}" "rc $rc: $(head -c 200 "$w/err"); left: $(ls "$w/full" | tr '\n' ' ')"
    done
    check disk-full-record-live-nothing-left '[ ! -e "$w/r3.rfsr" ] && ! compgen -G "$w/r3.rfsr.tmp*" >/dev/null'
    umount "$w/full"
else
    echo "SKIP rfseekd-log-disk-full: mount -t tmpfs not permitted"
fi

# --- row: rfseekd --replay of what is not an LCM log ---------------------------------------
head -c 51200 /dev/urandom >"$w/random.lcmlog"
err rfseekd-replay-random 1 "random.lcmlog: offset 0: not an LCM event" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/random.lcmlog"
sz=$(stat -c %s "$w/in.lcmlog")
head -c $((sz - 7)) "$w/in.lcmlog" >"$w/cut.lcmlog"
err rfseekd-replay-cut 1 "event cut short" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/cut.lcmlog"
{ cat "$w/in.lcmlog"; printf '\xed\xa1\xda\x01\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x03\xe8\0\0\0\0'; head -c 1000 /dev/zero | tr '\0' A; } >"$w/longch.lcmlog"
err rfseekd-replay-long-channel 1 "channel name of 1000 bytes" rfseekd --map $map --clock-lcm --lcm memq:// --replay "$w/longch.lcmlog"
# The same logs played to rfseek-sim-lcm through LCM's file:// provider (liblcm would stop
# without a word, or print its own line and play on): one line before any step, exit 1.
for c in "random:offset 0: not an LCM event" "cut:event cut short" "longch:channel name of 1000 bytes"; do
    err "sim-lcm-file-${c%%:*}" 1 "lcm: file://$w/${c%%:*}.lcmlog?speed=0: offset" \
        rfseek-sim-lcm scenarios/default.yaml --lcm "file://$w/${c%%:*}.lcmlog?speed=0" --max-time 1
    grep -qF "${c#*:}" "$w/err" || fail "sim-lcm-file-${c%%:*}-reason" "$(cat "$w/err")"
    [ -s "$w/out" ] && fail "sim-lcm-file-${c%%:*}-no-summary" "$(head -c 100 "$w/out")"
done
# /dev/zero has no size to measure events by (liblcm scanned it for a sync word for ever).
err rfseekd-replay-dev-zero 1 "/dev/zero: not a regular file" rfseekd --map $map --clock-lcm --lcm memq:// --replay /dev/zero
timeout 20 "$bin/rfseek-sim-lcm" scenarios/default.yaml --lcm "file:///dev/zero?speed=0" --max-time 1 >"$w/out" 2>"$w/err"
check sim-lcm-file-dev-zero '[ $? -eq 1 ] && [ "$(cat "$w/err")" = "rfseek-sim-lcm: lcm: file:///dev/zero?speed=0: not a regular file (an LCM log is read by its lengths)" ]'
check rfseekd-replay-valid 'bin/true 2>/dev/null; "$bin/rfseekd" --map $map --clock-lcm --lcm memq:// --replay "$w/in.lcmlog" >/dev/null 2>&1'

# --- row: replay streams without their END record ------------------------------------------
head -c 8 "$w/in.rfsr" >"$w/header.rfsr"
n=$(stat -c %s "$w/in.rfsr"); head -c $((n - 2)) "$w/in.rfsr" >"$w/noend.rfsr"
err replay-header-only 1 "header.rfsr: offset 8: truncated (only the header)" rfseek-replay "$w/header.rfsr" -o "$w/x.rfso"
err replay-header-only-print 1 "truncated (only the header)" rfseek-replay --print "$w/header.rfsr"
err replay-no-end 1 "noend.rfsr: offset $((n - 2)): truncated (no END record)" rfseek-replay "$w/noend.rfsr" -o "$w/x.rfso"
err replay-no-end-print 1 "truncated (no END record)" rfseek-replay --print "$w/noend.rfsr"
check replay-no-end-nothing-left '! compgen -G "$w/x.rfso*" >/dev/null'
# Read as it is parsed, through a 64 KB window: an endless input (the stream, then
# /dev/zero, on a pipe) ends at its END record in bounded memory (it was read whole first).
(ulimit -v 300000; cat "$w/in.rfsr" /dev/zero | timeout 20 "$bin/rfseek-replay" /dev/stdin -o "$w/endless.rfso"; exit "${PIPESTATUS[1]}") 2>"$w/err"
check replay-endless-input-stops-at-end '[ $? -eq 0 ] && [ ! -s "$w/err" ] && cmp -s "$w/endless.rfso" "$w/out.rfso"'
err replay-dev-zero 1 "/dev/zero: offset 0: not an rfseek stream (bad header)" rfseek-replay /dev/zero -o "$w/z.rfso"
check replay-output-stream-prints '"$bin/rfseek-replay" --print "$w/out.rfso" >/dev/null'
exit $((fails > 0))
