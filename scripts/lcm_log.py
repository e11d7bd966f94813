#!/usr/bin/python3
"""Read an LCM log (rfseekd --log, lcm-logger) in Python without the lcm module.

    scripts/lcm_log.py LOG [--channel REGEX] [--tsv] [--list] [--gen DIR]

Prints one JSON object per message: {"event", "utime" (the log's receive time, us),
"channel", "type", "msg": {field: value}} (byte arrays as lists, non-finite numbers as
null). --channel keeps the channels REGEX matches whole (Python re). --tsv prints one
channel's messages as a table instead: event, log_utime, then the fields of the first
message's type (byte arrays as hex, strings with tab, newline and backslash escaped);
the channel's messages of other types are left out and counted. --list prints one row per
channel: channel, type(s), messages, bytes. A message whose fingerprint is none of
lcm/*.lcm's, or whose length differs from its decoding, is left out and counted: one
stderr line at the end, exit status 0; liblcm's own LCM_SELF_TEST is left out silently. A damaged log (bad sync word, an event cut short,
a channel name that is not text): one error line naming the byte offset, exit 1.

Messages are decoded by the classes `lcm-gen --python` writes from lcm/*.lcm (make builds
them into build/gen/python; --gen DIR elsewhere); they need only Python's struct. As a
module: events(path) yields (event number, utime, channel, data bytes); decode(data,
types) gives (type name, message object); load_types(dir) the fingerprint table.
"""
import glob
import importlib
import io
import json
import math
import os
import re
import struct
import sys

SYNC = 0xEDA1DA01
HEADER = struct.Struct(">IqqII")  # sync, event number, utime, channel length, data length
SELF_TEST = "LCM_SELF_TEST"  # liblcm's own check of the udpm provider (lcm-logger logs it)
MAX_CHANNEL = 63  # LCM's limit on a channel name (lcm.h, LCM_MAX_CHANNEL_NAME_LENGTH)
DEFAULT_GEN = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "build", "gen",
                           "python")


class LogError(Exception):
    """A damaged log: the message names the byte offset."""


def events(path):
    """(event number, utime, channel, data) of each event of an LCM log, in file order."""
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        off = 0
        while True:
            head = f.read(HEADER.size)
            if not head:
                return
            if len(head) < HEADER.size:
                raise LogError("byte %d: event header cut short (%d of %d bytes)"
                               % (off, len(head), HEADER.size))
            sync, num, utime, clen, dlen = HEADER.unpack(head)
            if sync != SYNC:
                raise LogError("byte %d: bad sync word 0x%08X (want 0x%08X)" % (off, sync, SYNC))
            if clen == 0 or clen > MAX_CHANNEL:
                raise LogError("byte %d: channel name of %d bytes (1..%d)" % (off, clen, MAX_CHANNEL))
            if off + HEADER.size + clen + dlen > size:
                raise LogError("byte %d: event %d cut short (%d of %d bytes after its header)"
                               % (off, num, size - off - HEADER.size, clen + dlen))
            body = f.read(clen + dlen)
            try:
                channel = body[:clen].decode("ascii")
            except UnicodeDecodeError:
                raise LogError("byte %d: event %d: channel name is not ASCII" % (off, num)) from None
            if not channel.isprintable():
                raise LogError("byte %d: event %d: channel name has control characters" % (off, num))
            yield num, utime, channel, body[clen:]
            off += HEADER.size + clen + dlen


def load_types(gen_dir=None):
    """{packed fingerprint: class} of every type lcm-gen wrote under gen_dir/rfseek."""
    gen_dir = os.path.abspath(gen_dir or DEFAULT_GEN)
    files = sorted(glob.glob(os.path.join(gen_dir, "rfseek", "*_t.py")))
    if not files:
        raise OSError("%s: no lcm-gen Python types (make builds them; or --gen DIR)" % gen_dir)
    if gen_dir not in sys.path:
        sys.path.insert(0, gen_dir)
    table = {}
    for path in files:
        name = os.path.basename(path)[:-3]
        cls = getattr(importlib.import_module("rfseek." + name), name)
        table[cls._get_packed_fingerprint()] = cls
    return table


