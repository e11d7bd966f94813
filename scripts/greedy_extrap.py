#!/usr/bin/python3
"""Greedy decisions against their estimate's distance from the data (path-loss diagnostic).

    scripts/greedy_extrap.py DIR [DIR ...] [--wrong M] [--tsv FILE]

Each DIR is an `rfseek-sim --out` batch (place-K-seed-N/ or seed-N/ subdirectories with
summary.json, log.tsv, track.tsv; --model pathloss). For every greedy decision with a
model (log.tsv kind "greedy", no "no_model") it takes the estimate (max_x_m, max_y_m) and
  err   its distance from the true source (summary.json "sources"[0]),
  data  its distance from the nearest place the robot had been (track.tsv true x_m, y_m,
        rows up to the decision's time): how far the fit extrapolates,
  robot its distance from the robot at the decision,
  leg   the travel until the next decision (or the run's end),
and the fit's P0, n, W and spread area (log.tsv est_*; in the TSV only).
Prints, per DIR and over all: for data-distance thresholds, the decisions beyond each,
the fraction of them with err >= M (--wrong, default 15 m), the share of all wrong
decisions they hold (recall), and the travel their legs carried (of all greedy travel and
of the wrong legs' travel); the same for robot distance (the naive discriminator); a
data x robot table of wrong fractions; and the ROC AUC of data, robot and the fit's spread
area for err >= M. --tsv FILE writes one row per decision.
"""
import json
import math
import os
import sys

import numpy as np

THRESH = (5, 10, 15, 20, 30, 40)


def read_tsv(path):
    with open(path) as f:
        head = f.readline().rstrip("\n").split("\t")
        rows = [line.rstrip("\n").split("\t") for line in f if line.strip()]
    return head, rows


def run_rows(rundir):
    """One dict per greedy decision of a run, or [] without the files."""
    try:
        with open(os.path.join(rundir, "summary.json")) as f:
            s = json.load(f)
        lh, lr = read_tsv(os.path.join(rundir, "log.tsv"))
        th, tr = read_tsv(os.path.join(rundir, "track.tsv"))
    except (OSError, ValueError):
        return []
    sx, sy = s["sources"][0]
    li = {k: i for i, k in enumerate(lh)}
    ti = {k: i for i, k in enumerate(th)}
    tt = np.array([float(r[ti["t_s"]]) for r in tr])
    tx = np.array([float(r[ti["x_m"]]) for r in tr])
    ty = np.array([float(r[ti["y_m"]]) for r in tr])
    trav = [float(r[li["travelled_m"]]) for r in lr] + [s["distance_travelled_m"]]
    out = []
    for k, r in enumerate(lr):
        if r[li["kind"]] != "greedy" or "no_model" in r[li["reason"]]:
            continue
        t = float(r[li["t_s"]])
        mx, my = float(r[li["max_x_m"]]), float(r[li["max_y_m"]])
        n = int(np.searchsorted(tt, t, side="right"))
        if n == 0:
            continue
        data = float(np.min(np.hypot(tx[:n] - mx, ty[:n] - my)))
        out.append({
            "run": os.path.basename(rundir), "reached": bool(s["reached"]), "end": s["end"],
            "t": t, "err": math.hypot(mx - sx, my - sy), "data": data,
            "robot": math.hypot(mx - float(r[li["x_m"]]), my - float(r[li["y_m"]])),
            "leg": max(0.0, trav[k + 1] - trav[k]),
            "total": s["distance_travelled_m"],
            "shortest": s["shortest_path_m"],
            "p0": float(r[li["est_p0"]]), "n": float(r[li["est_n"]]),
            "w": float(r[li["est_w_db"]]), "area": float(r[li["est_area_m2"]]),
        })
    return out


def batch_rows(d):
    rows = []
    for name in sorted(os.listdir(d)):
        p = os.path.join(d, name)
        if os.path.isdir(p):
            rows += run_rows(p)
    return rows


def table(rows, key, wrong_m, label):
    err = np.array([r["err"] for r in rows])
    v = np.array([r[key] for r in rows])
    leg = np.array([r["leg"] for r in rows])
    wrong = err >= wrong_m
    print("  %-6s > D  decisions  wrong%%  recall%%  travel%%(all greedy)  travel%%(wrong legs)"
          % label)
    for d in (0,) + THRESH:
        sel = v > d
        n = int(sel.sum())
        fw = 100.0 * wrong[sel].mean() if n else float("nan")
        rec = 100.0 * (wrong & sel).sum() / max(1, wrong.sum())
        tr = 100.0 * leg[sel].sum() / max(1e-9, leg.sum())
        trw = 100.0 * leg[sel & wrong].sum() / max(1e-9, leg[wrong].sum())
        print("  %4d m     %9d  %6.1f  %7.1f  %19.1f  %19.1f" % (d, n, fw, rec, tr, trw))


