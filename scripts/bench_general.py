#!/usr/bin/python3
"""Seeking where nobody tuned: every shipped floor at random start/source placements
(rfseek-sim --placements, docs/SIMULATOR.md "Placements"), meta-path + pathloss and the
paper's meta + ridge on the same placements and seeds. Prints success, travel / shortest
path and a failure taxonomy for the tuning draws (placements 1..50) and the held-out
draws (51..100), and writes only the held-out half to its section of docs/RESULTS.md
(between the markers below). --placement-seed S (not 1) draws other pairs, all of them
fair tuning draws (nothing written); --only p or r runs one configuration. The floors held
out from all tuning (UNSEEN) run no tuning draws.

    /usr/bin/python3 scripts/bench_general.py [--placements 100] [--seeds 1..2]
        [--floors willow,3ne,...] [--sim build/bin/rfseek-sim] [--jobs 1]
        [--work build/bench_general] [--results docs/RESULTS.md | --no-write] [--held-out-only]
        [--placement-seed S] [--only p|r]

--placements P (even, 2..100) runs placements 1..P/2 and 51..50+P/2, so a smaller bench
keeps the same held-out draws (with another placement seed: 1..P). Batches of up to CHUNK placements go to WORK/<binary
hash>/...: a finished one is read back and an interrupted one resumed (rfseek-sim
--resume), so an interrupted bench continues where it stopped and a larger one reuses a
smaller one's runs; a rebuilt simulator starts afresh. --held-out-only skips the tuning
draws (the section is the same).

Failure taxonomy of a run that did not reach the source, first match wins, from the
fields of summary.json (and runs.tsv):
  near miss        final_distance_m <= 3 m (twice the stop radius)
  blocked          goal_blocked + goal_timeouts >= 3 (the drive gave up on 3 goals), or it
                   ended by the time cap parked (still_s >= 120) with its belief right
                   (belief_error_m <= 3 m)
  wrong belief     ended by the time cap parked (still_s >= 120 s) with the belief more
                   than 3 m from the source (or none): the robot waits where it wrongly
                   thinks the source is and learns nothing new
  exploring        ended by the travel budget (end "distance", 150 m)
  other            ended by the time cap still moving
Separately, "parked": runs that ended by the time cap with less than 100 m travelled.
"""
import argparse
import glob
import hashlib
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_pathloss_seek import commit, splice, wilson  # noqa: E402

REAL = ["willow", "3ne", "intel", "gdc2", "gdc4", "house"]
SYNTHETIC = ["default", "lshape", "open"]
# Floors held out from all tuning (docs/RESULTS.md): none of their placements, tuning half
# included, may choose an option or a value.
UNSEEN = ["bookstore", "warehouse"]
# (strategy, model, label, column prefix)
CONFIGS = [("meta-path", "pathloss", "meta-path + pathloss", "p"),
           ("meta", "ridge", "meta + ridge", "r")]
HELD_OUT_FIRST = 51  # placements 1..50 are the tuning draws, 51..100 the held-out ones
CHUNK = 10          # placements per batch
NEAR_M, STILL_S, BELIEF_M, ABANDONED, PARKED_M = 3.0, 120.0, 3.0, 3, 100.0
CATEGORIES = ["near miss", "blocked", "wrong belief", "exploring", "other"]
BEGIN = "<!-- bench_general: begin -->"
END = "<!-- bench_general: end -->"


def num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def category(r):
    """The taxonomy class of a run (a runs.tsv row as a dict), or None when it reached."""
    if r["reached"] == "1":
        return None
    belief = num(r["belief_error_m"])
    parked = r["end"] == "time" and num(r["still_s"]) >= STILL_S
    if num(r["final_distance_m"]) <= NEAR_M:
        return "near miss"
    if int(r["goal_blocked"]) + int(r["goal_timeouts"]) >= ABANDONED or (parked and belief <= BELIEF_M):
        return "blocked"
    if parked:
        return "wrong belief"  # belief > 3 m, or none (nan)
    if r["end"] == "distance":
        return "exploring"
    return "other"


