#!/usr/bin/env python3
"""The drive under localisation noise: success, travel, time turning on the spot, goals
abandoned and wall contacts for the paper's meta + ridge and for meta-path + pathloss on
the default office, the L-shaped floor and a real floor, from exact poses to 20 cm noise
and an AMCL-like drifting estimate (docs/SIMULATOR.md, "Localisation"); then wall contacts
and success on every shipped floor (each scenarios/*.yaml seeking one source) at the
default localisation. Writes its section of docs/RESULTS.md, between the markers below,
and nothing else.

    /usr/bin/python3 scripts/bench_drive.py [--seeds A..B] [--floors default,lshape,willow]
                                            [--all-floors all|none|a,b] [--jobs N]
                                            [--sim build/bin/rfseek-sim]
                                            [--results docs/RESULTS.md | --no-write]
                                            [--keep DIR]
    /usr/bin/python3 scripts/bench_drive.py --smoke   (2 seeds, 2 rows, one floor; a
                                                        self-check that writes nothing)

Seeds 1001..1200 by default: the drive was tuned on seeds 1..500 of the default office,
so these are draws it has not seen.
"""
import argparse
import atexit
import glob
import shutil
import tempfile
import os
import re
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_pathloss_seek import commit, scenario_file, splice, wilson  # noqa: E402

FLOORS = {f: (f, f"scenarios/{f}.yaml") for f in ("default", "lshape", "willow", "3ne", "intel")}
# (label, localisation settings)
NOISE = [("exact poses", "sigma_xy_m: 0, sigma_theta_rad: 0"),
         ("0 cm, 0.02 rad", "sigma_xy_m: 0, sigma_theta_rad: 0.02"),
         ("0 cm, 0.05 rad", "sigma_xy_m: 0, sigma_theta_rad: 0.05"),
         ("5 cm, 0.02 rad (default)", "sigma_xy_m: 0.05, sigma_theta_rad: 0.02"),
         ("5 cm, 0.05 rad", "sigma_xy_m: 0.05, sigma_theta_rad: 0.05"),
         ("10 cm, 0.02 rad", "sigma_xy_m: 0.10, sigma_theta_rad: 0.02"),
         ("10 cm, 0.05 rad", "sigma_xy_m: 0.10, sigma_theta_rad: 0.05"),
         ("20 cm, 0.02 rad", "sigma_xy_m: 0.20, sigma_theta_rad: 0.02"),
         ("20 cm, 0.05 rad", "sigma_xy_m: 0.20, sigma_theta_rad: 0.05"),
         ("AMCL-like", "sigma_xy_m: 0.05, sigma_theta_rad: 0.02, drift_m: 0.2, "
                       "drift_tau_s: 10, jump_m: 0.3, jump_rate_hz: 0.0167, jump_tau_s: 3")]
CONFIGS = [("meta", "ridge", "meta + ridge"), ("meta-path", "pathloss", "meta-path + pathloss")]
BEGIN = "<!-- bench_drive: begin -->"
END = "<!-- bench_drive: end -->"


def localisation_edit(path, settings):
    """Edits (or extra text) that give the scenario at path these localisation settings."""
    line = "localisation: {rate_hz: 10, " + settings + "}"
    if re.search(r"^localisation:.*$", open(path).read(), re.M):
        return [(r"(?m)^localisation:.*$", line)], ""
    return [], "\n" + line + "\n"


def run(sim, scenario, strategy, model, seeds, jobs, keep=None):
    """One batch's summary; with keep (a file name) its runs table is kept there and a
    kept one is read instead of running again."""
    if keep and os.path.exists(keep):
        return summarise(open(keep).read())
    cmd = [sim, scenario, "--strategy", strategy, "--model", model, "--seeds", seeds, "--quiet"]
    if jobs:
        cmd += ["--jobs", str(jobs)]
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"bench_drive: {scenario}: {out.stderr.strip()}")
    if keep:
        with open(keep + ".tmp", "w") as f:
            f.write(out.stdout)
        os.replace(keep + ".tmp", keep)
    return summarise(out.stdout)


