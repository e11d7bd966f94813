#!/usr/bin/env python3
"""map_tools.py RFSEEK_MAP - rfseek-map --mcu, --crop and --png (docs/MAPS.md, "rfseek-map").

References, computed here and not by the program:
  --mcu   bytes per bit grid ceil(w / 8) x h and the lattice count of rfs_map.h's rule
          (points origin + 0.125 + i 0.25 m inside the extent) against firmware/rfs_app.h's
          6,400 bytes and 12,800 points; scripts/map2c.py (which bakes maps into the
          image) must accept a map --mcu says fits and refuse one it says does not.
  --crop  every world point has the same cell state in the crop as in the original (both
          read here with the map_server rules), the cells cut were all unknown; the crop
          of a 250 x 250-cell map that is mostly unknown fits the image.
  --png   the size from the documented layout; the grid lines at exactly the columns and
          rows of the whole metres (round(LEFT + (k - origin_x) S / res), ...), x = 0 and
          y = 0 red, walls black, unknown gray, the middle of a room white; decoded with
          PIL.
"""
import math
import os
import random
import subprocess
import sys
import tempfile

from PIL import Image

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "lib"))
import pngenc  # noqa: E402
from checks import check, exit_status  # noqa: E402

BIN = sys.argv[1] if len(sys.argv) > 1 else "build/bin/rfseek-map"
ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
MAX_BYTES, MAX_LATTICE = 6400, 12800  # firmware/rfs_app.h
rng = random.Random(7)


def run(*args):
    return subprocess.run([BIN, *args], capture_output=True, text=True)


def read_yaml(path):
    kv = {}
    for line in open(path):
        if ":" in line and not line.startswith("#"):
            k, v = line.split(":", 1)
            kv[k.strip()] = v.strip()
    origin = [float(t) for t in kv["origin"].strip("[]").split(",")]
    return {"image": os.path.join(os.path.dirname(path), kv["image"].strip("'")), "res": float(kv["resolution"]),
            "ox": origin[0], "oy": origin[1], "occ": float(kv["occupied_thresh"]),
            "free": float(kv["free_thresh"]), "negate": int(kv["negate"]), "mode": kv.get("mode", "trinary")}


def states(meta):
    """Cell states (0 free, 1 occupied, 2 unknown), [row from the bottom][x], of a trinary
    map or a scale-mode RGBA map, by the map_server rules (docs/MAPS.md)."""
    im = Image.open(meta["image"])
    im = im.convert("RGBA") if im.mode in ("RGBA", "P") else im.convert("L")
    w, h = im.size
    px = im.load()
    out = [[2] * w for _ in range(h)]
    for y in range(h):
        for x in range(w):
            v = px[x, h - 1 - y]
            if isinstance(v, tuple):
                if meta["mode"] == "scale" and v[3] != 255:
                    continue
                mean = (v[0] + v[1] + v[2]) / 3
            else:
                mean = v
            p = mean / 255 if meta["negate"] else (255 - mean) / 255
            # scale values between the thresholds are 1..99: free (docs/MAPS.md)
            out[y][x] = 1 if p > meta["occ"] else (0 if p < meta["free"] or meta["mode"] == "scale" else 2)
    return out


def state_at(meta, st, x, y):
    cx = math.floor((x - meta["ox"]) / meta["res"])
    cy = math.floor((y - meta["oy"]) / meta["res"])
    if 0 <= cy < len(st) and 0 <= cx < len(st[0]):
        return st[cy][cx]
    return None  # off the map


def lattice(w, h, res):
    """Lattice points of rfs_map.h at 0.25 m over a w x h core grid: point i at 0.125 m +
    i 0.25 m strictly inside the extent, in the core's Q16 units."""
    rq = round(res * 65536)
    return tuple((n * rq - 8192 - 1) // 16384 + 1 for n in (w, h))


def map2c(yaml, res, d):
    r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "map2c.py"), yaml, "--res", str(res),
                        "-o", os.path.join(d, "fw_map.c")], capture_output=True, text=True)
    return r.returncode, r.stderr


