#!/bin/sh
# The live 802.11 run inside the VM (POSIX sh under busybox; tests/vm/run_wifi_vm_test.sh
# builds the VM and checks what this prints).
# usage: wifi_inner.sh DATADIR   (DATADIR holds the office map; rfseek-feed, rfseekd,
#                                 lcm_tool, hostapd, iw, tcpdump, candump and ip on PATH)
# Three mac80211_hwsim radios: phy0 an access point (hostapd, a beacon every 50 TU), phy1 a
# monitor interface mon0 made with iw, phy2 left in managed mode. On mon0 at once:
# tcpdump (the capture tshark reads on the host) and rfseek-feed --live --lcm publishing to
# rfseekd over udpm on loopback; lcm_tool poses as localisation; rfseekd drives vcan0,
# read by candump. The sender's simulated signal (hwsim's rx_rssi) steps every 0.4 s.
# Then, timed here and found again in the data on the host: the access point stops (the
# channel goes silent: the feed's heartbeats must go on), the feed is stopped with SIGSTOP
# (a hung feeder: heartbeats stop, the wheels must stop), continued, and ended with
# SIGTERM. Bad input: a managed-mode interface, and mon0 taken down under the feed.
# Prints PASS/FAIL lines for what is checked here, the files as "RFS-FILE NAME" + base64 of
# their gzip + "RFS-END", and a last line "RFS-VM-VERDICT: PASS" or "... FAIL (N)".
d=${1:?usage: wifi_inner.sh DATADIR}
w=/tmp/rfs-wifi
mkdir -p $w
fails=0
ok() { echo "PASS $1"; }
bad() { echo "FAIL $1"; fails=$((fails + 1)); }
dmesg -n 1  # no kernel lines inside the files printed below
url='udpm://239.255.76.67:7667?ttl=0'
ip link set lo up && ip route add 224.0.0.0/4 dev lo || bad wifi-loopback-multicast
ip link add dev vcan0 type vcan && ip link set vcan0 up || bad wifi-vcan0
mount -t debugfs none /sys/kernel/debug || bad wifi-debugfs

# The radios.
iw phy phy1 interface add mon0 type monitor && iw dev wlan1 del && ip link set mon0 up \
    && iw dev mon0 set freq 2412 && ok "wifi-monitor-mon0 ($(iw dev mon0 info | grep -c 'type monitor') monitor interface on phy1)" \
    || bad wifi-monitor-mon0
printf 'interface=wlan0\ndriver=nl80211\nssid=rfseek-live\nhw_mode=g\nchannel=1\nbeacon_int=50\n' > $w/hostapd.conf
hostapd -B -P $w/hostapd.pid $w/hostapd.conf > $w/hostapd.out 2>&1 || { bad wifi-hostapd; cat $w/hostapd.out; }
ap=$(cat /sys/class/net/wlan0/address)
echo "access point $ap"
rssi=/sys/kernel/debug/ieee80211/phy0/hwsim/rx_rssi  # the sender's: every receiver sees it
[ -w $rssi ] || bad "wifi-rx-rssi ($rssi missing)"

# Bad input: a managed-mode interface is not a monitor.
ip link set wlan2 up
rfseek-feed wlan2 --live --lcm "$url" --mac "$ap" > /dev/null 2> $w/bad1.err
rc=$?
if [ $rc -eq 1 ] && [ "$(wc -l < $w/bad1.err)" -eq 1 ] && grep -q "^rfseek-feed: wlan2: link type 1 (EN10MB) is not 127.*not a monitor-mode interface" $w/bad1.err; then
    ok "wifi-managed-interface-refused: $(cat $w/bad1.err)"
else
    bad "wifi-managed-interface-refused (exit $rc: $(cat $w/bad1.err))"
fi

# The run.
rfseekd --map $d/maps/office.yaml --lcm "$url" --can vcan0 --log $w/rfseekd.lcmlog > /dev/null 2> $w/rfseekd.err &
dpid=$!
lcm_tool pose "$url" 60 2> $w/pose.err &
ppid=$!
candump -L vcan0 > $w/can.log 2> $w/candump.err &
cpid=$!
tcpdump -i mon0 -w $w/mon0.pcap -U --immediate-mode --time-stamp-precision=nano > /dev/null 2> $w/tcpdump.err &
tpid=$!
sleep 1
rfseek-feed mon0 --live --lcm "$url" --mac "$ap" --stats > $w/feed.out 2> $w/feed.err &
fpid=$!
for v in -45 -52 -60 -67 -75 -70 -62 -55 -48 -41; do
    printf '%u\n' $v > $rssi || bad "wifi-rx-rssi $v"
    sleep 0.4
done
kill "$(cat $w/hostapd.pid)"  # silence
sleep 2.5
kill -STOP $fpid               # a hung feeder
sleep 1.5
kill -CONT $fpid
sleep 1.5
kill -TERM $fpid
wait $fpid
frc=$?
sleep 0.3
kill -TERM $dpid; wait $dpid
drc=$?
kill $ppid $cpid; kill -INT $tpid; wait $tpid
[ $frc -eq 0 ] && ok "wifi-feed-exit-0-on-sigterm ($(cat $w/feed.err))" || bad "wifi-feed-exit (rc $frc: $(cat $w/feed.err))"
[ $drc -eq 0 ] && ok "wifi-rfseekd-exit-0 ($(tail -1 $w/rfseekd.err))" || bad "wifi-rfseekd-exit (rc $drc: $(cat $w/rfseekd.err))"

# Bad input: the interface goes down under the feed: one line naming it, exit 1.
timeout 15 rfseek-feed mon0 --live --lcm "$url" --mac "$ap" > /dev/null 2> $w/bad2.err &
fpid=$!
sleep 1
ip link set mon0 down
wait $fpid
rc=$?
if [ $rc -eq 1 ] && [ "$(wc -l < $w/bad2.err)" -eq 1 ] && grep -q "^rfseek-feed: mon0: " $w/bad2.err; then
    ok "wifi-interface-down-ends-the-feed: $(cat $w/bad2.err)"
else
    bad "wifi-interface-down-ends-the-feed (exit $rc: $(cat $w/bad2.err))"
fi

for f in mon0.pcap rfseekd.lcmlog can.log feed.err rfseekd.err; do
    echo "RFS-FILE $f"
    gzip -c $w/$f | base64
    echo "RFS-END"
done
rm -rf $w
if [ $fails -eq 0 ]; then echo "RFS-VM-VERDICT: PASS"; else echo "RFS-VM-VERDICT: FAIL ($fails)"; fi
