#!/usr/bin/env bash
# budget.sh BUILD - the hardware image's link fails when flash, static RAM (SRAM) or CCM
# exceeds its budget (96 KB flash, 128 KB SRAM, 64 KB CCM). The real image links (make firmware);
# here the same objects are linked again with budgets just below what they use, and the
# link must fail with the linker script's message.
set -uo pipefail
B=${1:-build}
F=$B/firmware
fails=0
objs=("$F"/obj/firmware/port/stm32f4/{startup,board,rfs_bxcan,main}.o "$F"/obj/firmware/rfs_app.o "$F"/obj/fw_map.o "$F"/lib/librfs_core.a)
link() { arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfloat-abi=soft -nostartfiles --specs=nano.specs \
    -Wl,--gc-sections -T firmware/port/stm32f4/stm32f405.ld "$@" -o "$tmp" "${objs[@]}" 2>&1; }
tmp=$(mktemp); trap 'rm -f "$tmp"' EXIT
sym() { echo $((16#$(arm-none-eabi-nm "$F/firmware.elf" | awk -v s="$1" '$3 == s { print $1 }'))); }
flash=$(sym _rfs_flash_used); ram=$(sym _rfs_ram_used); ccm=$(sym _rfs_ccm_used)
if out=$(link); then echo "PASS links within the default budgets (flash $flash, RAM $ram, CCM $ccm bytes)"; else
    echo "FAIL links within the default budgets: $out"; fails=$((fails + 1)); fi
out=$(link -Wl,--defsym=RFS_RAM_BUDGET=$((ram - 4)))
if [ $? -ne 0 ] && grep -q 'static RAM budget exceeded' <<<"$out"; then
    echo "PASS link fails with RAM budget $((ram - 4)) < $ram: $(grep -o 'firmware: static RAM budget exceeded' <<<"$out")"
else echo "FAIL link must fail over the RAM budget"; fails=$((fails + 1)); fi
out=$(link -Wl,--defsym=RFS_FLASH_BUDGET=$((flash - 4)))
if [ $? -ne 0 ] && grep -q 'flash budget exceeded' <<<"$out"; then
    echo "PASS link fails with flash budget $((flash - 4)) < $flash: $(grep -o 'firmware: flash budget exceeded' <<<"$out")"
else echo "FAIL link must fail over the flash budget"; fails=$((fails + 1)); fi
out=$(link -Wl,--defsym=RFS_CCM_BUDGET=$((ccm - 4)))
if [ $? -ne 0 ] && grep -q 'CCM budget exceeded' <<<"$out"; then
    echo "PASS link fails with CCM budget $((ccm - 4)) < $ccm: $(grep -o 'firmware: CCM budget exceeded' <<<"$out")"
else echo "FAIL link must fail over the CCM budget"; fails=$((fails + 1)); fi
# CCM is reachable by the CPU alone, no DMA (RM0090 2.3): the sample store goes there,
# the CAN driver's state never.
nm=$(arm-none-eabi-nm -S "$F/firmware.elf")
in_ccm() { awk -v s="$1" '$4 == s { a = substr($1, 1, 2) } END { print (a == "10") ? "yes" : "no" }' <<<"$nm"; }
if [ "$(in_ccm s_samples)" = yes ] && [ "$(in_ccm s_can)" = no ] && [ "$(in_ccm s_app)" = no ]; then
    echo "PASS the sample store is in CCM (0x10000000), the CAN driver and the application in SRAM"
else echo "FAIL placement: s_samples $(in_ccm s_samples), s_can $(in_ccm s_can), s_app $(in_ccm s_app) in CCM"
    fails=$((fails + 1)); fi
exit $((fails > 0))
