#!/usr/bin/env bash
# Fail when the core library references an external symbol other than
# memcpy/memset/memmove (the core is freestanding: no libc, no libgcc helpers).
# Symbols one object uses and another defines are internal to the library.
#   scripts/check_core_symbols.sh NM LIB      (NM: nm or arm-none-eabi-nm)
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
nm_tool=${1:?usage: check_core_symbols.sh NM LIB} lib=${2:?usage: check_core_symbols.sh NM LIB}
undef=$("$nm_tool" -u "$lib" | awk 'NF && $0 !~ /:$/ {print $NF}' | sort -u)
defined=$("$nm_tool" --defined-only "$lib" | awk 'NF==3 {print $3}' | sort -u)
bad=$(comm -23 <(echo "$undef") <(echo "$defined") \
      | grep -vxE 'memcpy|memset|memmove|_GLOBAL_OFFSET_TABLE_|' || true)
if [ -n "$bad" ]; then
    echo "FAIL core-symbols $lib: external symbols: $(echo $bad)" >&2
    exit 1
fi
echo "PASS core-symbols $lib"
