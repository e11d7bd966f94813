#!/usr/bin/env python3
"""make_corpus.py - write the seed corpora of the fuzz targets (docs/RELIABILITY.md).

    /usr/bin/python3 tests/fuzz/make_corpus.py [tests/fuzz/corpus]

Seeds are built here from the documented formats (docs/CAN.md, the ROS map_server
convention, docs/SIMULATOR.md, the LCM wire format), not by the code under test:
  can/       12-byte frame records (see fuzz_can.c): pose pairs, RSSI, wheel, status, config,
             receiver heartbeats
  map/       YAML + "#PGM\\n" + PGM: tests/data/maps_bad fixtures and small P2/P5 images
  png/       a reading byte + a PNG (see fuzz_png.c): every colour type and depth, tRNS,
             interlaced (tests/lib/pngenc.py, from the PNG specification)
  scenario/  the scenarios/*.yaml files and a few hand-written edge cases
  pcap/      classic pcap (us and ns magic, both byte orders) and pcapng (if_tsresol 6, 9,
             2^-20) radiotap captures, timestamps at the formats' edges (libpcap's formats)
  poses/     the pose CSV of rfseek-feed --pose (docs/FEEDER.md): good files and edge values
  candump/   candump -L log lines (can-utils' format, docs/CAN.md "CAN logs"): our frames,
             29-bit, remote, error and CAN FD frames, candump -x directions, padded names
  lcm/       one message per channel, the receiver heartbeat and two seeker statuses included
             (LCM encoding: 8-byte fingerprint, big-endian fields; fingerprints computed with
             lcm-gen's hash) and small LCM logs
"""
import os
import struct
import sys

if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help"):
    print(__doc__.strip())
    sys.exit(0)
if len(sys.argv) > 2 or (len(sys.argv) > 1 and sys.argv[1].startswith("-")):
    sys.exit("make_corpus.py: expected at most one argument, the corpus folder (--help), got "
             + " ".join(sys.argv[1:]))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "corpus")
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def put(sub, name, data):
    d = os.path.join(OUT, sub)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


# --- CAN: records ctrl, dt (ms, LE u16), dlc, data[8] -----------------------------------
# ctrl bit 0 = fix the checksum; bits 1..3 = id index (0 wheel, 1 xy, 2 th, 3 rssi, 4 status,
# 5 receiver status, 6 config; 7 a raw id from data[0..1]).
T0 = 5_000_000_000  # the harness's start time, microseconds


def rec(idx, dt_ms, dlc, payload, fix=True):
    data = bytes(payload) + bytes(8 - len(payload))
    return bytes([(idx << 1) | (1 if fix else 0)]) + struct.pack("<H", dt_ms) + bytes([dlc]) + data


def s24(v):
    return struct.pack("<i", v)[:3]


def pose(counter, x_mm, y_mm, th_q13, t_us, dt_ms=100):
    t32 = t_us & 0xFFFFFFFF
    return (rec(1, dt_ms, 8, bytes([counter & 15]) + s24(x_mm) + s24(y_mm)) +
            rec(2, 0, 8, bytes([counter & 15]) + struct.pack("<hI", th_q13, t32)))


def rssi(counter, src, dbm, seq, t_us, dt_ms=5):
    return rec(3, dt_ms, 8, bytes([(counter & 15) | (src << 4), dbm & 0xFF, seq & 0xFF]) +
               struct.pack("<I", t_us & 0xFFFFFFFF))


stream = b""
now = T0
for i in range(12):
    now += 100_000
    stream += pose(i, 8000 + 100 * i, 6000, 1000 * (i - 6), now)
    for k in range(3):
        now += 5_000
        stream += rssi(3 * i + k, 0, -60 - k, 3 * i + k, now - 1000)
