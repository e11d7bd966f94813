#!/usr/bin/env python3
"""Generate radiotap captures in many field layouts for the feeder cross-check.

Pure python, writing pcap / pcapng bytes directly (no code under test involved), so
tshark is the independent reader the feeder's output is compared with. Deterministic:
a fixed seed per file.

usage: gen_captures.py OUTDIR

Writes into OUTDIR:
  layouts.pcap      random mix of radiotap layouts (TSFT, flags +/- FCS, rate, channel,
                    FHSS, dBm signal/noise, lock quality, antenna, RX flags, MCS, A-MPDU,
                    VHT, timestamp, per-chain signals, vendor namespaces, ext bitmaps)
                    and 802.11 frames (management, data in all four DS combinations,
                    QoS data, control frames with and without TA, truncated headers)
  ds.pcap           every ToDS/FromDS combination, data and QoS data, no FCS
  perchain.pcap     mac80211 per-chain layout: combined signal then one per antenna
  vendor.pcap       vendor namespaces (skip_length 0..13) before and between radiotap
                    namespace restarts
  ext.pcap          extended bitmaps continuing the default namespace (bits 32+)
  fcs.pcap          FCS flag set, 4 FCS bytes at the end, frames cut right at the FCS
  ns.pcapng         pcapng, nanosecond timestamps, two sections worth of frames
  bad/*.pcap*       damaged inputs: empty, truncated header, truncated record, wrong
                    link type, radiotap length lies, endless bitmaps, bad version,
                    field past it_len
Each file NAME gets NAME.macs: the transmitter addresses used in it, one per line.
"""
import os
import random
import struct
import sys

MACS = [
    bytes.fromhex("02aabbcc0001"),
    bytes.fromhex("02aabbcc0002"),
    bytes.fromhex("3c:22:fb:10:20:30".replace(":", "")),
    bytes.fromhex("f0:9f:c2:ab:cd:ef".replace(":", "")),
    bytes.fromhex("00:1d:93:94:ea:bc".replace(":", "")),
]
BSSID = bytes.fromhex("0a1b2c3d4e5f")
BCAST = b"\xff" * 6

# radiotap default namespace: bit -> (align, size)
FIELDS = {
    0: (8, 8), 1: (1, 1), 2: (1, 1), 3: (2, 4), 4: (2, 2), 5: (1, 1), 6: (1, 1),
    7: (2, 2), 8: (2, 2), 9: (2, 2), 10: (1, 1), 11: (1, 1), 12: (1, 1), 13: (1, 1),
    14: (2, 2), 15: (2, 2), 16: (1, 1), 17: (1, 1), 19: (1, 3), 20: (4, 8),
    21: (2, 12), 22: (8, 12),
}


def field_bytes(rng, bit, values):
    """Bytes of one radiotap field; `values` may pin a field's value (e.g. signal)."""
    if bit in values:
        return values[bit]
    if bit == 0:
        return struct.pack("<Q", rng.getrandbits(48))
    if bit == 1:
        return bytes([rng.choice([0x00, 0x02, 0x20])])
    if bit == 2:
        return bytes([rng.choice([2, 4, 11, 12, 22, 108])])
    if bit == 3:
        return struct.pack("<HH", rng.choice([2412, 2437, 2462, 5180, 5745]), rng.choice([0xA0, 0xC0, 0x140]))
    if bit == 5:
        return struct.pack("<b", rng.randint(-95, -10))
    if bit == 6:
        return struct.pack("<b", rng.randint(-100, -80))
    if bit == 11:
        return bytes([rng.randint(0, 3)])
    if bit == 19:
        return bytes([0x1F, rng.randint(0, 0x7F), rng.randint(0, 31)])
    if bit == 22:
        return struct.pack("<QHBB", rng.getrandbits(40), rng.randint(0, 100), 0x11, 0x00)
    return bytes(rng.getrandbits(8) for _ in range(FIELDS[bit][1]))


