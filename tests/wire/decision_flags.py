#!/usr/bin/python3
"""decision_flags.py - the decision flags and plan_wait that crossed LCM, against rfseekd's own.

    tests/wire/decision_flags.py DECISIONS LOG_TSV SUMMARY_JSON

DECISIONS: rfseekd --decisions (printed from the seeker's decision in rfseekd, before any
encoding); LOG_TSV and SUMMARY_JSON: rfseek-sim-lcm --log and its stdout, made from the
RFS_SEEKER_STATUS messages it decoded. Every decision's flags in the log's reason column
(sampled, near, hedged as rfseek-sim names them: the first set of the three; refuted,
pinned) must be rfseekd's, and summary.json's slow_decisions (plan_wait >= 2) and
plan_wait_max what rfseekd's lines give. Prints "N decisions, sampled S, near N, hedged H,
refuted R, pinned P, plan_wait_max W" and exits 0, or one line and exit 1.
"""
import json
import sys

ONE_OF = ("sampled", "near", "hedged")  # rfseek-sim's log shows the first that is set
FLAGS = ONE_OF + ("refuted", "pinned")


def rfseekd_lines(path):
    """{iteration: {key: int}} of rfseekd's `decision k=v ...` lines."""
    out = {}
    for line in open(path):
        kv = dict(f.split("=", 1) for f in line.split()[1:])
        out[int(kv["n"])] = {k: int(kv[k]) for k in FLAGS + ("plan_wait",)}
    return out


def log_flags(path):
    """{iteration: set of flag names} from log.tsv's reason column."""
    rows = [r.rstrip("\n").split("\t") for r in open(path)]
    col = rows[0].index("reason")
    return {int(r[0]): set(r[col].split(",")) & set(FLAGS) for r in rows[1:]}


def main(argv):
    if len(argv) != 4:
        sys.exit("usage: decision_flags.py DECISIONS LOG_TSV SUMMARY_JSON")
    dec, log = rfseekd_lines(argv[1]), log_flags(argv[2])
    summary = json.load(open(argv[3]))
    if sorted(dec) != sorted(log):
        sys.exit("decision_flags.py: iterations differ: rfseekd %d, log %d" % (len(dec), len(log)))
    for n in sorted(dec):
        d = dec[n]
        want = {next(f for f in ONE_OF if d[f])} if any(d[f] for f in ONE_OF) else set()
        want |= {f for f in ("refuted", "pinned") if d[f]}
        if log[n] != want:
            sys.exit("decision_flags.py: decision %d: rfseekd %s, LCM log %s"
                     % (n, sorted(want) or "none", sorted(log[n]) or "none"))
    waits = [d["plan_wait"] for d in dec.values()]
    want = (sum(w >= 2 for w in waits), max(waits, default=0))
    got = (summary["slow_decisions"], summary["plan_wait_max"])
    if got != want:
        sys.exit("decision_flags.py: slow_decisions, plan_wait_max %s in the summary, %s from "
                 "rfseekd" % (got, want))
    print("%d decisions, %s, plan_wait_max %d" % (
        len(dec), ", ".join("%s %d" % (f, sum(d[f] for d in dec.values())) for f in FLAGS),
        want[1]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
