#!/usr/bin/env bash
# safety.sh BUILD - safety: the wheels are commanded to zero within 200 ms when
# the pose or the RSSI input stops, at once when bxCAN goes bus-off, and after a
# watchdog reset; driving resumes when the inputs return. Each fault is injected into a
# simulated mission (scenarios/default.yaml) at a moment the robot is driving, and the
# recorded stream is played on the host build AND on the Cortex-M4 image under qemu;
# both output streams are checked (and must be identical).
set -uo pipefail
B=${1:-build}
. "$(dirname "$0")/../lib/fw_stream.sh"
rec() { "$bin/rfseek-record" scenarios/default.yaml --max-time 100 -o "$tmp/$1.rfsr" "${@:2}" >/dev/null; }
show() { "$bin/rfseek-replay" --print "$1"; }

# Moments the robot drives: OUT with non-zero wheels for the 300 ms before (6 steps).
rec base || { fail "baseline recording"; exit 1; }
"$bin/rfseek-replay" "$tmp/base.rfsr" -o "$tmp/base.rfso" && show "$tmp/base.rfso" >"$tmp/base.txt"
pick() { # pick AFTER_US -> first t >= AFTER_US preceded by 6 moving steps
    awk -v after="$1" '$1 == "OUT" { mv = ($3 != "left=0" || $4 != "right=0");
        run = mv ? run + 1 : 0; if (run >= 7 && $2 >= after) { print $2; exit } }' "$tmp/base.txt"
}
sec() { awk -v t="$1" -v d="${2:-0}" 'BEGIN { printf "%.6f", t / 1e6 + d }'; }

# check_stop NAME OUT_TXT KIND FAULT_US END_US STOP_US ALLOW_US FLAG
#   every OUT in [STOP_US + allowed, END_US) has zero wheels, there is at least one, the
#   robot moved in the 300 ms before FAULT_US, and moves again within 20 s after END_US.
check_stop() {
    local name=$1 txt=$2 kind=$3 t0=$4 t1=$5 stop=$6 allow=$7 flag=$8
    local r
    r=$(awk -v t0="$t0" -v t1="$t1" -v stop="$stop" -v allow="$allow" -v flag="$flag" '
        function hex(s,  i, c, v) { v = 0; s = tolower(substr(s, 3));
            for (i = 1; i <= length(s); i++) { c = index("0123456789abcdef", substr(s, i, 1)) - 1; v = v * 16 + c }
            return v }
        $1 == "OUT" { t = $2; mv = ($3 != "left=0" || $4 != "right=0"); split($6, f, "=");
            if (t >= t0 - 300000 && t < t0 && !mv) before_still++;
            if (t >= t0 - 300000 && t < t0) before++;
            if (t >= stop + allow && t < t1) { n++; if (mv) moving++; if (int(hex(f[2]) / flag) % 2) flagged++ }
            if (t >= t0 && t < t1 && mv && first_mv == "") first_mv = t;
            if (t >= t1 && t < t1 + 20000000 && mv && resume == "") resume = t }
        $1 == "CAN_TX" && $2 >= t0 && $2 < t1 { tx++ }
        END { printf "%d %d %d %d %d %s %s\n", before, before_still, n, moving, flagged + 0, tx + 0, (resume == "" ? "none" : resume) }' "$txt")
    read -r before still n moving flagged tx resume <<<"$r"
    local why=""
    [ "$before" -ge 5 ] && [ "$still" -eq 0 ] || why="robot not driving before the fault ($r)"
    [ -z "$why" ] && [ "$n" -ge 1 ] && [ "$moving" -eq 0 ] || why="${why:-$moving of $n steps still drive after $((allow / 1000)) ms}"
    [ -z "$why" ] && [ "$flagged" -eq "$n" ] || why="${why:-fault flag missing on $((n - flagged)) of $n steps}"
    if [ "$kind" = busoff ] && [ -z "$why" ] && [ "$tx" -ne 0 ]; then why="$tx frames sent while bus-off"; fi
    [ -z "$why" ] && [ "$resume" != none ] || why="${why:-did not resume within 20 s}"
    if [ -z "$why" ]; then
        pass "$name: zero within $((allow / 1000)) ms of the stop at $(sec "$stop") s, all $n steps until $(sec "$t1") s, resumed at $(sec "$resume") s"
    else
        fail "$name" "$why"
    fi
}

# case NAME KIND FLAG RECORD-OPTION...
run_case() {
    local name=$1 kind=$2 flag=$3 t0=$4 t1=$5; shift 5
    rec "$name" "$@" || { fail "$name: recording"; return; }
    "$bin/rfseek-replay" "$tmp/$name.rfsr" -o "$tmp/$name.host"
    qemu "$name.rfsr" "$name.qemu" || fail "$name: qemu image exit status"
    cmp -s "$tmp/$name.host" "$tmp/$name.qemu" || fail "$name: host and qemu outputs differ"
    show "$tmp/$name.rfsr" >"$tmp/$name.in.txt"
    # The stop moment: the last frame of the stopped stream(s) received before t0.
    local ids stop allow=200000
    case $kind in
        pose) ids="111" ;; rssi) ids="120" ;; both) ids="111 120" ;; *) ids="" ;;
    esac
    if [ -n "$ids" ]; then
        stop=$(awk -v t0="$t0" -v ids=" $ids " '$1 == "CAN" && $2 < t0 { split($3, a, "=");
            if (index(ids, " " a[2] " ")) last = $2 } END { print last + 0 }' "$tmp/$name.in.txt")
    else
        stop=$t0; allow=0 # bus-off and reset: zero from the very first step
    fi
    for side in host qemu; do
        show "$tmp/$name.$side" >"$tmp/$name.$side.txt"
        check_stop "$name ($side)" "$tmp/$name.$side.txt" "$kind" "$t0" "$t1" "$stop" "$allow" "$flag"
    done
}

t=$(pick 15000000); [ -n "$t" ] || { fail "no driving moment found in the baseline"; exit 1; }
run_case pose-stops pose 256 "$t" $((t + 2000000)) --drop-pose "$(sec "$t"):$(sec "$t" 2)"
t=$(pick $((t + 5000000)))
run_case rssi-stops rssi 512 "$t" $((t + 2000000)) --drop-rssi "$(sec "$t"):$(sec "$t" 2)"
t=$(pick $((t + 5000000)))
run_case inputs-stop both 256 "$t" $((t + 2000000)) --drop "$(sec "$t"):$(sec "$t" 2)"
t=$(pick $((t + 5000000)))
run_case bus-off busoff 1024 "$t" $((t + 1000000)) --bus-off "$(sec "$t"):$(sec "$t" 1)"
t=$(pick $((t + 5000000)))
# After a reset the application needs a pose and a measurement again: zero for >= 50 ms.
run_case watchdog-reset reset 2048 "$t" $((t + 50000)) --reset "$(sec "$t")"
exit $((fails > 0))
