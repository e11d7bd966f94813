#!/usr/bin/env python3
"""The path-loss model's named configurations: the paper's local ridge (strategy meta)
beside the map-aware pathloss model (strategy meta-path) with its preset improvements off,
on (the default) and with the node's transmit power known, on the shipped floors and
where it breaks (8 dB shadowing, a source in the corridor, nodes weaker than believed).
Writes its section of docs/RESULTS.md, between the markers below, and nothing else.

    /usr/bin/python3 scripts/bench_pathloss_seek.py [--seeds N] [--first-seed 1001]
                                                    [--sim build/bin/rfseek-sim] [--jobs N]
                                                    [--results docs/RESULTS.md | --no-write]
                                                    [--seek 'KEY: VALUE, ...'] [--only-pathloss]

--seek runs the meta-path + pathloss column with rfseek-sim --seek (a variant beside the
presets); --only-pathloss runs that column alone. Both print only (--no-write).
"""
import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

ROWS = [  # (label, scenario, yaml edits)
    ("default office", "scenarios/default.yaml", []),
    ("L-shaped floor", "scenarios/lshape.yaml", []),
    ("3ne (real map)", "scenarios/3ne.yaml", []),
    ("willow (real map)", "scenarios/willow.yaml", []),
    ("intel (real map)", "scenarios/intel.yaml", []),
]
BREAKS = [
    ("default, shadowing 8 dB", "scenarios/default.yaml",
     [(r"sigma_db: 4\.0, dcorr_m", "sigma_db: 8.0, dcorr_m")]),
    ("default, source in the corridor (20, 6)", "scenarios/default.yaml",
     [(r"position: \[27\.5, 10\.0\]", "position: [20.0, 6.0]")]),
    # The known-power row's belief (20 dBm, p0_min_dbm -32) wrong: weaker nodes.
    ("3ne, the node at 8 dBm (not 20)", "scenarios/3ne.yaml",
     [(r'(mac: "02:00:00:00:00:01")', '\\1\n    tx_dbm: 8')]),
    ("3ne, the node at 0 dBm (not 20)", "scenarios/3ne.yaml",
     [(r'(mac: "02:00:00:00:00:01")', '\\1\n    tx_dbm: 0')]),
]
# (strategy, model, column, extra scenario text): meta-path's preset improvements
# (recheck every step of a greedy leg against an adaptive threshold, epsilon annealed by
# travel, epsilon goals weighted by path length, epsilon goals drawn from the model's
# belief; docs/STRATEGIES.md) are also run switched off, so each row shows what they bring.
CONFIGS = [("meta", "ridge", "meta + ridge", ""),
           ("meta-path", "pathloss", "improvements off",
            "seek: {recheck_m: 0, eps_by_travel: false, eps_geodesic: false, "
            "recheck_adapt: false, eps_sample: false}\n"),
           ("meta-path", "pathloss", "meta-path + pathloss", ""),
           # The node's transmit power known (20 dBm EIRP): the P0 floor 12 dB below the
           # free-space 1 m signal (docs/PATHLOSS.md, "The P0 floor").
           ("meta-path", "pathloss", "transmit power known",
            "seek: {p0_min_dbm: -32}\n")]


def wilson(k, n, z=1.96):
    if n == 0:
        return (float("nan"), float("nan"))
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))


def run(sim, scenario, strategy, model, seeds, first=1, jobs=None, seek=""):
    cmd = [sim, scenario, "--strategy", strategy, "--model", model,
           "--seeds", f"{first}..{first + seeds - 1}", "--quiet"] + (["--seek", seek] if seek else [])
    out = subprocess.run(cmd + (["--jobs", str(jobs)] if jobs else []),
                         capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"bench_pathloss_seek: {scenario}: {out.stderr.strip()}")
    lines = out.stdout.strip().split("\n")
    head = lines[0].split("\t")
    rows = [dict(zip(head, l.split("\t"))) for l in lines[1:]]
    k = sum(r["reached"] == "1" for r in rows)
    ratios = [float(r["distance_travelled_m"]) / float(r["shortest_path_m"]) for r in rows]
    lo, hi = wilson(k, len(rows))
    return {"n": len(rows), "k": k, "lo": lo, "hi": hi,
            "ratio": statistics.median(ratios),
            "p90": sorted(ratios)[int(0.9 * (len(ratios) - 1))],
            "updates": statistics.median(int(r["model_updates"]) for r in rows)}


def scenario_file(path, edits, tmpdir, extra=""):
    if not edits and not extra:
        return path
    text = open(path).read() + extra
    for pat, rep in edits:
        text, n = re.subn(pat, rep, text)
        if n != 1:
            sys.exit(f"bench_pathloss_seek: edit {pat!r} did not apply to {path}")
    # Keep relative map paths valid: write beside the original.
    fd, tmp = tempfile.mkstemp(suffix=".yaml", dir=os.path.dirname(path))
    os.write(fd, text.encode())
    os.close(fd)
    tmpdir.append(tmp)
    return tmp


BEGIN = "<!-- bench_pathloss_seek: begin -->"
END = "<!-- bench_pathloss_seek: end -->"


def commit():
    """The checked-out commit, "-dirty" when the tracked files differ from it."""
    def git(*a):
        r = subprocess.run(["git"] + list(a), capture_output=True, text=True)
        return r.stdout.strip() if r.returncode == 0 else ""
    h = git("rev-parse", "--short=7", "HEAD") or "unknown"
    return h + ("-dirty" if git("status", "--porcelain", "--untracked-files=no") else "")


