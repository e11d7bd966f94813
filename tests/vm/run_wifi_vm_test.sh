#!/usr/bin/env bash
# The live 802.11 feed end to end (docs/FEEDER.md, "Live to the controller"): Debian's
# current kernel under qemu (TCG; tests/vm/vm_lib.sh, shared with the SocketCAN test) with
# mac80211_hwsim, cfg80211, mac80211 and vcan; hostapd's beacons on one simulated radio, a
# monitor interface made with iw on another, `rfseek-feed --live mon0 --lcm udpm://...`
# -> rfseekd (poses from lcm_tool) -> wheel frames on vcan0 read by candump
# (tests/vm/wifi_inner.sh runs it).
#
# The reference for the dBm values is tshark, run here on the host, not in the VM: tshark
# and its libraries would more than double the initramfs that qemu loads under TCG. In the
# VM, tcpdump captures the same interface at the same time (the same frames, the same
# kernel time stamps) into a pcap file; that file, rfseekd's LCM log (every RFS_RSSI and
# RFS_RSSI_STATUS it received), candump's log and the programs' last lines come out
# through the serial console (gzip + base64), and tests/vm/wifi_check.py compares them.
# usage: tests/vm/run_wifi_vm_test.sh BUILD   (kernel package cached in BUILD/vm/)
set -uo pipefail
build=${1:?usage: run_wifi_vm_test.sh BUILD}
here=$(cd "$(dirname "$0")" && pwd)
top=$here/../..
vm=$build/vm
fail() { echo "FAIL wifi-vm: $*"; exit 1; }
for p in "$build/bin/rfseek-feed" "$build/bin/rfseekd" "$build/tests/wire/lcm_tool"; do
    [ -x "$p" ] || fail "$p missing (make $p)"
done
mkdir -p "$vm"

. "$here/vm_lib.sh"
vm_kernel "mac80211_hwsim radios=3" can-raw vcan
vm_root "$vm/wifi-root"
cp "$here/wifi_inner.sh" "$root/inner.sh"
mkdir -p "$root/data/maps" "$root/etc"
cp "$top/scenarios/maps/office.yaml" "$top/scenarios/maps/office.pgm" "$root/data/maps/"
# tcpdump drops its privileges to the user tcpdump: uid 0 here.
printf 'root:x:0:0:root:/:/bin/sh\ntcpdump:x:0:0::/:/bin/sh\n' > "$root/etc/passwd"
printf 'root:x:0:\n' > "$root/etc/group"
for p in iw hostapd tcpdump ip candump; do vm_copy_dyn "$p"; done
PATH="$build/bin:$build/tests/wire:$PATH"
for p in rfseek-feed rfseekd lcm_tool; do vm_copy_dyn "$p"; done

# A timing check failed while the VM stalled (wifi_check.py exits 3: the host was too
# loaded to say): the VM runs once more, the first try's lines shown as "first try, PASS: ...".
for try in 1 2; do
    vm_boot wifi 512M 180 > "$vm/wifi-lines.txt"
    rc=$?
    out=$vm/wifi-out
    rm -rf "$out" && mkdir -p "$out"
    # The files: between "RFS-FILE NAME" and "RFS-END", base64 of their gzip.
    awk -v dir="$out" '/^RFS-FILE /{f = dir "/" $2 ".gz.b64"; next} /^RFS-END$/{f = ""; next} f != ""{print > f}' "$log.txt"
    for b in "$out"/*.gz.b64; do
        [ -e "$b" ] || break
        base64 -d < "$b" | gzip -dc > "${b%.gz.b64}" || fail "cannot decode $(basename "$b") from the console"
    done
    case $rc in
        0) ;;
        124) cat "$vm/wifi-lines.txt"; fail "qemu timed out (log $log.txt)" ;;
        *) cat "$vm/wifi-lines.txt"; grep -v '^[A-Za-z0-9+/=]*$' "$log.txt" | tail -30
           fail "no PASS verdict on the serial console (log $log.txt)" ;;
    esac
    ap=$(sed -n 's/^access point //p' "$log.txt")
    /usr/bin/python3 "$here/wifi_check.py" "$out" "$ap" "$build/gen/python" > "$vm/wifi-check.txt"
    crc=$?
    if [ $crc -eq 3 ] && [ $try -eq 1 ]; then
        sed -E 's/^(PASS|FAIL) /first try, \1: /' "$vm/wifi-lines.txt" "$vm/wifi-check.txt"
        continue
    fi
    cat "$vm/wifi-lines.txt"
    echo "PASS wifi-vm-verdict ($pkg)"
    cat "$vm/wifi-check.txt"
    exit $crc
done
