#!/usr/bin/env python3
"""Check a candump -L log of the rfseek bus against can/rfseek.dbc with canmatrix.

Independent of our C code: the lines are read with a regular expression of the can-utils
format, every frame is decoded by canmatrix from the DBC, the checksum recomputed with
scripts/check_dbc.py's CRC-8/SAE-J1850, and checked: the DLC is the DBC's, every signal
lies within its DBC range, enum signals hold a value of their VAL_ table, counters roll
by one per frame of an id (a pose's halves share one), the cycle times measured in the
log equal the DBC's GenMsgCycleTime. The DBC itself: its ECUs are the five nodes (the
receivers of a signal are separate ECUs), its value tables name the C enums of
common/rfs_seek.h, common/rfs_drive.h, common/rfs_can.h and firmware/rfs_app.h in order,
every raw value of the signal that carries the table.

  --sim        the log is a simulated recording (rfseek-record): every Time field equals
               the line's time modulo 2^32 us (the sender's clock is the log's)
  --asc FILE   FILE is log2asc's conversion of the log: one banner, one line per frame
               with the same id, DLC, bytes and time from the first frame
  --decode     print each frame decoded: t_us, frame name, Signal=raw ... (TSV)

Prints PASS/FAIL lines; exit 1 on any failure.
usage: check_candump.py DBC LOG [--sim] [--asc FILE] [--decode]
"""
import logging
import os
import re
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_dbc import crc8_j1850  # noqa: E402

LINE = re.compile(r"^\((\d+)\.(\d{6})\) (\S+) ([0-9A-F]{3})#((?:[0-9A-F]{2}){0,8})$")
NODES = ["CTRL", "MOTOR", "LOC", "RADIO", "OPER"]
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# VAL_ tables and the C enums they must name (header, the enum's first constant's prefix).
ENUMS = {
    "SeekState": ("common/rfs_seek.h", "rfs_seek_state", "RFS_SEEK_"),
    "DecisionKind": ("common/rfs_seek.h", "rfs_seek_kind", "RFS_SEEK_"),
    "DriveStatus": ("common/rfs_drive.h", "rfs_drive_status", "RFS_DRIVE_"),
    "Target": ("firmware/rfs_app.h", "rfs_app_target", "RFS_APP_TARGET_"),
    "Strategy": ("common/rfs_seek.h", "rfs_seek_strategy", "RFS_SEEK_"),
    "Model": ("common/rfs_can.h", "rfs_can_model", "RFS_CAN_MODEL_"),
}
TIME_SIGNALS = {"POSE_TH": "Time", "RSSI": "Time", "RX_STATUS": "Time"}


def c_enum(header, name, prefix):
    """{value: NAME} of `typedef enum name { PREFIX_NAME = 0, ... }` in a C header."""
    text = open(os.path.join(ROOT, header)).read()
    body = re.search(r"typedef enum %s \{(.*?)\}" % name, text, re.S).group(1)
    names = re.findall(r"^\s*%s(\w+)" % prefix, body, re.M)
    return {i: n for i, n in enumerate(names)}


def read_log(path):
    """[(t_us, ifname, id, bytes)] of every line; exits on a line not in the format."""
    frames = []
    with open(path) as fh:
        for lineno, line in enumerate(fh, 1):
            m = LINE.match(line.rstrip("\n"))
            if not m:
                print("FAIL candump-format %s:%d: %r" % (path, lineno, line[:80]))
                sys.exit(1)
            frames.append((int(m.group(1)) * 1000000 + int(m.group(2)), m.group(3),
                           int(m.group(4), 16), bytes.fromhex(m.group(5))))
    return frames


def check_dbc_shape(db, fails):
    ecus = sorted(e.name for e in db.ecus)
    recv = sorted({r for fr in db.frames for s in fr.signals for r in s.receivers})
    if ecus != sorted(NODES) or any(r not in NODES for r in recv):
        fails.append("dbc-ecus: ECUs %s, receivers %s; expected %s" % (ecus, recv, NODES))
    for table, (header, enum, prefix) in ENUMS.items():
        # The enum's values that fit the signal carrying the table (all of them must).
        got = db.value_tables.get(table)
        sigs = [s for fr in db.frames for s in fr.signals if got and s.values == got]
        top = int(sigs[0].max) if sigs else -1
        want = {k: v for k, v in c_enum(header, enum, prefix).items() if k <= top}
        if got != want or len(want) != top + 1:
            fails.append("dbc-value-table %s: %s != C enum %s %s (signal range 0..%d)" % (table, got, enum, want, top))


