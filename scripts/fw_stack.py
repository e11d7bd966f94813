#!/usr/bin/python3
"""fw_stack.py ELF ROOT[,ROOT...] SU... - worst-case stack depth of a firmware image's roots.

Frames come from gcc -fstack-usage (SU: the .su files of the image's objects), calls
from the linked image's disassembly: direct calls and tail calls exactly; an indirect call
(blx/bx through a register) reaches every function of the tables its source line calls
through (read with objdump -l): model ops (rfs_ridge_ops, rfs_pathloss_ops, registry
entries), target ops, strategy ops (k_strategies), the planner's search, the near query's
refuse; bxCAN's poll_hook is NULL on hardware. An indirect call whose line names none of
them may reach any of them. Recursion is an error (no bound). Frames of functions without
a .su entry (newlib's memcpy/memset) count LIBC_FRAME bytes.

Prints one line per root: its bound and the deepest path; then "indirect calls N", the
call sites through a register it read (tests/firmware/stack.sh counts them apart). Exit
status 1 on recursion or an unknown frame (other than the C library's).
"""
import collections
import os
import re
import struct
import subprocess
import sys

LIBC = {'memcpy': 16, 'memset': 16, 'memmove': 16}
# Tables whose function words an indirect call may reach, by kind.
TABLES = {
    'model': ['rfs_ridge_ops', 'rfs_pathloss_ops'],
    'init': ['rfs_models_pathloss', 'rfs_models_ridge'],
    'target': ['rfs_target_rssi', 'rfs_target_bridge'],
}
# k_strategies (rfs_seek_strategy_ops_t, 16 bytes an entry): word 1 choose, word 2 to_max.
STRATEGY_WORDS = {'choose': 1, 'to_max': 2}
# Source text of an indirect call's line -> kinds it may reach.
CALL_KINDS = [
    (re.compile(r'poll_hook|hook\('), []),
    (re.compile(r'init_default\('), ['init']),
    (re.compile(r'\bops->(fit|predict|predict_row|reset|argmax|row_monotone|bound|sample|near|'
                r'floor_gap|mean|warm)\('), ['model']),
    (re.compile(r'target->|->combine\('), ['target']),
    (re.compile(r'->choose\('), ['choose']),
    (re.compile(r'->to_max\('), ['to_max']),
    (re.compile(r'->search\('), ['search']),
    (re.compile(r'refuse\('), ['refuse']),
    (re.compile(r'index->|->put\(|->disc\('), ['index']),
]
NAMED = {'search': ['search_table'], 'refuse': ['near_refuse'], 'index': ['index_put', 'index_disc']}


def norm(name):
    return re.sub(r'\.\d+', '', name)


