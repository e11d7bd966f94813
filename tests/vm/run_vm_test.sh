#!/usr/bin/env bash
# SocketCAN test against the real Linux CAN stack. Where the host kernel has
# vcan, runs tests/vm/can_inner.sh natively; otherwise boots Debian's current kernel
# under qemu (TCG) with a busybox-static initramfs holding our static test binary,
# candump/cansend (can-utils) and ip, and reads the verdict from the serial console.
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

# The kernel: Debian's current linux-image-amd64, resolved with apt-cache (never pinned).
pkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}')
[ -n "$pkg" ] || fail "apt-cache cannot resolve linux-image-amd64"
deb=$(ls "$vm/${pkg}"_*.deb 2>/dev/null | head -1)
if [ -z "$deb" ]; then
    (cd "$vm" && apt-get download "$pkg" >/dev/null 2>&1) || fail "apt-get download $pkg failed"
    deb=$(ls "$vm/${pkg}"_*.deb | head -1)
fi
kdir=$vm/$pkg
if [ ! -f "$kdir/vmlinuz" ]; then
    rm -rf "$kdir.tmp" && mkdir -p "$kdir.tmp/x"
    dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$kdir.tmp/x" --wildcards './boot/vmlinuz-*' \
        './lib/modules/*/kernel/net/can/can.ko*' './lib/modules/*/kernel/net/can/can-raw.ko*' \
        './lib/modules/*/kernel/drivers/net/can/dev/can-dev.ko*' './lib/modules/*/kernel/drivers/net/can/vcan.ko*' \
        || fail "cannot extract $deb"
    cp "$kdir.tmp"/x/boot/vmlinuz-* "$kdir.tmp/vmlinuz"
    for m in can can-raw can-dev vcan; do
        f=$(find "$kdir.tmp/x" -name "$m.ko*" | head -1)
        [ -n "$f" ] || fail "module $m not in $deb"
        case "$f" in  # busybox insmod may not decompress: do it here
            *.xz) xz -dc "$f" > "$kdir.tmp/$m.ko" ;;
            *.zst) zstd -qdc "$f" > "$kdir.tmp/$m.ko" ;;
            *.gz) gzip -dc "$f" > "$kdir.tmp/$m.ko" ;;
            *) cp "$f" "$kdir.tmp/$m.ko" ;;
        esac
    done
    rm -rf "$kdir.tmp/x" "$kdir" && mv "$kdir.tmp" "$kdir"
fi

# The initramfs.
root=$vm/root
rm -rf "$root" && mkdir -p "$root"/{bin,sbin,lib/modules,lib64,proc,sys,dev,tmp,data,usr/bin}
cp /bin/busybox "$root/bin/busybox" || fail "busybox-static missing"
cp "$bin" "$root/bin/can_vm_test"
cp "$here/can_inner.sh" "$root/can_inner.sh"
cp "$data/cansend.txt" "$data/expect_recv.txt" "$data/now_us" "$root/data/"
cp "$kdir"/*.ko "$root/lib/modules/"
copy_dyn() {  # a host program plus the shared libraries ldd lists
    local p; p=$(command -v "$1") || fail "$1 not installed"
    cp "$p" "$root/bin/$1"
    ldd "$p" | grep -oE '/[^ ]+' | while read -r lib; do
        mkdir -p "$root$(dirname "$lib")"; cp -L "$lib" "$root$lib"
    done
}
copy_dyn candump; copy_dyn cansend; copy_dyn ip
# The two-process run over SocketCAN (optional: when the programs and the map exist).
if [ -x "$build/bin/rfseekd" ] && [ -x "$build/bin/rfseek-sim-lcm" ] && [ -f "$here/../../scenarios/maps/office.pgm" ]; then
    PATH="$build/bin:$PATH" copy_dyn rfseekd
    PATH="$build/bin:$PATH" copy_dyn rfseek-sim-lcm
    mkdir -p "$root/data/scn/maps"
    cp "$here/../../scenarios/default.yaml" "$root/data/scn/"
    cp "$here/../../scenarios/maps/office.yaml" "$here/../../scenarios/maps/office.pgm" "$root/data/scn/maps/"
fi
cat > "$root/init" <<'INIT'
#!/bin/busybox sh
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc; mount -t sysfs sys /sys; mount -t devtmpfs dev /dev; mount -t tmpfs tmp /tmp
for m in can can-raw can-dev vcan; do insmod /lib/modules/$m.ko || echo "FAIL insmod $m"; done
echo; date; sh /can_inner.sh /data 2>&1; date
poweroff -f
INIT
chmod +x "$root/init"
# GNU cpio when installed (scripts/deps.txt), else busybox's newc writer.
if command -v cpio >/dev/null; then mkcpio() { cpio -o -H newc --quiet; }; else mkcpio() { busybox cpio -o -H newc 2>/dev/null; }; fi
(cd "$root" && find . | mkcpio) > "$vm/initramfs.cpio" || fail "cpio failed"  # uncompressed: inflating under TCG costs more than loading

# Boot; qemu exits 0 either way, the verdict is in the serial log.
log=$vm/serial.log
timeout 400 qemu-system-x86_64 -accel tcg -M pc -m 256M -nographic -kernel "$kdir/vmlinuz" \
    -initrd "$vm/initramfs.cpio" -append 'console=ttyS0 panic=-1 quiet' -no-reboot > "$log" 2>&1
rc=$?
tr -d '\r' < "$log" > "$log.txt"
grep -E '^(PASS|FAIL) ' "$log.txt"
if grep -q '^RFS-VM-VERDICT: PASS' "$log.txt"; then
    echo "PASS can-vm-verdict ($pkg)"
    exit 0
fi
[ $rc -eq 124 ] && fail "qemu timed out (log $log.txt)"
tail -40 "$log.txt"
fail "no PASS verdict on the serial console (log $log.txt)"
