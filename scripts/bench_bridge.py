#!/usr/bin/env python3
"""Bridging (paper section 6): where the runs settle against the best point of the true
f = -|R1 - R2| - |R1 + R2|, for the paper's meta + ridge fitted on f and for meta-path +
pathloss with one fit per node (docs/STRATEGIES.md, "Bridging"), on every bridging
scenario. Writes its section of docs/RESULTS.md, between the markers below, and the
figure docs/figures/seek_bridge.png, and nothing else.

    /usr/bin/python3 scripts/bench_bridge.py [--seeds 1001..1200] [--jobs N]
                                             [--sim build/bin/rfseek-sim]
                                             [--results docs/RESULTS.md | --no-write]
    /usr/bin/python3 scripts/bench_bridge.py --smoke   (seed 1, no files written)
    /usr/bin/python3 scripts/bench_bridge.py --keep DIR ...   (also keep every runs.tsv; a
                                        table already there for the same seeds is reused)
    /usr/bin/python3 scripts/bench_bridge.py --from DIR       (the section from kept tables)

The simulator reports each run's true best point (the mean field's f over the points the
robot can stand on, reachable from the start), f where the robot ended, and the travel
after which it stayed within 1 m of that point (hs_bridge.h). Seeds 1001..1200 by
default: the per-node configuration was tuned on seeds 1..30 of scenarios/bridge.yaml.
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_pathloss_seek import commit, splice  # noqa: E402

SCENARIOS = ["bridge", "bridge_corridor", "bridge_intel", "bridge_3ne"]  # docs/SIMULATOR.md
CONFIGS = [("meta", "ridge", "paper"), ("meta-path", "pathloss", "per node")]
BEGIN = "<!-- bench_bridge: begin -->"
END = "<!-- bench_bridge: end -->"
NEAR_M = 3.0
SHORT_DB = 3.0  # the shortfall target


def run(sim, scenario, strategy, model, seeds, jobs, out):
    """The runs.tsv rows, and each per-node run's node fits (summary.json pred_sources)."""
    cmd = [sim, scenario, "--strategy", strategy, "--model", model, "--seeds", seeds,
           "--quiet", "--out", out]
    if jobs:
        cmd += ["--jobs", str(jobs)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"bench_bridge: {scenario}: {r.stderr.strip()}")
    with open(os.path.join(out, "runs.tsv")) as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    for row in rows:
        with open(os.path.join(out, f"seed-{row['seed']}", "summary.json")) as f:
            sm = json.load(f)
        fits = sm.get("pred_sources")
        for k, src in enumerate(sm["sources"]):
            fit = fits[k] if fits else [None] * 6
            row[f"fit{k}_err_m"] = ("nan" if fit[0] is None else
                                    f"{np.hypot(fit[0] - src[0], fit[1] - src[1]):.3f}")
            row[f"fit{k}_p0"], row[f"fit{k}_w"] = (
                "nan" if fit[i] is None else f"{fit[i]:.3f}" for i in (2, 4))
    return rows


def kept(path, seeds):
    """A kept table's rows when it holds exactly the seeds A..B, else None."""
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    a, b = (int(v) for v in seeds.split(".."))
    return rows if [int(r["seed"]) for r in rows] == list(range(a, b + 1)) else None


def stats(rows):
    """The figures of one scenario x configuration."""
    num = lambda k: np.array([float(r[k]) for r in rows])  # noqa: E731
    err, short = num("settle_error_m"), num("best_f_db") - num("settle_f_db")
    travel = num("settle_travel_m")
    pred = np.hypot(num("pred_x_m") - num("best_x_m"), num("pred_y_m") - num("best_y_m"))
    gap = np.hypot(num("pred_x_m") - num("final_x_m"), num("pred_y_m") - num("final_y_m"))
    return {"n": len(rows), "near": int((err <= NEAR_M).sum()), "err": err, "short": short,
            "travel": travel, "pred": pred, "gap": gap, "sigma": num("pred_sigma_db"),
            "final": np.c_[num("final_x_m"), num("final_y_m")],
            "fit_err": np.concatenate([num(f"fit{k}_err_m") for k in (0, 1)])
            if "fit0_err_m" in rows[0] else np.array([np.nan]),
            "fit_w": np.concatenate([num(f"fit{k}_w") for k in (0, 1)])
            if "fit0_w" in rows[0] else np.array([np.nan]),
            "best": np.c_[num("best_x_m"), num("best_y_m")],
            # the seeds whose true f has a point more than 3 m off within 3 dB of the best
            "runner": int((num("best_f_db") - num("far_f_db") <= SHORT_DB).sum())
            if "far_f_db" in rows[0] else None}


