#!/usr/bin/python3
"""Merge per-seed simulator runs into one table (the batch table of rfseek-sim --seeds).

    scripts/merge_runs.py DIR [--out FILE] [--seeds A..B] [--placements A..B]
                              [--allow-missing]        (default FILE: DIR/runs.tsv)

DIR holds seed-N/summary.json as written by `rfseek-sim SCENARIO --seed N --out DIR/seed-N`
(the commands `rfseek-sim SCENARIO --seeds A..B --emit-jobs --out DIR` prints, run by GNU
parallel or a Slurm array), or place-K-seed-N/summary.json for drawn placements (the
commands of `--placements ... --emit-jobs`). The table has the same columns and formatting
as the one `rfseek-sim --seeds A..B [--placements ...] --out DIR` writes, rows sorted by
placement and seed. Written to a temporary file and renamed, so a failed merge leaves no
half-written table.

The seeds (placements) expected are A..B of --seeds (--placements), else those of
DIR/batch.state (the state an interrupted `rfseek-sim --seeds A..B --out DIR` leaves), else
every one from the lowest to the highest directory. A run without its summary.json is
missing: the merge names the missing runs and fails unless --allow-missing (then it merges
the rest).
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
          "pred_area_m2", "far_f_db"]
FLOATS |= set(BRIDGE)
# A placed batch's table: the placement first, then COLS, then these.
PLACED = ["start_x_m", "start_y_m", "start_theta_rad", "source_x_m", "source_y_m",
          "est_error_m", "belief_error_m", "still_s"]


def placed_values(s):
    """The PLACED columns of one summary.json, formatted as rfseek-sim writes them."""
    num = lambda v: "nan" if v is None else "%.3f" % v  # noqa: E731
    return ["%.3f" % s["start"][0], "%.3f" % s["start"][1], "%.4f" % s["start_theta_rad"],
            "%.3f" % s["sources"][0][0], "%.3f" % s["sources"][0][1],
            num(s["est_error_m"]), num(s["belief_error_m"]), num(s["still_s"])]


def fmt(col, v):
    if col == "reached":
        return "1" if v else "0"
    if col in FLOATS:
        return "nan" if v is None else "%.3f" % v
    return str(v)


def batch_range(d, key):
    """The range A..B of key (seeds, placements) in DIR/batch.state's header, or None."""
    try:
        with open(os.path.join(d, "batch.state")) as fh:
            m = re.search(r"\t%s=(\d+)\.\.(\d+)(\t|$)" % key, fh.readline())
    except OSError:
        return None
    return (int(m.group(1)), int(m.group(2))) if m else None


def dir_range(d, pattern):
    """Lowest and highest N of the directories matching pattern (one group) in d."""
    ns = [int(m.group(1)) for m in (re.fullmatch(pattern, n) for n in os.listdir(d)) if m]
    return (min(ns), max(ns)) if ns else None


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
    ranges, allow_missing, i = {}, False, 2
    while i < len(argv):
        if argv[i] == "--out" and i + 1 < len(argv):
            out = argv[i + 1]
            i += 2
        elif (argv[i] in ("--seeds", "--placements") and i + 1 < len(argv)
              and re.fullmatch(r"\d+\.\.\d+", argv[i + 1])):
            ranges[argv[i][2:]] = tuple(int(x) for x in argv[i + 1].split(".."))
            i += 2
        elif argv[i] == "--allow-missing":
            allow_missing = True
            i += 1
        else:
            print("merge_runs.py: usage: merge_runs.py DIR [--out FILE] [--seeds A..B] "
                  "[--placements A..B] [--allow-missing]", file=sys.stderr)
            return 1
    files = glob.glob(os.path.join(d, "seed-*", "summary.json"))
    placed = not files
    if placed:
        files = glob.glob(os.path.join(d, "place-*-seed-*", "summary.json"))
    if not files:
        print("merge_runs.py: %s: no seed-*/summary.json or place-*-seed-*/summary.json" % d,
              file=sys.stderr)
        return 1
    rows = []
    for f in files:
        try:
            with open(f) as fh:
                s = json.load(fh)
            row = [fmt(c, s[c]) for c in COLS]
            key = (int(s["placement"]) if placed else 0, int(s["seed"]))
            if placed:
                row = [str(key[0])] + row + placed_values(s)
            bridge = s.get("target") == "bridge"
            row += [fmt(c, s[c]) for c in BRIDGE] if bridge else []
            rows.append((key, "\t".join(row)))
        except (OSError, ValueError, KeyError, TypeError, IndexError) as e:
            print("merge_runs.py: %s: %s" % (f, e), file=sys.stderr)
            return 1
    rows.sort()
    have = {k for k, _ in rows}
    seeds = ranges.get("seeds") or batch_range(d, "seeds")
    if seeds is None:  # every seed-N directory (of every placement)
        seeds = dir_range(d, r"(?:place-\d+-)?seed-(\d+)")
    places = [0]
    if placed:
        pr = (ranges.get("placements") or batch_range(d, "placements")
              or dir_range(d, r"place-(\d+)-seed-\d+"))
        places = list(range(pr[0], pr[1] + 1))
    want = [(p, s) for p in places for s in range(seeds[0], seeds[1] + 1)]
    missing = [k for k in want if k not in have]
    if missing and not allow_missing:
        if placed:
            what = ", ".join("%d/%d" % k for k in missing[:10]) + (", ..." if len(missing) > 10 else "")
            print("merge_runs.py: %s: %d of %d runs missing (placement/seed): %s (--allow-missing "
                  "merges the rest)" % (d, len(missing), len(want), what), file=sys.stderr)
        else:
            print("merge_runs.py: %s: %d of %d seeds missing: %s (--allow-missing merges the rest)"
                  % (d, len(missing), len(want), spans([s for _, s in missing])), file=sys.stderr)
        return 1
    tmp = out + ".tmp"
    with open(tmp, "w") as fh:
        fh.write("\t".join((["placement"] if placed else []) + COLS + (PLACED if placed else [])
                            + (BRIDGE if bridge else [])) + "\n")
        for _, r in rows:
            fh.write(r + "\n")
    os.replace(tmp, out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