class Radiotap:
    """Builds a radiotap header word by word, aligning each field to the header start."""

    def __init__(self):
        self.words = []   # list of present words (without bit 31; set at build)
        self.items = []   # (kind, payload): ('f', bit, bytes) or ('vendor', hdr, data)

    def build(self):
        n = len(self.words)
        words = [w | (1 << 31) if i < n - 1 else w for i, w in enumerate(self.words)]
        body = bytearray()
        off = 8 + 4 * (n - 1)
        for item in self.items:
            if item[0] == "f":
                align = FIELDS[item[1]][0]
                pad = (-off) % align
                body += b"\0" * pad
                body += item[2]
                off += pad + len(item[2])
            elif item[0] == "vendor":
                pad = (-off) % 2
                body += b"\0" * pad + item[1] + item[2]
                off += pad + len(item[1]) + len(item[2])
            elif item[0] == "raw":
                body += item[1]
                off += len(item[1])
        hdr = struct.pack("<BBH", 0, 0, off) + b"".join(struct.pack("<I", w) for w in words)
        return hdr + bytes(body)


def radiotap_random(rng, signal, fcs, style=None):
    """A random default-namespace layout, optionally with per-chain, vendor or ext words.
    Returns (bytes, flags-had-fcs)."""
    rt = Radiotap()
    bits = [b for b in sorted(FIELDS) if rng.random() < 0.35]
    if fcs and 1 not in bits:
        bits.append(1)
        bits.sort()
    if signal is not None and 5 not in bits:
        bits.append(5)
        bits.sort()
    if signal is None and 5 in bits:
        bits.remove(5)
    values = {}
    if signal is not None:
        values[5] = struct.pack("<b", signal)
    if 1 in bits:
        values[1] = bytes([(0x10 if fcs else 0x00) | rng.choice([0x00, 0x02, 0x20])])
    if style is None:
        style = rng.choice(["plain", "plain", "perchain", "vendor", "ext", "vendor_then_signal"])
    if style == "vendor_then_signal" and signal is not None:
        # signal only after a vendor namespace and a restart: parsing must skip by length
        bits = [b for b in bits if b not in (5,) and b < 5]
        w0 = sum(1 << b for b in bits) | (1 << 30)
        rt.words.append(w0)
        for b in bits:
            rt.items.append(("f", b, field_bytes(rng, b, values)))
        skip = rng.randint(0, 13)
        rt.items.append(("vendor", bytes([0x00, 0x13, 0x74, rng.randint(0, 3)]) + struct.pack("<H", skip),
                         bytes(rng.getrandbits(8) for _ in range(skip))))
        rt.words.append(rng.getrandbits(29) | (1 << 29))  # vendor bits: all inside skip data
        tail = [5] + ([11] if rng.random() < 0.5 else []) + ([0] if rng.random() < 0.3 else [])
        tail.sort()
        rt.words.append(sum(1 << b for b in tail))
        for b in tail:
            rt.items.append(("f", b, field_bytes(rng, b, values)))
        return rt.build()
    w0 = sum(1 << b for b in bits)
    if style == "perchain":
        w0 |= 1 << 29
    if style == "vendor":
        w0 |= 1 << 30
    rt.words.append(w0)
    for b in bits:
        rt.items.append(("f", b, field_bytes(rng, b, values)))
    if style == "perchain":
        chains = rng.randint(1, 3)
        for c in range(chains):
            last = c == chains - 1
            w = (1 << 5) | (1 << 11) | (0 if last else 1 << 29)
            rt.words.append(w)
            rt.items.append(("f", 5, struct.pack("<b", rng.randint(-95, -10))))
            rt.items.append(("f", 11, bytes([c])))
    elif style == "vendor":
        skip = rng.randint(0, 9)
        rt.items.append(("vendor", bytes([0x00, 0x10, 0x18, 1]) + struct.pack("<H", skip),
                         bytes(rng.getrandbits(8) for _ in range(skip))))
        rt.words.append(rng.getrandbits(29) | (1 << 29))
        rt.words.append((1 << 6) | (1 << 11))
        rt.items.append(("f", 6, struct.pack("<b", -90)))
        rt.items.append(("f", 11, bytes([1])))
    elif style == "ext":
        # bits 32+ of the default namespace are unknown: parsing ends, fields kept
        rt.words.append(rng.getrandbits(31) | 1)
        rt.items.append(("raw", bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 12)))))
    return rt.build()


