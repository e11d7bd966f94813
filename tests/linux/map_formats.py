#!/usr/bin/env python3
"""map_formats.py BUILD - map images as map_server reads them (docs/MAPS.md, "The
map_server convention"): PNG of every colour type and depth, PGM, modes trinary, scale
and raw, negate.

Reference: each pixel's occupancy value is computed here in exact rational arithmetic
from the rules of nav2's map_io.cpp (loadMapFromFile) as docs/MAPS.md states them, from
the pixels the images were written from (tests/lib/pngenc.py, Python's zlib, nothing of
libpng); map_dump (lx_map_load_values and lx_map_load) must give the same values and
cells for every pixel. Where the exact value sits on a rounding or threshold tie, either
neighbour is accepted (double precision may fall on either side; random pixels hit none
or almost none). Then damaged and oversized PNGs: one error line naming the file, exit
1, nothing written, and a 2^26-pixel PNG read within 100 MB.
"""
import os
import random
import resource
import subprocess
import sys
import tempfile
import zlib
from fractions import Fraction

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))
import pngenc  # noqa: E402
from checks import check, exit_status  # noqa: E402

BUILD = sys.argv[1] if len(sys.argv) > 1 else "build"
DUMP = os.path.join(BUILD, "tests", "map_dump")
MAP = os.path.join(BUILD, "bin", "rfseek-map")
rng = random.Random(20240601)


def nav2_value(ch, maxval, mode, negate, occ_s, free_s):
    """The set of values map_server may give (one, or two at an exact tie)."""
    occ, free = Fraction(occ_s), Fraction(free_s)
    alpha = len(ch) in (2, 4)
    colours = [ch[0]] * 3 if len(ch) <= 2 else ch[:3]
    parts = colours + ([ch[-1]] if alpha and mode == "trinary" else [])
    mean = Fraction(sum(parts), len(parts))
    if mode == "raw":  # round(shade * 255), half away from zero; negate not applied
        x = mean / maxval * 255
        v = int(x) + (1 if x - int(x) >= Fraction(1, 2) else 0)
        return {v if 0 <= v <= 100 else -1}
    if mode == "scale" and alpha and ch[-1] != maxval:
        return {-1}
    p = mean / maxval if negate else (maxval - mean) / maxval
    out = set()
    for q in ({p} if p not in (occ, free) else {p - Fraction(1, 10**12), p + Fraction(1, 10**12)}):
        if q > occ:
            out.add(100)
        elif q < free:
            out.add(0)
        elif mode == "trinary":
            out.add(-1)
        else:  # rint: half to even
            x = (q - free) / (occ - free) * 100
            lo = x.numerator // x.denominator
            if x - lo == Fraction(1, 2):
                out |= {lo, lo + 1}
            else:
                out.add(lo + (1 if x - lo > Fraction(1, 2) else 0))
    return out


def cell_of(v):
    return 2 if v < 0 else (1 if v >= 100 else 0)


def dump(yaml):
    r = subprocess.run([DUMP, yaml], capture_output=True, text=True)
    if r.returncode != 0:
        return None, r.stderr.strip()
    lines = r.stdout.split("\n")
    w, h = map(int, lines[0].split())
    vals = [list(map(int, ln.split())) for ln in lines[1:1 + h]]
    cells = [list(map(int, ln.split())) for ln in lines[1 + h:1 + 2 * h]]
    return (w, h, vals, cells), ""


def write_map(d, name, image_bytes, mode, negate, occ="0.65", free="0.196", ext="png"):
    ipath = os.path.join(d, f"{name}.{ext}")
    with open(ipath, "wb") as f:
        f.write(image_bytes)
    ypath = os.path.join(d, f"{name}_{mode}_{negate}.yaml")
    with open(ypath, "w") as f:
        f.write(f"image: {name}.{ext}\nresolution: 0.05\norigin: [-1.0, 2.0, 0.0]\nnegate: {negate}\n"
                f"occupied_thresh: {occ}\nfree_thresh: {free}\nmode: {mode}\n")
    return ypath


def random_pixels(w, h, color_type, depth, npal=0):
    """Random pixels, alpha mostly opaque (so scale mode has values to scale)."""
    top = (1 << depth) - 1
    n = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[color_type]
    rows = []
    for _ in range(h):
        row = []
        for _ in range(w):
            if color_type == 3:
                px = (rng.randrange(npal),)
            else:
                px = [rng.randint(0, top) for _ in range(n)]
                if color_type in (4, 6) and rng.random() < 0.7:
                    px[-1] = top
                px = tuple(px)
            row.append(px)
        rows.append(row)
    return rows


# Every colour type at every depth the specification allows, with and without tRNS,
# plain and interlaced.
KINDS = []
for depth in (1, 2, 4, 8, 16):
    KINDS.append((0, depth, False, False))
for depth in (8, 16):
    KINDS += [(2, depth, False, False), (4, depth, False, False), (6, depth, False, False)]
