#!/usr/bin/env bash
# pathloss_out.sh - the path-loss model's estimate and residual surface in the simulator's
# outputs (host side): log.tsv columns, summary.json, residual.tsv and
# residual.png; other models leave the same columns "nan" / null.
#   tests/host_sim/pathloss_out.sh build/bin/rfseek-sim        (from the repository root)
# Expected values are recomputed in python from the files (positions -> distances), never
# copied from the program.
set -uo pipefail
SIM=${1:?usage: pathloss_out.sh path/to/rfseek-sim}
T=$(mktemp -d /tmp/rfs_plhost.XXXXXX)
trap 'rm -rf -- "$T"' EXIT
. "$(dirname "$0")/../lib/checks.sh"

# One pathloss run on the default office and one on the L-shaped floor, one ridge run.
for r in "pl default.yaml --model pathloss --strategy meta-path" \
         "pll lshape.yaml --model pathloss --strategy meta-path" \
         "ridge default.yaml --model ridge"; do
    set -- $r
    name=$1 scn=$2
    shift 2
    if "$SIM" "scenarios/$scn" --seed 1 "$@" --out "$T/$name" >"$T/$name.out" 2>&1; then
        pass "run_$name"
    else
        fail "run_$name" "$(head -c 300 "$T/$name.out")"
    fi
done

# residual.tsv: the final estimate (summary.json and the last log row agree) within 2 m
# of one of the surface's three lowest points (the fit refines around its best 3 coarse
# candidates, 2 m apart, by less than a coarse step; docs/PATHLOSS.md) or held round the
# previous estimate (hold_k and the hold search), est_error_m = |estimate - source 0| recomputed here, stable columns.
for name in pl pll; do
    if /usr/bin/python3 - "$T/$name" <<'EOF'
import json, math, sys
d = sys.argv[1]
s = json.load(open(d + "/summary.json"))
with open(d + "/residual.tsv") as f:
    assert f.readline() == "x_m\ty_m\tresidual_db\tcell_x_m\tcell_y_m\n", "residual.tsv header"
    res = [tuple(float(v) for v in line.split("\t")) for line in f]
assert len(res) >= 10, "residual.tsv: %d rows" % len(res)
assert all(math.isfinite(r[2]) and r[2] >= 0.0 for r in res), "residual values"
# each candidate lies in its cell (the grid point or its snap, within a coarse half-step)
# and the cells are distinct points of one regular grid
cells = sorted({(r[3], r[4]) for r in res})
assert len(cells) == len(res), "residual.tsv: a cell twice"
step = min(abs(a[0] - b[0]) for a in cells for b in cells if a[0] != b[0])
assert all(abs(r[0] - r[3]) <= step / 2 + 1e-3 and abs(r[1] - r[4]) <= step / 2 + 1e-3
           for r in res), "residual.tsv: a candidate outside its cell"
with open(d + "/log.tsv") as f:
    head = f.readline().rstrip("\n").split("\t")
    rows = [line.rstrip("\n").split("\t") for line in f]
assert head[-6:] == ["est_src_x_m", "est_src_y_m", "est_n", "est_w_db", "est_p0",
                     "est_area_m2"], head[-6:]
assert all(len(r) == len(head) for r in rows), "log.tsv: ragged rows"
last = rows[-1]
lx, ly = float(last[head.index("est_src_x_m")]), float(last[head.index("est_src_y_m")])
ex, ey = s["est_src_x_m"], s["est_src_y_m"]
assert abs(lx - ex) <= 0.0015 and abs(ly - ey) <= 0.0015, ((lx, ly), (ex, ey))
low = sorted(res, key=lambda r: r[2])[:3]
dmin = min(math.hypot(r[0] - lx, r[1] - ly) for r in low)
# Or the last relearn held the previous source (hold_k): the hold search climbs at most
# 1 + 0.5 + 0.25 m along each axis from the previous estimate (the row before the last
# relearn's).
rel = [i for i, r in enumerate(rows) if r[head.index("relearned")] == "1"]
px = py = float("nan")
if rel and rel[-1] > 0:
    p = rows[rel[-1] - 1]
    px, py = float(p[head.index("est_src_x_m")]), float(p[head.index("est_src_y_m")])
