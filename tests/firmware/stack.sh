#!/usr/bin/env bash
# stack.sh BUILD - the hardware image's stack holds its deepest path: the main loop's worst
# (a CONFIG frame re-initialising the application) plus the deepest receive interrupt, the
# fault handler and two exception frames (32 bytes each, no FPU context, plus 4 when the
# hardware aligns the frame to 8 bytes: ARMv7-M B1.5.7), by
# scripts/fw_stack.py (-fstack-usage frames, the linked image's call graph). And the stack
# sits at the bottom of SRAM, so an overflow faults instead of corrupting .data/.bss.
set -uo pipefail
B=${1:-build}
F=$B/firmware
O=$F/obj
elf=$F/firmware.elf
fails=0
sym() { echo $((16#$(arm-none-eabi-nm "$elf" | awk -v s="$1" '$3 == s { print $1 }'))); }
out=$(/usr/bin/python3 scripts/fw_stack.py "$elf" Reset_Handler,CAN1_RX0_IRQHandler,CAN1_RX1_IRQHandler,SysTick_Handler,HardFault_Handler \
    "$O"/firmware/port/stm32f4/*.su "$O"/firmware/rfs_app.su "$O"/common/*.su "$O"/fw_map.su)
rc=$?
echo "$out"
depth() { awk -v r="$1" '$1 == r { print $2 }' <<<"$out"; }
thread=$(depth Reset_Handler)
isr=0
for h in CAN1_RX0_IRQHandler CAN1_RX1_IRQHandler SysTick_Handler; do
    d=$(depth $h); [ "${d:-0}" -gt "$isr" ] && isr=$d
done
need=$((thread + isr + 36 + $(depth HardFault_Handler) + 36))
size=$(sym RFS_STACK_SIZE)
if [ $rc -eq 0 ] && [ -n "$thread" ] && grep -q 'rfs_app_on_config' <<<"$out" && [ "$need" -le "$size" ]; then
    echo "PASS stack bound $need B (loop $thread + interrupt $isr + fault $(depth HardFault_Handler) + 2 x 36) <= $size B"
else echo "FAIL stack bound $need B (loop ${thread:-?} + interrupt $isr + fault $(depth HardFault_Handler) + 2 x 36) > $size B, or the analysis failed (rc $rc)"
    fails=$((fails + 1)); fi
# Every call through a register read (blx/bx to any register but lr, counted here apart
# from the script: r9..r12 print as sb, sl, fp, ip, which it once passed over, edges lost).
want=$(arm-none-eabi-objdump -d --no-show-raw-insn "$elf" | grep -cP '\t(blx|bx)\t(?!lr$)[a-z][a-z0-9]*$')
got=$(awk '$1 == "indirect" && $2 == "calls" { print $3 }' <<<"$out")
if [ "${got:-0}" -eq "$want" ] && [ "$want" -gt 0 ]; then echo "PASS the analysis read all $want calls through a register"
else echo "FAIL the analysis read ${got:-none} of the image's $want calls through a register"; fails=$((fails + 1)); fi
if [ "$(sym _sstack)" -eq $((0x20000000)) ] && [ "$(sym _estack)" -le "$(sym _sdata)" ]; then
    echo "PASS the stack is at the bottom of SRAM (0x20000000 .. $(printf 0x%x "$(sym _estack)")), below .data and .bss"
else echo "FAIL the stack is not at the bottom of SRAM"; fails=$((fails + 1)); fi
exit $((fails > 0))
