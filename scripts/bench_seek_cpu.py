#!/usr/bin/python3
"""bench_seek_cpu.py - CPU seconds of make bench-seek's batches under two simulators.

Every batch of scripts/bench_seek.py (the strategy sweep, the noise sweep, the internal
models), each at seeds 1..N, run by OLD and then by NEW one after the other (single
process, --jobs 1), so both see the same machine load; prints the user + system seconds
per section and their ratio (docs/PERFORMANCE.md, "Seek benchmark"). The outputs are
not compared: scripts/identity.sh does that.

  scripts/bench_seek_cpu.py OLD_RFSEEK_SIM NEW_RFSEEK_SIM [--seeds 10]
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import bench_seek

SECTIONS = ["sweep", "noise"] + [m for m in bench_seek.MODELS if m != "ridge"]


def cpu_of(binp, b, out):
    """User + system seconds of one batch b run by binp into out (removed after)."""
    p = subprocess.Popen([binp, b.scen_file, "--seeds", "1..%d" % b.seeds, "--jobs", "1",
                          "--quiet", "--out", out, "--strategy", b.strategy, "--model", b.model],
                         stdout=subprocess.DEVNULL)
    _, status, ru = os.wait4(p.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise subprocess.CalledProcessError(os.waitstatus_to_exitcode(status), p.args)
    shutil.rmtree(out)
    return ru.ru_utime + ru.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("old", help="rfseek-sim before")
    ap.add_argument("new", help="rfseek-sim after")
    ap.add_argument("--seeds", type=int, default=10, help="seeds 1..N of every batch")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    args = ap.parse_args()
    for binp in (args.old, args.new):
        if not os.access(binp, os.X_OK):
            sys.stderr.write("bench_seek_cpu.py: %s: not an executable\n" % binp)
            return 1
    if args.seeds < 1:
        sys.stderr.write("bench_seek_cpu.py: --seeds must be at least 1\n")
        return 1
    plan = argparse.Namespace(seeds=args.seeds, slow_model_seeds=args.seeds)
    tmp = tempfile.mkdtemp(prefix="bench_seek_cpu.")
    try:
        sweep_b, var_b, model_b = bench_seek.plan_batches(plan, tmp, bench_seek.SCENARIOS,
                                                          args.seeds, args.seeds)
        batches = list(sweep_b.values()) + list(var_b.values()) + list(model_b.values())
        tot = {(sec, w): 0.0 for sec in SECTIONS for w in ("old", "new")}
        for i, b in enumerate(batches):
            for w, binp in (("old", args.old), ("new", args.new)):
                tot[(b.section, w)] += cpu_of(binp, b, os.path.join(tmp, "out"))
            sys.stderr.write("[%d/%d] %s\n" % (i + 1, len(batches), b.tag))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("section\told_cpu_s\tnew_cpu_s\tnew/old")
    for sec in SECTIONS + ["all"]:
        o = sum(tot[(s, "old")] for s in SECTIONS) if sec == "all" else tot[(sec, "old")]
        n = sum(tot[(s, "new")] for s in SECTIONS) if sec == "all" else tot[(sec, "new")]
        print("%s\t%.1f\t%.1f\t%.3f" % (sec, o, n, n / o if o > 0 else float("nan")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
