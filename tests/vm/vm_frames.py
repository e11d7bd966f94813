#!/usr/bin/env python3
"""Frames for the receive half of the SocketCAN test, encoded independently of our C
code (struct packing from the layout in docs/CAN.md plus scripts/check_dbc.py's CRC),
and the lines can_vm_test must print when it decodes them at NOW_US.

usage: vm_frames.py OUTDIR     writes OUTDIR/cansend.txt, OUTDIR/expect_recv.txt, OUTDIR/now_us
"""
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
from check_dbc import crc8_j1850  # noqa: E402

NOW = 5000000000  # receiver time, microseconds: past the 32-bit wrap at 4294.97 s


def frame(cid, payload, bad_crc=False):
    crc = crc8_j1850(bytes([cid & 0xFF, cid >> 8]) + payload)
    if bad_crc:
        crc ^= 0x01
    return "%03X#%s" % (cid, (payload + bytes([crc])).hex().upper())


def t32(t):
    return t & 0xFFFFFFFF


def q16_of_mm(mm):
    # round half away from zero, as the C side documents
    v = abs(mm) * 65536
    q, r = divmod(v, 1000)
    if 2 * r >= 1000:
        q += 1
    return q if mm >= 0 else -q


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) == 2 else 2
    out = argv[1]
    send, want = [], []
    # 1. RSSI src 1, -67 dBm, seq 200, 1 ms ago
    send.append(frame(0x120, struct.pack("<BbBI", 0x10 | 0, -67, 200, t32(NOW - 1000))))
    want.append("RSSI src=1 dbm=-67 seq=200 t=%d" % (NOW - 1000))
    # 2-3. a pose: x 1.5 m, y -2.5 m, heading 12868 (Q2.13), 20 ms ago
    xy = struct.pack("<B", 0) + (1500).to_bytes(3, "little", signed=True) + (-2500).to_bytes(3, "little", signed=True)
    send.append(frame(0x110, xy))
    want.append("NONE")
    send.append(frame(0x111, struct.pack("<BhI", 0, 12868, t32(NOW - 20000))))
    want.append("POSE t=%d x=%d y=%d th=%d" % (NOW - 20000, q16_of_mm(1500), q16_of_mm(-2500), 12868 * 8))
    # 4. RSSI with a wrong checksum
    send.append(frame(0x120, struct.pack("<BbBI", 0x11, -60, 201, t32(NOW - 900)), bad_crc=True))
    want.append("DROP checksum")
    # 5. an id we do not use
    send.append("7FF#0102030405060708")
    want.append("DROP id")
    # 6. a short RSSI frame
    send.append("120#1122")
    want.append("DROP dlc")
    # 7. an extended frame: the adapter's kernel filter (EFF and RTR bits in the mask)
    #    keeps it out of our socket, so it is neither delivered nor counted
    send.append("12345678#00")
    # 8. wheel command, stop flag
    send.append(frame(0x100, struct.pack("<Bhh", 0x15, -700, 700)))
    want.append("WHEEL left=-700 right=700 flags=1")
    # 9. status: counter 9, state 3, kind 2, relearned, prev 2, configured, faults 5,
    #    iteration 300
    send.append(frame(0x180, struct.pack("<BBBI", 0x39, 2 | 4 | (2 << 4) | 0x80, 5, 300)))
    want.append("STATUS state=3 kind=2 prev=2 relearned=1 line=0 configured=1 faults=5 iter=300")
    # 10. RSSI counter 3 (last accepted 0: a jump), seq 202 (201 missing)
    send.append(frame(0x120, struct.pack("<BbBI", 0x13, -70, 202, t32(NOW - 500))))
    want.append("RSSI src=1 dbm=-70 seq=202 t=%d" % (NOW - 500))
    # 11. RSSI 2 s old: stale
    send.append(frame(0x120, struct.pack("<BbBI", 0x14, -70, 203, t32(NOW - 2000000))))
    want.append("DROP stale")
    # 12. a remote frame: filtered by the kernel like 7
    send.append("120#R")
    # 13. a receiver heartbeat, counter 0, 5 ms ago
    send.append(frame(0x121, struct.pack("<BI", 0x00, t32(NOW - 5000))))
    want.append("RECEIVER t=%d" % (NOW - 5000))
    # 14. a receiver heartbeat 300 ms ahead: beyond the 100 ms future window
    send.append(frame(0x121, struct.pack("<BI", 0x01, t32(NOW + 300000))))
    want.append("DROP future")
    # 15. CONFIG: meta-path (5), pathloss (4), -40 dBm (-5120 / 128), seed 0x123456
    send.append(frame(0x130, struct.pack("<BBh", 0x00, 5 | (4 << 4), -5120) + (0x123456).to_bytes(3, "little")))
    want.append("CONFIG target=0 fit_early=0 strategy=5 model=4 p0=-5120 seed=%d" % 0x123456)
    # 16. CONFIG: bridge (1 << 4), FitEarly on (2 << 6), meta, ridge, no floor, seed 7
    send.append(frame(0x130, struct.pack("<BBh", 0x01 | (1 << 4) | (2 << 6), 0, -32768) + (7).to_bytes(3, "little")))
    want.append("CONFIG target=1 fit_early=2 strategy=0 model=0 p0=-32768 seed=7")
    # 17. CONFIG with strategy 6: no such strategy
    send.append(frame(0x130, struct.pack("<BBh", 0x02, 6, 0) + bytes(3)))
    want.append("DROP range")
    # 18. CONFIG with FitEarly 3: reserved
    send.append(frame(0x130, struct.pack("<BBh", 0x03 | (3 << 6), 0, 0) + bytes(3)))
    want.append("DROP range")
    want.append("STATS delivered=16 foreign=0 dropped=7 checksum=1 rssi_jumps=1 seq_gaps=1")
    with open(os.path.join(out, "cansend.txt"), "w") as f:
        f.write("\n".join(send) + "\n")
    with open(os.path.join(out, "expect_recv.txt"), "w") as f:
        f.write("\n".join(want) + "\n")
    with open(os.path.join(out, "now_us"), "w") as f:
        f.write("%d\n" % NOW)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