put("can", "stream_pose_rssi", stream)
put("can", "wheel", rec(0, 20, 6, [0x10, 0x2c, 0x01, 0xd4, 0xfe]) + rec(0, 20, 6, [0x01, 0, 0, 0, 0]))
put("can", "status", rec(4, 100, 8, [0x30, 0x26, 0x05, 7, 0, 0, 0]) + rec(4, 100, 8, [0x01, 0x00, 0, 8, 0, 0, 0]))
put("can", "pose_wrap", pose(0, -8388608, 8388607, 25736, T0 + 2**32 + 100_000) +
    pose(1, 0, 0, -25736, T0 - 5_000_000))
put("can", "repeat_unpaired", pose(3, 1, 2, 3, T0 + 100_000) + pose(3, 1, 2, 3, T0 + 200_000) +
    rec(2, 0, 8, [0x05, 0, 0]) + rec(1, 1, 8, [0x06]) + rec(1, 1, 8, [0x07]))
put("can", "bad_dlc_crc", rec(3, 1, 7, [0], fix=True) + rec(3, 1, 8, [0] * 8, fix=False) +
    rec(7, 1, 8, [0xff, 0x07, 0, 0, 0, 0, 0, 0]) + rec(7, 1, 15, [0x11, 0x01]))
# CONFIG: meta-path + pathloss at -40 dBm, then a repeat, bridge + ridge without a floor,
# every limit past by one (target 2, strategy 6, model 5, P0Min 100 dBm + 1/128), then
# FitEarly (data[0] bits 6..7) on, off and the reserved 3.
put("can", "config", rec(6, 1, 8, [0x05, 0x45, 0x00, 0xEC, 0x56, 0x34, 0x12]) +
    rec(6, 1, 8, [0x05, 0x45, 0x00, 0xEC, 0x56, 0x34, 0x12]) +
    rec(6, 1, 8, [0x1F, 0x00, 0x00, 0x80, 0xFF, 0xFF, 0xFF]) + rec(6, 1, 8, [0x20]) +
    rec(6, 1, 8, [0x01, 0x06]) + rec(6, 1, 8, [0x02, 0x50]) + rec(6, 1, 8, [0x03, 0, 0x01, 0x32]) +
    rec(6, 1, 8, [0x86, 0x45, 0x00, 0xEC, 0x56, 0x34, 0x12]) +
    rec(6, 1, 8, [0x57, 0x00, 0x00, 0x80, 0x01, 0x00, 0x00]) + rec(6, 1, 8, [0xC8]))


def receiver(counter, t_us, dt_ms=50):
    return rec(5, dt_ms, 6, bytes([counter & 15]) + struct.pack("<I", t_us & 0xFFFFFFFF))


# A dead zone: heartbeats every 50 ms with no packet, one repeated, one from the future,
# one stale, one across the 32-bit wrap, then a damaged DLC and a reserved nibble.
hb = b""
now = T0
for i in range(8):
    now += 50_000
    hb += receiver(i, now - 2_000)
hb += receiver(7, now, dt_ms=1) + receiver(8, now + 50_000 + 200_000) + receiver(9, now - 2_000_000)
hb += receiver(10, T0 + 2**32 + 400_000, dt_ms=0) + rec(5, 1, 8, [0x0b, 0, 0, 0, 0, 0, 0])
hb += rec(5, 1, 6, [0x1c, 0, 0, 0, 0])
put("can", "receiver_dead_zone", hb)

