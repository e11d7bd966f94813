#!/usr/bin/python3
"""Merge per-seed simulator runs into one table (the batch table of rfseek-sim --seeds).

    scripts/merge_runs.py DIR [--out FILE] [--seeds A..B] [--allow-missing]
                                               (default FILE: DIR/runs.tsv)

DIR holds seed-N/summary.json as written by `rfseek-sim SCENARIO --seed N --out DIR/seed-N`
(the commands `rfseek-sim SCENARIO --seeds A..B --emit-jobs --out DIR` prints, run by GNU
parallel or a Slurm array). The table has the same columns and formatting as the one
`rfseek-sim --seeds A..B --out DIR` writes, rows sorted by seed. Written to a temporary
file and renamed, so a failed merge leaves no half-written table.

The seeds expected are A..B of --seeds, else those of DIR/batch.state (the state an
interrupted `rfseek-sim --seeds A..B --out DIR` leaves), else every seed from the lowest
to the highest seed-N directory. A seed without its summary.json is missing: the merge
names the missing seeds and fails unless --allow-missing (then it merges the rest).
"""
import glob
import json
import os
import re
import sys

COLS = ["seed", "reached", "end", "sim_time_s", "distance_travelled_m", "shortest_path_m",
        "shortest_to_stop_m", "final_distance_m", "final_x_m", "final_y_m", "iterations",
        "model_updates", "greedy", "epsilon", "packets_sent", "packets_received",
        "goal_timeouts", "goal_blocked", "turn_time_s", "wall_contacts"]
FLOATS = set(COLS[3:10]) | {"turn_time_s"}
# The columns a bridging run adds (hs_sim.h, HS_SIM_BRIDGE_COLUMNS).
BRIDGE = ["best_x_m", "best_y_m", "best_f_db", "settle_f_db", "settle_error_m",
          "settle_travel_m", "pred_x_m", "pred_y_m", "pred_f_db", "pred_sigma_db",
          "pred_area_m2"]
FLOATS |= set(BRIDGE)


def fmt(col, v):
    if col == "reached":
        return "1" if v else "0"
    if col in FLOATS:
        return "nan" if v is None else "%.3f" % v
    return str(v)


def batch_seeds(d):
    """The seeds A..B named in DIR/batch.state's header, or None."""
    try:
        with open(os.path.join(d, "batch.state")) as fh:
            m = re.search(r"\tseeds=(\d+)\.\.(\d+)\t", fh.readline())
    except OSError:
        return None
    return (int(m.group(1)), int(m.group(2))) if m else None


def spans(seeds):
    """Sorted seeds as '3, 5-9, 12' (at most 10 spans, then '...')."""
    out, start = [], seeds[0]
    for a, b in zip(seeds, seeds[1:] + [None]):
        if b != a + 1:
            out.append(str(start) if start == a else "%d-%d" % (start, a))
            start = b
    return ", ".join(out[:10]) + (", ..." if len(out) > 10 else "")


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 1
    d = argv[1]
    out = os.path.join(d, "runs.tsv")
    seeds, allow_missing, i = None, False, 2
    while i < len(argv):
        if argv[i] == "--out" and i + 1 < len(argv):
            out = argv[i + 1]
            i += 2
        elif argv[i] == "--seeds" and i + 1 < len(argv) and re.fullmatch(r"\d+\.\.\d+", argv[i + 1]):
            seeds = tuple(int(x) for x in argv[i + 1].split(".."))
            i += 2
        elif argv[i] == "--allow-missing":
            allow_missing = True
            i += 1
        else:
            print("merge_runs.py: usage: merge_runs.py DIR [--out FILE] [--seeds A..B] "
                  "[--allow-missing]", file=sys.stderr)
            return 1
    if seeds is None:
        seeds = batch_seeds(d)
    rows = []
    cols = COLS
    files = glob.glob(os.path.join(d, "seed-*", "summary.json"))
    if not files:
        print("merge_runs.py: %s: no seed-*/summary.json" % d, file=sys.stderr)
        return 1
    for f in files:
        try:
            with open(f) as fh:
                s = json.load(fh)
            cols = COLS + BRIDGE if s.get("target") == "bridge" else COLS
            rows.append((int(s["seed"]), "\t".join(fmt(c, s[c]) for c in cols)))
        except (OSError, ValueError, KeyError) as e:
            print("merge_runs.py: %s: %s" % (f, e), file=sys.stderr)
            return 1
    rows.sort()
    have = {s for s, _ in rows}
    if seeds is None:
        dirs = [int(m.group(1)) for m in (re.fullmatch(r"seed-(\d+)", n) for n in os.listdir(d)) if m]
        seeds = (min(dirs), max(dirs))
    missing = [s for s in range(seeds[0], seeds[1] + 1) if s not in have]
    if missing and not allow_missing:
        print("merge_runs.py: %s: %d of %d seeds missing: %s (--allow-missing merges the rest)"
              % (d, len(missing), seeds[1] - seeds[0] + 1, spans(missing)), file=sys.stderr)
        return 1
    tmp = out + ".tmp"
    with open(tmp, "w") as fh:
        fh.write("\t".join(cols) + "\n")
        for _, r in rows:
            fh.write(r + "\n")
    os.replace(tmp, out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