def seqctl(seq, frag=0):
    return struct.pack("<H", ((seq & 0xFFF) << 4) | (frag & 15))


def wlan_frame(rng, kind, sa, ds=None, seq=0):
    """An 802.11 frame (without FCS). kind: mgmt, data, qos, ctrl_ta, ack, cts, cut."""
    other = rng.choice([m for m in MACS if m != sa] + [BSSID])
    if kind == "mgmt":
        sub = rng.choice([0, 4, 5, 8, 10, 11, 12])
        order = rng.random() < 0.15  # +HTC: 4 more header bytes
        fc = struct.pack("<BB", sub << 4, 0x80 if order else 0)
        body = bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 30)))
        htc = b"\x01\x02\x03\x04" if order else b""
        return fc + b"\0\0" + rng.choice([BCAST, other]) + sa + BSSID + seqctl(seq) + htc + body
    if kind in ("data", "qos"):
        ds = rng.randint(0, 3) if ds is None else ds
        sub = 0 if kind == "data" else 8
        order = kind == "qos" and rng.random() < 0.15
        fc = struct.pack("<BB", 0x08 | (sub << 4), ds | (0x80 if order else 0))
        da = rng.choice([BCAST, other])
        if ds == 0:
            a1, a2, a3 = da, sa, BSSID
        elif ds == 1:
            a1, a2, a3 = BSSID, sa, da
        elif ds == 2:
            a1, a2, a3 = da, BSSID, sa
        else:
            a1, a2, a3 = other, rng.choice(MACS), da
        hdr = fc + b"\0\0" + a1 + a2 + a3 + seqctl(seq, rng.randint(0, 1) if rng.random() < 0.1 else 0)
        if ds == 3:
            hdr += sa
        if kind == "qos":
            hdr += struct.pack("<H", rng.randint(0, 7))
            if order:
                hdr += b"\x01\x02\x03\x04"
        return hdr + bytes.fromhex("aaaa0300000088b5") + bytes(rng.getrandbits(8) for _ in range(rng.randint(0, 20)))
    if kind == "ctrl_ta":
        sub = rng.choice([8, 9, 10, 11, 14, 15])
        fc = struct.pack("<BB", 0x04 | (sub << 4), 0)
        tail = b"\0\0\0\0" if sub in (8, 9) else b""
        return fc + b"\0\0" + other + sa + tail
    if kind in ("ack", "cts"):
        fc = struct.pack("<BB", 0x04 | ((13 if kind == "ack" else 12) << 4), 0)
        return fc + b"\0\0" + sa
    if kind == "cut":
        full = wlan_frame(rng, rng.choice(["mgmt", "data", "qos"]), sa, seq=seq)
        return full[: rng.randint(1, 36)]
    raise ValueError(kind)


def fcs_bytes(frame):
    import zlib
    return struct.pack("<I", zlib.crc32(frame) & 0xFFFFFFFF)