# --- map: YAML "#PGM\n" PGM -------------------------------------------------------------
MAP_YAML = ("image: m.pgm\nresolution: 0.05\norigin: [-1.0, 2.5, 0.0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
p5 = b"P5\n# test\n4 3\n255\n" + bytes([254, 254, 0, 205, 254, 254, 254, 254, 0, 0, 205, 254])
p2 = b"P2\n3 2\n15\n15 0 7\n15 15 0\n"
p5_16 = b"P5 2 2 65535\n" + struct.pack(">4H", 65535, 0, 30000, 65535)
put("map", "p5", MAP_YAML.encode() + b"#PGM\n" + p5)
put("map", "p2", MAP_YAML.replace("negate: 0", "negate: true").encode() + b"#PGM\n" + p2)
put("map", "p5_16bit", MAP_YAML.encode() + b"#PGM\n" + p5_16)
put("map", "flow_style", b"{image: m.pgm, resolution: 1, origin: [0, 0, 0], occupied_thresh: 0.9,"
    b" free_thresh: 0.1, negate: 0, mode: trinary}\n#PGM\n" + p2)
bad = os.path.join(ROOT, "tests", "data", "maps_bad")
if os.path.isdir(bad):
    for name in sorted(os.listdir(bad)):
        if not name.endswith(".yaml"):
            continue
        text = open(os.path.join(bad, name), "rb").read()
        img = b""
        for line in text.decode(errors="replace").splitlines():
            if line.startswith("image:"):
                ref = line.split(":", 1)[1].strip()
                if os.path.exists(os.path.join(bad, ref)):
                    img = open(os.path.join(bad, ref), "rb").read()
                text = text.replace(ref.encode(), b"m.pgm")
        put("map", "bad_" + name[:-5], text + b"#PGM\n" + img)

# A PNG in place of the PGM: map_server tells the two apart by content.
sys.path.insert(0, os.path.join(ROOT, "tests", "lib"))
import pngenc  # noqa: E402
put("map", "png_scale", MAP_YAML.replace("free_thresh: 0.196", "free_thresh: 0.196\nmode: scale").encode() +
    b"#PGM\n" + pngenc.encode([[(0, 255), (128, 255), (254, 0)], [(90, 255), (200, 128), (254, 255)]], 4, 8))

# --- png: reading byte (mode = b % 3, negate = b / 3 % 2) + PNG ------------------------------
def _px(w, h, n, top, k):
    return [[tuple((x * 37 + y * 11 + c * 5 + k) % (top + 1) for c in range(n)) for x in range(w)] for y in range(h)]


for ct, depth, trns, inter, b in ((0, 1, None, False, 0), (0, 2, None, True, 1), (0, 4, None, False, 2),
                                  (0, 8, b"\x00\x80", False, 3), (0, 16, None, False, 4), (2, 8, None, False, 5),
                                  (2, 16, b"\x00\x01\x00\x02\x00\x03", True, 0), (4, 8, None, False, 1),
                                  (4, 16, None, False, 2), (6, 8, None, True, 3), (6, 16, None, False, 4)):
    n = {0: 1, 2: 3, 4: 2, 6: 4}[ct]
    put("png", f"ct{ct}_d{depth}{'_trns' if trns else ''}{'_i' if inter else ''}",
        bytes([b]) + pngenc.encode(_px(5, 4, n, (1 << depth) - 1, b), ct, depth, None, trns, inter))
for depth in (1, 2, 4, 8):
    pal = [(i * 50 % 256, i * 90 % 256, i * 20 % 256) for i in range(min(1 << depth, 6))]
    put("png", f"palette_d{depth}", bytes([depth % 6]) + pngenc.encode(
        _px(6, 3, 1, len(pal) - 1, depth), 3, depth, pal, bytes([0, 255, 128][:len(pal)])))

# --- scenario -----------------------------------------------------------------------------
scn = os.path.join(ROOT, "scenarios")
for name in sorted(os.listdir(scn)):
    if name.endswith(".yaml"):
        put("scenario", name[:-5], open(os.path.join(scn, name), "rb").read())
put("scenario", "minimal", b"map: m.yaml\nsources:\n  - {position: [1, 2]}\nstart: {position: [0, 0]}\n")
put("scenario", "bridge_two", b"map: m.yaml\ntarget: bridge\nsources:\n  - {name: a, position: [1, 2],"
    b" mac: '02:00:00:00:00:0a'}\n  - {name: b, position: [3, 4], rate_hz: 50, tx_dbm: 10}\n"
    b"start: {position: [0, 0], theta: 3.14}\nstop: {goal: [2, 3], radius_m: 0}\n")
put("scenario", "mac_signed", b"-1:00:00:00:00:00")  # once accepted as ff:00:... (%2x took the sign)
put("scenario", "mac_upper", b"02:00:00:00:00:0A")
put("scenario", "anchors", b"base: &b {position: [1, 2]}\nmap: m.yaml\nsources: [*b, *b, *b]\n"
    b"start: {position: [0, 0]}\n")
put("scenario", "seek_all", b"map: m.yaml\nmodel: pathloss\nstrategy: meta-path\n"
    b"seek: {recheck_m: 1, eps_by_travel: true, eps_rate: 0.2, eps_geodesic: false, "
    b"recheck_adapt: true, p0_min_dbm: -32}\nsources:\n  - {position: [1, 2], tx_dbm: 20}\n"
    b"start: {position: [0, 0]}\n")

# --- LCM: fingerprint + big-endian fields ----------------------------------------------------
def lcm_hash(fields):
    """lcm-gen's fingerprint of a struct of primitive, fixed-size fields (lcmgen.c)."""
    def upd(v, c):
        v = (((v << 8) & 0xFFFFFFFFFFFFFFFF) ^ (v >> 55 if v < 2**63 else ((v - 2**64) >> 55) & 0xFFFFFFFFFFFFFFFF)) + c
        return v & 0xFFFFFFFFFFFFFFFF

    def upd_s(v, s):
        v = upd(v, len(s))
        for ch in s.encode():
            v = upd(v, ch if ch < 128 else ch - 256)
        return v

    v = 0x12345678
    for name, typ, ndim in fields:
        v = upd_s(v, name)
        v = upd_s(v, typ)
        v = upd(v, ndim)
        if ndim:
            v = upd(v, 0)       # LCM_CONST dimension
            v = upd_s(v, "8")
    return ((v << 1) & 0xFFFFFFFFFFFFFFFF) + ((v >> 63) & 1)


POSE = [("utime", "int64_t", 0), ("x", "double", 0), ("y", "double", 0), ("theta", "double", 0)]
RSSI = [("utime", "int64_t", 0), ("source", "int16_t", 0), ("dbm", "int16_t", 0), ("seq", "int32_t", 0)]
CLOCK = [("utime", "int64_t", 0)]
WHEEL = [("utime", "int64_t", 0), ("left_mm_s", "int16_t", 0), ("right_mm_s", "int16_t", 0),
         ("stop", "boolean", 0)]
CAN = [("utime", "int64_t", 0), ("id", "int32_t", 0), ("dlc", "int8_t", 0), ("data", "byte", 1)]
RSSI_STATUS = [("utime", "int64_t", 0), ("seq", "int32_t", 0)]
STATUS = ([("utime", "int64_t", 0), ("state", "int8_t", 0), ("faults", "int32_t", 0),
           ("left_mm_s", "int16_t", 0), ("right_mm_s", "int16_t", 0), ("decided", "boolean", 0),
           ("iteration", "int32_t", 0), ("decision_utime", "int64_t", 0), ("kind", "int8_t", 0),
           ("reason", "string", 0)] +
          [(n, "boolean", 0) for n in ("model_updated", "line_search", "model_valid", "mean_valid")] +
          [("prev", "int8_t", 0)] +
          [(n, "double", 0) for n in ("prediction", "mean", "epsilon", "x", "y", "goal_x", "goal_y",
                                      "max_x", "max_y", "path_len")] +
          [("samples", "int32_t", 0)] +
          [(n, "boolean", 0) for n in ("sampled", "near", "hedged", "pinned", "refuted")] +
          [("plan_wait", "int32_t", 0), ("est_valid", "boolean", 0)] +
          [(n, "double", 0) for n in ("est_x", "est_y", "est_n", "est_w", "est_p0", "est_rms",
                                      "est_area")] +
          [("bridge_valid", "boolean", 0)] +
          [(n, "double", 0) for n in ("bridge_x", "bridge_y", "bridge_f", "bridge_sigma",
                                      "bridge_area")])


def status(kind, reason, flags, plan_wait, est):
    """A decided seeker_status_t (lcm/seeker_status_t.lcm): flags are sampled, near, hedged,
    pinned, refuted; est the 7 path-loss values or None."""
    r = reason.encode() + b"\0"
    return (struct.pack(">Q", lcm_hash(STATUS)) +
            struct.pack(">qbihhbiqb", 2_000_000, 3, 0, 250, 300, 1, 4, 2_000_000, kind) +
            struct.pack(">i", len(r)) + r + struct.pack(">5b", 1, 0, 1, 1, 0) +
            struct.pack(">10d", -60.5, -58.25, 0.25, 8.0, 6.0, 12.5, 6.0, 12.5, 6.0, 4.75) +
            struct.pack(">i", 300) + struct.pack(">5bib", *flags, plan_wait, est is not None) +
            struct.pack(">7d", *(est or [0.0] * 7)) + struct.pack(">b5d", 0, 0, 0, 0, 0, 0))


msgs = {
    0: struct.pack(">Q", lcm_hash(POSE)) + struct.pack(">qddd", 1_000_000, 8.0, 6.0, 7.0),
    1: struct.pack(">Q", lcm_hash(RSSI)) + struct.pack(">qhhi", 1_000_000, 0, -60, 7),
    2: struct.pack(">Q", lcm_hash(CLOCK)) + struct.pack(">q", 2_000_000),
    3: struct.pack(">Q", lcm_hash(WHEEL)) + struct.pack(">qhhb", 1_000_000, 300, -300, 0),
    4: status(2, "greedy+relearn", (0, 0, 0, 0, 1), 1, [27.875, 11.375, 2.5, 4.0, -20.0, 2.0, 3.0]),
    5: struct.pack(">Q", lcm_hash(CAN)) + struct.pack(">qib", 1_000_000, 0x120, 8) + bytes(range(8)),
    6: struct.pack(">Q", lcm_hash(RSSI_STATUS)) + struct.pack(">qi", 1_050_000, 21),
}
for sel, m in msgs.items():
    put("lcm", "msg_%d" % sel, bytes([sel]) + m)
put("lcm", "msg_4_garbage", bytes([4]) + b"\x00" * 40)
put("lcm", "msg_4_sampled", bytes([4]) + status(3, "epsilon+relearn", (1, 0, 0, 0, 0), 65535, None))
put("lcm", "msg_6_clock", bytes([6]) + msgs[2])  # a clock_t on the heartbeat channel


def log_event(num, t, ch, data):
    return struct.pack(">IqqII", 0xEDA1DA01, num, t, len(ch), len(data)) + ch.encode() + data


names = ["RFS_POSE", "RFS_RSSI", "RFS_CLOCK", "RFS_WHEEL_CMD", "RFS_SEEKER_STATUS", "RFS_CAN_FALLBACK",
         "RFS_RSSI_STATUS"]
log = b"".join(log_event(i, 1_000_000 + i, names[sel], m) for i, (sel, m) in enumerate(msgs.items()))
put("lcm", "log_all", b"\x80" + log)
put("lcm", "log_unknown_channel", b"\x80" + log_event(0, 5, "OTHER", b"abc") + log_event(1, 6, "RFS_POSE", b"x"))


# --- pcap / pcapng: radiotap (dBm signal only) + an 802.11 data frame ------------------------
FRAME = (struct.pack("<BBHI", 0, 0, 9, 0x20) + struct.pack("<b", -40) + bytes([0x08, 0x01, 0, 0]) +
         bytes.fromhex("0a1b2c3d4e5f" "02aabbcc0001" "0a1b2c3d4e5f") + struct.pack("<H", 1 << 4))


def classic(magic, end, records):
    head = struct.pack(end + "IHHiIII", magic, 2, 4, 0, 0, 65535, 127)
    return head + b"".join(struct.pack(end + "IIII", sec, frac, len(FRAME), len(FRAME)) + FRAME
                           for sec, frac in records)


put("pcap", "classic_us", classic(0xA1B2C3D4, "<", [(1700000000, 1), (1700000000, 999999)]))
put("pcap", "classic_ns_be", classic(0xA1B23C4D, ">", [(1700000000, 999999999)]))
put("pcap", "classic_2e31", classic(0xA1B2C3D4, "<", [(2**31, 0), (2**32 - 1, 999999)]))
# fractions of a second or more: 2^31 us and up reads negative in libpcap (found by fuzz_pcap)
put("pcap", "classic_frac_big", classic(0xA1B2C3D4, "<", [(0x21210001, 0xB90D0D21), (5, 1000000)]))
put("pcap", "classic_cut", classic(0xA1B2C3D4, "<", [(1, 2)])[:-5])


def block(kind, body):
    body += b"\0" * (-len(body) % 4)
    return struct.pack("<II", kind, len(body) + 12) + body + struct.pack("<I", len(body) + 12)


def pcapng(tsresol, stamps):
    shb = block(0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1))
    idb = block(1, struct.pack("<HHI", 127, 0, 65535) + struct.pack("<HHB3x", 9, 1, tsresol) + b"\0" * 4)
    return shb + idb + b"".join(block(6, struct.pack("<IIIII", 0, t >> 32, t & 0xFFFFFFFF, len(FRAME), len(FRAME))
                                      + FRAME) for t in stamps)