def mp(a):
    """median (p90), or - when there is nothing to report."""
    a = a[np.isfinite(a)]
    return "-" if len(a) == 0 else f"{np.median(a):.1f} ({np.percentile(a, 90):.1f})"


def section(seeds, wall, at, jobs, table):
    per = [s for _, cfgs in table for (st, _, _), s in cfgs if st == "meta-path"]
    gap = np.concatenate([s["gap"] for s in per])
    fit_err = np.concatenate([s["fit_err"] for s in per])
    fit_w = [f"{np.nanmedian(s['fit_w']):.1f}" for s in per]
    L = [BEGIN, "## Bridging (paper section 6)", "",
         f"`/usr/bin/python3 scripts/bench_bridge.py --seeds {seeds}"
         f"{f' --jobs {jobs}' if jobs else ''}` at {at} "
         f"({'kept tables' if wall is None else f'{wall:.0f} s'}); runs end at 150 m or "
         "600 s. *Best point*: the true f's (mean field, no fading; reachable points, 0.1 m "
         "grid; hs_bridge.h). *Distance*, *shortfall* f(best) - f(end): where "
         "a run ends; *travel to settle*: after which it stayed within 1 m. Per node: ends "
         f"{np.nanmedian(gap):.2f} m from the predicted point; fitted nodes "
         f"{np.nanmedian(fit_err):.1f} m off (p90 {np.nanpercentile(fit_err, 90):.1f}), W "
         f"{', '.join(fit_w)} dB (true 5, 5, 3, 3). Cells: median (p90). *paper*: meta + ridge on f; *per node*: meta-path + "
         "pathloss.", "",
         "| scenario | configuration | within 3 m | distance, m | shortfall, dB | "
         "travel to settle, m | runner-up (over 3 m off) within 3 dB |",
         "|---|---|---|---|---|---|---|"]
    for sc, cfgs in table:
        for (_, _, label), s in cfgs:
            L.append(f"| {sc} | {label} | {s['near']} of {s['n']} | {mp(s['err'])} | "
                     f"{mp(s['short'])} | {mp(s['travel'])} | "
                     f"{'' if s['runner'] is None or label == 'paper' else s['runner']} |")
    L += ["", "![bridging](figures/seek_bridge.png)", "", END]
    return "\n".join(L) + "\n"