def summarise(table):
    """Success, travel, turning, goals abandoned and contacts of one runs.tsv table."""
    lines = table.strip().split("\n")
    head = lines[0].split("\t")
    rows = [dict(zip(head, ln.split("\t"))) for ln in lines[1:]]
    n = len(rows)
    k = sum(r["reached"] == "1" for r in rows)
    lo, hi = wilson(k, n)
    ratios = [float(r["distance_travelled_m"]) / float(r["shortest_path_m"]) for r in rows]
    turn = sum(float(r["turn_time_s"]) for r in rows) / sum(float(r["sim_time_s"]) for r in rows)
    return {"n": n, "k": k, "lo": lo, "hi": hi, "ratio": statistics.median(ratios),
            "turn": turn,
            "timeouts": sum(int(r["goal_timeouts"]) for r in rows) / n,
            "blocked": sum(int(r["goal_blocked"]) for r in rows) / n,
            "contacts": sum(int(r["wall_contacts"]) for r in rows)}


def cell(r):
    """One compact cell: success, then travel/turning/abandoned/contacts."""
    return (f"{100 * r['k'] / r['n']:.1f}% {r['ratio']:.2f}/{100 * r['turn']:.0f}%/"
            f"{r['timeouts'] + r['blocked']:.2f}/{r['contacts']}")


def shipped_floors():
    """Every scenarios/*.yaml that seeks one source (no `target:` other than rssi)."""
    names = []
    for path in sorted(glob.glob("scenarios/*.yaml")):
        m = re.search(r"(?m)^target:\s*(\S+)", open(path).read())
        if m is None or m.group(1) == "rssi":
            names.append(os.path.splitext(os.path.basename(path))[0])
    return names


