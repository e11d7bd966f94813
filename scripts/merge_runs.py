#!/usr/bin/python3
"""Merge per-seed simulator runs into one table (the batch table of rfseek-sim --seeds).

    scripts/merge_runs.py DIR [--out FILE]     (default FILE: DIR/runs.tsv)

DIR holds seed-N/summary.json as written by `rfseek-sim SCENARIO --seed N --out DIR/seed-N`
(the commands `rfseek-sim SCENARIO --seeds A..B --emit-jobs --out DIR` prints, run by GNU
parallel or a Slurm array). The table has the same columns and formatting as the one
`rfseek-sim --seeds A..B --out DIR` writes, rows sorted by seed. Written to a temporary
file and renamed, so a failed merge leaves no half-written table.
"""
import glob
import json
import os
import sys

COLS = ["seed", "reached", "end", "sim_time_s", "distance_travelled_m", "shortest_path_m",
        "shortest_to_stop_m", "final_distance_m", "final_x_m", "final_y_m", "iterations",
        "model_updates", "greedy", "epsilon", "packets_sent", "packets_received"]
FLOATS = set(COLS[3:10])


def fmt(col, v):
    if col == "reached":
        return "1" if v else "0"
    if col in FLOATS:
        return "nan" if v is None else "%.3f" % v
    return str(v)


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 1
    d = argv[1]
    out = os.path.join(d, "runs.tsv")
    if len(argv) == 4 and argv[2] == "--out":
        out = argv[3]
    elif len(argv) != 2:
        print("merge_runs.py: usage: merge_runs.py DIR [--out FILE]", file=sys.stderr)
        return 1
    rows = []
    files = glob.glob(os.path.join(d, "seed-*", "summary.json"))
    if not files:
        print("merge_runs.py: %s: no seed-*/summary.json" % d, file=sys.stderr)
        return 1
    for f in files:
        try:
            with open(f) as fh:
                s = json.load(fh)
            rows.append((int(s["seed"]), "\t".join(fmt(c, s[c]) for c in COLS)))
        except (OSError, ValueError, KeyError) as e:
            print("merge_runs.py: %s: %s" % (f, e), file=sys.stderr)
            return 1
    rows.sort()
    tmp = out + ".tmp"
    with open(tmp, "w") as fh:
        fh.write("\t".join(COLS) + "\n")
        for _, r in rows:
            fh.write(r + "\n")
    os.replace(tmp, out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