def quantile(xs, q):
    """Linear interpolation between order statistics (numpy's default); nan when empty."""
    xs = sorted(xs)
    if not xs:
        return float("nan")
    h = (len(xs) - 1) * q
    i = int(h)
    return xs[i] if i + 1 >= len(xs) else xs[i] + (h - i) * (xs[i + 1] - xs[i])


def stats(rows):
    """Success with its Wilson interval, travel / shortest over the successful runs
    (median, 90th percentile), the taxonomy counts and the parked count."""
    n = len(rows)
    k = sum(r["reached"] == "1" for r in rows)
    p, (lo, hi) = k / n if n else float("nan"), wilson(k, n)
    ratios = [num(r["distance_travelled_m"]) / num(r["shortest_path_m"])
              for r in rows if r["reached"] == "1"]
    cats = {c: 0 for c in CATEGORIES}
    for r in rows:
        c = category(r)
        if c:
            cats[c] += 1
    parked = sum(r["end"] == "time" and num(r["distance_travelled_m"]) < PARKED_M for r in rows)
    return {"n": n, "k": k, "p": p, "lo": lo, "hi": hi, "med": quantile(ratios, 0.5),
            "p90": quantile(ratios, 0.9), "cats": cats, "parked": parked}


def read_runs(path):
    with open(path) as f:
        head = f.readline().rstrip("\n").split("\t")
        return [dict(zip(head, line.rstrip("\n").split("\t"))) for line in f]


def batch(a, floor, strategy, model, first, last, base):
    """The runs of placements first..last in batches of CHUNK (each run, resumed or read
    back in base/...), and the host seconds the batches took when they ran."""
    rows, spent = [], 0.0
    for lo in range(first, last + 1, CHUNK):
        r, el = chunk(a, floor, strategy, model, lo, min(last, lo + CHUNK - 1), base)
        rows += r
        spent += el
    return rows, spent


def chunk(a, floor, strategy, model, first, last, base):
    """The runs of one batch, run (or resumed, or read back) in base/..."""
    seek = a.seek if strategy == "meta-path" else ""
    tag = "-seek" + hashlib.sha256(seek.encode()).hexdigest()[:8] if seek else ""
    ps = f"-ps{a.placement_seed}" if a.placement_seed != 1 else ""
    d = os.path.join(base, floor, f"{strategy}-{model}-p{first}..{last}{ps}-s{a.seeds}{tag}")
    runs = os.path.join(d, "runs.tsv")
    if not os.path.exists(runs):
        t0 = time.time()
        os.makedirs(os.path.dirname(d), exist_ok=True)
        cmd = [a.sim, f"scenarios/{floor}.yaml", "--placements", f"{first}..{last}",
               "--placement-seed", str(a.placement_seed), "--seeds", a.seeds, "--strategy", strategy, "--model",
               model, "--jobs", str(a.jobs), "--quiet", "--out", d]
        if seek:
            cmd += ["--seek", seek]
        if os.path.exists(d) or glob.glob(d + ".tmp-*"):
            cmd.append("--resume")
        out = subprocess.run(cmd, capture_output=True, text=True)
        if out.returncode != 0:
            sys.exit(f"bench_general: {' '.join(cmd)}: {out.stderr.strip()}")
        with open(os.path.join(d, "elapsed_s"), "w") as f:  # the bench's time, read back
            f.write(f"{time.time() - t0:.1f}\n")
    with open(os.path.join(d, "elapsed_s")) as f:
        return read_runs(runs), float(f.read())


def cells(s, parked):
    """One configuration's cells: success % (Wilson interval), travel / shortest median and
    90th percentile, the taxonomy counts in CATEGORIES order, and parked when asked."""
    return (f"**{100 * s['p']:.1f}** ({100 * s['lo']:.0f}-{100 * s['hi']:.0f}) | "
            f"{s['med']:.2f} / {s['p90']:.2f} | " + "/".join(str(s["cats"][c]) for c in CATEGORIES)
            + (f" | {s['parked']}" if parked else ""))