def cross(rows, wrong_m):
    err = np.array([r["err"] for r in rows])
    data = np.array([r["data"] for r in rows])
    rob = np.array([r["robot"] for r in rows])
    edges = (0, 10, 20, 30, 1e9)
    print("  wrong % (n) by data distance (rows) x robot distance (columns)")
    print("  %-10s" % "" + "".join("%14s" % ("%g-%s" % (edges[j], "" if edges[j + 1] > 1e8
                                                          else "%g" % edges[j + 1]))
                                    for j in range(len(edges) - 1)))
    for i in range(len(edges) - 1):
        line = "  %-10s" % ("%g-%s" % (edges[i], "" if edges[i + 1] > 1e8 else "%g" % edges[i + 1]))
        for j in range(len(edges) - 1):
            sel = ((data >= edges[i]) & (data < edges[i + 1]) & (rob >= edges[j])
                   & (rob < edges[j + 1]))
            n = int(sel.sum())
            cell = "-" if n == 0 else "%.0f (%d)" % (100.0 * (err[sel] >= wrong_m).mean(), n)
            line += "%14s" % cell
        print(line)


def auc(score, label):
    """Area under the ROC curve of score for label (ties count half)."""
    order = np.argsort(score, kind="mergesort")
    ranks = np.empty(len(score))
    s = score[order]
    i = 0
    while i < len(s):
        j = i
        while j + 1 < len(s) and s[j + 1] == s[i]:
            j += 1
        ranks[order[i:j + 1]] = (i + j) / 2.0 + 1.0
        i = j + 1
    npos = int(label.sum())
    nneg = len(label) - npos
    if npos == 0 or nneg == 0:
        return float("nan")
    return (ranks[label].sum() - npos * (npos + 1) / 2.0) / (npos * nneg)


def report(name, rows, wrong_m):
    err = np.array([r["err"] for r in rows])
    leg = np.array([r["leg"] for r in rows])
    runs = {(r.get("batch"), r["run"]) for r in rows}
    bad = err >= wrong_m
    print("%s: %d greedy decisions in %d runs; err >= %g m: %d (%.1f %%), %.0f %% of greedy travel"
          % (name, len(rows), len(runs), wrong_m, int(bad.sum()), 100.0 * bad.mean(),
             100.0 * leg[bad].sum() / max(1e-9, leg.sum())))
    table(rows, "data", wrong_m, "data")
    table(rows, "robot", wrong_m, "robot")
    cross(rows, wrong_m)
    wrong = err >= wrong_m
    print("  AUC for err >= %g m: data %.3f, robot %.3f, spread area %.3f" % (
        wrong_m, auc(np.array([r["data"] for r in rows]), wrong),
        auc(np.array([r["robot"] for r in rows]), wrong),
        auc(np.array([r["area"] for r in rows]), wrong)))
    print()


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 1
    dirs, wrong_m, tsv = [], 15.0, None
    i = 1
    while i < len(argv):
        if argv[i] == "--wrong" and i + 1 < len(argv):
            try:
                wrong_m = float(argv[i + 1])
            except ValueError:
                wrong_m = float("nan")
            if not wrong_m > 0.0 or math.isinf(wrong_m):
                print("greedy_extrap.py: --wrong %s: not a positive distance in metres"
                      % argv[i + 1], file=sys.stderr)
                return 1
            i += 2
        elif argv[i] == "--tsv" and i + 1 < len(argv):
            tsv = argv[i + 1]
            i += 2
        elif argv[i] in ("--wrong", "--tsv"):
            print("greedy_extrap.py: %s needs a value" % argv[i], file=sys.stderr)
            return 1
        elif argv[i].startswith("--"):
            print("greedy_extrap.py: unknown option %s" % argv[i], file=sys.stderr)
            return 1
        else:
            dirs.append(argv[i])
            i += 1
    if not dirs:
        print("greedy_extrap.py: no DIR", file=sys.stderr)
        return 1
    allrows = []
    for d in dirs:
        if not os.path.isdir(d):
            print("greedy_extrap.py: %s: not a directory" % d, file=sys.stderr)
            return 1
        rows = batch_rows(d)
        for r in rows:
            r["batch"] = d
        allrows += rows
        if len(dirs) > 1 and rows:
            report(d, rows, wrong_m)
    if not allrows:
        print("greedy_extrap.py: no greedy decisions", file=sys.stderr)
        return 1
    report("all", allrows, wrong_m)
    if tsv:
        keys = ("batch", "run", "reached", "end", "t", "err", "data", "robot", "leg", "total",
                "shortest", "p0", "n", "w", "area")
        tmp = "%s.tmp-%d" % (tsv, os.getpid())
        try:
            with open(tmp, "w") as f:
                f.write("\t".join(keys) + "\n")
                for r in allrows:
                    f.write("\t".join(str(r[k]) for k in keys) + "\n")
            os.replace(tmp, tsv)
        except OSError as e:
            if os.path.exists(tmp):
                os.unlink(tmp)
            print("greedy_extrap.py: %s: %s" % (tsv, e.strerror), file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
