# tests/lib/qemu.sh - the Cortex-M4 application image (firmware/port/qemu) playing a
# recorded input stream under qemu-system-arm (bash), sourced:
#   . "$(dirname "$0")/../lib/qemu.sh"

# qemu_play ELF DIR IN OUT [SECONDS]: the image ELF plays DIR/IN into DIR/OUT. IN and OUT
# are names inside DIR: the image opens them by semihosting, relative to the emulator's
# working directory, which is DIR. The image's console (semihosting) stays on this
# shell's stdout/stderr. Returns the image's exit status; 124 when it runs longer than
# SECONDS (default 120) of wall time.
qemu_play() {
    local elf
    elf=$(realpath -m -- "$1")
    (cd "$2" && timeout "${5:-120}" qemu-system-arm -M netduinoplus2 -nographic -monitor none \
        -serial null -semihosting-config enable=on,target=native -kernel "$elf" -append "$3 $4")
}