def pcap_bytes(records, linktype=127, snaplen=65535):
    out = bytearray(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, snaplen, linktype))
    for t_us, data in records:
        out += struct.pack("<IIII", t_us // 1000000, t_us % 1000000, len(data), len(data)) + data
    return bytes(out)


def pcapng_bytes(records_ns):
    def block(btype, body):
        pad = (-len(body)) % 4
        total = 12 + len(body) + pad
        return struct.pack("<II", btype, total) + body + b"\0" * pad + struct.pack("<I", total)

    shb = block(0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1))
    # IDB: link type 127, snaplen 0; option if_tsresol (9) = 9 (nanoseconds), end of options
    opts = struct.pack("<HHB3x", 9, 1, 9) + struct.pack("<HH", 0, 0)
    idb = block(1, struct.pack("<HHI", 127, 0, 0) + opts)
    out = bytearray(shb + idb)
    for t_ns, data in records_ns:
        pad = (-len(data)) % 4
        body = struct.pack("<IIIII", 0, t_ns >> 32, t_ns & 0xFFFFFFFF, len(data), len(data)) + data + b"\0" * pad
        out += block(6, body)
    return bytes(out)


def write(path, data, macs):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)
    if macs is not None:
        with open(path + ".macs", "w") as f:
            f.write("".join(":".join("%02x" % b for b in m) + "\n" for m in macs))


def gen_mixed(seed, n, kinds, style_fn, t0=1700000000123456):
    rng = random.Random(seed)
    recs = []
    t = t0
    seq = {m: rng.randint(0, 4095) for m in MACS}
    for _ in range(n):
        t += rng.choice([0, 1, 7, 999, 1000, 123457, 2000000])
        sa = rng.choice(MACS)
        seq[sa] = (seq[sa] + 1) & 0xFFF
        kind = rng.choice(kinds)
        frame = wlan_frame(rng, kind, sa, seq=seq[sa])
        signal = rng.randint(-95, -10) if rng.random() < 0.85 else None
        fcs = rng.random() < 0.4
        rt = style_fn(rng, signal, fcs)
        data = rt + frame + (fcs_bytes(frame) if fcs else b"")
        recs.append((t, data))
    return recs


