#!/usr/bin/env bash
# fw_budget.sh ELF - print the flash, static-RAM (SRAM) and CCM use of a firmware image
# against the budgets its linker script asserts (stm32f405.ld: _rfs_flash_used,
# _rfs_ram_used, _rfs_ccm_used).
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
elf=${1:?usage: fw_budget.sh ELF}
[ -r "$elf" ] || { echo "fw_budget.sh: $elf: no such file" >&2; exit 1; }
sym() {
    local hex
    hex=$(arm-none-eabi-nm "$elf" | awk -v s="$1" '$3 == s { print $1 }')
    echo $((16#$hex))
}
flash=$(sym _rfs_flash_used); ram=$(sym _rfs_ram_used); ccm=$(sym _rfs_ccm_used)
fb=$(sym RFS_FLASH_BUDGET); rb=$(sym RFS_RAM_BUDGET); cb=$(sym RFS_CCM_BUDGET); st=$(sym RFS_STACK_SIZE)
echo "$elf: flash $flash of $fb bytes ($((100 * flash / fb))%)," \
     "static RAM $ram of $rb bytes ($((100 * ram / rb))%, stack $st included)," \
     "CCM $ccm of $cb bytes ($((100 * ccm / cb))%)"
