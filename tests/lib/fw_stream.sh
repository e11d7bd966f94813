# tests/lib/fw_stream.sh - the opening of the scripts that play recorded streams on the
# host build and on the Cortex-M4 image (tests/firmware/bit_identical.sh, safety.sh,
# tests/wire/heartbeat_replay.sh; bash), sourced once B (the build directory) is set:
#   . "$(dirname "$0")/../lib/fw_stream.sh"
# Sets bin (B/bin: rfseek-record, rfseek-replay), elf (B/firmware/qemu.elf) and tmp (a
# directory removed on exit), and brings pass/fail/$fails (checks.sh) and qemu.
. "${BASH_SOURCE[0]%/*}/checks.sh"
. "${BASH_SOURCE[0]%/*}/qemu.sh"
bin=$B/bin; elf=$B/firmware/qemu.elf
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

# qemu IN OUT: the image plays tmp/IN into tmp/OUT; returns its exit status.
qemu() { qemu_play "$elf" "$tmp" "$1" "$2"; }
