#!/usr/bin/env bash
# SocketCAN test against the real Linux CAN stack. Where the host kernel has
# vcan, runs tests/vm/can_inner.sh natively; otherwise boots Debian's current kernel
# under qemu (TCG) with a busybox-static initramfs holding our static test binary,
# candump/cansend (can-utils) and ip, and reads the verdict from the serial console
# (tests/vm/vm_lib.sh, shared with the 802.11 test).
# usage: tests/vm/run_vm_test.sh BUILD     (kernel package cached in BUILD/vm/)
set -uo pipefail
build=${1:?usage: run_vm_test.sh BUILD}
here=$(cd "$(dirname "$0")" && pwd)
vm=$build/vm
bin=$build/tests/vm/can_vm_test
mkdir -p "$vm"
fail() { echo "FAIL can-vm: $*"; exit 1; }
[ -x "$bin" ] || fail "$bin missing (make $bin)"
data=$vm/data
mkdir -p "$data"
/usr/bin/python3 "$here/vm_frames.py" "$data" || fail "vm_frames.py failed"

# Native run where the kernel has vcan, inside a network namespace of our own (the
# probe too: nothing is created in the default namespace).
ns=rfscan$$
if ip netns add "$ns" 2>/dev/null; then
    if ip netns exec "$ns" ip link add dev rfsprobe type vcan 2>/dev/null; then
        trap 'ip netns del "$ns" 2>/dev/null' EXIT
        ip netns exec "$ns" ip link del dev rfsprobe
        if [ -f "$here/../../scenarios/maps/office.pgm" ]; then
            mkdir -p "$data/scn/maps"
            cp "$here/../../scenarios/default.yaml" "$data/scn/"
            cp "$here/../../scenarios/maps/office.yaml" "$here/../../scenarios/maps/office.pgm" "$data/scn/maps/"
        fi
        out=$(PATH="$(dirname "$bin"):$build/bin:$PATH" ip netns exec "$ns" sh "$here/can_inner.sh" "$data" 2>&1)
        ip netns del "$ns"; trap - EXIT
        echo "$out" | grep -E '^(PASS|FAIL) '
        echo "$out" | grep -q '^RFS-VM-VERDICT: PASS' && { echo "PASS can-native-verdict"; exit 0; }
        echo "$out"; fail "native verdict not PASS"
    fi
    ip netns del "$ns"
fi

# The kernel with can-raw and vcan (and what they depend on), and the initramfs.
. "$here/vm_lib.sh"
vm_kernel can-raw vcan
vm_root "$vm/can-root"
cp "$bin" "$root/bin/can_vm_test"
cp "$here/can_inner.sh" "$root/inner.sh"
cp "$data/cansend.txt" "$data/expect_recv.txt" "$data/now_us" "$root/data/"
vm_copy_dyn candump; vm_copy_dyn cansend; vm_copy_dyn ip
# The two-process run over SocketCAN (optional: when the programs and the map exist).
if [ -x "$build/bin/rfseekd" ] && [ -x "$build/bin/rfseek-sim-lcm" ] && [ -f "$here/../../scenarios/maps/office.pgm" ]; then
    PATH="$build/bin:$PATH" vm_copy_dyn rfseekd
    PATH="$build/bin:$PATH" vm_copy_dyn rfseek-sim-lcm
    mkdir -p "$root/data/scn/maps"
    cp "$here/../../scenarios/default.yaml" "$root/data/scn/"
    cp "$here/../../scenarios/maps/office.yaml" "$here/../../scenarios/maps/office.pgm" "$root/data/scn/maps/"
fi

vm_boot can 256M 400
case $? in
    0) echo "PASS can-vm-verdict ($pkg)"; exit 0 ;;
    124) fail "qemu timed out (log $log.txt)" ;;
esac
tail -40 "$log.txt"
fail "no PASS verdict on the serial console (log $log.txt)"
