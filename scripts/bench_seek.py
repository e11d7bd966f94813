#!/usr/bin/python3
"""bench_seek.py - the seeking-efficacy benchmark: docs/RESULTS.md + figures.

Runs every strategy on every shipped scenario with the simulator's batch mode
(rfseek-sim --seeds A..B --jobs N), the default scenario at other shadowing and noise
levels and the internal models; then writes the tables (docs/RESULTS.md) and figures
(docs/figures/seek_*.png). Bridging is scripts/bench_bridge.py's.

  scripts/bench_seek.py [--seeds 200] [--first-seed 1001] [--model-seeds 200] [--slow-model-seeds 30]
                        [--jobs 2] [--bin build/bin/rfseek-sim]
  scripts/bench_seek.py --smoke --bin build-x/bin/rfseek-sim    (2 seeds, a self-check)

Definitions (also written into RESULTS.md):
  success      within the stop radius (1.5 m) of the source before 150 m of travel
               (and 900 s), as the simulator reports it ("reached").
  ratio        distance travelled / shortest path around walls (start to the legal point
               nearest the source), median over the successful runs.
  epsilon %    travel during iterations whose decision was an epsilon step (from the
               per-iteration log: odometry at each decision), over all travel.
  detour %     sum over iterations of (planned path length - straight line from the
               position at the decision to the goal), over the sum of planned path
               lengths: the part of the planned travel spent going around walls.
Everything goes to a temporary directory first; RESULTS.md is written to a temporary
file and renamed. Parts of the old RESULTS.md are kept as they are: the hand-written
Summary (between the HAND markers) and the sections other benches write between their own
markers (scripts/bench_pathloss_seek.py and bench_bridge.py in place, bench_drive.py and
bench_general.py at the end).
"""
import argparse
import glob
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import bench_pathloss_seek  # its section markers and commit(), beside this script

STRATEGIES = ["meta", "meta-global", "fd-gradient", "plane-gradient", "chemotaxis", "meta-path"]
# The strategies' internal model: the local ridge (the paper's), except meta-path, which
# runs with the map-aware path-loss model (docs/PATHLOSS.md).
STRAT_MODEL = {"meta-path": "pathloss"}
BASELINES = ["meta-global", "fd-gradient", "plane-gradient", "chemotaxis"]


def model_of(st):
    return STRAT_MODEL.get(st, "ridge")
SCENARIOS = ["default", "open", "lshape", "willow", "3ne", "intel"]
MODELS = ["ridge", "mlp", "knn", "radius", "pathloss"]
SLOW_MODELS = {"mlp", "knn"}

# Labelled regions (name, x0, y0, x1, y1), first match wins; scripts/make_maps.py built
# these floors. Real floors (willow, 3ne, intel) have no labels: their failed runs are
# classified by the walls between the end point and the source (simulator geometry).
OFFICE = [("corridor", 0, 5, 35, 7)] + [
    ("room %s%d" % (side, i), 5 * i, y0, 5 * i + 5, y0 + 5)
    for i in range(7) for side, y0 in (("S", 0), ("N", 7))]
LSHAPE = ([("corridor", 0, 4, 24, 6), ("corridor", 24, 4, 26, 24)] +
          [("room S%d" % i, 5 * i, 0, 5 * i + 5, 4) for i in range(4)] +
          [("room N%d" % i, 5 * i, 6, 5 * i + 5, 10) for i in range(4)] +
          [("room E0", 20, 0, 24, 4), ("room E1", 26, 0, 30, 4), ("room W0", 20, 6, 24, 10),
           ("room W1", 20, 10, 24, 14), ("room W2", 20, 14, 24, 18), ("room W3", 20, 18, 24, 24),
           ("room E2", 26, 4, 30, 10), ("room E3", 26, 10, 30, 14), ("room E4", 26, 14, 30, 18),
           ("room E5", 26, 18, 30, 24)])
REGIONS = {"default": OFFICE, "bridge": OFFICE, "lshape": LSHAPE,
           "open": [("room", -1, -1, 21, 21)]}


def log(msg):
    sys.stderr.write(msg + "\n")
    sys.stderr.flush()


def wilson(k, n, z=1.959964):
    if n == 0:
        return (float("nan"),) * 3
    p = k / n
    den = 1 + z * z / n
    c = (p + z * z / (2 * n)) / den
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return p, max(0.0, c - h), min(1.0, c + h)


def read_tsv(path):
    with open(path) as f:
        head = f.readline().rstrip("\n").split("\t")
        rows = []
        for line in f:
            v = line.rstrip("\n").split("\t")
            rows.append(dict(zip(head, v)))
    return rows


