#!/usr/bin/python3
"""placements.py - rfseek-sim --placements against an independent computation.

    /usr/bin/python3 tests/host_sim/placements.py build/bin/rfseek-sim   (repository root)

Determinism (the same pairs twice, placement k the same in any range, another seed other
pairs); every drawn pair legal and its shortest path 10-40 m, checked against a reference
computed here from the map image alone, in double precision with numpy and scipy: the
map_server trinary reading of the PGM, legality as erosion of the free cells by the
clearance disc at the image's own resolution, and Dijkstra (scipy.sparse.csgraph) over
the legal cells with 16 neighbours at Euclidean lengths, from the start to the legal cell
nearest the source. The simulator walks 0.1 m core cells instead, so the two agree
within quantisation: 4 % plus 0.5 m. Then a run at one placement reports the listed
shortest path; batches over placements: the table, the job list and its merge, and a
resumed interrupted batch, each equal to the plain batch; bad options and a floor too
small for any pair: one line, exit 1.
"""
import json
import os
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np
from PIL import Image
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from checks import check, exit_status  # noqa: E402

SIM = sys.argv[1]
CLEARANCE, STOP_M, LO_M, HI_M = 0.25, 1.5, 10.0, 40.0


def sim(*args, **kw):
    return subprocess.run([SIM] + list(args), capture_output=True, text=True, **kw)


def table(text):
    lines = text.strip().split("\n")
    head = lines[0].split("\t")
    return [dict(zip(head, ln.split("\t"))) for ln in lines[1:]]


def load_map(yaml_path):
    """(free mask with row 0 at the bottom, resolution, origin x, origin y)."""
    kv = {}
    for line in open(yaml_path):
        if ":" in line:
            k, v = line.split(":", 1)
            kv[k.strip()] = v.strip()
    img = np.asarray(Image.open(os.path.join(os.path.dirname(yaml_path), kv["image"])), float)
    p = (255.0 - img) / 255.0
    free = p < float(kv.get("free_thresh", 0.196))
    ox, oy = [float(x) for x in kv["origin"].strip("[]").split(",")[:2]]
    return free[::-1, :], float(kv["resolution"]), ox, oy


def legal_cells(free, res):
    """Cells whose square-nearest neighbours within CLEARANCE are all free (off-map: not)."""
    r = int(np.ceil(CLEARANCE / res)) + 1
    d = np.arange(-r, r + 1)
    ex = np.maximum(np.abs(d) - 0.5, 0.0) * res
    disc = (ex[:, None] ** 2 + ex[None, :] ** 2) < CLEARANCE ** 2
    return ndimage.binary_erosion(free, structure=disc, border_value=0)


def graph(legal, res):
    """The legal cells' 16-neighbour graph (a diagonal needs both side cells legal, a
    knight move the two cells beside its midpoint)."""
    h, w = legal.shape
    idx = np.arange(h * w).reshape(h, w)
    rows, cols, costs = [], [], []
    moves = [(1, 0), (0, 1), (1, 1), (1, -1), (2, 1), (2, -1), (1, 2), (1, -2)]
    for dx, dy in moves:
        ok = np.zeros_like(legal)
        ys, ye = max(0, -dy), min(h, h - dy)
        xs, xe = 0, w - dx
        a = legal[ys:ye, xs:xe] & legal[ys + dy:ye + dy, xs + dx:xe + dx]
        if abs(dx) == 1 and abs(dy) == 1:
            a &= legal[ys:ye, xs + dx:xe + dx] & legal[ys + dy:ye + dy, xs:xe]
        elif dx == 2:
            a &= legal[ys:ye, xs + 1:xe + 1] & legal[ys + dy:ye + dy, xs + 1:xe + 1]
        elif abs(dy) == 2:
            sy = dy // 2
            a &= legal[ys + sy:ye + sy, xs:xe] & legal[ys + sy:ye + sy, xs + 1:xe + 1]
        ok[ys:ye, xs:xe] = a
        yy, xx = np.nonzero(ok)
        rows.append(idx[yy, xx])
        cols.append(idx[yy + dy, xx + dx])
        costs.append(np.full(len(yy), res * np.hypot(dx, dy)))
    r, c, v = np.concatenate(rows), np.concatenate(cols), np.concatenate(costs)
    return coo_matrix((v, (r, c)), shape=(h * w, h * w)).tocsr()