def decode(data, types):
    """(type name, message) of one message; ValueError when it is none of the types or its
    length is not exactly its decoding's."""
    cls = types.get(bytes(data[:8]))
    if cls is None:
        raise ValueError("unknown fingerprint %s" % bytes(data[:8]).hex())
    buf = io.BytesIO(data)
    try:
        msg = cls.decode(buf)
        used = buf.tell()
    except (struct.error, ValueError, UnicodeError) as e:
        raise ValueError("%s: %s" % (cls.__name__, e)) from None
    if used != len(data):
        raise ValueError("%s of %d bytes, %d decoded" % (cls.__name__, len(data), used))
    return cls.__name__, msg


def fields(msg):
    """The message's fields in declaration order as plain values."""
    return [(k, getattr(msg, k)) for k in msg.__slots__]


def json_value(v):
    if isinstance(v, (bytes, bytearray)):
        return list(v)
    if isinstance(v, (list, tuple)):
        return [json_value(x) for x in v]
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def tsv_value(v):
    if isinstance(v, (bytes, bytearray)):
        return v.hex()
    if isinstance(v, (list, tuple)):
        return ",".join(tsv_value(x) for x in v)
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, str):
        return v.replace("\\", "\\\\").replace("\t", "\\t").replace("\n", "\\n")
    return str(v)


def die(msg):
    print("lcm_log.py: %s" % str(msg).replace("\n", "?"), file=sys.stderr)
    sys.exit(1)


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip(), file=sys.stdout if len(argv) >= 2 else sys.stderr)
        return 0 if len(argv) >= 2 else 2
    path, opts, flags, i = argv[1], {}, set(), 2
    while i < len(argv):
        a = argv[i]
        if a in ("--tsv", "--list"):
            flags.add(a)
            i += 1
        elif a in ("--channel", "--gen") and i + 1 < len(argv):
            opts[a] = argv[i + 1]
            i += 2
        else:
            die("%s: unknown option or missing value (see --help)" % a)
    if "--tsv" in flags and "--list" in flags:
        die("--tsv and --list exclude each other")
    try:
        want = re.compile(opts.get("--channel", ".*"))
    except re.error as e:
        die("--channel: %s" % e)
    try:
        types = load_types(opts.get("--gen"))
    except (OSError, ImportError, AttributeError) as e:
        die(e)
    out = sys.stdout
    bad, other, first_bad = 0, 0, None
    table_type, counts = None, {}
    try:
        for num, utime, channel, data in events(path):
            if channel == SELF_TEST or not want.fullmatch(channel):
                continue
            try:
                name, msg = decode(data, types)
            except ValueError as e:
                bad += 1
                first_bad = first_bad or "event %d on %s: %s" % (num, channel, e)
                if "--list" in flags:
                    c = counts.setdefault(channel, [set(), 0, 0])
                    c[1], c[2] = c[1] + 1, c[2] + len(data)
                continue
            if "--list" in flags:
                c = counts.setdefault(channel, [set(), 0, 0])
                c[0].add(name)
                c[1], c[2] = c[1] + 1, c[2] + len(data)
            elif "--tsv" in flags:
                if table_type is None:
                    table_type = name
                    out.write("\t".join(["event", "log_utime"] + list(msg.__slots__)) + "\n")
                if name != table_type:
                    other += 1
                    continue
                out.write("\t".join([str(num), str(utime)] + [tsv_value(v) for _, v in fields(msg)])
                          + "\n")
            else:
                out.write(json.dumps({"event": num, "utime": utime, "channel": channel,
                                      "type": name,
                                      "msg": {k: json_value(v) for k, v in fields(msg)}}) + "\n")
    except LogError as e:
        die("%s: %s" % (path, e))
    except BrokenPipeError:
        raise
    except OSError as e:
        die("%s: %s" % (path, e.strerror or e))
    if "--list" in flags:
        for ch in sorted(counts):
            t, n, b = counts[ch]
            out.write("%s\t%s\t%d\t%d\n" % (ch, ",".join(sorted(t)) or "-", n, b))
    if bad or other:
        print("lcm_log.py: %s: %d messages not decoded%s%s" % (
            path, bad, " (first: %s)" % first_bad if first_bad else "",
            ", %d of another type than %s left out" % (other, table_type) if other else ""),
            file=sys.stderr)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except BrokenPipeError:
        # The reader of stdout left (head): no message, and none at exit either.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(0)