def fnum(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return float("nan")


def scenario_path(name):
    return os.path.join("scenarios", name + ".yaml")


def leg_stats(logrows, total):
    """(epsilon travel m, planned path m, planned detour m) of one run's log."""
    eps = 0.0
    path = 0.0
    detour = 0.0
    for i, r in enumerate(logrows):
        t0 = fnum(r["travelled_m"])
        t1 = fnum(logrows[i + 1]["travelled_m"]) if i + 1 < len(logrows) else total
        if r["kind"] == "epsilon":
            eps += max(0.0, t1 - t0)
        p = fnum(r["path_m"])
        if p > 0:
            straight = math.hypot(fnum(r["goal_x_m"]) - fnum(r["est_x_m"]),
                                  fnum(r["goal_y_m"]) - fnum(r["est_y_m"]))
            path += p
            detour += max(0.0, p - straight)
    return eps, path, detour


# CPU seconds per run, a model's on the default office, and a scenario's factor (measured
# with make bench-seek; docs/PERFORMANCE.md, "Seek benchmark"): only for the order in which
# run_all() starts the batches, so a stale value costs time, never a figure.
RUN_CPU = {"ridge": 0.08, "pathloss": 0.25, "radius": 0.2, "knn": 0.5, "mlp": 0.6}
SCEN_CPU = {"default": 1.0, "open": 0.6, "lshape": 1.0, "willow": 2.5, "3ne": 2.0, "intel": 3.0}


class Batch:
    """One rfseek-sim --seeds batch: a strategy with a model on a scenario file."""

    def __init__(self, section, tag, scen, scen_file, strategy, model, seeds, keep=(),
                 first=1):
        self.section, self.tag, self.scen_file = section, tag, scen_file
        self.strategy, self.model, self.seeds, self.keep = strategy, model, seeds, set(keep)
        self.first = first
        self.est = seeds * RUN_CPU.get(model, 1.0) * SCEN_CPU.get(scen, 1.0)
        self.res, self.cpu = None, 0.0


def read_batch(out, keep):
    """The per-run dicts of a finished batch in out; seed logs not in keep are removed."""
    runs = read_tsv(os.path.join(out, "runs.tsv"))
    res = []
    for r in runs:
        seed = int(r["seed"])
        sd = os.path.join(out, "seed-%d" % seed)
        total = fnum(r["distance_travelled_m"])
        lg = read_tsv(os.path.join(sd, "log.tsv"))
        eps, path, detour = leg_stats(lg, total)
        res.append({
            "seed": seed, "reached": r["reached"] == "1", "end": r["end"],
            "dist": total, "shortest": fnum(r["shortest_path_m"]),
            "final_d": fnum(r["final_distance_m"]), "fx": fnum(r["final_x_m"]),
            "fy": fnum(r["final_y_m"]), "updates": int(r["model_updates"]),
            "iters": int(r["iterations"]), "eps_m": eps, "path_m": path, "detour_m": detour,
        })
        if seed not in keep:
            shutil.rmtree(sd)
    return res


def plan_batches(args, tmp, scenarios, ns, ms):
    """The batches of the three sections, as dicts: (scenario, strategy) -> the strategy
    sweep's; (strategy, shadowing, noise) -> the noise sweep's; (scenario, model) -> the
    internal models'. Rows that are another section's runs have no batch of their own."""
    sweep_b, var_b, model_b = {}, {}, {}
    # 1. every strategy on every scenario
    for sc in scenarios:
        for st in STRATEGIES:
            f = args.first_seed
            keep = range(f, f + 5) if sc == "default" else ()
            sweep_b[(sc, st)] = Batch("sweep", "%s-%s" % (sc, st), sc, scenario_path(sc), st,
                                      model_of(st), args.seeds, keep, f)
    # 2. shadowing and noise on the default scenario (4/4 is the default itself)
    for st in STRATEGIES:
        for sh, no in [(0, 4), (8, 4), (4, 2), (4, 8)] + ([] if ns == args.seeds else [(4, 4)]):
            var_b[(st, sh, no)] = Batch("noise", "var-%s-%g-%g" % (st, sh, no), "default",
                                        make_variant(tmp, sh, no), st, model_of(st), ns,
                                        first=args.first_seed)
    # 3. internal models under meta
    for sc in scenarios:
        for m in MODELS:
            n = args.slow_model_seeds if m in SLOW_MODELS else ms
            if n > 0 and not (m == "ridge" and n == args.seeds):
                model_b[(sc, m)] = Batch(m, "model-%s-%s" % (sc, m), sc, scenario_path(sc),
                                         "meta", m, n, first=args.first_seed)
    return sweep_b, var_b, model_b


def run_all(args, tmp, batches):
    """Every batch, one single-process rfseek-sim each, args.jobs at a time, the longest
    (by estimate) first: a core frees only when a batch ends, and the last to start are
    the shortest, so no core waits for a section to finish. Fills each batch's res and
    cpu (its process's user + system seconds)."""
    todo = sorted(batches, key=lambda b: -b.est)
    running, finished, t0 = {}, [], time.time()
    while todo or running or finished:
        while todo and len(running) < args.jobs:
            b = todo.pop(0)
            cmd = [args.bin, b.scen_file, "--seeds", "%d..%d" % (b.first, b.first + b.seeds - 1),
                   "--jobs", "1",
                   "--quiet", "--out", os.path.join(tmp, b.tag), "--strategy", b.strategy,
                   "--model", b.model]
            p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL)
            running[p.pid] = (p, b)
        if finished:
            b = finished.pop(0)
            b.res = read_batch(os.path.join(tmp, b.tag), b.keep)
            if not args.quiet:
                log("[%d/%d] %s: %d seeds, %.1f s CPU (%.0f s so far)" % (
                    len(batches) - len(todo) - len(running) - len(finished), len(batches),
                    b.tag, b.seeds, b.cpu, time.time() - t0))
            continue
        pid, status, ru = os.wait4(-1, 0)
        if pid not in running:
            continue
        p, b = running.pop(pid)
        p.returncode = os.waitstatus_to_exitcode(status)
        if p.returncode != 0:
            for q, _ in running.values():
                q.kill()
            raise subprocess.CalledProcessError(p.returncode, p.args)
        b.cpu = ru.ru_utime + ru.ru_stime
        finished.append(b)