def cell(r):
    return (f"{100 * r['k'] / r['n']:.0f} % ({100 * r['lo']:.0f}-{100 * r['hi']:.0f}), "
            f"{r['ratio']:.2f}")


def section(seeds, first, wall, at, table):
    """The section as it goes into RESULTS.md; table: [(title, [(label, [cell])])]."""
    L = [BEGIN, "## The path-loss model's configurations", "",
         f"Written by `/usr/bin/python3 scripts/bench_pathloss_seek.py --seeds {seeds}"
         f"{'' if first == 1001 else f' --first-seed {first}'}` at "
         f"commit {at} ({wall:.0f} s on two cores). Each cell: success (95 % Wilson "
         "interval), then the median over **all** runs of travel / shortest path (a failed "
         "run counts its 150 m; the tables above take the median over the successful runs). "
         f"Seeds {first}..{first + seeds - 1} (1..500 are the tuning draws), the scenario's "
         "radio settings unless the row says otherwise. "
         "Columns: `meta + ridge` is the paper; the others are `meta-path + pathloss` "
         "(docs/STRATEGIES.md, docs/PATHLOSS.md) with its preset improvements off (`seek: "
         "{recheck_m: 0, eps_by_travel: false, eps_geodesic: false, recheck_adapt: false, "
         "eps_sample: false}`), as shipped, and with the node's transmit power known (`seek: "
         "{p0_min_dbm: -32}`: 20 dBm EIRP - 52 dB, docs/PATHLOSS.md \"The P0 floor\"). The "
         "last two rows are nodes weaker than that belief. Target: >= 95 % success and "
         "<= 2x the shortest path on every floor.", ""]
    for title, rows in table:
        L.append(f"| {title} | " + " | ".join(c[2] for c in CONFIGS) + " |")
        L.append("|---" * (len(CONFIGS) + 1) + "|")
        for label, cells in rows:
            L.append(f"| {label} | " + " | ".join(cells) + " |")
        L.append("")
    L.append(END)
    return "\n".join(L) + "\n"


def splice(path, text, begin=BEGIN, end=END):
    """RESULTS.md with its section between begin and end replaced by text (appended when
    the file has none); written to a temporary file and renamed."""
    old = open(path).read() if os.path.exists(path) else ""
    b, e = old.find(begin), old.find(end)
    if b >= 0 and e > b:
        rest = old[e + len(end):].lstrip("\n")
        new = old[:b] + text + ("\n" + rest if rest else "")
    elif b >= 0 or e >= 0:
        sys.exit(f"{begin}: {path}: one section marker without the other")
    else:
        new = old.rstrip("\n") + ("\n\n" if old else "") + text
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(new)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--seeds", type=int, default=200, help="seeds a configuration")
    ap.add_argument("--first-seed", type=int, default=1001,
                    help="seeds FIRST..FIRST+N-1 (1..500 are the tuning draws: report on others)")
    ap.add_argument("--sim", default="build/bin/rfseek-sim", help="the rfseek-sim to run")
    ap.add_argument("--jobs", type=int, default=0,
                    help="rfseek-sim worker processes (0: all cores)")
    ap.add_argument("--results", default="docs/RESULTS.md",
                    help="the markdown file whose section is replaced")
    ap.add_argument("--no-write", action="store_true",
                    help="print the section instead of writing it into --results")
    ap.add_argument("--seek", default="",
                    help="rfseek-sim --seek for the meta-path + pathloss column ('KEY: VALUE, "
                         "...'; needs --no-write)")
    ap.add_argument("--only-pathloss", action="store_true",
                    help="run only the meta-path + pathloss column, a line a row (needs --no-write)")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    if not os.access(a.sim, os.X_OK):
        sys.exit(f"bench_pathloss_seek: {a.sim}: not an executable (make all)")
    if (a.seek or a.only_pathloss) and not a.no_write:
        sys.exit("bench_pathloss_seek: --seek and --only-pathloss need --no-write "
                 "(RESULTS.md holds the presets)")
    if a.seek:  # checked once, before any run
        chk = subprocess.run([a.sim, "scenarios/open.yaml", "--seek", a.seek, "--placements", "1",
                              "--list-placements"], capture_output=True, text=True)
        if chk.returncode != 0:
            sys.exit(f"bench_pathloss_seek: {chk.stderr.strip()}")
    if a.seeds < 1 or a.first_seed < 1:
        sys.exit("bench_pathloss_seek: --seeds and --first-seed must be at least 1")
    if a.jobs < 0:
        sys.exit("bench_pathloss_seek: --jobs must be 0 (all cores) or more")
    tmps = []
    t0 = time.time()
    table = []
    try:
        for title, rows in (("floor", ROWS), ("where it breaks", BREAKS)):
            out = []
            for label, path, edits in rows:
                cells = []
                for strategy, model, name, extra in CONFIGS:
                    main_col = name == "meta-path + pathloss"
                    if a.only_pathloss and not main_col:
                        continue
                    scen = scenario_file(path, edits, tmps, extra)
                    cells.append(cell(run(a.sim, scen, strategy, model, a.seeds,
                                          a.first_seed, a.jobs, a.seek if main_col else "")))
                    print(f"{label} | {name} | {cells[-1]}", flush=True)
                out.append((label, cells))
            table.append((title, out))
    finally:
        for t in tmps:
            os.unlink(t)
    if a.only_pathloss:
        return  # one column: the lines above are the result
    text = section(a.seeds, a.first_seed, time.time() - t0, commit(), table)
    if a.no_write:
        print(text)
        return
    splice(a.results, text)
    print(f"wrote {a.results} ({time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
