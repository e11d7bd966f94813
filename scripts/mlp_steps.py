#!/usr/bin/env python3
"""Why the paper's MLP seeks worse than the local ridge (docs/MODELS.md, "Seeking with it"):
greedy steps judged on the simulator's mean field, near the source and far from it, for
meta + mlp and meta + ridge on the same seeds; then scikit-learn's MLPRegressor with the
paper's settings (100 logistic units, SGD at 0.01 with momentum 0.1, one sample a step,
standardised data) on one failed mission's samples at some of its decisions, 3 epochs and
30, against the core's own MLP at the same decisions.

    /usr/bin/python3 scripts/mlp_steps.py [--sim build/bin/rfseek-sim] [--seeds 1001..1012]
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import warnings

import numpy as np
from sklearn.neural_network import MLPRegressor

SCENARIO = "scenarios/default.yaml"
SOURCE = (27.5, 10.0)  # the default office's node
NEAR_M = 6.0


def run(sim, model, seed, out):
    subprocess.run([sim, SCENARIO, "--strategy", "meta", "--model", model, "--seed", str(seed),
                    "--field", "--out", out], check=True, capture_output=True)


def field_of(d):
    """The run's mean field (path loss, walls, shadowing) on its 0.1 m grid, as a lookup."""
    f = np.loadtxt(os.path.join(d, "field.tsv"), skiprows=1, usecols=(0, 1, 3))
    i, j = np.round((f[:, 0] - 0.05) / 0.1).astype(int), np.round((f[:, 1] - 0.05) / 0.1).astype(int)
    g = np.full((i.max() + 2, j.max() + 2), np.nan)
    g[i, j] = f[:, 2]
    return lambda x, y: g[int(x / 0.1), int(y / 0.1)]


def steps(d):
    """(near, gain dB) of every greedy step: the mean field at its goal minus at its start."""
    f = field_of(d)
    out = []
    for r in csv.DictReader(open(os.path.join(d, "log.tsv")), delimiter="\t"):
        if r["kind"] != "greedy":
            continue
        x, y = float(r["x_m"]), float(r["y_m"])
        v = f(float(r["goal_x_m"]), float(r["goal_y_m"])) - f(x, y)
        if not np.isnan(v):
            out.append((np.hypot(x - SOURCE[0], y - SOURCE[1]) < NEAR_M, v))
    return out


def sk_fit(x, y, epochs):
    mx, sx, my, sy = x.mean(0), x.std(0), y.mean(), y.std()
    m = MLPRegressor(hidden_layer_sizes=(100,), activation="logistic", solver="sgd",
                     learning_rate_init=0.01, momentum=0.1, nesterovs_momentum=False,
                     batch_size=1, max_iter=epochs, shuffle=True, alpha=0.0, tol=0.0,
                     n_iter_no_change=10 ** 6, random_state=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m.fit((x - mx) / sx, (y - my) / sy)
    return lambda z: m.predict((z - mx) / sx) * sy + my


def sklearn_check(d, picks):
    s = np.loadtxt(os.path.join(d, "samples.tsv"), skiprows=1, usecols=(0, 2, 3, 5))
    grid = np.loadtxt(os.path.join(d, "field.tsv"), skiprows=1, usecols=(0, 1))
    log = list(csv.DictReader(open(os.path.join(d, "log.tsv")), delimiter="\t"))
    rng = np.random.default_rng(1)
    for k in picks:
        if k >= len(log):
            continue
        r = log[k]
        sel = s[s[:, 0] <= float(r["t_s"])]
        if len(sel) > 10000:  # the store's capacity
            sel = sel[np.sort(rng.choice(len(sel), 10000, replace=False))]
        ours = np.hypot(float(r["max_x_m"]) - SOURCE[0], float(r["max_y_m"]) - SOURCE[1])
        cells = [f"decision {k}: {len(sel)} samples; the core's MLP maximum {ours:.1f} m from the source"]
        for ep in (3, 30):
            p = sk_fit(sel[:, 1:3], sel[:, 3], ep)(grid)
            i = int(np.argmax(p))
            cells.append(f"scikit-learn {ep} epochs {np.hypot(grid[i, 0] - SOURCE[0], grid[i, 1] - SOURCE[1]):.1f} m")
        print("; ".join(cells), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sim", default="build/bin/rfseek-sim")
    ap.add_argument("--seeds", default="1001..1012")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    m = re.fullmatch(r"(\d+)\.\.(\d+)", a.seeds)
    if m is None or int(m.group(1)) > int(m.group(2)):
        sys.exit(f"mlp_steps: --seeds: '{a.seeds}' is not A..B with A <= B")
    if not os.access(a.sim, os.X_OK):
        sys.exit(f"mlp_steps: --sim: {a.sim}: not an executable")
    lo, hi = int(m.group(1)), int(m.group(2))
    tmp = tempfile.mkdtemp(prefix="mlp_steps.")
    gains = {}
    failed = None
    for seed in range(lo, hi + 1):
        for model in ("mlp", "ridge"):
            d = os.path.join(tmp, f"{model}-{seed}")
            run(a.sim, model, seed, d)
            for near, v in steps(d):
                gains.setdefault((model, near), []).append(v)
            reached = json.load(open(os.path.join(d, "summary.json")))["reached"]
            if model == "mlp" and not reached and failed is None:
                failed = d
    print(f"greedy steps, seeds {a.seeds}: mean-field gain median dB, share improving")
    for model in ("mlp", "ridge"):
        for near in (False, True):
            g = np.array(gains.get((model, near), [np.nan]))
            where = f"within {NEAR_M:.0f} m" if near else "farther"
            print(f"  {model:5s} {where:11s} {len(g):4d} steps  {np.median(g):+.2f} dB  {100 * np.mean(g > 0):.0f} %")
    if failed is not None:
        print(f"scikit-learn on a failed mission's samples ({os.path.basename(failed)}):")
        sklearn_check(failed, (10, 30, 60))


if __name__ == "__main__":
    sys.exit(main())
