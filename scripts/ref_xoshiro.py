#!/usr/bin/python3
"""Reference outputs of rfs_rng (splitmix64 seeding + xoshiro128++), written from the
published algorithms (Vigna; xoshiro128plusplus.c, splitmix64.c), independent of
common/rfs_fix.c. tests/common/test_fix.c embeds what this prints.

usage: ref_xoshiro.py [SEED ...]   (default seeds 0 1 20260521)
"""
import sys

M64 = (1 << 64) - 1
M32 = (1 << 32) - 1


def splitmix64(x):
    x = (x + 0x9E3779B97F4A7C15) & M64
    z = x
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M64
    return x, z ^ (z >> 31)


def rotl(x, k):
    return ((x << k) | (x >> (32 - k))) & M32


def outputs(seed, n):
    x, a = splitmix64(seed & M64)
    x, b = splitmix64(x)
    s = [a & M32, a >> 32, b & M32, b >> 32]
    if not any(s):
        s[0] = 1
    out = []
    for _ in range(n):
        out.append((rotl((s[0] + s[3]) & M32, 7) + s[0]) & M32)
        t = (s[1] << 9) & M32
        s[2] ^= s[0]
        s[3] ^= s[1]
        s[1] ^= s[2]
        s[0] ^= s[3]
        s[2] ^= t
        s[3] = rotl(s[3], 11)
    return out


def main(argv):
    if len(argv) > 1 and argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0
    try:
        seeds = [int(a, 0) for a in argv[1:]] or [0, 1, 20260521]
    except ValueError as e:
        sys.exit("ref_xoshiro.py: %s (see --help)" % e)
    for seed in seeds:
        print(seed, " ".join("0x%08x" % v for v in outputs(seed, 6)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