def summarise(res):
    n = len(res)
    k = sum(r["reached"] for r in res)
    p, lo, hi = wilson(k, n)
    dist = np.array([r["dist"] for r in res])
    ok = [r for r in res if r["reached"]]
    ratio = np.array([r["dist"] / r["shortest"] for r in ok]) if ok else np.array([np.nan])
    tot = dist.sum()
    path = sum(r["path_m"] for r in res)
    return {
        "n": n, "k": k, "p": p, "lo": lo, "hi": hi,
        "med": float(np.median(dist)), "p90": float(np.percentile(dist, 90)),
        "med_ok": float(np.median([r["dist"] for r in ok])) if ok else float("nan"),
        "ratio": float(np.median(ratio)),
        "updates": float(np.median([r["updates"] for r in res])),
        "eps": 100.0 * sum(r["eps_m"] for r in res) / tot if tot > 0 else float("nan"),
        "detour": 100.0 * sum(r["detour_m"] for r in res) / path if path > 0 else float("nan"),
    }


def fmt(v, nd=1):
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else "%.*f" % (nd, v)


def row(scenario, label, s):
    return ("| %s | %s | **%.1f** (%.1f-%.1f) | %s | %s | %s | %s | %s | %s |" %
            (scenario, label, 100 * s["p"], 100 * s["lo"], 100 * s["hi"], fmt(s["med"]),
             fmt(s["p90"]), fmt(s["ratio"], 2), fmt(s["updates"], 0), fmt(s["eps"]),
             fmt(s["detour"])))


HEAD = ("| scenario | strategy | success % (95% Wilson CI) | median travel m "
        "| p90 travel m | median ratio to shortest (successful) | median model updates "
        "| epsilon travel % | detour % |\n|---|---|---|---|---|---|---|---|---|")


def load_map(scen_file):
    """(occupancy image as float array, extent [x0, x1, y0, y1]) of a scenario's map."""
    mp = None
    d = os.path.dirname(scen_file)
    with open(scen_file) as f:
        for line in f:
            if line.startswith("map:"):
                mp = os.path.join(d, line.split(":", 1)[1].split("#")[0].strip())
    meta = {}
    with open(mp) as f:
        for line in f:
            line = line.split("#")[0]
            if ":" in line:
                k, v = line.split(":", 1)
                meta[k.strip()] = v.strip()
    res = float(meta["resolution"])
    ox, oy = [float(x) for x in meta["origin"].strip("[]").split(",")[:2]]
    with open(os.path.join(os.path.dirname(mp), meta["image"]), "rb") as f:
        data = f.read()
    # P5 header: magic, width, height, maxval, separated by whitespace and comments.
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    w, h = int(fields[1]), int(fields[2])
    img = np.frombuffer(data[pos + 1:pos + 1 + w * h], dtype=np.uint8).reshape(h, w)
    return img, [ox, ox + w * res, oy, oy + h * res]