def check_floor(name, n):
    """n placements of scenarios/NAME.yaml against the reference."""
    scn = f"scenarios/{name}.yaml"
    out = sim(scn, "--placements", str(n), "--list-placements")
    check(f"{name}_list", out.returncode == 0, out.stderr)
    pl = table(out.stdout)
    check(f"{name}_count", [int(p["placement"]) for p in pl] == list(range(1, n + 1)))
    mp = [ln.split(":", 1)[1].strip() for ln in open(scn) if ln.startswith("map:")][0]
    free, res, ox, oy = load_map(os.path.join("scenarios", mp))
    legal = legal_cells(free, res)
    g = graph(legal, res)
    h, w = legal.shape
    cy, cx = np.mgrid[0:h, 0:w]
    bad_legal, bad_path, worst = [], [], 0.0
    for p in pl:
        sx, sy, gx, gy = (float(p[k]) for k in ("start_x_m", "start_y_m", "source_x_m", "source_y_m"))
        path = float(p["shortest_path_m"])
        i, j = int((sx - ox) / res), int((sy - oy) / res)
        gi, gj = int((gx - ox) / res), int((gy - oy) / res)
        # The start at least clearance - one core cell (0.1 m) and its diagonal from any
        # cell that is not free; the source on a free cell; the path in range.
        nf = ~free
        yy, xx = np.nonzero(nf[max(0, j - 8):j + 9, max(0, i - 8):i + 9])
        nx = ox + (xx + max(0, i - 8)) * res
        ny = oy + (yy + max(0, j - 8)) * res
        ddx = np.maximum(np.maximum(nx - sx, sx - (nx + res)), 0.0)
        ddy = np.maximum(np.maximum(ny - sy, sy - (ny + res)), 0.0)
        clear = np.min(np.hypot(ddx, ddy)) if len(nx) else 1.0
        if not (free[j, i] and free[gj, gi] and clear >= CLEARANCE - 0.15 and LO_M <= path <= HI_M):
            bad_legal.append((p["placement"], clear, path))
        # Reference path: from the start's cell (the nearest legal one when quantisation
        # puts it just outside) to the legal reachable cell nearest the source.
        if not legal[j, i]:
            ly, lx = np.nonzero(legal[j - 3:j + 4, i - 3:i + 4])
            k = np.argmin((lx - 3) ** 2 + (ly - 3) ** 2)
            i, j = i - 3 + lx[k], j - 3 + ly[k]
        dist = dijkstra(g, directed=False, indices=j * w + i).reshape(h, w)
        gd = np.hypot(ox + (cx + 0.5) * res - gx, oy + (cy + 0.5) * res - gy)
        gd[~np.isfinite(dist)] = np.inf
        k = np.unravel_index(np.argmin(gd), gd.shape)
        ref = dist[k]
        worst = max(worst, abs(path - ref) / ref)
        if not (gd[k] <= STOP_M and abs(path - ref) <= 0.04 * ref + 0.5):
            bad_path.append((p["placement"], path, round(float(ref), 3), round(float(gd[k]), 2)))
    check(f"{name}_pairs_legal", not bad_legal, str(bad_legal[:5]))
    check(f"{name}_paths_match_reference", not bad_path, str(bad_path[:5]))
    print(f"# {name}: {n} placements, largest path difference {100 * worst:.1f} %")
    return pl


