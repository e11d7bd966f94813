#!/bin/sh
# The SocketCAN test proper (POSIX sh: runs under busybox in the VM, or natively).
# usage: can_inner.sh DATADIR   (DATADIR holds cansend.txt, expect_recv.txt, now_us;
#                                can_vm_test, candump, cansend and ip are on PATH)
# Prints PASS/FAIL lines and a last line "RFS-VM-VERDICT: PASS" or "RFS-VM-VERDICT: FAIL".
d=${1:?usage: can_inner.sh DATADIR}
w=/tmp/rfs-can-$$
mkdir -p $w
fails=0
ok() { echo "PASS $1"; }
bad() { echo "FAIL $1"; fails=$((fails + 1)); }

if ip link add dev vcan0 type vcan && ip link set vcan0 up; then ok can-vcan0-up; else bad can-vcan0-up; fi

# 1. Our frames on the bus exactly as encoded: candump -L's lines are our writer's (lx_candump)
#    but for the time stamps.
candump -L vcan0 > $w/candump.log 2>$w/candump.err &
cpid=$!
sleep 1
if can_vm_test send vcan0 $w/expect_send.txt; then ok can-send; else bad can-send; fi
sleep 1
kill $cpid; wait $cpid 2>/dev/null
cut -d' ' -f2- $w/candump.log > $w/got_send.txt
cut -d' ' -f2- $w/expect_send.txt > $w/want_send.txt
if [ -s $w/want_send.txt ] && cmp -s $w/want_send.txt $w/got_send.txt; then
    ok "can-candump-matches ($(wc -l < $w/got_send.txt) frames)"
else
    bad can-candump-matches; echo "expected:"; cat $w/want_send.txt; echo "candump:"; cat $w/got_send.txt $w/candump.err
fi

# 2. Frames sent with cansend reach our receiver and decode; bad ones are counted.
can_vm_test recv vcan0 "$(cat $d/now_us)" > $w/got_recv.txt 2>&1 &
rpid=$!
sleep 1
while read -r fr; do cansend vcan0 "$fr" || bad "cansend $fr"; done < $d/cansend.txt
wait $rpid
if cmp -s $d/expect_recv.txt $w/got_recv.txt; then
    ok "can-cansend-decoded ($(wc -l < $w/got_recv.txt) lines)"
else
    bad can-cansend-decoded; echo "expected:"; cat $d/expect_recv.txt; echo "got:"; cat $w/got_recv.txt
fi

# 3. Interface down/up, bus-off report and recovery, missing interface.
can_vm_test faults vcan0 > $w/faults.txt 2>&1
rc=$?
cat $w/faults.txt
if [ $rc -ne 0 ] || grep -q '^FAIL' $w/faults.txt || ! grep -q '^PASS can-busoff-recovers' $w/faults.txt; then
    fails=$((fails + 1))
fi

# 4. The simulator and rfseekd as two processes, wheel commands over SocketCAN (vcan0),
#    pose/RSSI/clock/status over udpm on loopback (a VM or a namespace of our own). Under
#    TCG a whole mission takes minutes: run the first 8 simulated seconds and require
#    decisions, movement and an answer to every control step.
if command -v rfseekd >/dev/null && command -v rfseek-sim-lcm >/dev/null && [ -f $d/scn/default.yaml ]; then
    ip link set lo up; ip route add 224.0.0.0/4 dev lo 2>/dev/null
    url='udpm://239.255.76.67:7667?ttl=0'
    rfseekd --map $d/scn/maps/office.yaml --lcm "$url" --can vcan0 --clock-lcm --idle-exit 3000 \
        > /dev/null 2> $w/d.err &
    dpid=$!
    sleep 1
    t0=$(date +%s); rfseek-sim-lcm $d/scn/default.yaml --lcm "$url" --can vcan0 --max-time 8 --timeout-ms 20000 \
        > $w/summary.json 2> $w/s.err
    src=$?; echo "two-process run took $(( $(date +%s) - t0 )) s"
    wait $dpid
    it=$(sed -n 's/.*"iterations": *\([0-9]*\).*/\1/p' $w/summary.json)
    dist=$(sed -n 's/.*"distance_travelled_m": *\([0-9]*\).*/\1/p' $w/summary.json)
    if [ $src -eq 0 ] && [ "${it:-0}" -ge 2 ] && [ "${dist:-0}" -ge 1 ]; then
        ok "can-two-process-socketcan ($it decisions, ${dist} m in 8 s, every step answered over vcan0)"
    else
        bad "can-two-process-socketcan (rc $src, iterations ${it:-?}, distance ${dist:-?})"; cat $w/s.err $w/d.err | head -5
    fi
    tail -1 $w/d.err
fi

ip link del dev vcan0
rm -rf $w
if [ $fails -eq 0 ]; then echo "RFS-VM-VERDICT: PASS"; else echo "RFS-VM-VERDICT: FAIL ($fails)"; fi