def figure(path, sim, seed, best, finals):
    """The office scenario's true f for one seed with where every run settled."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    with tempfile.TemporaryDirectory() as d:
        r = subprocess.run([sim, "scenarios/bridge.yaml", "--seed", str(seed), "--field",
                            "--out", os.path.join(d, "o")], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"bench_bridge: field: {r.stderr.strip()}")
        a = np.loadtxt(os.path.join(d, "o", "field.tsv"), skiprows=1, usecols=(0, 1, 3))
        b = np.loadtxt(os.path.join(d, "o", "field1.tsv"), skiprows=1, usecols=(0, 1, 3))
    f = -np.abs(a[:, 2] - b[:, 2]) - np.abs(a[:, 2] + b[:, 2])
    fig, ax = plt.subplots(figsize=(10, 4))
    sc = ax.scatter(a[:, 0], a[:, 1], c=f, s=2, cmap="viridis", marker="s", linewidths=0,
                    vmin=np.max(f) - 40, vmax=np.max(f))
    fig.colorbar(sc, ax=ax, label=f"true f, dB (seed {seed} field, no fading)")
    for (label, pts), style in zip(finals, ("r.", "w.")):
        ax.plot(pts[:, 0], pts[:, 1], style, ms=4, label=f"{label}: where the runs settled")
    ax.plot(best[0], best[1], "w*", ms=14, mec="k", label=f"best point of f (seed {seed})")
    ax.plot([7.5, 27.5], [2.0, 10.0], "^", color="orange", ms=10, mec="k", ls="none",
            label="nodes")
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="upper left", ncol=2)
    ax.set_title("bridging on scenarios/bridge.yaml (paper section 6, cf. fig. 7)")
    fig.tight_layout()
    fig.savefig(path + ".tmp.png", dpi=80)
    os.replace(path + ".tmp.png", path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--seeds", default="1001..1200", help="seeds A..B (1..500 are the tuning draws)")
    ap.add_argument("--sim", default="build/bin/rfseek-sim", help="the rfseek-sim to run")
    ap.add_argument("--jobs", type=int, default=0, help="worker processes (0: one a core)")
    ap.add_argument("--results", default="docs/RESULTS.md", help="the markdown file whose section is replaced")
    ap.add_argument("--figure", default="docs/figures/seek_bridge.png", help="the figure written")
    ap.add_argument("--no-write", action="store_true", help="print the table only")
    ap.add_argument("--smoke", action="store_true", help="seed 1, print, check, no files")
    ap.add_argument("--keep", help="also copy every runs.tsv (and the run's commit) here")
    ap.add_argument("--from", dest="from_dir", help="write from the tables --keep kept")
    ap.add_argument("--only", choices=[c[2] for c in CONFIGS],
                    help="with --keep: run only this configuration's tables, write nothing")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    if a.smoke:
        a.seeds, a.no_write = "1..1", True
    if a.only and not a.keep:
        sys.exit("bench_bridge: --only needs --keep")
    m = re.fullmatch(r"(\d+)\.\.(\d+)", a.seeds)
    if not m:
        sys.exit("bench_bridge: --seeds: expected A..B")
    if not a.from_dir and not os.access(a.sim, os.X_OK):
        sys.exit(f"bench_bridge: --sim: {a.sim}: not an executable (make all)")
    t0 = time.time()
    table, reused = [], False
    if a.keep:
        os.makedirs(a.keep, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for sc in SCENARIOS:
            cfgs = []
            for strategy, model, label in CONFIGS:
                if a.only and label != a.only:
                    continue
                name = f"{sc}-{strategy}"
                rows = kept(os.path.join(a.keep, name + ".tsv"), a.seeds) if a.keep else None
                reused = reused or rows is not None
                if a.from_dir:
                    with open(os.path.join(a.from_dir, name + ".tsv")) as f:
                        rows = list(csv.DictReader(f, delimiter="\t"))
                elif rows is None:
                    rows = run(a.sim, f"scenarios/{sc}.yaml", strategy, model, a.seeds, a.jobs,
                               os.path.join(tmp, name))
                if a.keep:
                    path = os.path.join(a.keep, name + ".tsv")
                    with open(path + ".tmp", "w") as f:
                        w = csv.DictWriter(f, fieldnames=list(rows[0]), delimiter="\t")
                        w.writeheader()
                        w.writerows(rows)
                    os.replace(path + ".tmp", path)
                s = stats(rows)
                cfgs.append(((strategy, model, label), s))
                print(f"{sc} | {label} | {s['near']}/{s['n']} | {mp(s['err'])} | "
                      f"{mp(s['short'])} | {mp(s['travel'])} | {mp(s['pred'])} | {s['runner']}", flush=True)
            table.append((sc, cfgs))
    if a.only:
        return 0
    at, wall = commit(), time.time() - t0
    if a.from_dir:  # the commit and wall time of the run that kept the tables
        with open(os.path.join(a.from_dir, "run.txt")) as f:
            at, wall, a.seeds, a.jobs = f.read().split()
        wall, a.jobs = float(wall), int(a.jobs)
    elif a.keep:
        with open(os.path.join(a.keep, "run.txt"), "w") as f:
            f.write(f"{at} {wall:.0f} {a.seeds} {a.jobs}\n")
    text = section(a.seeds, None if reused else wall, at, a.jobs, table)
    if a.smoke:
        ok = text.count("| bridge") == 2 * len(SCENARIOS) and all(
            np.isfinite(s["err"]).all() for _, cfgs in table for _, s in cfgs)
        print("%s bench-bridge-smoke" % ("PASS" if ok else "FAIL"))
        return 0 if ok else 1
    if not a.no_write:
        office = table[0][1]
        figure(a.figure, a.sim, int(str(a.seeds).split("..")[0]), office[0][1]["best"][0],
               [(label, s["final"]) for (_, _, label), s in office])
        splice(a.results, text, BEGIN, END)
        print(f"wrote {a.results} and {a.figure} ({time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