for depth in (1, 2, 4, 8):
    KINDS.append((3, depth, False, False))
KINDS += [(0, 8, True, False), (0, 16, True, False), (2, 8, True, False), (3, 8, True, False), (3, 4, True, True),
          (6, 8, False, True), (0, 1, False, True), (2, 16, True, True)]
READINGS = [(m, n, o, f) for m in ("trinary", "scale", "raw") for n in (0, 1)
            for o, f in (("0.65", "0.196"), ("0.9", "0.1"))]

with tempfile.TemporaryDirectory() as d:
    # --- every kind of PNG in every reading -------------------------------------------
    for (ct, depth, with_trns, interlace) in KINDS:
        w, h = rng.randint(9, 23), rng.randint(5, 17)
        palette = trns = None
        npal = 0
        if ct == 3:
            npal = rng.randint(2, 1 << depth)
            palette = [(rng.randrange(256), rng.randrange(256), rng.randrange(256)) for _ in range(npal)]
            if with_trns:
                trns = bytes(rng.choice((0, 255, rng.randrange(256))) for _ in range(rng.randint(1, npal)))
        pixels = random_pixels(w, h, ct, depth, npal)
        if with_trns and ct in (0, 2):
            t = pixels[rng.randrange(h)][rng.randrange(w)]  # a colour that occurs
            trns = pngenc.trns_bytes(ct, depth, t[0] if ct == 0 else t)
        data = pngenc.encode(pixels, ct, depth, palette, trns, interlace)
        name = f"ct{ct}_d{depth}{'_trns' if with_trns else ''}{'_i' if interlace else ''}"
        bad, ties, total = [], 0, 0
        for mode, neg, occ, free in READINGS:
            got, err = dump(write_map(d, name, data, mode, neg, occ, free))
            if got is None:
                bad.append(f"{mode}/{neg}: {err}")
                continue
            gw, gh, vals, cells = got
            if (gw, gh) != (w, h):
                bad.append(f"size {gw} x {gh}, wrote {w} x {h}")
                continue
            for y in range(h):
                for x in range(w):
                    ch, mx = pngenc.expand(pixels[y][x], ct, depth, palette, trns)
                    want = nav2_value(ch, mx, mode, neg, occ, free)
                    total += 1
                    ties += len(want) > 1
                    if vals[y][x] not in want or cells[y][x] != cell_of(vals[y][x]):
                        bad.append(f"{mode}/{neg}/{occ}/{free} ({x}, {y}) {ch} of {mx}: value {vals[y][x]} "
                                   f"cell {cells[y][x]}, want {sorted(want)}")
        check(f"png-{name}", not bad, "; ".join(bad[:3]))
        if ties:
            print(f"  ({name}: {ties} of {total} pixels on an exact tie)")

    # --- PGM in every reading: P5 of maxval 255, 1000 and 65535, P2 -------------------
    for magic, maxval in (("P5", 255), ("P5", 1000), ("P5", 65535), ("P2", 255), ("P2", 7)):
        w, h = 11, 7
        pix = [[rng.randint(0, maxval) for _ in range(w)] for _ in range(h)]
        if magic == "P5":
            body = b"".join(v.to_bytes(2 if maxval > 255 else 1, "big") for row in pix for v in row)
        else:
            body = "\n".join(" ".join(map(str, row)) for row in pix).encode() + b"\n"
        data = f"{magic}\n{w} {h}\n{maxval}\n".encode() + body
        bad = []
        for mode, neg, occ, free in READINGS:
            got, err = dump(write_map(d, f"pgm_{magic}_{maxval}", data, mode, neg, occ, free, ext="pgm"))
            if got is None:
                bad.append(err)
                continue
            _, _, vals, cells = got
            for y in range(h):
                for x in range(w):
                    want = nav2_value([pix[y][x]], maxval, mode, neg, occ, free)
                    if vals[y][x] not in want or cells[y][x] != cell_of(vals[y][x]):
                        bad.append(f"{mode}/{neg} ({x}, {y}) {pix[y][x]}: {vals[y][x]}, want {sorted(want)}")
        check(f"pgm-{magic}-{maxval}", not bad, "; ".join(bad[:3]))

    # --- rfseek-map counts a scale-mode RGBA PNG as the reference does ----------------
    pixels = random_pixels(40, 30, 6, 8)
    data = pngenc.encode(pixels, 6, 8)
    y = write_map(d, "count", data, "scale", 0)
    want = [0, 0, 0]
    partial = 0
    for row in pixels:
        for px in row:
            (v,) = nav2_value(list(px), 255, "scale", 0, "0.65", "0.196")
            want[cell_of(v)] += 1
            partial += 0 < v < 100
    out = subprocess.run([MAP, y], capture_output=True, text=True).stdout
    check("rfseek-map-counts", f"image cells  free {want[0]}, occupied {want[1]}, unknown {want[2]}" in out and
          f"reading      PNG RGBA, 8 bits, mode scale, negate 0: {partial} cells of value 1..99, read as free" in out,
          out)

    # --- damaged PNGs: one line naming the file, exit 1, nothing written ---------------
    good = pngenc.encode(random_pixels(8, 6, 0, 8), 0, 8)
    idat_at = good.index(b"IDAT") - 4
    bad_crc = bytearray(good)
    bad_crc[20] ^= 0xFF  # inside IHDR's data: its CRC no longer matches
    cases = [
        ("truncated", good[:idat_at + 20], "damaged PNG: truncated"),
        ("ihdr-crc", bytes(bad_crc), "damaged PNG: IHDR: CRC error"),
        ("signature-only", pngenc.SIGNATURE, "damaged PNG: truncated"),
        ("zero-width", pngenc.SIGNATURE + pngenc.ihdr(0, 5, 8, 0) + good[33:], "damaged PNG: Invalid IHDR data"),
        ("after-iend", good + b"junk", "data after the IEND chunk"),
        ("huge", pngenc.SIGNATURE + pngenc.ihdr(100000, 100000, 8, 0) + good[33:],
         "image size 100000 x 100000 out of range (1..67108864 pixels, at most 2^20 a side)"),
        ("wide", pngenc.SIGNATURE + pngenc.ihdr(1 << 21, 1, 8, 0) + good[33:], "image size 2097152 x 1 out of range"),
        ("interlaced-big", pngenc.SIGNATURE + pngenc.ihdr(8192, 8192, 16, 6, True) + good[33:],
         "interlaced PNG of 8192 x 8192 needs 512 MB decoded, above 32 MB (save it non-interlaced)"),
        ("bad-idat", good[:idat_at] + pngenc.chunk(b"IDAT", b"\x78\x9c garbage") + pngenc.chunk(b"IEND", b""),
         "damaged PNG: "),
    ]
    for name, data, text in cases:
        ipath = os.path.join(d, f"bad_{name}.png")
        y = write_map(d, f"bad_{name}", data, "trinary", 0)
        out = os.path.join(d, f"out_{name}.pgm")
        r = subprocess.run([MAP, y, "--pgm", out, "--png", out + ".png"], capture_output=True, text=True)
        lines = r.stderr.splitlines()
        left = [f for f in os.listdir(d) if f.startswith(f"out_{name}")]
        check(f"bad-png-{name}", r.returncode == 1 and len(lines) == 1 and lines[0].startswith(f"rfseek-map: {ipath}: ")
              and text in lines[0] and not left, f"exit {r.returncode}, stderr {r.stderr!r}, left {left}")

    # --- memory: 2^26-pixel PNGs (the most lx_map reads), within 100 MB --------------
    # The streams are compressed row by row so that this process stays small: a child's
    # peak as the kernel reports it is never below its parent's (vfork, then exec).
    def idat(row, h, cut=False):
        z = zlib.compressobj(9)
        parts = [z.compress(row) for _ in range(h)] + [z.flush()]
        data = b"".join(parts)
        return pngenc.chunk(b"IDAT", data[:len(data) // 2] if cut else data)

    def big_png(w, h, depth, ct, sample, cut=False):
        px = sample.to_bytes(depth // 8, "big") * {0: 1, 6: 4}[ct]
        return pngenc.SIGNATURE + pngenc.ihdr(w, h, depth, ct) + idat(b"\0" + px * w, h, cut) + \
            pngenc.chunk(b"IEND", b"")

    ypath = write_map(d, "big", big_png(8192, 8192, 8, 0, 254), "trinary", 0)
    r = subprocess.run([MAP, ypath, "--res", "0.4"], capture_output=True, text=True)
    check("big-png-loads", r.returncode == 0 and "image        8192 x 8192 cells" in r.stdout and
          "image cells  free 67108864, occupied 0, unknown 0" in r.stdout, r.stdout + r.stderr)
    ypath = write_map(d, "big_cut", big_png(8192, 8192, 8, 0, 254, cut=True), "trinary", 0)
    r = subprocess.run([MAP, ypath], capture_output=True, text=True)
    check("big-png-cut", r.returncode == 1 and "damaged PNG" in r.stderr, r.stderr)
    # The widest rows: 2^20 pixels of 16-bit RGBA (8 MB a row), 64 rows.
    ypath = write_map(d, "wide", big_png(1 << 20, 64, 16, 6, 0xFFFE), "trinary", 0)
    r = subprocess.run([MAP, ypath, "--res", "10"], capture_output=True, text=True)
    check("wide-png-reads", "the core rejects the map (5243 x 1 cells at 10 m" in r.stderr, r.stderr)
    rss_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    check("memory-under-100MB", rss_mb < 100, f"{rss_mb:.0f} MB")
    print(f"  (largest child: {rss_mb:.0f} MB)")

sys.exit(exit_status())