put("pcap", "ng_res6", pcapng(6, [1700000000000001, 1700000000999999]))
put("pcap", "ng_res9_max", pcapng(9, [2**64 - 1, 0]))
put("pcap", "ng_res0_max", pcapng(0, [2**64 - 1]))
put("pcap", "ng_res2_20", pcapng(0x94, [(1700000000 << 20) + 3, 2**64 - 1]))
put("pcap", "ng_res2_63", pcapng(0xBF, [2**64 - 1]))

# --- poses: t_us,x_m,y_m,theta_rad -----------------------------------------------------------
HDR = b"t_us,x_m,y_m,theta_rad\n"
put("poses", "good", HDR + b"1700000000000000,8,6,0\n1700000000100000,8.05,6,0.01\n1700000000200000,8.1,6,-3.14\n")
put("poses", "crlf_blank", HDR.replace(b"\n", b"\r\n") + b"0,0,0,0\r\n\r\n1,1e-3,-2,6.3\r\n")
put("poses", "theta_big", HDR + b"0,1,1,1e9\n1,1,1,-1e300\n2,1,1,201.0619298297468\n")
put("poses", "t_edges", HDR + b"-9223372036854775808,0,0,0\n9007199254740992,0,0,0\n")
put("poses", "xy_edges", HDR + b"0,32767,-32767,0\n1,32767.0001,0,0\n")

# --- candump: candump -L lines (can-utils: "(%010ld.%06ld) %*s " + ID#HEX) --------------------
put("candump", "mission", b"(0000004294.969796) can0 120#00A100C4090000BD\n"
    b"(0000004295.017296) can0 100#011700E9FF73\n(0000004295.017296) can0 180#3005000000000046\n")
put("candump", "kinds", b"(1700000000.000001) vcan0 12345678#DEADBEEF\n(1700000000.000002) vcan0 7FF#R\n"
    b"(1700000000.000003) vcan0 123#R8\n(1700000000.000004) vcan0 20000004#0004000000000000\n"
    b"(1700000000.000005) vcan0 123##1112233\n(1700000000.000006) vcan0 123#11.22.33\n")
put("candump", "directions", b"(1700000000.000001)  can0 100#1000000000A2 T\n(1700000000.000002) can10 111#00 R\r\n")
put("candump", "edges", b"(999999999999.999999) a 000#\n(0.000000) x 7FF#0011223344556677\n"
    b"(1700000000.000001) can0 100#112233445566778899\n(1700000000.1) can0 100#\n")