def main(argv):
    if len(argv) < 4 or argv[1] in ('-h', '--help'):
        print(__doc__.strip())
        return 0 if len(argv) > 1 and argv[1] in ('-h', '--help') else 2
    elf, roots, sus = argv[1], argv[2].split(','), argv[3:]
    frame = {}
    for su in sus:
        for line in open(su):
            loc, size, _kind = line.rstrip('\n').split('\t')
            name = norm(loc.split(':')[-1])
            frame[name] = max(frame.get(name, 0), int(size))
    syms = {}
    for line in subprocess.run(['arm-none-eabi-nm', '-S', elf], capture_output=True, text=True,
                               check=True).stdout.splitlines():
        p = line.split()
        if len(p) == 4:
            syms[p[3]] = (int(p[0], 16), int(p[1], 16))
    dis = subprocess.run(['arm-none-eabi-objdump', '-d', '-l', '--no-show-raw-insn', elf],
                         capture_output=True, text=True, check=True).stdout
    funcs, calls, icalls = {}, collections.defaultdict(set), collections.defaultdict(set)
    cur, src, sources, unknown, nindirect = None, [], {}, [], 0
    for line in dis.splitlines():
        m = re.match(r'^([0-9a-f]+) <([^>]+)>:$', line)
        if m:
            cur = m.group(2)
            funcs[cur] = int(m.group(1), 16)
            continue
        m = re.match(r'^(/\S+\.c):(\d+)', line)
        if m:
            src = [m.group(1), int(m.group(2))]
            continue
        if cur is None or '\t' not in line:
            continue
        m = re.search(r'\t(b[a-z]*(?:\.w)?)\s+[0-9a-f]+ <([^>+]+)>', line)
        if m and m.group(2) != cur:  # a call, or a tail call (any branch to another function)
            calls[cur].add(m.group(2))
            continue
        # Any register but lr (a return): r0..r12 print as ip, sl, fp and sb too.
        if re.search(r'\t(blx|bx)\s+(r\d+|ip|sl|fp|sb)\b', line):
            nindirect += 1
            text = ''
            if src:
                if src[0] not in sources:
                    sources[src[0]] = open(src[0]).read().splitlines()
                lines = sources[src[0]]
                text = ' '.join(lines[max(0, src[1] - 3):src[1]])
            kinds = None
            for rx, k in CALL_KINDS:
                if rx.search(text):
                    kinds = (kinds or []) + k
            if kinds is None:
                unknown.append('%s at %s:%s' % (cur, src[0] if src else '?', src[1] if src else '?'))
                kinds = list(TABLES) + list(STRATEGY_WORDS) + list(NAMED)
            icalls[cur] |= set(kinds)
    by_addr = {a | 1: n for n, a in funcs.items()}
    # The tables are const: in .text with the code (stm32f405.ld).
    out = '/tmp/fw_stack_%d.bin' % os.getpid()
    subprocess.run(['arm-none-eabi-objcopy', '-O', 'binary', '-j', '.text', elf, out], check=True)
    hdr = subprocess.run(['arm-none-eabi-objdump', '-h', elf], capture_output=True, text=True,
                         check=True).stdout
    base = int(re.search(r'\s\.text\s+[0-9a-f]+\s+([0-9a-f]+)', hdr).group(1), 16)
    with open(out, 'rb') as fh:
        blob = fh.read()
    os.unlink(out)
    targets = collections.defaultdict(set)
    for kind, tables in TABLES.items():
        for t in tables:
            if t not in syms:
                continue
            addr, size = syms[t]
            for off in range(addr - base, addr - base + size, 4):
                w = struct.unpack_from('<I', blob, off)[0]
                if w in by_addr:
                    targets[kind].add(by_addr[w])
    if 'k_strategies' in syms:
        addr, size = syms['k_strategies']
        for kind, word in STRATEGY_WORDS.items():
            for off in range(addr - base + 4 * word, addr - base + size, 16):
                w = struct.unpack_from('<I', blob, off)[0]
                if w in by_addr:
                    targets[kind].add(by_addr[w])
    for kind, names in NAMED.items():
        targets[kind] |= {n for n in names if n in funcs}
    bad = []

    def fr(n):
        k = norm(n)
        if k in frame:
            return frame[k]
        if k in LIBC:
            return LIBC[k]
        bad.append('no frame size for %s' % n)
        return 0

    memo = {}

    def worst(n, stack):
        if n in stack:
            bad.append('recursion: %s' % ' > '.join(stack + (n,)))
            return 0, [n]
        if n in memo:
            return memo[n]
        succ = set(calls[n])
        for k in icalls[n]:
            succ |= targets[k]
        best, path = 0, []
        for s in sorted(succ):
            w, p = worst(s, stack + (n,))
            if w > best:
                best, path = w, p
        memo[n] = (fr(n) + best, [n] + path)
        return memo[n]

    for r in roots:
        if r not in funcs:
            bad.append('no function %s in %s' % (r, elf))
            continue
        w, p = worst(r, ())
        print('%s %d %s' % (r, w, ' > '.join('%s(%d)' % (x, fr(x)) for x in p)))
    print('indirect calls %d' % nindirect)
    for u in sorted(set(unknown)):
        print('fw_stack.py: indirect call of no known table (any may be reached): %s' % u,
              file=sys.stderr)
    for b in sorted(set(bad)):
        print('fw_stack.py: %s' % b, file=sys.stderr)
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
