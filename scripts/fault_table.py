#!/usr/bin/python3
"""fault_table.py - the table of faults survived (docs/FAULTS.md, `make bench-faults`).

For every fault scenario scenarios/faults/<map>-<fault>.yaml and seeds 1..N, runs
rfseek-sim twice side by side in one invocation: with the fault and with --no-faults (the
base scenario, byte for byte), and prints one Markdown row per fault:

  reached with / without the fault, runs still going when the fault began ("exercised"),
  wheel commands given while the newest pose or RSSI timestamp the controller had received
  was more than 200 ms from now (old, or ahead after a clock jump) and how many of those
  were non-zero (must be 0), and the longest time from the last delivered wheel command to the
  motor model stopping the wheels (must be <= 200 ms).

Command ages are measured here (awk over each run's faults.tsv) from the timestamps of
the inputs that were delivered, not taken from the core's own fault flags.

  scripts/fault_table.py --sim build/bin/rfseek-sim [--seeds 50] [--jobs 2] [--maps office,open]
"""
import argparse
import glob
import os
import shutil
import subprocess
import sys
import tempfile

# Per faults.tsv: commands, commands with an input older than 200 ms (a receiver heartbeat
# keeps the RSSI stream fresh like a packet), non-zero ones among them, and the
# longest wait from the last delivered command to a motor timeout (seconds).
AWK = r'''
BEGIN { FS = "\t"; pm = -1e18; rm = -1e18; ld = -1e18; worst = 0 }
NR == 1 { next }
$2 == "pose" { if ($3 + 0 > pm) pm = $3 + 0; next }
$2 == "rssi" || $2 == "receiver" { if ($3 + 0 > rm) rm = $3 + 0; next }
$2 == "cmd" {
    n++
    a = $1 - pm; b = $1 - rm; if (a < 0) a = -a; if (b < 0) b = -b
    if (a > 0.2 + 1e-6 || b > 0.2 + 1e-6) { st++; if ($3 != 0 || $4 != 0) mv++ }
    if ($5 == 1) ld = $1 + 0
    next
}
$2 == "motor" && $3 == 1 { d = $1 - ld; if (d > worst) worst = d }
END { printf "%d %d %d %.3f\n", n, st, mv, worst }
'''


def runs_table(path):
    """Rows of a runs.tsv as dicts."""
    with open(path) as f:
        head = f.readline().rstrip('\n').split('\t')
        return [dict(zip(head, line.rstrip('\n').split('\t'))) for line in f if line.strip()]


def fault_start(scenario):
    """start_s of the scenario's (single) fault, from its YAML text."""
    with open(scenario) as f:
        text = f.read()
    part = text.split('start_s:', 1)[1]
    return float(part.split(',', 1)[0].split('}', 1)[0])


def run(sim, scenario, seeds, jobs, out, extra):
    cmd = [sim, scenario, '--seeds', '1..%d' % seeds, '--jobs', str(jobs), '--quiet',
           '--out', out] + extra
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    return p.returncode, p.stderr.strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--sim', required=True, help='path of rfseek-sim')
    ap.add_argument('--seeds', type=int, default=50, help='seeds 1..N per fault (50)')
    ap.add_argument('--jobs', type=int, default=2, help='worker processes (2)')
    ap.add_argument('--maps', default='office,open', help='scenario prefixes (office,open)')
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    if a.seeds < 1:
        sys.exit('fault_table.py: --seeds: must be at least 1')
    if a.jobs < 1:
        sys.exit('fault_table.py: --jobs: must be at least 1')
    if not os.access(a.sim, os.X_OK):
        sys.exit('fault_table.py: --sim: %s: not an executable' % a.sim)
    for m in a.maps.split(','):
        if not glob.glob('scenarios/faults/%s-*.yaml' % m):
            sys.exit('fault_table.py: --maps: no scenarios/faults/%s-*.yaml (run from the repository root)' % m)
    tmp = tempfile.mkdtemp(prefix='rfs_fault_table.')
    bad = 0
    try:
        print('| scenario | fault | reached with | reached without | exercised '
              '| stale-input commands | non-zero of those | worst wheel stop |')
        print('|---|---|---|---|---|---|---|---|')
        for m in a.maps.split(','):
            for scn in sorted(glob.glob('scenarios/faults/%s-*.yaml' % m)):
                fault = os.path.basename(scn)[len(m) + 1:-5]
                with_dir = os.path.join(tmp, 'with')
                base_dir = os.path.join(tmp, 'base')
                rc1, e1 = run(a.sim, scn, a.seeds, a.jobs, with_dir, [])
                rc2, e2 = run(a.sim, scn, a.seeds, a.jobs, base_dir, ['--no-faults'])
                if rc1 != 0 or rc2 != 0:
                    # A crash or error in any seed fails the whole batch: the row says so.
                    print('| %s | %s | FAILED: %s |' % (m, fault, (e1 or e2).replace('|', '/')))
                    bad += 1
                    shutil.rmtree(with_dir, ignore_errors=True)
                    shutil.rmtree(base_dir, ignore_errors=True)
                    continue
                rw = runs_table(os.path.join(with_dir, 'runs.tsv'))
                rb = runs_table(os.path.join(base_dir, 'runs.tsv'))
                t0 = fault_start(scn)
                exercised = sum(float(r['sim_time_s']) > t0 for r in rw)
                n = st = mv = 0
                worst = 0.0
                for s in range(1, a.seeds + 1):
                    log = os.path.join(with_dir, 'seed-%d' % s, 'faults.tsv')
                    o = subprocess.run(['awk', AWK, log], capture_output=True, text=True,
                                       check=True).stdout.split()
                    n += int(o[0])
                    st += int(o[1])
                    mv += int(o[2])
                    worst = max(worst, float(o[3]))
                reached_w = sum(r['reached'] == '1' for r in rw)
                reached_b = sum(r['reached'] == '1' for r in rb)
                bad += (mv != 0) + (worst > 0.2 + 1e-6)
                print('| %s | %s | %d / %d | %d / %d | %d | %d of %d | %d | %s |' % (
                    m, fault, reached_w, a.seeds, reached_b, a.seeds, exercised, st, n, mv,
                    '%.0f ms' % (worst * 1000) if worst > 0 else 'no timeout'))
                sys.stdout.flush()
                shutil.rmtree(with_dir)
                shutil.rmtree(base_dir)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