def table(results, floors, parked=True):
    """One row per floor, both configurations side by side, then the real floors pooled;
    the parked columns unless parked is False."""
    configs = [x for x in CONFIGS if any(k[1] == x[2] for k in results)]
    head = ["floor (runs)"]
    for _, _, _, c in configs:
        head += [f"{c} success %", f"{c} ratio median / p90", f"{c} failures"] + \
            ([f"{c} parked"] if parked else [])
    L = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    rows = [(f, [f]) for f in floors]
    for label, kind in (("**all real**", REAL), ("**all unseen**", UNSEEN)):
        if len([f for f in floors if f in kind]) > 1:
            rows.append((label, [f for f in floors if f in kind]))
    for label, group in rows:
        st = [stats([r for f in group for r in results[(f, cfg)]]) for _, _, cfg, _ in configs]
        L.append(f"| {label} ({st[0]['n']}) | " + " | ".join(cells(x, parked) for x in st) + " |")
    return L


def section(cmd, at, minutes, nruns, seeds, held, floors, results):
    """The RESULTS.md section: the table without the parked columns, the parked runs per
    configuration (and floor) in the text."""
    parked = []
    for _, _, cfg, c in CONFIGS:
        per = [(f, stats(results[(f, cfg)])["parked"]) for f in floors]
        where = ", ".join(f"{f} {n}" for f, n in per if n)
        parked.append(f"{c} {sum(n for _, n in per)}" + (f" ({where})" if where else ""))
    L = [BEGIN, "## Generalisation: random placements", "",
         f"Written by `{cmd}` at commit {at} ({nruns} runs, {minutes:.0f} min): held-out "
         f"placements {held} (1..50 tune, but on {' and '.join(UNSEEN)} none: floors held "
         "out from all tuning) of every shipped floor "
         "(docs/SIMULATOR.md, \"Placements\"), seeds "
         f"{seeds}; `p` meta-path + pathloss, `r` meta + ridge (the "
         "paper). Ratio: travel / shortest path, successful runs. Failures (first match; "
         "defined in scripts/bench_general.py): near miss / blocked / wrong belief / exploring "
         "(150 m spent) / other. "
         f"Parked (time cap, under 100 m): {', '.join(parked)}.", ""]
    L += table(results, floors, parked=False)
    L += ["", END]
    return "\n".join(L) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--placements", type=int, default=100, help="placements a floor (even: the first half tunes, the second is held out)")
    ap.add_argument("--seeds", default="1..2", help="simulator seeds a placement, A..B")
    ap.add_argument("--floors", default=",".join(REAL + SYNTHETIC + UNSEEN), help="comma-separated floors (scenarios/NAME.yaml)")
    ap.add_argument("--sim", default="build/bin/rfseek-sim", help="the rfseek-sim to run")
    ap.add_argument("--jobs", type=int, default=1, help="worker processes a batch")
    ap.add_argument("--work", default="build/bench_general", help="folder for the batches' runs")
    ap.add_argument("--results", default="docs/RESULTS.md", help="the markdown file whose section is replaced")
    ap.add_argument("--no-write", action="store_true", help="print the tables only")
    ap.add_argument("--seek", default="",
                    help="rfseek-sim --seek for meta-path + pathloss ('KEY: VALUE, ...'; a variant "
                         "beside the preset, the paper's runs unchanged)")
    ap.add_argument("--held-out-only", action="store_true",
                    help="run placements 51.. only (the tuning draws are not run)")
    ap.add_argument("--placement-seed", type=int, default=1,
                    help="the seed the pairs are drawn from; any but 1 gives tuning draws only "
                         "(needs --no-write)")
    ap.add_argument("--only", default="",
                    help="run only this configuration (p: meta-path + pathloss, r: meta + ridge; "
                         "needs --no-write)")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    if a.only not in ("", "p", "r"):
        sys.exit(f"bench_general: --only: expected p or r, not {a.only!r}")
    if a.placement_seed < 1:
        sys.exit("bench_general: --placement-seed: expected a positive integer")
    if (a.placement_seed != 1 or a.only) and not a.no_write:
        sys.exit("bench_general: --placement-seed and --only need --no-write "
                 "(RESULTS.md holds the held-out draws of placement seed 1, both configurations)")
    if a.placement_seed != 1 and a.held_out_only:
        sys.exit("bench_general: --held-out-only: only placement seed 1 has held-out draws")
    if not (2 <= a.placements <= 100 and a.placements % 2 == 0):
        sys.exit("bench_general: --placements: expected an even number from 2 to 100")
    if not re.fullmatch(r"\d+\.\.\d+", a.seeds) or int(a.seeds.split("..")[0]) > int(a.seeds.split("..")[1]):
        sys.exit("bench_general: --seeds: expected A..B with A <= B")
    if not 1 <= a.jobs <= 1024:  # rfseek-sim's range: refused here, not in every batch
        sys.exit("bench_general: --jobs: expected a number from 1 to 1024")
    floors = a.floors.split(",")
    for f in floors:
        if f not in REAL + SYNTHETIC + UNSEEN:
            sys.exit(f"bench_general: --floors: unknown floor {f!r} "
                     f"(known: {', '.join(REAL + SYNTHETIC + UNSEEN)})")
    if a.placement_seed != 1 and all(f in UNSEEN for f in floors):
        sys.exit(f"bench_general: --floors: {', '.join(floors)}: held out from all tuning "
                 "(no tuning draws; placement seed 1's held-out draws only)")
    if not os.access(a.sim, os.X_OK):
        sys.exit(f"bench_general: {a.sim}: not an executable (make all)")
    if a.seek:  # checked once, before any batch
        chk = subprocess.run([a.sim, "scenarios/open.yaml", "--seek", a.seek, "--placements", "1",
                              "--list-placements"], capture_output=True, text=True)
        if chk.returncode != 0:
            sys.exit(f"bench_general: {chk.stderr.strip()}")
    with open(a.sim, "rb") as f:
        base = os.path.join(a.work, hashlib.sha256(f.read()).hexdigest()[:12])
    half = a.placements // 2
    halves = [("tuning", 1, half), ("held-out", HELD_OUT_FIRST, HELD_OUT_FIRST + half - 1)]
    if a.placement_seed != 1:  # every pair of another seed is a tuning draw
        halves = [(f"tuning (placement seed {a.placement_seed})", 1, a.placements)]
    if a.held_out_only:
        halves = halves[1:]
    # The floors each half runs: no tuning draw of a floor held out from all tuning.
    on = {h: [f for f in floors if h == "held-out" or f not in UNSEEN] for h, _, _ in halves}
    if any(f in UNSEEN for f in floors) and halves[0][0] != "held-out":
        print(f"bench_general: {', '.join(f for f in floors if f in UNSEEN)}: held-out draws "
              "only (held out from all tuning)", file=sys.stderr)
    t0, spent = time.time(), 0.0
    results = {h: {} for h, _, _ in halves}
    for f in floors:
        for strategy, model, cfg, c in CONFIGS:
            if a.only and c != a.only:
                continue
            for h, first, last in halves:
                if f not in on[h]:
                    continue
                results[h][(f, cfg)], el = batch(a, f, strategy, model, first, last, base)
                spent += el
                s = stats(results[h][(f, cfg)])
                print(f"{f} {cfg} {h}: {s['k']}/{s['n']} reached ({el:.0f} s)",
                      file=sys.stderr, flush=True)
    for h, first, last in halves:
        print(f"\n### {h} placements {first}..{last}, seeds {a.seeds}\n")
        print("\n".join(table(results[h], on[h])))
    if not a.no_write:
        nice = os.nice(0)
        cmd = (f"nice -n {nice} " if nice else "") + "/usr/bin/python3 scripts/bench_general.py" + \
            "".join(f" {o}" for o in sys.argv[1:])
        nruns = sum(len(v) for r in results.values() for v in r.values())
        text = section(cmd, commit(), spent / 60, nruns, a.seeds,
                       f"{halves[-1][1]}..{halves[-1][2]}", floors, results["held-out"])
        splice(a.results, text, BEGIN, END)
        print(f"\nwrote {a.results} ({time.time() - t0:.0f} s)")


if __name__ == "__main__":
    main()