held = abs(lx - px) <= 1.7515 and abs(ly - py) <= 1.7515
assert dmin <= 2.0 or held, ("the surface's three lowest points %s are %.3f m or more from "
                             "the estimate, and the previous estimate (%.3f, %.3f) is not "
                             "within 1.75 m" % ([(r[0], r[1]) for r in low], dmin, px, py))
sx, sy = s["sources"][0]
err = math.hypot(ex - sx, ey - sy)
# Both sides are printed to 1 mm: the recomputed distance may differ by rounding only.
assert abs(err - s["est_error_m"]) <= 0.002, (err, s["est_error_m"])
assert 1.5 <= s["est_n"] <= 5.0 and 0.0 <= s["est_w_db"] <= 15.0, "n, W outside their bounds"
assert s["est_area_m2"] > 0.0, "uncertainty area"
print("%s: estimate (%.3f, %.3f), error %.3f m, surface minimum %.3f m away, %d candidates"
      % (d, ex, ey, err, dmin, len(res)))
EOF
    then pass "residual_$name"; else fail "residual_$name"; fi
done

# Other models: the same columns, all "nan"; summary est_* null; no residual.tsv.
if /usr/bin/python3 - "$T/ridge" "$T/pl" <<'EOF'
import json, os, sys
d, pl = sys.argv[1], sys.argv[2]
s = json.load(open(d + "/summary.json"))
with open(d + "/log.tsv") as f:
    head = f.readline().rstrip("\n").split("\t")
    rows = [line.rstrip("\n").split("\t") for line in f]
assert head == open(pl + "/log.tsv").readline().rstrip("\n").split("\t"), "header differs"
assert rows and all(len(r) == len(head) for r in rows), "log.tsv: ragged rows"
assert all(v == "nan" for r in rows for v in r[-6:]), "ridge rows carry an estimate"
for k in ("est_src_x_m", "est_src_y_m", "est_n", "est_w_db", "est_p0", "est_area_m2",
          "est_error_m"):
    assert k in s and s[k] is None, k
assert not os.path.exists(d + "/residual.tsv")
EOF
then pass other_model_nan; else fail other_model_nan; fi

# The plot script draws residual.png for pathloss runs only.
if /usr/bin/python3 scripts/plot_run.py "$T/pl" >"$T/plot.out" 2>&1 &&
   [ "$(head -c 8 "$T/pl/residual.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] &&
   /usr/bin/python3 scripts/plot_run.py "$T/ridge" >>"$T/plot.out" 2>&1 &&
   [ ! -e "$T/ridge/residual.png" ] && [ -s "$T/ridge/trajectory.png" ]; then
    pass plot_residual
else
    fail plot_residual "$(head -c 300 "$T/plot.out")"
fi

# Bad residual.tsv: one error line naming the file, exit 1, no residual.png.
rm -f "$T/pl/residual.png"
printf 'x_m\ty_m\tresidual_db\n1.0\tabc\t2.0\n' >"$T/pl/residual.tsv"
/usr/bin/python3 scripts/plot_run.py "$T/pl" >"$T/bad.out" 2>"$T/bad.err"
rc=$?
if [ $rc -eq 1 ] && [ "$(wc -l <"$T/bad.err")" -eq 1 ] && grep -q "residual.tsv" "$T/bad.err" &&
   [ ! -e "$T/pl/residual.png" ]; then
    pass plot_bad_residual
else
    fail plot_bad_residual "exit $rc: $(head -c 300 "$T/bad.err")"
fi

[ $fails -eq 0 ]
