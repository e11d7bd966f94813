#!/usr/bin/env bash
# identity.sh SIM OUTDIR [SEEDS] - one runs.tsv per scenario x strategy x model, for proving a
# change behaviour-preserving (docs/ARCHITECTURE.md, "Bit-identical runs"): run it with the
# old and the new rfseek-sim into two folders, then `diff -r` them.
#   SCENARIOS="default lshape 3ne" (default), SEEDS 1..50 (default), JOBS=2; MODELS and
#   STRATEGIES narrow the sweep (default: every model and strategy below); ARGS adds
#   rfseek-sim options to every run (e.g. ARGS="--fit-budget mcu")
set -u
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
sim=${1:?usage: identity.sh SIM OUTDIR [SEEDS]} out=${2:?usage: identity.sh SIM OUTDIR [SEEDS]}
seeds=${3:-1..50}
# Checked first: a bad SIM or SEEDS would fill every file with the same ERROR (diff: equal).
[ -x "$sim" ] || { echo "identity.sh: $sim: not an executable" >&2; exit 1; }
[[ $seeds =~ ^[0-9]+\.\.[0-9]+$ ]] || { echo "identity.sh: SEEDS: expected A..B, got '$seeds'" >&2; exit 1; }
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
for model in ${MODELS:-ridge radius pathloss knn mlp}; do
for sc in ${SCENARIOS:-default lshape 3ne}; do
for st in ${STRATEGIES:-meta meta-global fd-gradient plane-gradient chemotaxis meta-path}; do
    f="$out/${sc}_${st}_${model}.tsv"
    [ -s "$f" ] && continue
    d=$(mktemp -d)
    if "$sim" "$here/scenarios/$sc.yaml" --strategy "$st" --model "$model" --seeds "$seeds" \
           --jobs "${JOBS:-2}" --quiet --out "$d/o" ${ARGS:-} > "$d/log" 2>&1; then
        cp "$d/o/runs.tsv" "$f"
    else
        { echo "ERROR"; cat "$d/log"; } > "$f"
    fi
    rm -rf "$d"
done; done; done
