#!/usr/bin/python3
"""compare_plan.py - seeking with two simulator builds, paired by seed (docs/PERFORMANCE.md,
"Planning in slices"): the same scenarios, configurations and seeds through a baseline
rfseek-sim and a new one, e.g. before and after a planner change.

    /usr/bin/python3 scripts/compare_plan.py --base BASE/bin/rfseek-sim
        [--new build/bin/rfseek-sim] [--seeds 200] [--jobs 2] [--work build/compare_plan]

Per scenario and configuration (meta + ridge, meta-path + pathloss): success (reached
the source within the run's limits) of each build with its 95 % Wilson interval, the
discordant pairs (seeds only one build reached) with McNemar's exact two-sided p, the
median travel ratio (distance travelled / shortest path) of each over the seeds both
reached and the mean change of its log over those seeds (+- one standard error); from each
build's summaries (base / new) the decisions that waited two or more control periods for
their search tree (over 100 ms at 20 Hz; summary.json slow_decisions) as a share of all
decisions (the new build's count), and the longest decision latency (a leg's end to the
wheel command: a period per wait and the deciding one).
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys

SCENARIOS = ["default", "lshape", "3ne", "intel"]
CONFIGS = [("meta", "ridge"), ("meta-path", "pathloss")]


def wilson(k, n, z=1.959964):
    if n == 0:
        return (0.0, 0.0)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (c - h, c + h)


def mcnemar(b, c):
    """Exact two-sided binomial p of b against c discordant pairs."""
    n = b + c
    if n == 0:
        return 1.0
    k = min(b, c)
    p = sum(math.comb(n, i) for i in range(k + 1)) / 2.0 ** n
    return min(1.0, 2 * p)


def run(binary, scen, strat, model, seeds, jobs, out):
    if not os.path.exists(os.path.join(out, "runs.tsv")):
        os.makedirs(os.path.dirname(out), exist_ok=True)
        cmd = [binary, "scenarios/%s.yaml" % scen, "--seeds", "1..%d" % seeds, "--strategy",
               strat, "--model", model, "--jobs", str(jobs), "--out", out, "--quiet"]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    rows = {}
    with open(os.path.join(out, "runs.tsv")) as f:
        head = f.readline().rstrip("\n").split("\t")
        for line in f:
            r = dict(zip(head, line.rstrip("\n").split("\t")))
            rows[int(r["seed"])] = r
    return rows


def summaries(out, seeds):
    s = {}
    for k in seeds:
        p = os.path.join(out, "seed-%d" % k, "summary.json")
        if os.path.exists(p):
            with open(p) as f:
                s[k] = json.load(f)
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--base", required=True, help="the rfseek-sim to compare against (required)")
    ap.add_argument("--new", default="build/bin/rfseek-sim", help="the rfseek-sim under test")
    ap.add_argument("--seeds", type=int, default=200, help="seeds 1..N a configuration")
    ap.add_argument("--jobs", type=int, default=2, help="worker processes")
    ap.add_argument("--work", default="build/compare_plan", help="folder for the runs")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    for opt, sim in (("--base", a.base), ("--new", a.new)):
        if not os.access(sim, os.X_OK):
            sys.exit(f"compare_plan.py: {opt}: {sim}: not an executable")
    if a.seeds < 1 or a.jobs < 1:
        sys.exit("compare_plan.py: --seeds and --jobs: expected at least 1")
    print("| scenario, configuration | success base | success new | only base / new (p) | "
          "ratio base / new | paired | decisions > 100 ms | longest latency |")
    print("|---|---|---|---|---|---|---|---|")
    for scen in SCENARIOS:
        for strat, model in CONFIGS:
            res = {}
            for tag, binary in (("base", a.base), ("new", a.new)):
                out = os.path.join(a.work, tag, "%s-%s-%s" % (scen, strat, model))
                res[tag] = run(binary, scen, strat, model, a.seeds, a.jobs, out)
            seeds = sorted(set(res["base"]) & set(res["new"]))
            ok = {t: {k for k in seeds if res[t][k]["reached"] == "1"} for t in res}
            n = len(seeds)
            cell = []
            for t in ("base", "new"):
                lo, hi = wilson(len(ok[t]), n)
                cell.append("%.1f %% [%.1f, %.1f]" % (100.0 * len(ok[t]) / n, 100 * lo, 100 * hi))
            b = len(ok["base"] - ok["new"])
            c = len(ok["new"] - ok["base"])

            def ratio(t, k):
                r = res[t][k]
                return float(r["distance_travelled_m"]) / float(r["shortest_path_m"])
            both = sorted(ok["base"] & ok["new"])
            rb = [ratio("base", k) for k in both]
            rn = [ratio("new", k) for k in both]
            med = lambda v: statistics.median(v) if v else float("nan")  # noqa: E731
            logs = [math.log(y / x) for x, y in zip(rb, rn)]
            if len(logs) < 2:
                logs = []
            mlog = statistics.mean(logs) if logs else float("nan")
            se = statistics.stdev(logs) / math.sqrt(len(logs)) if len(logs) > 1 else float("nan")
            waits = []
            for t in ("base", "new"):
                sm = summaries(os.path.join(a.work, t, "%s-%s-%s" % (scen, strat, model)), seeds)
                dec = sum(int(s["iterations"]) for s in sm.values())
                slow = sum(int(s.get("slow_decisions", 0)) for s in sm.values())
                wait = max([int(s.get("plan_wait_max", 0)) for s in sm.values()] or [0])
                waits.append((100.0 * slow / max(dec, 1), dec, 50 * (wait + 1)))
            print("| %s, %s + %s | %s | %s | %d / %d (%.2f) | %.2f / %.2f | %+.3f +- %.3f | "
                  "%.2f / %.2f %% of %d | %d / %d ms |" % (
                      scen, strat, model, cell[0], cell[1], b, c, mcnemar(b, c), med(rb),
                      med(rn), mlog, se, waits[0][0], waits[1][0], waits[1][1], waits[0][2],
                      waits[1][2]))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
