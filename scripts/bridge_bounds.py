#!/usr/bin/env python3
"""Bounds on bridging (docs/STRATEGIES.md, "Bridging: one fit per node"): for each seed, one
meta-path + pathloss run of a bridging scenario with its fields dumped, and where four
references would settle against the simulator's best point of the true f:

  pathloss  the best point of f on the path-loss fields of the true parameters (the
            scenario's P0, n = 3, W a wall, the simulator's wall counts) without shadowing:
            a perfect per-node fit that knows nothing of the shadowing
  fits      the same with the run's final per-node fits (summary.json pred_sources: the
            fitted position, P0, n and W; the walls still counted to the true node)
  track     the best true f within 1 m of the robot's track: the best a seeker could
            choose among the places it has been
  tolerance the legal point, connected to the best one, whose worst true f within 0.15 m
            (goal tolerance 0.1 m, pose noise about 5 cm) is highest: the best place a
            robot can be sure to stand on

Each seed's line also gives how far the best point stands above its own worst f within
0.15 m (*narrow*), the wall counts there to each node and the fewest among those
neighbours, and the run's end against the tolerance point (distance; shortfall of the
worst f within 0.15 m).

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
from scipy import ndimage
from scipy.spatial import cKDTree

REF_LOSS_DB, EXPONENT = 39.6, 3.0  # docs/SIMULATOR.md, the radio's defaults
TOL_M, CLEARANCE_M = 0.15, 0.25  # where a settled robot stands; sim.clearance_m


def f_of(r1, r2):
    return -np.abs(r1 - r2) - np.abs(r1 + r2)


def disc(r, step):
    """The grid offsets within r (metres) of a grid of this step, as a footprint."""
    k = int(np.floor(r / step + 1e-9))
    o = np.arange(-k, k + 1)
    return np.add.outer(o ** 2, o ** 2) <= (r / step) ** 2 + 1e-9


def tolerant(xy, f, best, tol=TOL_M, clearance=CLEARANCE_M):
    """On a field's points xy (a regular grid) with values f: each point's worst f within
    tol, and the index of the legal point (its whole clearance disc on the grid), in the
    4-connected legal part that holds the legal point nearest best, whose worst is highest."""
    step = np.min(np.diff(np.unique(xy[:, 0])))
    ix = np.rint((xy[:, 0] - xy[:, 0].min()) / step).astype(int)
    iy = np.rint((xy[:, 1] - xy[:, 1].min()) / step).astype(int)
    grid = np.full((iy.max() + 1, ix.max() + 1), np.inf)
    grid[iy, ix] = f
    worst = ndimage.minimum_filter(grid, footprint=disc(tol, step), mode="constant",
                                   cval=np.inf)[iy, ix]
    legal = ndimage.binary_erosion(np.isfinite(grid), structure=disc(clearance, step))
    label = ndimage.label(legal)[0][iy, ix]
    near = np.flatnonzero(label > 0)
    part = label[near[np.argmin(np.hypot(*(xy[near] - best).T))]]
    ok = np.flatnonzero(label == part)
    return worst, int(ok[np.argmax(worst[ok])])


def one(sim, scenario, seed, wall_db):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "o")
        r = subprocess.run([sim, scenario, "--seed", str(seed), "--field", "--strategy",
                            "meta-path", "--model", "pathloss", "--out", out],
                           capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"bridge_bounds: seed {seed}: {r.stderr.strip()}")
        return analyse(out, seed, wall_db)


def analyse(out, seed, wall_db):
    """The references of one run's output directory (summary.json, both fields, track)."""
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
    worst, t = tolerant(a[:, :2], f, (bx, by))
    res["tolerance"] = at(t)
    tree = cKDTree(a[:, :2])
    # the field's points are cell centres, the best point's grid the cells' corners
    cell = tree.query_ball_point((bx, by), 0.75 * (np.min(np.diff(np.unique(a[:, 0])))))
    b0 = cell[int(np.argmax(f[cell]))] if cell else tree.query((bx, by))[1]
    ring = [k for k in tree.query_ball_point(a[b0, :2], TOL_M) if k != b0]
    res["narrow"] = float(f[b0] - worst[b0])
    res["walls"] = [(int(fl[b0, 2]), int(fl[ring, 2].min())) for fl in (a, b)]
    e = tree.query((s["final_x_m"], s["final_y_m"]))[1]
    res["end"] = (float(np.hypot(*(a[e, :2] - a[t, :2]))), float(worst[t] - worst[e]))
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("seeds")
    ap.add_argument("--sim", default="build/bin/rfseek-sim")
    ap.add_argument("--jobs", type=int, default=2)
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
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
    keys = ["run", "pathloss", "fits", "track", "tolerance"]
    for r in rows:
        print(r["seed"], "  ".join(f"{k} {r[k][0]:.1f} m {r[k][1]:.1f} dB" for k in keys if k in r),
              f" narrow {r['narrow']:.1f} dB, walls " +
              ", ".join(f"{w} ({m} near)" for w, m in r["walls"]) +
              f"; end to tolerance {r['end'][0]:.1f} m {r['end'][1]:.1f} dB")
    for k in keys:
        v = np.array([r[k] for r in rows if k in r])
        if len(v):
            print(f"{k}: within 3 m {int((v[:, 0] <= 3.0).sum())} of {len(v)}, shortfall "
                  f"median {np.median(v[:, 1]):.1f} dB, p90 {np.percentile(v[:, 1], 90):.1f} dB")
    narrow = np.array([r["narrow"] for r in rows])
    end = np.array([r["end"] for r in rows])
    print(f"narrow: the best point above its worst f within {TOL_M} m: median "
          f"{np.median(narrow):.1f} dB, p90 {np.percentile(narrow, 90):.1f} dB, by over 3 dB "
          f"in {int((narrow > 3.0).sum())} of {len(rows)}")
    print(f"end to tolerance: within 3 m {int((end[:, 0] <= 3.0).sum())} of {len(end)}, "
          f"shortfall (worst within {TOL_M} m) median {np.median(end[:, 1]):.1f} dB, p90 "
          f"{np.percentile(end[:, 1], 90):.1f} dB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
