"""pcap_build.py - classic pcap bytes built in pure Python for the feeder's tests
(tests/feed/replay_test.py, tests/wire/feed_heartbeat.py): one 802.11 data frame per
record, to the access point BSSID, behind a minimal radiotap header whose only field is the
dBm antenna signal (present bit 5), microsecond timestamps, link type 127 (radiotap)."""
import struct

BSSID = bytes.fromhex("0a1b2c3d4e5f")


def record(t_us, mac, seq, dbm):
    """One pcap record: a data frame from mac (6 bytes) with sequence number seq (12 bits)
    heard at dbm, captured at t_us (microseconds since the epoch)."""
    rt = struct.pack("<BBHI", 0, 0, 9, 0x20) + struct.pack("<b", dbm)
    hdr = struct.pack("<BB", 0x08, 0x01) + b"\0\0" + BSSID + mac + BSSID + struct.pack("<H", (seq & 0xFFF) << 4)
    data = rt + hdr
    return struct.pack("<IIII", t_us // 1000000, t_us % 1000000, len(data), len(data)) + data


def write(path, records):
    """A classic pcap file (version 2.4, snaplen 65535, radiotap) of the given records."""
    with open(path, "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 127) + b"".join(records))