def scenario_sources(scen_file):
    src, start = [], None
    with open(scen_file) as f:
        for line in f:
            s = line.strip()
            if s.startswith("position:"):
                src.append([float(x) for x in s.split("[")[1].split("]")[0].split(",")])
            if s.startswith("start:"):
                start = [float(x) for x in s.split("[")[1].split("]")[0].split(",")]
    return src, start


def region_of(scen, x, y, src, walls_at):
    regs = REGIONS.get(scen)
    if regs:
        def lab(px, py):
            for name, x0, y0, x1, y1 in regs:
                if x0 <= px <= x1 and y0 <= py <= y1:
                    return name
            return "outside"
        here, there = lab(x, y), lab(src[0], src[1])
        if here == there:
            return "source room"
        return "corridor" if here == "corridor" else "another room"
    wl = walls_at(x, y)
    return "0 walls" if wl == 0 else ("1 wall" if wl == 1 else "2+ walls")


def walls_lookup(field_tsv):
    a = np.loadtxt(field_tsv, skiprows=1, usecols=(0, 1, 2, 3))

    def f(x, y):
        i = np.argmin((a[:, 0] - x) ** 2 + (a[:, 1] - y) ** 2)
        return int(a[i, 2])
    return f


def single_run(args, scen_file, seed, out, strategy="meta", field=False):
    cmd = [args.bin, scen_file, "--seed", str(seed), "--out", out, "--strategy", strategy,
           "--model", model_of(strategy)]
    if field:
        cmd.append("--field")
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def make_variant(tmp, shadow, noise):
    """The default scenario with other shadowing / noise sigmas (absolute map path)."""
    src = scenario_path("default")
    out = []
    with open(src) as f:
        for line in f:
            s = line.strip()
            if s.startswith("map:"):
                line = "map: %s\n" % os.path.abspath(os.path.join("scenarios", s[4:].strip()))
            elif s.startswith("shadowing:"):
                line = ("  shadowing: {enabled: %s, sigma_db: %.1f, dcorr_m: 5.0}\n" %
                        ("true" if shadow > 0 else "false", max(shadow, 1.0)))
            elif s.startswith("noise:"):
                line = "  noise: {enabled: true, sigma_db: %.1f}\n" % noise
            out.append(line)
    p = os.path.join(tmp, "default-sh%g-n%g.yaml" % (shadow, noise))
    with open(p, "w") as f:
        f.writelines(out)
    return p


# ---- figures ---------------------------------------------------------------------------

def fig_trajectories(figdir, tmp, tags, scen, nseeds, first):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    img, ext = load_map(scenario_path(scen))
    src, start = scenario_sources(scenario_path(scen))
    out = []
    for st in STRATEGIES:
        d = os.path.join(tmp, tags[(scen, st)])
        npan = min(5, nseeds)
        fig, axs = plt.subplots(npan, 1, figsize=(8, 2.6 * npan), squeeze=False)
        for k, ax in enumerate(axs[:, 0]):
            sd = os.path.join(d, "seed-%d" % (first + k))
            ax.imshow(img, cmap="gray", extent=ext, origin="upper", vmin=0, vmax=255)
            tr = np.loadtxt(os.path.join(sd, "track.tsv"), skiprows=1, usecols=(1, 2))
            lg = read_tsv(os.path.join(sd, "log.tsv"))
            ax.plot(tr[:, 0], tr[:, 1], "-", color="tab:blue", lw=0.8)
            up = [(fnum(r["x_m"]), fnum(r["y_m"])) for r in lg if r["relearned"] == "1"]
            if up:
                u = np.array(up)
                ax.plot(u[:, 0], u[:, 1], "o", ms=3, mfc="none", color="tab:red",
                        label="model update")
            ep = [(fnum(r["x_m"]), fnum(r["y_m"])) for r in lg if r["kind"] in
                  ("epsilon", "tumble")]
            if ep:
                u = np.array(ep)
                ax.plot(u[:, 0], u[:, 1], "x", ms=3, color="tab:orange",
                        label="epsilon / tumble step")
            ax.plot(src[0][0], src[0][1], "*", ms=12, color="gold", mec="k", label="source")
            ax.plot(start[0], start[1], "s", ms=6, color="tab:green", label="start")
            summ = read_tsv(os.path.join(d, "runs.tsv"))[k]
            ax.set_title("%s, seed %d: %s after %.0f m, %s model updates" %
                         (st, first + k, summ["end"], fnum(summ["distance_travelled_m"]),
                          summ["model_updates"]), fontsize=9)
            ax.set_xlim(ext[0], ext[1])
            ax.set_ylim(ext[2], ext[3])
            if k == 0:
                ax.legend(fontsize=7, loc="upper left", ncol=4)
        fig.tight_layout()
        p = os.path.join(figdir, "seek_traj_%s.png" % st)
        fig.savefig(p + ".tmp.png", dpi=80)
        os.replace(p + ".tmp.png", p)
        plt.close(fig)
        out.append(p)
    return out


