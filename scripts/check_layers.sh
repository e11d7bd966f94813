#!/usr/bin/env bash
# check_layers.sh - the include direction: host_sim -> firmware/port/linux -> firmware ->
# common, never back, and each outside library from its one adapter file. One FAIL line
# per offending include (file, header, the rule), a PASS line when there is none.
#   scripts/check_layers.sh            (from the repository root)
set -uo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
cd "$(dirname "$0")/.."

# Where each project header lives (names are unique across the tree).
declare -A home
while read -r h; do home[$(basename "$h")]=$(dirname "$h"); done \
    < <(find common firmware host_sim -name '*.h' | sort)
for n in lcm/*.lcm; do home[rfseek_$(basename "$n" .lcm).h]=gen; done

# The folders a file in DIR may include from.
allowed() {
    case $1 in
        common) echo "common" ;;
        firmware) echo "common firmware" ;;
        firmware/port/linux|firmware/port/linux/*) echo "common firmware firmware/port/linux gen" ;;
        firmware/port/qemu) echo "common firmware firmware/port/qemu firmware/port/stm32f4" ;;
        firmware/port/*) echo "common firmware $1" ;;
        host_sim|host_sim/*) echo "common firmware firmware/port/linux gen host_sim" ;;
        *) echo "" ;;
    esac
}
# <system headers> of an outside library and the one file allowed to include them.
adapter_of() {
    case $1 in
        yaml.h) echo firmware/port/linux/lx_yaml.c ;;
        lcm/*) echo firmware/port/linux/lx_lcm.c ;;
        pcap.h|pcap/*) echo firmware/port/linux/lx_pcap.c ;;
        png.h|pngconf.h) echo firmware/port/linux/lx_png.c ;;
        linux/can.h|linux/can/*) echo firmware/port/linux/lx_can.c ;;
        box2d/*) echo host_sim/hs_box2d.cpp ;;
    esac
}

bad=0 files=0
while read -r f; do
    files=$((files + 1))
    dir=$(dirname "$f")
    ok=" $(allowed "$dir") "
    while IFS= read -r line; do
        if [[ $line =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\"([^\"]+)\" ]]; then
            inc=${BASH_REMATCH[1]}
            from=${home[$(basename "$inc")]:-}
            [ -z "$from" ] && continue  # not a project header
            if [[ $ok != *" $from "* ]]; then
                echo "FAIL layers: $f includes $inc from $from/ (from $dir/ only $(allowed "$dir" | sed 's/[^ ]*/&\//g'))"
                bad=$((bad + 1))
            fi
        elif [[ $line =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\<([^\>]+)\> ]]; then
            inc=${BASH_REMATCH[1]}
            want=$(adapter_of "$inc")
            if [ -n "$want" ] && [ "$f" != "$want" ]; then
                echo "FAIL layers: $f includes <$inc>, which only $want may include"
                bad=$((bad + 1))
            fi
        fi
    done < "$f"
done < <(find common firmware host_sim -name '*.[ch]' -o -name '*.cpp' | sort)

if [ $bad -ne 0 ]; then exit 1; fi
echo "PASS layers: $files files, every include points down (host_sim -> firmware/port/linux -> firmware -> common)"
