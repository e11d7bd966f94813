#!/usr/bin/env python3
"""Bounds on bridging (docs/STRATEGIES.md, "Bridging: what limits it"): for each seed, one
meta-path + pathloss run of a bridging scenario with its fields dumped, and where three
references would settle against the simulator's best point of the true f:

  pathloss  the best point of f on the path-loss fields of the true parameters (the
            scenario's P0, n = 3, W a wall, the simulator's wall counts) without shadowing:
            a perfect per-node fit that knows nothing of the shadowing
  fits      the same with the run's final per-node fits (summary.json pred_sources: the
            fitted position, P0, n and W; the walls still counted to the true node)
  track     the best true f within 1 m of the robot's track: the best a seeker could
            choose among the places it has been

    /usr/bin/python3 scripts/bridge_bounds.py SCENARIO A..B [--sim build/bin/rfseek-sim]
                                              [--jobs 2]

Prints one line a seed and a summary (within 3 m of the best point, median and p90
shortfall f(best) - f(point), dB). Fields come from rfseek-sim --field on its field grid,
so a reference point can lie a grid step from where the simulator's best is; a shortfall
can then be a little below 0.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.spatial import cKDTree

REF_LOSS_DB, EXPONENT = 39.6, 3.0  # docs/SIMULATOR.md, the radio's defaults


def f_of(r1, r2):
    return -np.abs(r1 - r2) - np.abs(r1 + r2)


def one(sim, scenario, seed, wall_db):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "o")
        r = subprocess.run([sim, scenario, "--seed", str(seed), "--field", "--strategy",
                            "meta-path", "--model", "pathloss", "--out", out],
                           capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"bridge_bounds: seed {seed}: {r.stderr.strip()}")
        with open(os.path.join(out, "summary.json")) as fh:
            s = json.load(fh)
        a = np.loadtxt(os.path.join(out, "field.tsv"), skiprows=1, usecols=(0, 1, 2, 3))
        b = np.loadtxt(os.path.join(out, "field1.tsv"), skiprows=1, usecols=(0, 1, 2, 3))
        track = np.loadtxt(os.path.join(out, "track.tsv"), skiprows=1, usecols=(1, 2))
    tx = 20.0  # the bridging scenarios' nodes
    f = f_of(a[:, 3], b[:, 3])

    def pl(fld, src, p0, n, w):
        d = np.maximum(np.hypot(fld[:, 0] - src[0], fld[:, 1] - src[1]), 1.0)
        return p0 - 10.0 * n * np.log10(d) - w * fld[:, 2]

    bx, by, bf = s["best_x_m"], s["best_y_m"], s["best_f_db"]

    def at(i):
        return float(np.hypot(a[i, 0] - bx, a[i, 1] - by)), float(bf - f[i])

    src, p0 = s["sources"], tx - REF_LOSS_DB
    res = {"seed": seed, "run": (s["settle_error_m"], bf - s["settle_f_db"]),
           "pathloss": at(np.argmax(f_of(pl(a, src[0], p0, EXPONENT, wall_db),
                                         pl(b, src[1], p0, EXPONENT, wall_db))))}
    fits = s.get("pred_sources")
    if fits:
        g = f_of(pl(a, fits[0][:2], fits[0][2], fits[0][3], fits[0][4]),
                 pl(b, fits[1][:2], fits[1][2], fits[1][3], fits[1][4]))
        res["fits"] = at(np.argmax(g))
    near = cKDTree(track).query(a[:, :2])[0] < 1.0
    res["track"] = at(np.flatnonzero(near)[np.argmax(f[near])])
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("seeds")
    ap.add_argument("--sim", default="build/bin/rfseek-sim")
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args()
    m = re.fullmatch(r"(\d+)\.\.(\d+)", a.seeds)
    if not m:
        sys.exit("bridge_bounds: seeds: expected A..B")
    if not os.access(a.sim, os.X_OK):
        sys.exit(f"bridge_bounds: --sim: {a.sim}: not an executable (make all)")
    if not os.path.isfile(a.scenario):
        sys.exit(f"bridge_bounds: {a.scenario}: no such scenario file")
    with open(a.scenario) as fh:
        w = re.search(r"db_per_wall:\s*([0-9.]+)", fh.read())
    wall_db = float(w.group(1)) if w else 5.0  # docs/SIMULATOR.md's default
    seeds = range(int(m.group(1)), int(m.group(2)) + 1)
    with ThreadPoolExecutor(max(1, a.jobs)) as ex:
        rows = list(ex.map(lambda sd: one(a.sim, a.scenario, sd, wall_db), seeds))
    keys = ["run", "pathloss", "fits", "track"]
    for r in rows:
        print(r["seed"], "  ".join(f"{k} {r[k][0]:.1f} m {r[k][1]:.1f} dB" for k in keys if k in r))
    for k in keys:
        v = np.array([r[k] for r in rows if k in r])
        if len(v):
            print(f"{k}: within 3 m {int((v[:, 0] <= 3.0).sum())} of {len(v)}, shortfall "
                  f"median {np.median(v[:, 1]):.1f} dB, p90 {np.percentile(v[:, 1], 90):.1f} dB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