def fig_rssi(figdir, tmp, args, scen):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(len(STRATEGIES), 1, figsize=(8, 12), sharex=True)
    for ax, st in zip(axs, STRATEGIES):
        d = os.path.join(tmp, "rssi-%s" % st)
        single_run(args, scenario_path(scen), args.first_seed, d, st)
        a = np.loadtxt(os.path.join(d, "samples.tsv"), skiprows=1, usecols=(4, 5))
        ax.plot(a[:, 0], a[:, 1], ",", color="0.6", alpha=0.5)
        # Moving average over a sliding 1 m window of distance (odometry is monotonic).
        c = np.concatenate([[0.0], np.cumsum(a[:, 1])])
        xs = np.arange(0.5, a[-1, 0] - 0.5 + 1e-9, 0.1)
        lo = np.searchsorted(a[:, 0], xs - 0.5)
        hi = np.searchsorted(a[:, 0], xs + 0.5)
        ok = hi > lo
        ma = (c[hi[ok]] - c[lo[ok]]) / (hi[ok] - lo[ok])
        ax.plot(xs[ok], ma, "-", color="tab:blue", lw=1.2, label="1 m moving average")
        ax.set_ylabel("RSSI dBm")
        ax.set_title("%s, %s, seed %d" % (scen, st, args.first_seed), fontsize=9)
        ax.legend(fontsize=7, loc="lower right")
    axs[-1].set_xlabel("distance travelled, m")
    fig.tight_layout()
    p = os.path.join(figdir, "seek_rssi_vs_distance.png")
    fig.savefig(p + ".tmp.png", dpi=80)
    os.replace(p + ".tmp.png", p)
    plt.close(fig)
    return p


def fig_noise(figdir, sweep):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, key, lab in ((axs[0], "shadow", "shadowing sigma, dB (noise 4 dB)"),
                         (axs[1], "noise", "measurement noise sigma, dB (shadowing 4 dB)")):
        for st in STRATEGIES:
            pts = sorted(sweep[key][st].items())
            xs = [x for x, _ in pts]
            ps = np.array([100 * s["p"] for _, s in pts])
            lo = np.array([100 * s["lo"] for _, s in pts])
            hi = np.array([100 * s["hi"] for _, s in pts])
            # Wilson bounds can sit a rounding error inside p at 0 % and 100 %.
            ax.errorbar(xs, ps, yerr=[np.maximum(ps - lo, 0.0), np.maximum(hi - ps, 0.0)],
                        marker="o", capsize=3, label=st)
        ax.set_xlabel(lab)
        ax.set_xticks([0, 2, 4, 8])
        ax.grid(alpha=0.3)
    axs[0].set_ylabel("success rate %, 95% Wilson CI")
    axs[0].legend(fontsize=8)
    fig.suptitle("default office scenario")
    fig.tight_layout()
    p = os.path.join(figdir, "seek_success_vs_noise.png")
    fig.savefig(p + ".tmp.png", dpi=80)
    os.replace(p + ".tmp.png", p)
    plt.close(fig)
    return p


