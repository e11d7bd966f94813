#!/usr/bin/env python3
"""Check can/rfseek.dbc against frames encoded by our C code.

Loads the DBC with canmatrix (an independent implementation of the format), reads
"ID#HEX Field=raw ..." lines produced by build/.../can_vectors, decodes each frame's
bytes with the DBC and compares every signal's raw value with the value the C side
encoded; a DBC signal a vector does not name is a failure too (a field the codec
gained without the DBC, or the reverse). The checksum is recomputed here with an independent CRC-8/SAE-J1850 and the
DLC compared with the DBC's frame size. Prints PASS/FAIL lines; exit 1 on any failure.

usage: check_dbc.py DBC VECTORS_FILE
"""
import logging
import os
import sys


def crc8_j1850(data):
    """CRC-8/SAE-J1850: poly 0x1D, init 0xFF, xorout 0xFF, not reflected."""
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


def main(argv):
    if len(argv) > 1 and argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0
    if len(argv) != 3:
        sys.exit("usage: check_dbc.py DBC VECTORS_FILE (see --help)")
    logging.disable(logging.CRITICAL)
    import canmatrix.formats
    dbc_path, vec_path = argv[1], argv[2]
    try:
        db = canmatrix.formats.loadp_flat(dbc_path)
    except Exception as e:  # canmatrix raises many kinds
        print("FAIL dbc-load %s: %s" % (dbc_path, e))
        return 1
    if len(db.frames) != 7:
        print("FAIL dbc-load %s: expected 7 frames, found %d" % (dbc_path, len(db.frames)))
        return 1
    print("PASS dbc-load %s (%d frames)" % (dbc_path, len(db.frames)))
    assert crc8_j1850(b"123456789") == 0x4B  # the catalogue check value
    failures = 0
    count = 0
    seen = set()
    with open(vec_path) as fh:
        for lineno, line in enumerate(fh, 1):
            parts = line.split()
            if not parts:
                continue
            cid, hexdata = parts[0].split("#")
            cid = int(cid, 16)
            data = bytes.fromhex(hexdata)
            want = {k: int(v) for k, v in (p.split("=") for p in parts[1:])}
            fr = db.frame_by_id(canmatrix.ArbitrationId(cid))
            where = "%s:%d %03X" % (vec_path, lineno, cid)
            if fr is None:
                print("FAIL dbc-decode %s: id not in the DBC" % where)
                failures += 1
                continue
            errs = []
            if len(data) != fr.size:
                errs.append("dlc %d != DBC size %d" % (len(data), fr.size))
            dec = fr.decode(bytearray(data))
            unnamed = sorted(s.name for s in fr.signals if s.name != "Checksum" and s.name not in want)
            if unnamed:
                errs.append("DBC signals without an encoded value: %s" % ", ".join(unnamed))
            for name, value in want.items():
                if name not in dec:
                    errs.append("%s missing in DBC" % name)
                elif int(dec[name].raw_value) != value:
                    errs.append("%s: DBC %s != encoded %d" % (name, dec[name].raw_value, value))
            crc = crc8_j1850(bytes([cid & 0xFF, cid >> 8]) + data[:-1])
            if int(dec["Checksum"].raw_value) != crc or data[-1] != crc:
                errs.append("checksum %02X != independent CRC %02X" % (data[-1], crc))
            count += 1
            seen.add(cid)
            if errs:
                failures += 1
                print("FAIL dbc-decode %s %s: %s" % (where, fr.name, "; ".join(errs)))
    if count == 0:
        print("FAIL dbc-decode %s: no vectors" % vec_path)
        return 1
    missing = sorted(fr.arbitration_id.id for fr in db.frames if fr.arbitration_id.id not in seen)
    if missing:
        print("FAIL dbc-coverage: no vectors for %s" % ", ".join("%03X" % i for i in missing))
        failures += 1
    if failures == 0:
        print("PASS dbc-decode %d frames match field by field" % count)
    return 1 if failures else 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except OSError as e:  # a missing or unreadable file: one line, not a traceback
        sys.exit("%s: %s: %s" % (os.path.basename(sys.argv[0]), e.filename, e.strerror))