def section(seeds, wall, at, floors, rows, every):
    """floors: [label]; rows: [(noise label, [cell per floor x configuration])];
    every: [(floor, [cell per configuration])] at the default localisation."""
    L = [BEGIN, "## The drive under localisation noise", "",
         f"Written by `/usr/bin/python3 scripts/bench_drive.py --seeds {seeds}` at commit "
         f"{at} ({wall:.0f} s on two cores): each floor's scenario with only `localisation` "
         "changed (10 Hz; AMCL-like: 0.2 m drift, 0.3 m jumps, docs/SIMULATOR.md). `r`: "
         "meta + ridge (the paper), `p`: meta-path + pathloss. Cells: success (95 % "
         "interval +-5 points at 85 %), then median travel / shortest path (all runs), time "
         "turning on the spot, goals abandoned per run, wall contacts in all runs.", ""]
    head = ["localisation"] + [f"{f} {c}" for f in floors for c in ("r", "p")]
    L.append("| " + " | ".join(head) + " |")
    L.append("|---" * len(head) + "|")
    for label, cs in rows:
        L.append(f"| {label} | " + " | ".join(cs) + " |")
    if every:
        L += ["", "Every shipped floor at the scenario's own localisation (5 cm, 0.02 rad), "
              "same seeds and cells:", "", "| floor | meta + ridge | meta-path + pathloss |",
              "|---|---|---|"]
        L += [f"| {f} | " + " | ".join(cs) + " |" for f, cs in every]
    L.append("")
    L.append(END)
    return "\n".join(L) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--seeds", default="1001..1200", help="seeds A..B (1..500 are the tuning draws)")
    ap.add_argument("--floors", default="default,lshape,willow", help="floors of the pose-noise table")
    ap.add_argument("--all-floors", default="all",
                    help="floors of the every-floor table: all shipped, none, or a list")
    ap.add_argument("--sim", default="build/bin/rfseek-sim", help="the rfseek-sim to run")
    ap.add_argument("--jobs", type=int, default=0, help="worker processes (0: one a core)")
    ap.add_argument("--results", default="docs/RESULTS.md", help="the markdown file whose section is replaced")
    ap.add_argument("--no-write", action="store_true", help="print the tables only")
    ap.add_argument("--keep", metavar="DIR",
                    help="keep each batch's runs table in DIR and reuse the ones there "
                         "(same binary and seeds: a resumed or extended bench)")
    ap.add_argument("--smoke", action="store_true",
                    help="seeds 1..2, exact poses and AMCL-like on the default floor, the "
                         "section written to a temporary copy and checked; prints PASS/FAIL "
                         "bench-drive-smoke")
    ap.error = lambda msg: ap.exit(2, "%s: %s (see --help)\n" % (ap.prog, msg))  # one line, no usage
    a = ap.parse_args()
    noise = NOISE
    if a.smoke:
        a.seeds, a.floors, a.all_floors, a.keep = "1..2", "default", "default", None
        noise = [NOISE[0], NOISE[-1]]
        tmpdir = tempfile.mkdtemp(prefix="bench_drive_smoke.")
        atexit.register(shutil.rmtree, tmpdir, True)
        shutil.copy(a.results, os.path.join(tmpdir, "RESULTS.md"))
        a.results = os.path.join(tmpdir, "RESULTS.md")
    if not re.fullmatch(r"\d+\.\.\d+", a.seeds):
        sys.exit("bench_drive: --seeds: expected A..B")
    if not os.access(a.sim, os.X_OK):
        sys.exit(f"bench_drive: --sim: {a.sim}: not an executable (make all)")
    for f in a.floors.split(","):
        if f not in FLOORS:
            sys.exit(f"bench_drive: --floors: unknown floor {f!r} (known: {', '.join(FLOORS)})")
    shipped = shipped_floors()
    every_floors = (shipped if a.all_floors == "all" else
                    [] if a.all_floors == "none" else a.all_floors.split(","))
    for f in every_floors:
        if f not in shipped:
            sys.exit(f"bench_drive: --all-floors: {f!r} is not a shipped floor "
                     f"(known: {', '.join(shipped)})")
    tmps = []
    t0 = time.time()
    floors = a.floors.split(",")
    rows = []
    every = []
    try:
        if a.keep:
            os.makedirs(a.keep, exist_ok=True)
        for i, (nlabel, settings) in enumerate(noise):
            cs = []
            for f in floors:
                path = FLOORS[f][1]
                edits, extra = localisation_edit(path, settings)
                scen = scenario_file(path, edits, tmps, extra)
                for strategy, model, _ in CONFIGS:
                    keep = a.keep and os.path.join(a.keep, f"noise{i}_{f}_{strategy}_{model}.tsv")
                    cs.append(cell(run(a.sim, scen, strategy, model, a.seeds, a.jobs, keep)))
            rows.append((nlabel, cs))
            print(f"{nlabel} | " + " | ".join(cs), flush=True)
        for f in every_floors:
            cs = [cell(run(a.sim, f"scenarios/{f}.yaml", strategy, model, a.seeds, a.jobs,
                           a.keep and os.path.join(a.keep, f"{f}_{strategy}_{model}.tsv")))
                  for strategy, model, _ in CONFIGS]
            every.append((f, cs))
            print(f"{f} | " + " | ".join(cs), flush=True)
    finally:
        for t in tmps:
            os.unlink(t)
    if not a.no_write:
        text = section(a.seeds, time.time() - t0, commit(), floors, rows, every)
        splice(a.results, text, BEGIN, END)
        print(f"wrote {a.results} ({time.time() - t0:.0f} s)")
    if a.smoke:
        ok = smoke_check(a.results, [lb for lb, _ in noise], every_floors)
        print("%s bench-drive-smoke" % ("PASS" if ok else "FAIL"))
        sys.exit(0 if ok else 1)


CELL = re.compile(r"\d+\.\d% \d+\.\d\d/\d+%/\d+\.\d\d/\d+")


def smoke_check(results, labels, every_floors):
    """The section between the markers holds one row per localisation label and per
    floor, each with two well-formed cells of two runs (0.0 or 50.0 or 100.0 %)."""
    text = open(results).read()
    if text.count(BEGIN) != 1 or text.count(END) != 1:
        return False
    body = text[text.index(BEGIN):text.index(END)]
    rows = {ln.split(" | ")[0].lstrip("| "): ln for ln in body.split("\n") if ln.startswith("| ")}
    for name in labels + every_floors:
        cells = CELL.findall(rows.get(name, ""))
        if len(cells) != 2 or any(c.split("%")[0] not in ("0.0", "50.0", "100.0")
                                   for c in cells):
            return False
    return True


if __name__ == "__main__":
    main()