def check_frames(db, frames, sim, fails, decode):
    counters = {}
    last_xy = None
    for n, (t, _ifname, cid, data) in enumerate(frames, 1):
        fr = db.frame_by_id(canmatrix.ArbitrationId(cid))
        where = "frame %d (%03X at %d us)" % (n, cid, t)
        if fr is None:
            fails.append("decode %s: id not in the DBC" % where)
            continue
        if len(data) != fr.size:
            fails.append("dlc %s: %d bytes, DBC %d" % (where, len(data), fr.size))
            continue
        dec = fr.decode(bytearray(data))
        crc = crc8_j1850(bytes([cid & 0xFF, cid >> 8]) + data[:-1])
        if data[-1] != crc or int(dec["Checksum"].raw_value) != crc:
            fails.append("checksum %s: %02X, CRC-8 %02X" % (where, data[-1], crc))
        for sig in fr.signals:
            v = dec[sig.name]
            if not (float(sig.min) <= float(v.phys_value) <= float(sig.max)):
                fails.append("range %s %s: %s outside [%s, %s]" % (where, sig.name, v.phys_value, sig.min, sig.max))
            if sig.values and int(v.raw_value) not in sig.values:
                fails.append("enum %s %s: %d not in its VAL_ table" % (where, sig.name, int(v.raw_value)))
        c = int(dec["Counter"].raw_value)
        if fr.name == "POSE_TH":
            if last_xy != c:
                fails.append("counter %s: POSE_TH %d after POSE_XY %s" % (where, c, last_xy))
        elif cid in counters and c != (counters[cid] + 1) % 16:
            fails.append("counter %s: %d after %d" % (where, c, counters[cid]))
        counters[cid] = c
        last_xy = c if fr.name == "POSE_XY" else None
        if sim and fr.name in TIME_SIGNALS:
            raw = int(dec[TIME_SIGNALS[fr.name]].raw_value)
            if raw != t % 2**32:
                fails.append("time %s: Time %d, line time mod 2^32 %d" % (where, raw, t % 2**32))
        if decode:
            print("%d\t%s\t%s" % (t, fr.name, "\t".join("%s=%d" % (s.name, int(dec[s.name].raw_value))
                                                          for s in fr.signals)))


def check_cycles(db, frames, fails, passes):
    for fr in db.frames:
        cycle = int(fr.cycle_time or 0)
        times = [t for t, _i, cid, _d in frames if cid == fr.arbitration_id.id]
        if cycle == 0 or len(times) < 3:
            continue
        period_ms = statistics.median(b - a for a, b in zip(times, times[1:])) / 1000.0
        if abs(period_ms - cycle) > 1.0:
            fails.append("cycle %s: median period %.1f ms, GenMsgCycleTime %d ms" % (fr.name, period_ms, cycle))
        else:
            passes.append("cycle %s: median period %.1f ms = GenMsgCycleTime %d ms (%d frames)"
                          % (fr.name, period_ms, cycle, len(times)))


def check_asc(path, frames, fails):
    """log2asc's output: a banner, then "   S.UUUUUU 1  ID  Rx   d DLC BB ..." per frame."""
    lines = open(path).read().splitlines()
    body = [ln for ln in lines if re.match(r"^\s*\d+\.\d{6} ", ln)]
    if sum(ln.startswith("date ") for ln in lines) != 1 or len(body) != len(frames):
        fails.append("asc: %d banners, %d frame lines for %d frames"
                     % (sum(ln.startswith("date ") for ln in lines), len(body), len(frames)))
        return
    t0 = frames[0][0]
    for ln, (t, _i, cid, data) in zip(body, frames):
        f = ln.split()
        want = ["%d.%06d" % divmod(t - t0, 1000000), "1", "%X" % cid, "Rx", "d", "%X" % len(data)]
        want += ["%02X" % b for b in data]
        if f != want:
            fails.append("asc: %r, expected %r" % (ln, " ".join(want)))
            return


def main(argv):
    if "--help" in argv or "-h" in argv:
        print(__doc__.strip())
        return 0
    args, i = [], 1
    while i < len(argv):
        a = argv[i]
        if a == "--asc" and i + 1 < len(argv):
            i += 1
        elif a.startswith("-") and a not in ("--sim", "--decode"):
            sys.exit("check_candump.py: %s: unknown option or missing value (see --help)" % a)
        elif not a.startswith("-"):
            args.append(a)
        i += 1
    if len(args) != 2:
        sys.exit("usage: check_candump.py DBC LOG [--sim] [--asc FILE] [--decode] (see --help)")
    logging.disable(logging.CRITICAL)
    global canmatrix
    import canmatrix
    import canmatrix.formats
    dbc, log = args[0], args[1]
    asc = argv[argv.index("--asc") + 1] if "--asc" in argv else None
    db = canmatrix.formats.loadp_flat(dbc)
    frames = read_log(log)
    fails, passes = [], []
    check_dbc_shape(db, fails)
    check_frames(db, frames, "--sim" in argv, fails, "--decode" in argv)
    check_cycles(db, frames, fails, passes)
    if asc:
        check_asc(asc, frames, fails)
    if not frames:
        fails.append("log %s: no frame" % log)
    for p in passes:
        print("PASS " + p)
    for f in fails[:20]:
        print("FAIL " + f)
    if not fails:
        ids = sorted({cid for _t, _i, cid, _d in frames})
        print("PASS candump-decode %s: %d frames of %s decode with canmatrix; checksums, DLCs, ranges, "
              "enums, counters%s%s ok" % (os.path.basename(log), len(frames), " ".join("%03X" % i for i in ids),
                                           ", Time fields" if "--sim" in argv else "",
                                           ", log2asc's lines" if asc else ""))
    return 1 if fails else 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except OSError as e:  # a missing or unreadable file: one line, not a traceback
        sys.exit("%s: %s: %s" % (os.path.basename(sys.argv[0]), e.filename, e.strerror))