def main():
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):  # "--x" is no folder to make
        sys.exit("usage: gen_captures.py OUTDIR (see --help)")
    out = sys.argv[1]
    os.makedirs(os.path.join(out, "bad"), exist_ok=True)
    allk = ["mgmt", "data", "qos", "ctrl_ta", "ack", "cts", "cut"]
    write(os.path.join(out, "layouts.pcap"), pcap_bytes(gen_mixed(1, 3000, allk, radiotap_random)), MACS)

    def plain(rng, signal, fcs):
        rt = Radiotap()
        bits = [0, 1, 3] + ([5] if signal is not None else [])
        rt.words.append(sum(1 << b for b in bits))
        vals = {1: bytes([0x10 if fcs else 0]), 5: struct.pack("<b", signal if signal is not None else 0)}
        for b in bits:
            rt.items.append(("f", b, field_bytes(rng, b, vals)))
        return rt.build()

    rng = random.Random(2)
    recs = []
    t = 1600000000000000
    for i in range(400):
        sa = MACS[i % len(MACS)]
        frame = wlan_frame(rng, "data" if i % 2 else "qos", sa, ds=(i // 2) % 4, seq=i)
        recs.append((t + i * 1001, plain(rng, rng.randint(-90, -20), False) + frame))
    write(os.path.join(out, "ds.pcap"), pcap_bytes(recs), MACS)

    def only(*styles):
        return lambda rng, signal, fcs: radiotap_random(rng, signal, fcs, rng.choice(styles))

    write(os.path.join(out, "perchain.pcap"), pcap_bytes(gen_mixed(3, 300, ["mgmt", "data", "qos"], only("perchain"))), MACS)
    write(os.path.join(out, "vendor.pcap"), pcap_bytes(gen_mixed(4, 300, ["mgmt", "data", "qos"], only("vendor", "vendor_then_signal"))), MACS)
    write(os.path.join(out, "ext.pcap"), pcap_bytes(gen_mixed(5, 300, ["mgmt", "data", "qos"], only("ext"))), MACS)

    def with_fcs(rng, signal, fcs):
        return plain(rng, signal if signal is not None else -50, True)

    rng = random.Random(6)
    recs = []
    for i in range(300):
        sa = MACS[i % len(MACS)]
        frame = wlan_frame(rng, rng.choice(["mgmt", "data", "qos", "ack", "ctrl_ta"]), sa, seq=i)
        data = with_fcs(rng, rng.randint(-90, -20), True) + frame + fcs_bytes(frame)
        if i % 10 == 9:
            data = data[: len(data) - rng.randint(1, 4)]  # cut inside the FCS
        recs.append((1500000000000000 + i * 77, data))
    write(os.path.join(out, "fcs.pcap"), pcap_bytes(recs), MACS)

    recs = gen_mixed(7, 300, ["mgmt", "data", "qos"], radiotap_random)
    rng = random.Random(8)
    recs_ns = [(t * 1000 + rng.randint(0, 999), d) for t, d in recs]
    write(os.path.join(out, "ns.pcapng"), pcapng_bytes(recs_ns), MACS)

    # damaged inputs
    good = pcap_bytes(gen_mixed(9, 20, ["data"], radiotap_random))
    bad = os.path.join(out, "bad")
    write(os.path.join(bad, "empty.pcap"), b"", None)
    write(os.path.join(bad, "short_header.pcap"), good[:13], None)
    write(os.path.join(bad, "cut_record.pcap"), good[: len(good) - 5], None)
    write(os.path.join(bad, "cut_record_header.pcap"), good[: 24 + 7], None)
    write(os.path.join(bad, "linktype_105.pcap"), pcap_bytes([(0, b"\x08\x01" + b"\0" * 22)], linktype=105), None)
    write(os.path.join(bad, "linktype_1.pcap"), pcap_bytes([(0, b"\0" * 14)], linktype=1), None)
    write(os.path.join(bad, "not_a_capture.pcap"), b"hello, this is not a pcap file at all\n", None)
    rng = random.Random(10)
    frame = wlan_frame(rng, "data", MACS[0], ds=1, seq=1)
    recs = []
    recs.append((1, struct.pack("<BBHI", 1, 0, 8, 0x20) + frame))                    # version 1
    recs.append((2, struct.pack("<BBHI", 0, 0, 200, 0x20) + b"\xc8" + frame))       # it_len > caplen
    recs.append((3, struct.pack("<BBHI", 0, 0, 4, 0x20) + frame))                    # it_len < 8
    recs.append((4, struct.pack("<BBH", 0, 0, 16) + struct.pack("<III", 0x80000020, 0x80000000, 0x80000000) + frame))  # endless bitmap
    recs.append((5, struct.pack("<BBHI", 0, 0, 9, 0x21) + b"\xc8" + frame))          # TSFT past it_len
    recs.append((6, struct.pack("<BBHI", 0, 0, 9, 0x40000020) + b"\xc8" + frame))    # vendor header past it_len
    recs.append((7, struct.pack("<BBHI", 0, 0, 16, 0x40000020) + b"\xc8\0\x00\x13\x74\x00\xff\x00" + frame))  # vendor skip past it_len
    recs.append((8, b"\0\0\x08"))                                                   # 3-byte record
    recs.append((9, struct.pack("<BBHI", 0, 0, 9, 0x20) + b"\xc8"))                  # no 802.11 at all
    recs.append((10, struct.pack("<BBHI", 0, 0, 9, 0x20) + b"\xc8" + frame[:11]))    # cut inside addr2
    recs.append((11, struct.pack("<BBHI", 0, 0, 9, 0x20) + b"\xc8" + frame))         # a good one
    write(os.path.join(bad, "radiotap_lies.pcap"), pcap_bytes(recs), [MACS[0]])
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except OSError as e:  # a missing or unreadable file: one line, not a traceback
        sys.exit("%s: %s: %s" % (os.path.basename(sys.argv[0]), e.filename, e.strerror))