# ---- the benchmark ---------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="build/bin/rfseek-sim", help="rfseek-sim to run")
    ap.add_argument("--seeds", type=int, default=200, help="seeds per strategy x scenario")
    ap.add_argument("--first-seed", type=int, default=1001,
                    help="seeds FIRST..FIRST+N-1 (1..500 are the tuning draws: report on others)")
    ap.add_argument("--noise-seeds", type=int, default=None, help="seeds per noise point")
    ap.add_argument("--model-seeds", type=int, default=None, help="seeds per model x scenario")
    ap.add_argument("--slow-model-seeds", type=int, default=30, help="seeds for mlp and knn")
    ap.add_argument("--jobs", type=int, default=2, help="worker processes (both cores: 2)")
    ap.add_argument("--results", default="docs/RESULTS.md", help="markdown output")
    ap.add_argument("--figures", default="docs/figures", help="figure directory")
    ap.add_argument("--quiet", action="store_true", help="no per-batch progress bars")
    ap.add_argument("--smoke", action="store_true",
                    help="2 seeds, default scenario only, output to a temporary directory; "
                         "prints PASS/FAIL bench-seek-smoke")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    args = ap.parse_args()
    if not os.access(args.bin, os.X_OK):
        sys.stderr.write("bench_seek.py: %s: not an executable (build it first)\n" % args.bin)
        return 1
    if args.seeds < 1 or args.jobs < 1 or args.first_seed < 1:
        sys.stderr.write("bench_seek.py: --seeds, --first-seed and --jobs must be at least 1\n")
        return 1
    scenarios = ["default"] if args.smoke else SCENARIOS
    if args.smoke:
        args.seeds, args.slow_model_seeds, args.quiet = 2, 0, True
    ns = args.noise_seeds or args.seeds
    ms = args.model_seeds or args.seeds
    tmp = tempfile.mkdtemp(prefix="bench_seek.")
    smoke_dir = tempfile.mkdtemp(prefix="bench_seek_out.") if args.smoke else None
    results = os.path.join(smoke_dir, "RESULTS.md") if args.smoke else args.results
    figdir = os.path.join(smoke_dir, "figures") if args.smoke else args.figures
    os.makedirs(figdir, exist_ok=True)
    t_all = time.time()
    try:
        sweep_b, var_b, model_b = plan_batches(args, tmp, scenarios, ns, ms)
        tags = {k: b.tag for k, b in sweep_b.items()}
        variants = [(0, 4), (8, 4), (4, 2), (4, 8)]
        batches = list(sweep_b.values()) + list(var_b.values()) + list(model_b.values())
        log("%d batches, %d runs, %d at a time" % (len(batches), sum(b.seeds for b in batches),
                                                   args.jobs))
        run_all(args, tmp, batches)
        table = {k: b.res for k, b in sweep_b.items()}
        sweep = {"shadow": {st: {} for st in STRATEGIES}, "noise": {st: {} for st in STRATEGIES}}
        for st in STRATEGIES:
            for sh, no in [(4, 4)] + variants:
                b = var_b.get((st, sh, no))
                s = summarise(b.res if b else table[("default", st)])
                if no == 4:
                    sweep["shadow"][st][sh] = s
                if sh == 4:
                    sweep["noise"][st][no] = s
        mtab = {}
        for sc in scenarios:
            for m in MODELS:
                b = model_b.get((sc, m))
                n = args.slow_model_seeds if m in SLOW_MODELS else ms
                mtab[(sc, m)] = (summarise(b.res) if b else
                                 summarise(table[(sc, "meta")]) if n > 0 else None)
        cpu = {sec: sum(b.cpu for b in batches if b.section == sec) for sec in ("sweep", "noise")}
        t_model = {m: sum(b.cpu for b in model_b.values() if b.model == m) for m in MODELS}
        t_run = time.time() - t_all
        # 4. figures
        figs = fig_trajectories(figdir, tmp, tags, "default", args.seeds, args.first_seed)
        figs.append(fig_rssi(figdir, tmp, args, "default"))
        figs.append(fig_noise(figdir, sweep))
        # failure analysis needs the walls for the unlabelled floors
        walls = {}
        for sc in scenarios:
            if sc not in REGIONS:
                d = os.path.join(tmp, "field-%s" % sc)
                single_run(args, scenario_path(sc), args.first_seed, d, "meta", field=True)
                walls[sc] = walls_lookup(os.path.join(d, "field.tsv"))
        t_total = time.time() - t_all
        times = dict(sweep=cpu["sweep"], noise=cpu["noise"], models=sum(t_model.values()),
                     model=t_model, runs=t_run, total=t_total)
        log("CPU s: strategy sweep %.0f, noise sweep %.0f, models %.0f (%s); wall s: batches "
            "%.0f, whole %.0f" % (times["sweep"], times["noise"], times["models"],
                                  ", ".join("%s %.0f" % kv for kv in t_model.items()), t_run,
                                  t_total))
        write_results(args, results, scenarios, table, sweep, mtab, walls, figs, times, ns, ms)
    except BaseException:
        if smoke_dir:
            shutil.rmtree(smoke_dir, ignore_errors=True)
        raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if args.smoke:
        with open(results) as f:
            text = f.read()
        ok = all(("| %s |" % st) in text for st in STRATEGIES) and all(
            os.path.getsize(p) > 10000 for p in glob.glob(os.path.join(figdir, "*.png"))) and \
            len(glob.glob(os.path.join(figdir, "*.png"))) == len(STRATEGIES) + 2
        shutil.rmtree(smoke_dir, ignore_errors=True)
        print("%s bench-seek-smoke" % ("PASS" if ok else "FAIL"))
        return 0 if ok else 1
    log("wrote %s (%.0f s)" % (results, time.time() - t_all))
    return 0


