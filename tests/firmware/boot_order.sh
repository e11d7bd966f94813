#!/usr/bin/env bash
# boot_order.sh BUILD - the hardware image starts its independent watchdog before
# anything that can fault or hang: main calls rfs_board_watchdog_start before start()
# (clocks, CAN, rfs_app_init), so a HardFault there (the handler sends a Stop and spins)
# or a stuck oscillator resets the board instead of hanging it. Read from the linked
# image's disassembly: qemu has no independent watchdog to watch it fire.
set -uo pipefail
B=${1:-build}
elf=$B/firmware/firmware.elf
calls=$(arm-none-eabi-objdump -d --no-show-raw-insn "$elf" |
        awk '/^[0-9a-f]+ <main>:$/ { on = 1; next } on && /^$/ { exit } on && /\tbl\t/ { print $NF }')
first() { grep -n -m1 -F "<$1>" <<<"$calls" | cut -d: -f1; }
w=$(first rfs_board_watchdog_start)
s=$(first start)
if [ -n "$w" ] && [ -n "$s" ] && [ "$w" -lt "$s" ]; then
    echo "PASS main starts the watchdog (call $w) before start() (call $s)"
    exit 0
fi
echo "FAIL main's calls: the watchdog at ${w:-none}, start() at ${s:-none} ($(tr '\n' ' ' <<<"$calls"))"
exit 1