def main():
    t = tempfile.mkdtemp(prefix="rfs_placements.")
    # --- the pairs against the reference: a synthetic floor, a real one, the house --------
    lsh = check_floor("lshape", 30)
    check_floor("intel", 15)
    check_floor("house", 15)

    # --- determinism -------------------------------------------------------------------------
    a = sim("scenarios/lshape.yaml", "--placements", "30", "--list-placements").stdout
    b = sim("scenarios/lshape.yaml", "--placements", "21..25", "--list-placements").stdout
    c = sim("scenarios/lshape.yaml", "--placements", "30", "--placement-seed", "2",
            "--list-placements").stdout
    check("same_twice", a == sim("scenarios/lshape.yaml", "--placements", "30",
                                 "--list-placements").stdout)
    check("same_in_any_range", table(b) == lsh[20:25])
    other = table(c)
    check("other_seed_other_pairs", sum(x == y for x, y in zip(other, lsh)) == 0)

    # --- one placement as a single run: the listed shortest path -------------------------------
    one = sim("scenarios/lshape.yaml", "--placement", "7", "--seed", "3")
    s = json.loads(one.stdout) if one.returncode == 0 else {}
    p7 = lsh[6]
    check("single_run_at_placement",
          s.get("placement") == 7 and s.get("placement_seed") == 1 and
          "%.3f" % s["shortest_path_m"] == p7["shortest_path_m"] and
          s["start"] == [float(p7["start_x_m"]), float(p7["start_y_m"])] and
          s["sources"] == [[float(p7["source_x_m"]), float(p7["source_y_m"])]] and
          "%.4f" % s["start_theta_rad"] == p7["start_theta_rad"], one.stderr + str(s)[:300])

    # --- the end-of-run fields against the run's own logs ----------------------------------------
    # still_s: seconds at the end within 2 m of the end point, from track.tsv (10 Hz true
    # poses; summary.json counts whole seconds); belief_error_m: the path-loss estimate's
    # error, or for ridge the last greedy decision's model maximum in log.tsv.
    for model, strategy in (("pathloss", "meta-path"), ("ridge", "meta")):
        d = f"{t}/end-{model}"
        r = sim("scenarios/lshape.yaml", "--placement", "4", "--seed", "2", "--model", model,
                "--strategy", strategy, "--out", d)
        s = json.load(open(f"{d}/summary.json")) if r.returncode == 0 else {}
        trk = np.loadtxt(f"{d}/track.tsv", skiprows=1, usecols=(0, 1, 2), ndmin=2)
        fx, fy, end = s.get("final_x_m", 0), s.get("final_y_m", 0), s.get("sim_time_s", 0)
        out = trk[np.hypot(trk[:, 1] - fx, trk[:, 2] - fy) > 2.0]
        still = end - (out[-1, 0] if len(out) else 0.0)
        logs = table(open(f"{d}/log.tsv").read()) if r.returncode == 0 else []
        greedy = [x for x in logs if x["kind"] == "greedy" and "no_model" not in x["reason"]]
        bx, by = ((s.get("est_src_x_m"), s.get("est_src_y_m")) if model == "pathloss" else
                  (float(greedy[-1]["max_x_m"]), float(greedy[-1]["max_y_m"])) if greedy else (0, 0))
        sx, sy = s.get("sources", [[0, 0]])[0]
        check(f"end_fields_{model}", r.returncode == 0 and abs(s["still_s"] - still) <= 1.1 and
              abs(s["belief_error_m"] - np.hypot(bx - sx, by - sy)) <= 0.002 and
              s["belief_x_m"] == bx, f"{r.stderr} still {s.get('still_s')} vs {still:.2f}, "
              f"belief {s.get('belief_error_m')} vs {np.hypot(bx - sx, by - sy):.3f}")

    # --- batches: table, job list + merge, resume ----------------------------------------------
    args = ["scenarios/lshape.yaml", "--placements", "3..5", "--seeds", "1..2", "--quiet",
            "--strategy", "meta-path", "--model", "pathloss"]  # 0.2-0.5 s a run: time to interrupt
    r = sim(*args, "--jobs", "2", "--out", f"{t}/batch")
    rows = table(open(f"{t}/batch/runs.tsv").read()) if r.returncode == 0 else []
    want = [(str(k), str(sd)) for k in range(3, 6) for sd in (1, 2)]
    check("batch_rows", [(x["placement"], x["seed"]) for x in rows] == want, r.stderr)
    check("batch_rows_placed", all(x["start_x_m"] == lsh[int(x["placement"]) - 1]["start_x_m"] and
                                   x["source_y_m"] == lsh[int(x["placement"]) - 1]["source_y_m"] and
                                   x["shortest_path_m"] == lsh[int(x["placement"]) - 1]["shortest_path_m"]
                                   for x in rows) and len(rows) == 6)
    jobs = sim(*args, "--emit-jobs", "--out", f"{t}/jobs").stdout.strip().split("\n")
    os.mkdir(f"{t}/jobs")
    ok = len(jobs) == 6 and all(subprocess.run(j, shell=True, capture_output=True).returncode == 0
                                for j in jobs)
    m = subprocess.run([sys.executable, "scripts/merge_runs.py", f"{t}/jobs"], capture_output=True,
                       text=True)
    check("emit_jobs_merge", ok and m.returncode == 0 and
          open(f"{t}/jobs/runs.tsv").read() == open(f"{t}/batch/runs.tsv").read(), m.stderr)
    # Interrupted after two runs (SIGINT), then resumed: the same table.
    p = subprocess.Popen([SIM] + args + ["--jobs", "1", "--out", f"{t}/res"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    state = None
    for _ in range(3000):
        tmp = [d for d in os.listdir(t) if d.startswith("res.tmp-")]
        state = os.path.join(t, tmp[0], "batch.state") if tmp else None
        if state and os.path.exists(state) and len(open(state).readlines()) >= 3:
            break
        time.sleep(0.01)
    p.send_signal(signal.SIGINT)
    p.wait()
    rr = sim(*args, "--jobs", "2", "--resume", "--out", f"{t}/res")
    check("resume_placed_batch", p.returncode == 1 and rr.returncode == 0 and
          open(f"{t}/res/runs.tsv").read() == open(f"{t}/batch/runs.tsv").read(), rr.stderr)

    # --- bad input: one line, exit 1 -----------------------------------------------------------
    def bad(name, want, *a):
        r = sim(*a)
        lines = r.stderr.strip().split("\n")
        check(name, r.returncode == 1 and len(lines) == 1 and want in r.stderr, r.stderr)
    scn = "scenarios/lshape.yaml"
    bad("bad_zero", "--placements: expected N or A..B", scn, "--placements", "0", "--list-placements")
    bad("bad_too_many", "at most 10000 placements", scn, "--placements", "10001", "--list-placements")
    bad("bad_range", "--placements: expected N or A..B", scn, "--placements", "5..3", "--list-placements")
    bad("bad_word", "got 'many'", scn, "--placements", "many", "--list-placements")
    bad("bad_index", "--placement: expected a number from 1", scn, "--placement", "0")
    bad("bad_seed_alone", "--placement-seed needs --placements", scn, "--placement-seed", "3")
    bad("bad_with_start", "not with --start", scn, "--placements", "3", "--seeds", "1..2", "--start", "11,5")
    bad("bad_no_seeds", "--placements needs --seeds", scn, "--placements", "3")
    bad("bad_list_out", "--list-placements needs --placements", scn, "--placements", "3",
        "--list-placements", "--out", f"{t}/x")
    bad("bad_two_sources", "placements need a scenario with one source", "scenarios/bridge.yaml",
        "--placements", "3", "--list-placements")
    # A 6 x 6 m room: no path as long as 10 m anywhere.
    room = np.full((140, 140), 205, np.uint8)
    room[10:130, 10:130] = 0
    room[12:128, 12:128] = 254
    Image.fromarray(room).save(f"{t}/room.pgm")
    open(f"{t}/room.yaml", "w").write("image: room.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                      "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    open(f"{t}/room_s.yaml", "w").write(f"map: {t}/room.yaml\nsources: [{{position: [3.5, 3.5]}}]\n"
                                        "start: {position: [2.0, 2.0]}\n")
    bad("bad_small_floor", "no start and source 10 to 40 m apart", f"{t}/room_s.yaml", "--placements",
        "2", "--list-placements")
    subprocess.run(["rm", "-rf", "--", t])
    return exit_status()


if __name__ == "__main__":
    sys.exit(main())
