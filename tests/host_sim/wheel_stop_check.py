#!/usr/bin/python3
"""Check that rfseekd's run ends with a stop: the last wheel command of an LCM log.

    tests/host_sim/wheel_stop_check.py LOG.lcmlog [live]

Decodes rfseek.wheel_cmd_t (RFS_WHEEL_CMD) and rfseek.can_frame_t (RFS_CAN_FALLBACK) by
hand in the order of their .lcm files (big-endian, after the 8-byte fingerprint) and the
WHEEL_CMD layout of docs/CAN.md (Stop: bit 4 of byte 0; speeds little-endian int16 at
bytes 1..4). The run's last step is followed by one more command, zero with Stop, on both
channels: at the step's time in lock-step, not before it when `live`. Prints PASS/FAIL lines; exits 1 on failure.
"""
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from checks import check, exit_status  # noqa: E402
from status_est_check import events  # noqa: E402


def main(path, live):
    wheel, frames = [], []
    for _t, ch, b in events(path):
        if ch == "RFS_WHEEL_CMD":
            wheel.append(struct.unpack_from(">qhhb", b, 8))
        elif ch == "RFS_CAN_FALLBACK":
            utime, fid, dlc = struct.unpack_from(">qib", b, 8)
            frames.append((utime, fid, dlc, b[8 + 13:8 + 21]))
    check("wheel_stop_commands", len(wheel) >= 2, "%d RFS_WHEEL_CMD messages" % len(wheel))
    if len(wheel) < 2:
        return
    last, before = wheel[-1], wheel[-2]
    check("wheel_stop_last_is_stop", last[1:] == (0, 0, 1),
          "last RFS_WHEEL_CMD left %d right %d stop %d" % last[1:])
    check("wheel_stop_after_the_last_step", last[0] >= before[0] if live else last[0] == before[0],
          "last RFS_WHEEL_CMD at %d, the one before at %d" % (last[0], before[0]))
    cmds = [f for f in frames if f[1] == 0x100]
    ok = bool(cmds) and cmds[-1][2] == 6 and cmds[-1][3][0] >> 4 == 1 and cmds[-1][3][1:5] == bytes(4)
    check("wheel_stop_last_can_frame", ok, "last WHEEL_CMD frame %s" % (cmds[-1][3].hex() if cmds else "none"))


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3) or sys.argv[2:] not in ([], ["live"]):
        sys.exit("usage: wheel_stop_check.py LOG.lcmlog [live]")
    main(sys.argv[1], sys.argv[2:] == ["live"])
    sys.exit(exit_status())