with tempfile.TemporaryDirectory() as d:
    # --- a 250 x 250-cell map (25 x 25 m), a 12.1 x 8.1 m room, the rest unknown ---------
    # Scale mode, RGBA: the unknown is transparent, as nav2's map_saver writes it.
    W = H = 250
    x0, y0, rw, rh = 60, 100, 121, 81  # the room in image pixels, y0 from the top
    pix = [[(205, 205, 205, 0)] * W for _ in range(H)]
    for y in range(y0, y0 + rh):
        for x in range(x0, x0 + rw):
            edge = x in (x0, x0 + rw - 1) or y in (y0, y0 + rh - 1)
            v = 0 if edge or rng.random() < 0.02 else rng.choice((254, 240, 180))
            pix[y][x] = (v, v, v, 255)
    with open(os.path.join(d, "big.png"), "wb") as f:
        f.write(pngenc.encode(pix, 6, 8))
    big = os.path.join(d, "big.yaml")
    with open(big, "w") as f:
        f.write("image: big.png\nresolution: 0.1\norigin: [-12.5, -12.5, 0.0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: scale\n")

    r = run(big, "--mcu")
    bytes_big = math.ceil(W / 8) * H
    lw, lh = lattice(W, H, 0.1)
    bytes_crop = math.ceil(rw / 8) * rh
    cw, ch = lattice(rw, rh, 0.1)
    check("mcu-big-exit", r.returncode == 3, f"exit {r.returncode}: {r.stderr}")
    check("mcu-big-why", f"bit grids {W} x {H} cells, {bytes_big} bytes each of the image's {MAX_BYTES} "
          "(RFS_APP_MAX_MAP_BYTES): too large" in r.stdout and
          f"lattice {lw} x {lh} = {lw * lh} points of the image's {MAX_LATTICE} (RFS_APP_MAX_LATTICE)\n" in r.stdout,
          r.stdout)
    check("mcu-big-crop-hint", f"the known area, {rw} x {rh} cells from column {x0}, row {H - y0 - rh} " in r.stdout
          and "fits: --crop OUT.yaml writes it" in r.stdout, r.stdout)

    small = os.path.join(d, "room.yaml")
    r = run(big, "--crop", small)
    check("crop-writes", r.returncode == 0 and os.path.exists(small) and os.path.exists(os.path.join(d, "room.pgm"))
          and not [f for f in os.listdir(d) if f.endswith(".tmp")], r.stderr)
    mb, ms = read_yaml(big), read_yaml(small)
    sb, ss = states(mb), states(ms)
    check("crop-size", (len(ss[0]), len(ss)) == (rw, rh), f"{len(ss[0])} x {len(ss)}")
    # Every cell centre of the original and 5,000 random points: the same state.
    bad = []
    pts = [(mb["ox"] + (x + 0.5) * 0.1, mb["oy"] + (y + 0.5) * 0.1) for y in range(H) for x in range(W)]
    pts += [(rng.uniform(-12.5, 12.5), rng.uniform(-12.5, 12.5)) for _ in range(5000)]
    for (x, y) in pts:
        fx, fy = (x - mb["ox"]) / 0.1, (y - mb["oy"]) / 0.1
        if min(abs(fx - round(fx)), abs(fy - round(fy))) < 1e-6:
            continue  # on a cell edge: either side
        a, b = state_at(mb, sb, x, y), state_at(ms, ss, x, y)
        if (b is None and a != 2) or (b is not None and a != b):
            bad.append(f"({x:.3f}, {y:.3f}) {a} -> {b}")
    check("crop-same-world", not bad, "; ".join(bad[:5]))
    counts = [sum(row.count(k) for row in sb) for k in range(3)]
    r = run(small, "--mcu")
    check("crop-counts", f"image cells  free {counts[0]}, occupied {counts[1]}, unknown 0" in r.stdout, r.stdout)
    check("crop-fits", r.returncode == 0 and "fits the STM32 image at 0.1 m" in r.stdout and
          f"bit grids {rw} x {rh} cells, {bytes_crop} bytes each" in r.stdout and
          f"lattice {cw} x {ch} = {cw * ch} points" in r.stdout, r.stdout)
    check("crop-map2c", map2c(small, 0.1, d)[0] == 0 and map2c(big, 0.1, d)[0] == 1, "map2c disagrees")

    # --- 40 x 20 m at 0.05 m, all known: too large at 0.1 m, fits at 0.15 m -------------
    w, h = 800, 400
    rows = [bytes(0 if x in (0, w - 1) or y in (0, h - 1) else 254 for x in range(w)) for y in range(h)]
    with open(os.path.join(d, "hall.pgm"), "wb") as f:
        f.write(f"P5\n{w} {h}\n255\n".encode() + b"".join(rows))
    hall = os.path.join(d, "hall.yaml")
    with open(hall, "w") as f:
        f.write("image: hall.pgm\nresolution: 0.05\norigin: [-3.37, 1.21, 0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    # The finest whole multiple of 0.05 m above 0.1 m whose grid fits, by the formulas.
    want = next(k * 0.05 for k in range(3, 21)
                if math.ceil(math.ceil(w / k) / 8) * math.ceil(h / k) <= MAX_BYTES and
                math.prod(lattice(math.ceil(w / k), math.ceil(h / k), k * 0.05)) <= MAX_LATTICE)
    r = run(hall, "--mcu")
    check("mcu-hall", r.returncode == 3 and f"{math.ceil(w / 2 / 8) * h // 2} bytes each" in r.stdout and
          f"the map fits at --res {want:g} ({round(want / 0.05)} image cells a side)" in r.stdout, r.stdout)
    r = run(hall, "--mcu", "--res", f"{want:g}")
    check("mcu-hall-coarser", r.returncode == 0 and "fits" in r.stdout, r.stdout)
    check("mcu-hall-map2c", map2c(hall, want, d)[0] == 0 and map2c(hall, 0.1, d)[0] == 1, "map2c disagrees")
    r = run(hall, "--mcu", "--res", "0.125")
    check("mcu-note-multiple", "note: scripts/map2c.py bakes a map only at a whole multiple of its 0.05 m cells"
          in r.stdout, r.stdout)

    # --- 60 x 60 m at 0.5 m: few bytes, too many lattice points -------------------------
    w = h = 120
    with open(os.path.join(d, "yard.pgm"), "wb") as f:
        f.write(f"P5\n{w} {h}\n255\n".encode() + bytes([254]) * (w * h))
    yard = os.path.join(d, "yard.yaml")
    with open(yard, "w") as f:
        f.write("image: yard.pgm\nresolution: 0.5\norigin: [0, 0, 0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    lw, lh = lattice(w, h, 0.5)
    r = run(yard, "--mcu", "--res", "0.5")
    check("mcu-lattice", r.returncode == 3 and f"lattice {lw} x {lh} = {lw * lh} points of the image's 12800 "
          "(RFS_APP_MAX_LATTICE): too many" in r.stdout and "(the lattice is too large)" in r.stdout, r.stdout)

    # --- --png ----------------------------------------------------------------------------
    def png_checks(name, yaml, w, h, res, ox, oy):
        out = os.path.join(d, name + "_picture.png")
        r = run(yaml, "--png", out)
        if r.returncode not in (0, 3):
            check(f"png-{name}", False, r.stderr)
            return None
        im = Image.open(out).convert("RGB")
        s = max(1, math.ceil(20 * res - 1e-9))
        check(f"png-{name}-size", im.size == (88 + s * w + 16, 24 + s * h + 44), f"{im.size}, S {s}")
        px = im.load()
        left, top, right, bottom = 88, 24, 88 + s * w, 24 + s * h
        cols = {k: 88 + round((k - ox) * s / res) for k in range(math.floor(ox), math.ceil(ox + w * res) + 1)}
        rows = {k: 24 + round((oy + h * res - k) * s / res) for k in range(math.floor(oy), math.ceil(oy + h * res) + 1)}
        cols = {k: c for k, c in cols.items() if left <= c < right}
        rows = {k: r_ for k, r_ in rows.items() if top <= r_ < bottom}
        grid, red = (0x8C, 0xB4, 0xEB), (0xDC, 0x28, 0x28)
        plain_rows = [y for y in range(top, bottom) if y not in rows.values()]
        plain_cols = [x for x in range(left, right) if x not in cols.values()]
        got_cols = {x for x in range(left, right) if any(px[x, y] in (grid, red) for y in plain_rows)}
        got_rows = {y for y in range(top, bottom) if any(px[x, y] in (grid, red) for x in plain_cols)}
        check(f"png-{name}-grid-columns", got_cols == set(cols.values()),
              f"extra {sorted(got_cols - set(cols.values()))[:5]} missing {sorted(set(cols.values()) - got_cols)[:5]}")
        check(f"png-{name}-grid-rows", got_rows == set(rows.values()),
              f"extra {sorted(got_rows - set(rows.values()))[:5]} missing {sorted(set(rows.values()) - got_rows)[:5]}")
        ok = True
        if 0 in cols:
            ok = ok and all(px[cols[0], y] == red for y in range(top, bottom))
        if 0 in rows:
            ok = ok and all(px[x, rows[0]] == red for x in range(left, right))
        check(f"png-{name}-axes", ok and (0 in cols or 0 in rows), f"x=0 {cols.get(0)}, y=0 {rows.get(0)}")
        return px, s

    got = png_checks("big", big, W, H, 0.1, -12.5, -12.5)
    if got:
        px, s = got
        # Cell (x, y) from the bottom: its block's pixel nearest the block's centre.
        def block(x, y):
            return px[88 + s * x + s // 2, 24 + s * (H - 1 - y) + s // 2]
        wall = (x0, H - y0 - rh // 2)                   # the room's left wall
        unknown = (10, 10)
        inside = (x0 + rw // 2 + 3, H - y0 - rh // 2 + 3)  # near the room's middle
        def clear(x, y):  # no obstacle within 4 cells: legal at 0.25 m clearance
            return all(sb[y + j][x + i] == 0 for i in range(-4, 5) for j in range(-4, 5))
        if not clear(*inside):
            inside = next((x, y) for y in range(H - y0 - rh + 5, H - y0 - 5) for x in range(x0 + 5, x0 + rw - 5)
                          if clear(x, y))
        check("png-big-colours", block(*wall) == (0, 0, 0) and block(*unknown) == (0xB4, 0xB4, 0xB4) and
              block(*inside) in ((255, 255, 255), (0x8C, 0xB4, 0xEB)),
              f"wall {block(*wall)}, unknown {block(*unknown)}, inside {block(*inside)}")
    png_checks("hall", hall, 800, 400, 0.05, -3.37, 1.21)

    # --- outputs: never an input, never each other; an all-unknown map has nothing to crop -
    r = run(big, "--crop", big)
    check("crop-not-input", r.returncode == 1 and "is the input" in r.stderr, r.stderr)
    r = run(hall, "--crop", os.path.join(d, "hall.yml"))
    check("crop-not-input-image", r.returncode == 1 and "hall.pgm: is the input" in r.stderr, r.stderr)
    r = run(big, "--png", os.path.join(d, "same"), "--pgm", os.path.join(d, "same"))
    check("outputs-distinct", r.returncode == 1 and "is also written as" in r.stderr, r.stderr)
    with open(os.path.join(d, "void.pgm"), "wb") as f:
        f.write(b"P5\n4 3\n255\n" + bytes([205]) * 12)
    void = os.path.join(d, "void.yaml")
    with open(void, "w") as f:
        f.write("image: void.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    r = run(void, "--crop", os.path.join(d, "void_crop.yaml"))
    check("crop-all-unknown", r.returncode == 1 and len(r.stderr.splitlines()) == 1 and
          "every cell is unknown, nothing to keep" in r.stderr and not os.path.exists(os.path.join(d, "void_crop.yaml"))
          and not os.path.exists(os.path.join(d, "void_crop.pgm")), r.stderr)
    h = run("--help").stdout
    check("help", all(t in h for t in ("--mcu", "--crop OUT.yaml", "--png OUT.png", "3 when --mcu")), h)

sys.exit(exit_status())
