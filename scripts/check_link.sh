#!/usr/bin/env bash
# check_link.sh - the Linux port's programs link neither Box2D nor the C++ runtime: the
# daemon builds without the simulator (docs/ARCHITECTURE.md). One PASS/FAIL line per
# program, from its dynamic section (readelf NEEDED).
#   scripts/check_link.sh PROGRAM...
set -uo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
[ $# -ge 1 ] || { echo "usage: check_link.sh PROGRAM..." >&2; exit 2; }
rc=0
for p in "$@"; do
    if ! needed=$(readelf -d "$p" 2>/dev/null | awk '/\(NEEDED\)/ {gsub(/[][]/, "", $NF); print $NF}'); then
        echo "FAIL link $p: cannot read its dynamic section"; rc=1; continue
    fi
    bad=$(echo "$needed" | grep -E '^lib(box2d|stdc\+\+)' | tr '\n' ' ')
    if [ -n "$bad" ]; then
        echo "FAIL link $p: needs $bad"; rc=1
    else
        echo "PASS link $p: needs $(echo $needed)"
    fi
done
exit $rc
