#!/usr/bin/python3
"""greedy_extrap_check.py - scripts/greedy_extrap.py against an independent computation.

    /usr/bin/python3 tests/host_sim/greedy_extrap_check.py build/bin/rfseek-sim   (repository root)

A meta-path + pathloss batch on the default office (seeds 1..4); every greedy decision's
row of --tsv recomputed here with the csv module from the run's summary.json, log.tsv and
track.tsv (the estimate's distance from the source, from the nearest true position up to
the decision, from the robot); the printed ROC AUCs against scikit-learn's
roc_auc_score; bad options and inputs: one line on stderr, exit 1, no TSV left.
"""
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile

from sklearn.metrics import roc_auc_score

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from checks import check, exit_status  # noqa: E402

SIM = sys.argv[1]
SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                      "greedy_extrap.py")


def tool(*args):
    return subprocess.run([sys.executable, SCRIPT] + list(args), capture_output=True, text=True)


def expected(batch):
    """(run, t) -> (err, data, robot) for every greedy decision with a model."""
    out = {}
    for run in sorted(os.listdir(batch)):
        d = os.path.join(batch, run)
        if not os.path.isdir(d):
            continue
        with open(os.path.join(d, "summary.json")) as f:
            sx, sy = json.load(f)["sources"][0]
        with open(os.path.join(d, "track.tsv")) as f:
            track = [(float(r["t_s"]), float(r["x_m"]), float(r["y_m"]))
                     for r in csv.DictReader(f, delimiter="\t")]
        with open(os.path.join(d, "log.tsv")) as f:
            for r in csv.DictReader(f, delimiter="\t"):
                if r["kind"] != "greedy" or "no_model" in r["reason"]:
                    continue
                t = float(r["t_s"])
                mx, my = float(r["max_x_m"]), float(r["max_y_m"])
                seen = [math.hypot(x - mx, y - my) for (tt, x, y) in track if tt <= t]
                if not seen:
                    continue
                out[(run, t)] = (math.hypot(mx - sx, my - sy), min(seen),
                                 math.hypot(mx - float(r["x_m"]), my - float(r["y_m"])))
    return out


def main():
    with tempfile.TemporaryDirectory() as tmp:
        batch = os.path.join(tmp, "batch")
        r = subprocess.run([SIM, "scenarios/default.yaml", "--strategy", "meta-path", "--model",
                            "pathloss", "--seeds", "1..4", "--out", batch, "--quiet"],
                           capture_output=True, text=True)
        check("greedy_extrap: the batch runs", r.returncode == 0, r.stderr.strip())
        tsv = os.path.join(tmp, "rows.tsv")
        r = tool(batch, "--wrong", "5", "--tsv", tsv)
        check("greedy_extrap: exit 0 on a batch", r.returncode == 0, r.stderr.strip())
        want = expected(batch)
        with open(tsv) as f:
            got = list(csv.DictReader(f, delimiter="\t"))
        check("greedy_extrap: one row per greedy decision", len(got) == len(want) > 5,
              "%d rows, %d expected" % (len(got), len(want)))
        bad = [g for g in got
               if any(abs(float(g[k]) - v) > 1e-6
                      for k, v in zip(("err", "data", "robot"), want.get(
                          (g["run"], float(g["t"])), (math.nan,) * 3)))]
        check("greedy_extrap: err, data and robot distances as recomputed", not bad,
              "%d rows differ, first %s" % (len(bad), bad[:1]))
        wrong = [float(g["err"]) >= 5.0 for g in got]
        line = [ln for ln in r.stdout.splitlines() if "AUC for err >= 5 m" in ln]
        m = re.search(r"data ([0-9.]+), robot ([0-9.]+), spread area ([0-9.]+)", line[-1]) \
            if line else None
        if m and 0 < sum(wrong) < len(wrong):
            ref = [roc_auc_score(wrong, [float(g[k]) for g in got]) for k in ("data", "robot", "area")]
            ok = all(abs(float(m.group(i + 1)) - ref[i]) < 1e-3 for i in range(3))
            check("greedy_extrap: AUCs as scikit-learn's", ok, "%s against %s" % (m.groups(), ref))
        else:
            check("greedy_extrap: AUCs printed, both classes present", False, r.stdout[-300:])
        for args, what in ((["--wrong", "x", batch], "--wrong x"),
                           (["--wrong", "-3", batch], "--wrong -3"),
                           (["--bogus", batch], "unknown option"),
                           ([batch, "--tsv"], "--tsv without a value"),
                           ([os.path.join(tmp, "none")], "missing DIR"),
                           ([tmp + "/rows.tsv"], "a file as DIR"),
                           ([batch, "--tsv", os.path.join(tmp, "no", "x.tsv")], "unwritable TSV")):
            r = tool(*args)
            lines = r.stderr.strip().splitlines()
            check("greedy_extrap: %s: one line, exit 1" % what,
                  r.returncode == 1 and len(lines) == 1 and lines[0].startswith("greedy_extrap.py: "),
                  "exit %d, stderr %r" % (r.returncode, r.stderr))
        check("greedy_extrap: no TSV left by a failed write",
              not os.path.exists(os.path.join(tmp, "no")))
    return exit_status()


if __name__ == "__main__":
    sys.exit(main())
