"""pngenc.py - PNG files written from the PNG specification (W3C PNG, 2nd edition), with
Python's zlib and nothing of libpng: every colour type and bit depth, a palette, tRNS,
Adam7 interlacing, extra chunks. Test code only.

    sys.path.insert(0, <this directory>); import pngenc
    data = pngenc.encode(pixels, color_type, depth, palette=None, trns=None, interlace=False)

pixels[y][x] is a tuple of samples: (gray,), (gray, alpha), (r, g, b), (r, g, b, a), or
(index,) for a palette; row 0 is the top. expand() gives what a pixel means: its samples
as gray, gray + alpha, RGB or RGBA at 8 or 16 bits, the maximum sample, as the
specification defines the palette, the tRNS chunk and gray of fewer than 8 bits.
"""
import struct
import zlib

SIGNATURE = b"\x89PNG\r\n\x1a\n"
# Adam7 passes: first column, first row, column step, row step.
ADAM7 = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]


def chunk(kind, data):
    """One chunk: length, type, data, CRC-32 of type and data."""
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def ihdr(w, h, depth, color_type, interlace=False):
    return chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, color_type, 0, 0, 1 if interlace else 0))


def _row_bytes(pixels, depth):
    if depth >= 8:
        return b"".join(v.to_bytes(depth // 8, "big") for px in pixels for v in px)
    out, acc, bits = bytearray(), 0, 0
    for px in pixels:
        acc, bits = (acc << depth) | px[0], bits + depth
        if bits == 8:
            out.append(acc)
            acc, bits = 0, 0
    if bits:
        out.append(acc << (8 - bits))
    return bytes(out)


def raw_data(pixels, depth, interlace=False):
    """The filtered (filter 0) scanlines, before compression."""
    h, w = len(pixels), len(pixels[0])
    raw = bytearray()
    passes = ADAM7 if interlace else [(0, 0, 1, 1)]
    for x0, y0, dx, dy in passes:
        xs = range(x0, w, dx)
        if len(xs) == 0:
            continue
        for y in range(y0, h, dy):
            raw += b"\0" + _row_bytes([pixels[y][x] for x in xs], depth)
    return bytes(raw)


def encode(pixels, color_type, depth, palette=None, trns=None, interlace=False, extra=b"", tail=b""):
    """A PNG file of pixels; extra goes before IDAT, tail after IEND."""
    h, w = len(pixels), len(pixels[0])
    out = SIGNATURE + ihdr(w, h, depth, color_type, interlace)
    if palette is not None:
        out += chunk(b"PLTE", b"".join(bytes(c) for c in palette))
    if trns is not None:
        out += chunk(b"tRNS", trns)
    out += extra
    out += chunk(b"IDAT", zlib.compress(raw_data(pixels, depth, interlace)))
    return out + chunk(b"IEND", b"") + tail


def trns_bytes(color_type, depth, value):
    """The tRNS chunk of a gray (value an int) or RGB (a tuple) image."""
    if color_type == 0:
        return struct.pack(">H", value)
    return struct.pack(">HHH", *value)


def expand(px, color_type, depth, palette=None, trns=None):
    """(samples, maximum sample) of one pixel as the specification defines it."""
    if color_type == 3:
        r, g, b = palette[px[0]]
        if trns is None:
            return [r, g, b], 255
        return [r, g, b, trns[px[0]] if px[0] < len(trns) else 255], 255
    top = (1 << depth) - 1
    if color_type == 0:
        v = px[0]
        # Gray of 1, 2 or 4 bits scales to 8 by replicating its bits: v * 255 / (2^d - 1).
        out, out_max = ([v * 255 // top], 255) if depth < 8 else ([v], top)
        if trns is not None:
            (t,) = struct.unpack(">H", trns)
            out.append(0 if v == t else out_max)
        return out, out_max
    if color_type == 2:
        out = list(px)
        if trns is not None:
            out.append(0 if tuple(px) == struct.unpack(">HHH", trns) else top)
        return out, top
    return list(px), top  # gray + alpha, RGBA
