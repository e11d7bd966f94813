#!/usr/bin/env bash
# demo.sh - run the default scenario and draw the paper's figures 2 to 4 (make demo).
#   scripts/demo.sh [OUTDIR]      (default out/demo; uses $BUILD/bin/rfseek-sim)
# The run goes to OUTDIR/run (replaced), the figures to OUTDIR/*.png.
# A second run with the map-aware path-loss model (--model pathloss --strategy
# meta-path) goes to OUTDIR/pathloss/run, its figures (with residual.png) to OUTDIR/pathloss.
set -euo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
OUT=${1:-out/demo}
SIM=${BUILD:-build}/bin/rfseek-sim
SEED=${SEED:-1}
mkdir -p "$OUT"
rm -rf -- "$OUT/run"
"$SIM" scenarios/default.yaml --seed "$SEED" --field --out "$OUT/run" >/dev/null
/usr/bin/python3 scripts/plot_run.py "$OUT/run" --outdir "$OUT"
echo "demo (the paper's meta + ridge, seed $SEED): $(grep -E '"(reached|distance_travelled_m|shortest_path_m|model_updates)"' "$OUT/run/summary.json" | tr -d ' \n')"
echo "demo: figures in $OUT: trajectory.png rssi.png hexbin.png"
mkdir -p "$OUT/pathloss"
rm -rf -- "$OUT/pathloss/run"
"$SIM" scenarios/default.yaml --seed "$SEED" --model pathloss --strategy meta-path \
    --out "$OUT/pathloss/run" >/dev/null
/usr/bin/python3 scripts/plot_run.py "$OUT/pathloss/run" --outdir "$OUT/pathloss"
echo "demo (meta-path + pathloss, seed $SEED): $(grep -E '"(reached|distance_travelled_m|shortest_path_m|est_error_m|est_area_m2)"' "$OUT/pathloss/run/summary.json" | tr -d ' \n')"
echo "demo: figures in $OUT/pathloss: trajectory.png rssi.png residual.png"