HAND = ("<!-- hand-written: begin -->", "<!-- hand-written: end -->")
PATHLOSS = (bench_pathloss_seek.BEGIN, bench_pathloss_seek.END)
BRIDGE = ("<!-- bench_bridge: begin -->", "<!-- bench_bridge: end -->")


def kept(old, marks):
    """The text of old from marks[0] through marks[1], or ""."""
    b, e = old.find(marks[0]), old.find(marks[1])
    return old[b:e + len(marks[1])] if 0 <= b < e else ""


def short(s):
    """One compact cell: success % (Wilson interval), median ratio over the successful."""
    return "**%.1f** (%.1f-%.1f), %s" % (100 * s["p"], 100 * s["lo"], 100 * s["hi"],
                                         fmt(s["ratio"], 2))


def sweep_tables(sweep):
    """The shadowing and noise sweep, one row per strategy, one column per level."""
    L = []
    for key, lab in (("shadow", "shadowing (noise 4 dB)"), ("noise", "noise (shadowing 4 dB)")):
        levels = sorted(next(iter(sweep[key].values())).keys())
        L.append("| strategy, %s | " % lab + " | ".join("%g dB" % x for x in levels) + " |")
        L.append("|---" * (len(levels) + 1) + "|")
        for st, byx in sweep[key].items():
            L.append("| %s | " % st + " | ".join(short(byx[x]) for x in levels) + " |")
        L.append("")
    return L


def model_table(mtab, scenarios, counts):
    """Internal models under meta: one row per model, one column per scenario."""
    L = ["| model (seeds) | " + " | ".join(scenarios) + " |",
         "|---" * (len(scenarios) + 1) + "|"]
    for m in MODELS:
        if all(mtab[(sc, m)] is None for sc in scenarios):
            continue
        L.append("| %s (%d) | " % (m, counts[m]) + " | ".join(
            short(mtab[(sc, m)]) if mtab[(sc, m)] else "not run" for sc in scenarios) + " |")
    L.append("")
    return L


