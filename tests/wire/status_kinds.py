#!/usr/bin/env python3
"""STATUS frames in a candump log against rfseekd's decision lines: every frame's Kind
(data[1] bits 0..1) is docs/CAN.md's code for the kind its Iteration's decision line names
(none 0, initial 1, greedy/gradient/run 2, epsilon/probe/tumble 3; 0 before the first).
Frames in State 2 (learning) are skipped: their decision is still being made. usage: status_kinds.py CANDUMP DECISIONS; prints the codes seen, exit 1 on a
mismatch."""
import re
import sys

CODE = {"none": 0, "initial": 1, "greedy": 2, "gradient": 2, "run": 2,
        "epsilon": 3, "probe": 3, "tumble": 3}


def main(dump, decisions):
    kind_of = {}
    with open(decisions) as f:
        for line in f:
            m = re.match(r"decision t=-?\d+ n=(\d+) kind=([a-z]+) ", line)
            if m:
                kind_of[int(m.group(1))] = m.group(2)
    seen, bad, n = set(), 0, 0
    with open(dump) as f:
        for line in f:
            m = re.match(r"\(\d+\.\d+\) \S+ 180#([0-9A-F]{16})$", line.strip())
            if not m:
                continue
            d = bytes.fromhex(m.group(1))
            it = int.from_bytes(d[3:7], "little")
            want = CODE[kind_of[it]] if it in kind_of else 0
            kind = d[1] & 3
            if (d[0] >> 4) & 3 == 2:
                continue
            if kind != want and not (kind == 0 and it == 0 and seen <= {0}):
                if bad < 3:
                    print("STATUS iteration %d (%s): Kind %d, want %d"
                          % (it, kind_of.get(it, "none"), kind, want))
                bad += 1
            n += 1
            seen.add(kind)
    print("%d STATUS frames out of learning, %d decisions, Kind codes %s" % (n, len(kind_of), sorted(seen)))
    return 1 if bad or n == 0 or not kind_of else 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]) if len(sys.argv) == 3 else 2)
