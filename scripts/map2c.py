#!/usr/bin/env python3
"""map2c.py - bake a map into the firmware image as const bit grids.

    map2c.py MAP.yaml [--res 0.1] -o OUT.c      a ROS map_server map (yaml + PGM)
    map2c.py --box W H [--res 0.1] -o OUT.c     an empty W x H m room (walls round it)

Writes `const rfs_app_map_t rfs_fw_map` with its free and wall grids in the core's
layout (common/rfs_map.h: bit (cx, cy) is bit cx & 7 of byte cy * stride + cx / 8,
row 0 at the bottom). Downsampling is conservative, as the host loader's: a core cell is
free only when every map cell under it is free, a wall when any is occupied; cells past
the image edge count as unknown. ROS trinary reading: p = (255 - v) / 255 (v / 255 with
negate), occupied if p > occupied_thresh, free if p < free_thresh.
Exits 1 with one line "map2c: FILE: reason" on bad input; writes OUT atomically.
"""
import argparse
import math
import os
import re
import sys
import tempfile

MAX_BYTES = 6400  # RFS_APP_MAX_MAP_BYTES in firmware/rfs_app.h


def die(msg):
    print("map2c: " + msg, file=sys.stderr)
    sys.exit(1)


def read_yaml(path):
    try:
        text = open(path, encoding="utf-8").read()
    except OSError as e:
        die(f"{path}: {e.strerror}")
    kv = {}
    for line in text.splitlines():
        m = re.match(r"^\s*([A-Za-z_]+)\s*:\s*(.*?)\s*(#.*)?$", line)
        if m:
            kv[m.group(1)] = m.group(2)
    for k in ("image", "resolution", "origin"):
        if k not in kv:
            die(f"{path}: missing key '{k}'")
    try:
        res = float(kv["resolution"])
        origin = [float(v) for v in kv["origin"].strip("[]").split(",")]
        occ = float(kv.get("occupied_thresh", "0.65"))
        fre = float(kv.get("free_thresh", "0.196"))
        negate = int(kv.get("negate", "0"))
    except ValueError:
        die(f"{path}: malformed number")
    if res <= 0 or len(origin) != 3 or origin[2] != 0.0:
        die(f"{path}: resolution must be > 0 and origin [x, y, 0]")
    image = kv["image"].strip("'\"")
    image = os.path.join(os.path.dirname(path), image)
    return image, res, origin[0], origin[1], occ, fre, negate


def read_pgm(path):
    try:
        data = open(path, "rb").read()
    except OSError as e:
        die(f"{path}: {e.strerror}")
    toks, i = [], 0
    while len(toks) < 4:
        while i < len(data) and data[i:i + 1].isspace():
            i += 1
        if i < len(data) and data[i:i + 1] == b"#":
            while i < len(data) and data[i:i + 1] != b"\n":
                i += 1
            continue
        j = i
        while j < len(data) and not data[j:j + 1].isspace():
            j += 1
        if j == i:
            die(f"{path}: truncated header")
        toks.append(data[i:j])
        i = j
    if toks[0] != b"P5":
        die(f"{path}: not a binary PGM (P5)")
    w, h, maxval = int(toks[1]), int(toks[2]), int(toks[3])
    if maxval != 255:
        die(f"{path}: maxval {maxval}, expected 255")
    pix = data[i + 1:]
    if len(pix) < w * h:
        die(f"{path}: {len(pix)} pixel bytes, header says {w * h}")
    return w, h, pix


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("yaml", nargs="?")
    ap.add_argument("--box", nargs=2, type=float, metavar=("W", "H"))
    ap.add_argument("--res", type=float, default=0.1)
    ap.add_argument("-o", "--out", required=True)
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    if (a.yaml is None) == (a.box is None):
        die("give MAP.yaml or --box W H")
    if a.box:
        w = int(round(a.box[0] / a.res))
        h = int(round(a.box[1] / a.res))
        ox = oy = 0.0
        cell = lambda cx, cy: 1 if cx in (0, w - 1) or cy in (0, h - 1) else 0  # 1 = wall
        free = lambda cx, cy: cell(cx, cy) == 0
        wall = lambda cx, cy: cell(cx, cy) == 1
        name = f"box {a.box[0]:g} x {a.box[1]:g} m"
    else:
        image, res, ox, oy, occ, fre, negate = read_yaml(a.yaml)
        iw, ih, pix = read_pgm(image)
        f = a.res / res
        if abs(f - round(f)) > 1e-6 or round(f) < 1:
            die(f"{a.yaml}: core resolution {a.res} is not a multiple of {res}")
        f = int(round(f))
        w, h = math.ceil(iw / f), math.ceil(ih / f)

        def fine(x, y):  # 0 free, 1 occupied, 2 unknown; y = 0 is the bottom row
            if x >= iw or y >= ih:
                return 2
            v = pix[(ih - 1 - y) * iw + x]
            p = v / 255.0 if negate else (255 - v) / 255.0
            return 1 if p > occ else (0 if p < fre else 2)

        cache = {}

        def block(cx, cy):
            k = (cx, cy)
            if k not in cache:
                vals = [fine(cx * f + i, cy * f + j) for j in range(f) for i in range(f)]
                cache[k] = (all(v == 0 for v in vals), any(v == 1 for v in vals))
            return cache[k]

        free = lambda cx, cy: block(cx, cy)[0]
        wall = lambda cx, cy: block(cx, cy)[1]
        name = os.path.basename(a.yaml)
    stride = (w + 7) // 8
    if w > 65535 or h > 65535 or stride * h > MAX_BYTES:
        die(f"{a.yaml or 'box'}: {w} x {h} cells need {stride * h} bytes per grid, "
            f"the image holds {MAX_BYTES}")
    grids = {}
    for gname, fn in (("free", free), ("wall", wall)):
        b = bytearray(stride * h)
        for cy in range(h):
            for cx in range(w):
                if fn(cx, cy):
                    b[cy * stride + cx // 8] |= 1 << (cx & 7)
        grids[gname] = b
    q16 = lambda v: int(round(v * 65536))
    out = [f"/* Generated by scripts/map2c.py from {name}: {w} x {h} cells at {a.res} m. */",
           '#include "rfs_app.h"', ""]
    for gname, b in grids.items():
        out.append(f"static const uint8_t k_{gname}[{len(b)}] = {{")
        for i in range(0, len(b), 16):
            out.append("    " + ", ".join(f"0x{x:02x}" for x in b[i:i + 16]) + ",")
        out.append("};")
    out.append("const rfs_app_map_t rfs_fw_map = {")
    out.append(f"    .w = {w}, .h = {h}, .res = {q16(a.res)}, .origin_x = {q16(ox)}, "
               f".origin_y = {q16(oy)},")
    out.append("    .free = k_free, .wall = k_wall,")
    out.append("};")
    d = os.path.dirname(os.path.abspath(a.out))
    if not os.path.isdir(d) or os.path.isdir(a.out):
        die(f"{a.out}: {'is a directory' if os.path.isdir(a.out) else 'its folder does not exist'}")
    fd, tmp = tempfile.mkstemp(dir=d, prefix=".map2c.")
    with os.fdopen(fd, "w") as fh:
        fh.write("\n".join(out) + "\n")
    os.replace(tmp, a.out)


if __name__ == "__main__":
    main()