def write_results(args, path, scenarios, table, sweep, mtab, walls, figs, times, ns, ms):
    old = open(path).read() if os.path.exists(path) else ""
    L = []
    A = L.append
    A("# Results\n")
    A("Written by `make bench-seek` (`%s scripts/bench_seek.py --seeds %d --jobs %d "
      "--slow-model-seeds %d%s%s`) at commit %s: `rfseek-sim`, in-process fixed-point "
      "core. Seeds %d.. of every scenario (1..500 are the tuning draws), the same seeds for "
      "every strategy, so rows are paired. Do not edit the tables by hand: re-run the "
      "benchmark."
      % (sys.executable, args.seeds, args.jobs, args.slow_model_seeds,
         " --noise-seeds %d" % ns if ns != args.seeds else "",
         " --model-seeds %d" % ms if ms != args.seeds else "", bench_pathloss_seek.commit(),
         args.first_seed))
    A("")
    A("**Definitions.** *Success*: within 1.5 m of the source before 150 m of travel (and "
      "900 s). *Travel*: path length of the true robot position. *Ratio*: travel / "
      "shortest path from the start around walls (0.25 m clearance), median over the "
      "successful runs. *Model updates*: decisions that relearnt the model. *Epsilon "
      "travel %*: travel during epsilon steps over all travel. *Detour %*: planned path "
      "length beyond the straight line to the goal, over all planned path length. Cells "
      "of the compact tables: success % (95 % Wilson interval), ratio.\n")
    A("**Strategies** (docs/STRATEGIES.md): `meta` is the paper's, with its parameters and "
      "local ridge; `meta-global`, `fd-gradient`, `plane-gradient` and `chemotaxis` are "
      "baselines with the same sensors, step, legality and planner; `meta-path`, with the "
      "map-aware path-loss model (docs/PATHLOSS.md), is the improvement.\n")
    hand = kept(old, HAND)
    A(hand + "\n" if hand else "%s\n## Summary\n\n(to be written)\n\n%s\n" % HAND)
    A("## Every strategy on every shipped scenario (shadowing and noise as the scenario "
      "file says; default: 4 dB / 4 dB; %d seeds each)\n" % args.seeds)
    A(HEAD)
    for sc in scenarios:
        for st in STRATEGIES:
            A(row(sc, st if st not in STRAT_MODEL else "%s + %s" % (st, STRAT_MODEL[st]),
                  summarise(table[(sc, st)])))
    A("")
    # where meta does not win
    A("### Where meta does not win\n")
    notes = []
    for sc in scenarios:
        m = summarise(table[(sc, "meta")])
        for st in BASELINES:
            o = summarise(table[(sc, st)])
            if o["p"] >= m["p"]:
                sig = " (CIs overlap)" if o["lo"] <= m["hi"] else " (CIs do not overlap)"
                notes.append("- %s: `%s` %.1f %% >= `meta` %.1f %%%s" %
                             (sc, st, 100 * o["p"], 100 * m["p"], sig))
    A("\n".join(notes) if notes else "- meta has a higher success rate than every baseline "
      "(meta-global, fd-gradient, plane-gradient, chemotaxis) in every scenario.")
    A("")
    A("## Default scenario at other shadowing and noise levels\n")
    A("Variants of scenarios/default.yaml (shadowing correlation 5 m; 0 dB: off), %d "
      "seeds each, every strategy with its model as above.\n" % ns)
    L.extend(sweep_tables(sweep))
    A("![success vs shadowing and noise](figures/seek_success_vs_noise.png)\n")
    A("## Failure analysis\n")
    A("Where failed runs ended and their final straight-line distance to the source. "
      "Regions: office: corridor y 5..7 m, 5 m rooms either side; lshape: the corridors "
      "and rooms of scripts/make_maps.py; open: one hall; real floors (no room labels): "
      "the walls the straight line to the source crosses. Strategies without a failed run "
      "are left out.\n")
    A("| scenario | strategy | failed | end region counts | median final distance m | "
      "min final distance m |\n|---|---|---|---|---|---|")
    for sc in scenarios:
        src, _ = scenario_sources(scenario_path(sc))
        for st in STRATEGIES:
            fails = [r for r in table[(sc, st)] if not r["reached"]]
            if not fails:
                continue
            cnt = {}
            for r in fails:
                k = region_of(sc, r["fx"], r["fy"], src[0], walls.get(sc))
                cnt[k] = cnt.get(k, 0) + 1
            fd = [r["final_d"] for r in fails]
            A("| %s | %s | %d | %s | %.1f | %.1f |" %
              (sc, st, len(fails), ", ".join("%s %d" % kv for kv in sorted(cnt.items())),
               float(np.median(fd)), float(np.min(fd))))
    A("")
    bridge = kept(old, BRIDGE)
    if bridge:
        A(bridge + "\n")
    A("## Internal models (strategy meta)\n")
    A("Registry models (common/rfs_models.h, `--model NAME`) under the paper's `meta`; mlp "
      "and knn on fewer seeds (1-4 s of CPU a run), so wider intervals. The ridge row is "
      "the meta runs above.\n")
    counts = {m: (args.slow_model_seeds if m in SLOW_MODELS else ms) for m in MODELS}
    counts["ridge"] = args.seeds if ms == args.seeds else ms
    L.extend(model_table(mtab, scenarios, counts))
    pl = kept(old, PATHLOSS)
    if pl:
        A(pl + "\n")
    A("## Figures\n")
    A("Seeds 1-5 of each strategy on the default office (red circles: model updates; "
      "orange crosses: epsilon or tumble steps), then the RSSI of seed 1 of each against "
      "distance travelled (every packet grey, 1 m moving average blue).\n")
    for st in STRATEGIES:
        A("![%s](figures/seek_traj_%s.png)" % (st, st))
    A("![rssi](figures/seek_rssi_vs_distance.png)\n")
    A("## Wall time of the benchmark\n")
    A("On this machine (2 cores), `--jobs %d` (every batch in one pool, longest first), CPU "
      "time: strategy sweep (%d scenarios x %d strategies x %d seeds) %.0f s; noise sweep "
      "%.0f s; models %.0f s (%s). Wall: batches %.0f s, whole benchmark with figures %.0f s."
      % (args.jobs, len(scenarios), len(STRATEGIES), args.seeds, times["sweep"],
         times["noise"], times["models"],
         ", ".join("%s %.0f" % (m, t) for m, t in times["model"].items() if t >= 0.5),
         times["runs"], times["total"]))
    A("")
    # Sections other benches write (scripts/bench_drive.py, scripts/bench_general.py), kept.
    for name in re.findall(r"<!-- ([\w-]+): begin -->", old):
        marks = ("<!-- %s: begin -->" % name, "<!-- %s: end -->" % name)
        if marks not in (HAND, PATHLOSS, BRIDGE) and kept(old, marks):
            A(kept(old, marks) + "\n")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(L))
    os.replace(tmp, path)


if __name__ == "__main__":
    sys.exit(main())
