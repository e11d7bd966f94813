# tests/vm/vm_lib.sh - what the VM tests share (sourced by run_vm_test.sh, SocketCAN, and
# run_wifi_vm_test.sh, 802.11): Debian's current kernel with the modules a test names and
# their dependencies, a busybox-static initramfs, and a qemu (TCG) boot whose verdict is
# read from the serial console. Before sourcing: vm (the cache directory, BUILD/vm) and
# fail MESSAGE (prints a FAIL line and exits). Everything cached is written to a temporary
# name and renamed, so two tests running at once share the cache safely.

PATH="$PATH:/usr/sbin:/sbin"  # modinfo, and the tools copied into a VM (iw, hostapd)

# vm_kernel "MODULE [PARAM=VALUE ...]"...: the package resolved with apt-cache (never
# pinned) and downloaded once; sets pkg, kdir ($kdir/vmlinuz) and vm_mods (one line per
# module to load: "NAME [PARAMS]", each after its dependencies, from modinfo -F depends;
# the modules built into the kernel left out), the .ko files decompressed as
# $kdir/NAME.ko (busybox insmod may not decompress).
vm_kernel() {
    command -v modinfo > /dev/null || fail "modinfo missing (kmod, scripts/deps.txt)"
    pkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}')
    [ -n "$pkg" ] || fail "apt-cache cannot resolve linux-image-amd64"
    local deb
    deb=$(ls "$vm/${pkg}"_*.deb 2>/dev/null | head -1)
    if [ -z "$deb" ]; then
        local dl; dl=$(mktemp -d "$vm/dl.XXXXXX")
        (cd "$dl" && apt-get download "$pkg" >/dev/null 2>&1) || { rm -rf "$dl"; fail "apt-get download $pkg failed"; }
        mv "$dl"/*.deb "$vm/" && rm -rf "$dl"
        deb=$(ls "$vm/${pkg}"_*.deb | head -1)
    fi
    kdir=$vm/$pkg
    mkdir -p "$kdir"
    # The file list, the kernel and the list of built-in modules: once.
    if [ ! -f "$kdir/files.txt" ] || [ ! -f "$kdir/vmlinuz" ] || [ ! -f "$kdir/builtin.txt" ]; then
        local x; x=$(mktemp -d "$kdir/x.XXXXXX")
        dpkg-deb -c "$deb" | awk '{print $NF}' > "$x/files.txt" || fail "cannot list $deb"
        dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$x" --wildcards './boot/vmlinuz-*' './lib/modules/*/modules.builtin' \
            || fail "cannot extract $deb"
        sed 's|.*/||; s|\.ko.*||; s|-|_|g' "$x"/lib/modules/*/modules.builtin > "$x/builtin.txt"
        mv "$x"/boot/vmlinuz-* "$kdir/vmlinuz.$$" && mv "$kdir/vmlinuz.$$" "$kdir/vmlinuz"
        mv "$x/builtin.txt" "$kdir/builtin.txt" && mv "$x/files.txt" "$kdir/files.txt"
        rm -rf "$x"
    fi
    # The modules, one tar pass per level of dependencies.
    local want=() arg m
    for arg in "$@"; do want+=("${arg%% *}"); done
    local todo=("${want[@]}") seen=" "
    while [ ${#todo[@]} -gt 0 ]; do
        local missing=() fresh=() next=()
        for m in "${todo[@]}"; do
            local n=${m//-/_}
            case "$seen" in *" $n "*) continue ;; esac
            seen="$seen$n "
            grep -qx "$n" "$kdir/builtin.txt" && continue
            fresh+=("$n")
            [ -f "$kdir/$n.ko" ] || missing+=("$n")
        done
        if [ ${#missing[@]} -gt 0 ]; then
            local x; x=$(mktemp -d "$kdir/x.XXXXXX")
            local paths=()
            for n in "${missing[@]}"; do
                local p; p=$(grep -E "/${n//_/[-_]}\.ko(\.xz|\.zst|\.gz)?\$" "$kdir/files.txt" | head -1)
                [ -n "$p" ] || fail "module $n not in $deb"
                paths+=("$p")
            done
            dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$x" "${paths[@]}" || fail "cannot extract ${missing[*]} from $deb"
            for p in "${paths[@]}"; do
                local f=$x/${p#./} b; b=$(basename "$p"); n=${b%%.ko*}; n=${n//-/_}
                case "$f" in
                    *.xz) xz -dc "$f" > "$x/$n.ko" ;;
                    *.zst) zstd -qdc "$f" > "$x/$n.ko" ;;
                    *.gz) gzip -dc "$f" > "$x/$n.ko" ;;
                    *) cp "$f" "$x/$n.ko" ;;
                esac || fail "cannot decompress $p"
                mv "$x/$n.ko" "$kdir/$n.ko"
            done
            rm -rf "$x"
        fi
        for n in "${fresh[@]}"; do
            local d; for d in $(modinfo -F depends "$kdir/$n.ko" | tr ',' ' '); do next+=("$d"); done
        done
        todo=("${next[@]}")
    done
    # Load order: each module after what it depends on (depth first).
    vm_mods=""
    local done_=" "
    _vm_order() {
        local n=${1//-/_} d
        case "$done_" in *" $n "*) return ;; esac
        done_="$done_$n "
        [ -f "$kdir/$n.ko" ] || return 0  # built in
        for d in $(modinfo -F depends "$kdir/$n.ko" | tr ',' ' '); do _vm_order "$d"; done
        local a p=""
        for a in "${@:2}"; do p="$p $a"; done
        vm_mods="$vm_mods$n$p"$'\n'
    }
    for arg in "$@"; do
        # shellcheck disable=SC2086
        _vm_order $arg
    done
}

# vm_root DIR: a fresh root for the initramfs in $root: busybox, the modules of vm_kernel
# (and /modules.txt, their load order), an /init that loads them and runs /inner.sh /data,
# then powers off.
vm_root() {
    root=$1
    rm -rf "$root" && mkdir -p "$root"/{bin,sbin,lib/modules,lib64,proc,sys,dev,tmp,data,usr/bin}
    cp /bin/busybox "$root/bin/busybox" || fail "busybox-static missing"
    printf '%s' "$vm_mods" > "$root/modules.txt"
    local n
    while read -r n _; do [ -z "$n" ] || cp "$kdir/$n.ko" "$root/lib/modules/"; done <<< "$vm_mods"
    cat > "$root/init" <<'INIT'
#!/bin/busybox sh
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc; mount -t sysfs sys /sys; mount -t devtmpfs dev /dev; mount -t tmpfs tmp /tmp
while read -r m args; do insmod /lib/modules/$m.ko $args || echo "FAIL insmod $m"; done < /modules.txt
echo; date; sh /inner.sh /data 2>&1; date
poweroff -f
INIT
    chmod +x "$root/init"
}

# vm_copy_dyn PROG: a program on PATH into $root/bin, with the shared libraries ldd lists.
vm_copy_dyn() {
    local p lib; p=$(command -v "$1") || fail "$1 not installed"
    cp "$p" "$root/bin/$1"
    ldd "$p" | grep -oE '/[^ ]+' | while read -r lib; do
        mkdir -p "$root$(dirname "$lib")"; cp -L "$lib" "$root$lib"
    done
}

# vm_boot NAME MEMORY TIMEOUT: pack $root and boot it; the console in $vm/NAME.log.txt.
# Prints the PASS/FAIL lines; returns 0 when the last verdict line says PASS, 124 when
# qemu timed out, else 1.
vm_boot() {
    local name=$1 mem=$2 tmo=$3
    # GNU cpio when installed (scripts/deps.txt), else busybox's newc writer.
    local mkcpio="cpio -o -H newc --quiet"
    command -v cpio >/dev/null || mkcpio="busybox cpio -o -H newc"
    # uncompressed: inflating under TCG costs more than loading
    (cd "$root" && find . | $mkcpio 2>/dev/null) > "$vm/$name.cpio" || fail "cpio failed"
    log=$vm/$name.log
    # qemu exits 0 either way: the verdict is in the serial log.
    timeout "$tmo" qemu-system-x86_64 -accel tcg -M pc -m "$mem" -nographic -kernel "$kdir/vmlinuz" \
        -initrd "$vm/$name.cpio" -append 'console=ttyS0 panic=-1 quiet' -no-reboot > "$log" 2>&1
    local rc=$?
    tr -d '\r' < "$log" > "$log.txt"
    grep -E '^(PASS|FAIL) ' "$log.txt"
    grep -q '^RFS-VM-VERDICT: PASS' "$log.txt" && return 0
    [ $rc -eq 124 ] && return 124
    return 1
}
