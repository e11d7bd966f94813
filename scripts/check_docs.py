#!/usr/bin/env python3
"""check_docs.py - the docs' cross-references and scenario keys against the code.

    scripts/check_docs.py [--root DIR]

1. Every reference to a section, `docs/X.md, "Heading"` (also `X.md "Heading"`,
   `X.md ("Heading"`, broken across lines), in README.md and docs/*.md names a file that
   exists and a Markdown heading, or a bold run-in opening a paragraph or bullet, that is
   or begins with "Heading"; every `docs/X.md` named exists.
2. Scenario keys: every key host_sim/hs_scenario.c accepts is named, in a code span or a
   fenced block, in the page that documents its section (faults: docs/FAULTS.md, radio: docs/RADIO_MODEL.md or
   docs/SIMULATOR.md, the rest: docs/SIMULATOR.md); every key in SIMULATOR.md's example
   scenario is accepted; every key named in its `seek:` paragraph is a seek key.

One FAIL line per problem on stdout and exit 1, or one PASS line and exit 0.
"""
import argparse
import glob
import os
import re
import sys

REF = re.compile(r'\b((?:docs/)?[A-Z][A-Z_]*\.md)[,:]?\s*\(?"([^"]+)"')
DOC = re.compile(r'\b(docs/[A-Za-z_]+\.md)\b')


def read(root, rel):
    with open(os.path.join(root, rel), encoding='utf-8') as f:
        return f.read()


def headings(text):
    out, fence = [], False
    for line in text.split('\n'):
        if line.startswith('```'):
            fence = not fence
        elif not fence and line.startswith('#'):
            out.append(re.sub(r'\s+', ' ', line.lstrip('#').strip()))
        elif not fence:  # a bold run-in opening a paragraph or bullet: "**Walls.** ..."
            m = re.match(r'(?:- )?\*\*([^*]+?)[.:]?\*\*', line)
            if m:
                out.append(m.group(1))
    return out


def check_links(root, n):
    bad = []
    files = ['README.md'] + sorted(os.path.relpath(p, root)
                                   for p in glob.glob(os.path.join(root, 'docs', '*.md')))
    cache = {}
    for rel in files:
        text = read(root, rel)
        for m in DOC.finditer(text):
            if not os.path.exists(os.path.join(root, m.group(1))):
                bad.append('%s: %s does not exist' % (rel, m.group(1)))
        for m in REF.finditer(re.sub(r'\s+', ' ', text)):
            n['links'] += 1
            target, section = m.group(1), m.group(2).strip()
            if not target.startswith('docs/') and not os.path.exists(os.path.join(root, target)):
                target = 'docs/' + target
            if not os.path.exists(os.path.join(root, target)):
                bad.append('%s: %s does not exist (section "%s")' % (rel, target, section))
                continue
            hs = cache.setdefault(target, headings(read(root, target)))
            if not any(h == section or h.startswith(section) for h in hs):
                bad.append('%s: %s has no section "%s"' % (rel, target, section))
    return bad


def scenario_keys(root):
    """{section: [keys]} from hs_scenario.c's key lists and the check_keys() using them."""
    src = read(root, 'host_sim/hs_scenario.c')
    out = {}
    for m in re.finditer(r'static const char \*const (\w+)\[\] = \{(.*?)\};', src, re.S):
        keys = re.findall(r'"([^"]+)"', m.group(2))
        use = re.compile(r'check_keys\(\w+, \w+, ("[^"]+"|\w+), %s\)' % m.group(1))
        u = use.search(src, m.end())
        if not u or not keys:
            continue
        where = u.group(1).strip('"')
        if where == 'where':  # a list item: the kind of list from the key names
            where = 'faults' if 'kind' in keys else 'sources' if 'tx_dbm' in keys else where
        out[where] = keys
    return out


def named_code(text):
    """The code a page names keys in: its `code spans` and its fenced blocks (without their
    comments): a key that is an English word ("seed", "kind") is not named by prose."""
    blocks = re.findall(r'```[^\n]*\n(.*?)```', text, re.S)
    spans = re.findall(r'`([^`\n]+)`', re.sub(r'```.*?```', ' ', text, flags=re.S))
    return [re.sub(r'#.*', '', b) for b in blocks] + spans


def check_keys(root, n):
    bad = []
    keys = scenario_keys(root)
    n['keys'] = sum(len(ks) for ks in keys.values())
    if 'seek' not in keys or 'scenario' not in keys:
        return ['host_sim/hs_scenario.c: no seek or top-level key list found (checker stale)']
    sim = read(root, 'docs/SIMULATOR.md')
    pages = {'faults': ['docs/FAULTS.md']}
    for where, ks in sorted(keys.items()):
        docs = pages.get(where, ['docs/SIMULATOR.md'] +
                         (['docs/RADIO_MODEL.md'] if where.startswith('radio') else []))
        code = named_code(' '.join(read(root, d) for d in docs))
        for k in ks:  # bare, or qualified by its section (`stop.goal`)
            key = r'(?<![\w.-])(?:(?:\w+\.)*%s\.)?%s(?![\w-])' % (re.escape(where.split('.')[-1]),
                                                                 re.escape(k))
            if not any(re.search(key, c) for c in code):
                bad.append('%s: key %s.%s accepted by hs_scenario.c is not named'
                           % (' or '.join(docs), where, k))
    every = set(k for ks in keys.values() for k in ks)
    block = re.search(r'```yaml\n(.*?)```', sim, re.S)
    if not block:
        bad.append('docs/SIMULATOR.md: no example scenario (```yaml block)')
    else:
        yaml = re.sub(r'#.*', '', block.group(1))  # comments name keys in prose
        for k in re.findall(r'([A-Za-z_]\w*):', yaml):
            if k not in every:
                bad.append('docs/SIMULATOR.md: example key %s is not accepted' % k)
    para = re.search(r'`seek:` \(or.*?\n\n', sim, re.S)
    if not para:
        bad.append('docs/SIMULATOR.md: no "`seek:` (or ..." paragraph (checker stale)')
    else:
        for span in re.findall(r'`([^`]+)`', para.group(0)):
            m = re.match(r'([a-z][a-z0-9]*_[a-z0-9_]*)(:|$)', span)
            if m and '.' not in span and m.group(1) not in keys['seek']:
                bad.append('docs/SIMULATOR.md: %s is named as a seek: key but not accepted'
                           % m.group(1))
    return bad


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[1],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split('\n\n', 2)[2])
    ap.add_argument('--root', default=os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'),
                    help="the repository (default: this script's parent directory)")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    n = {'links': 0, 'keys': 0}
    bad = check_links(a.root, n) + check_keys(a.root, n)
    for line in bad:
        print('FAIL docs: ' + line)
    if not bad:
        print('PASS docs: %d section references resolve; %d scenario keys documented'
              % (n['links'], n['keys']))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
