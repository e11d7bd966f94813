#!/usr/bin/env bash
# strategy_cli.sh SIM - rfseek-sim's --strategy / --model options and the
# analysis scripts' own input checks: bad names or options give one error line and exit 1; good
# names run and are reported in summary.json.
set -u
sim=${1:?usage: strategy_cli.sh path/to/rfseek-sim}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
. "$(dirname "$0")/../lib/checks.sh"

"$sim" scenarios/default.yaml --seed 1 --strategy gradient >"$tmp/o" 2>"$tmp/e"
rc=$?
check strategy-unknown-exit '[ $rc -eq 1 ]'
check strategy-unknown-one-line '[ "$(wc -l <"$tmp/e")" -eq 1 ] && grep -q "^rfseek-sim: --strategy: unknown .gradient." "$tmp/e"'
check strategy-unknown-no-stdout '[ ! -s "$tmp/o" ]'

"$sim" scenarios/default.yaml --seed 1 --model ridge2 >"$tmp/o" 2>"$tmp/e"
rc=$?
check model-unknown-exit '[ $rc -eq 1 ]'
check model-unknown-one-line '[ "$(wc -l <"$tmp/e")" -eq 1 ] && grep -q "^rfseek-sim: --model: unknown .ridge2." "$tmp/e"'

"$sim" scenarios/default.yaml --seed 1 --strategy >"$tmp/o" 2>"$tmp/e"
check strategy-missing-name '[ $? -eq 1 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ]'

# A scenario naming an unknown strategy is rejected when the run starts.
sed -e 's/^strategy: meta$/strategy: spiral/' -e "s|^map: |map: $PWD/scenarios/|" \
    scenarios/default.yaml >"$tmp/bad.yaml"
"$sim" "$tmp/bad.yaml" --seed 1 >"$tmp/o" 2>"$tmp/e"
rc=$?
check scenario-strategy-unknown '[ $rc -eq 1 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && grep -q "strategy: unknown .spiral." "$tmp/e"'

for st in fd-gradient chemotaxis plane-gradient meta-global; do
    "$sim" scenarios/open.yaml --seed 2 --strategy "$st" --out "$tmp/run-$st" 2>"$tmp/e"
    rc=$?
    check "run-$st" '[ $rc -eq 0 ] && grep -q "\"strategy\": \"$st\"" "$tmp/run-$st/summary.json"'
done
# The decision kinds of each strategy appear in its log (and only those).
check log-kinds-fd '[ -z "$(cut -f8 "$tmp/run-fd-gradient/log.tsv" | tail -n +2 | sort -u | grep -vx -e probe -e gradient -e tumble)" ] && cut -f8 "$tmp/run-fd-gradient/log.tsv" | grep -qx probe'
check log-kinds-chemo '[ -z "$(cut -f8 "$tmp/run-chemotaxis/log.tsv" | tail -n +2 | sort -u | grep -vx -e run -e tumble)" ]'
check log-kinds-plane '[ -z "$(cut -f8 "$tmp/run-plane-gradient/log.tsv" | tail -n +2 | sort -u | grep -vx -e initial -e gradient -e tumble)" ]'

"$sim" scenarios/open.yaml --seed 2 --model pathloss --out "$tmp/run-pl" 2>"$tmp/e"
check run-model-pathloss '[ $? -eq 0 ] && grep -q "\"model\": \"pathloss\"" "$tmp/run-pl/summary.json"'

/usr/bin/python3 scripts/bench_seek.py --bin "$tmp/nonexistent" >"$tmp/o" 2>"$tmp/e"
rc=$?
check bench-bad-bin '[ $rc -eq 1 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && grep -q "nonexistent: not an executable" "$tmp/e"'
# The analysis scripts: a bad option is one line on stderr, exit 1, nothing on stdout.
i=0
while IFS='|' read -r script args want; do
    i=$((i + 1))
    # shellcheck disable=SC2086
    /usr/bin/python3 "scripts/$script" $args >"$tmp/o" 2>"$tmp/e"
    rc=$?
    check "script-bad-option-$i-$script" '[ $rc -eq 1 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && [ ! -s "$tmp/o" ] && grep -q -- "$want" "$tmp/e"'
done <<'LIST'
bench_drive.py|--seeds x|--seeds: expected A..B
bench_drive.py|--floors nope|unknown floor 'nope'
bench_drive.py|--all-floors nope|'nope' is not a shipped floor
bench_drive.py|--sim /nonexistent|/nonexistent: not an executable
mlp_steps.py|--seeds 5..1|'5..1' is not A..B
mlp_steps.py|--sim /nonexistent|/nonexistent: not an executable
bench_general.py|--placements 0|--placements: expected an even number
bench_general.py|--sim /nonexistent|/nonexistent: not an executable
bench_general.py|--seek bogus:1|a space after each colon
bench_general.py|--only x --no-write|--only: expected p or r
bench_general.py|--placement-seed 0 --no-write|--placement-seed: expected a positive integer
bench_general.py|--placement-seed 2|--placement-seed and --only need --no-write
bench_general.py|--placement-seed 2 --no-write --held-out-only|only placement seed 1 has held-out draws
bench_bridge.py|--sim /nonexistent|/nonexistent: not an executable
bench_bridge.py|--seeds x|--seeds: expected A..B
bridge_bounds.py|--sim /nonexistent scenarios/bridge.yaml 1..2|/nonexistent: not an executable
bridge_bounds.py|scenarios/nope.yaml 1..2|no such scenario file
bench_seek.py|--bin /bin/true --first-seed 0|--first-seed and --jobs must be at least 1
bench_pathloss_seek.py|--first-seed 0|--first-seed must be at least 1
bench_pathloss_seek.py|--jobs -1|--jobs must be 0 (all cores) or more
bench_pathloss_seek.py|--seek leg_m:2 --no-write|a space after each colon
bench_pathloss_seek.py|--only-pathloss|--seek and --only-pathloss need --no-write
bench_pathloss_seek.py|--sim /nonexistent|/nonexistent: not an executable
bench_general.py|--seeds 5..1|--seeds: expected A..B with A <= B
bench_general.py|--jobs 0|--jobs: expected a number from 1 to 1024
fault_table.py|--sim /nonexistent|--sim: /nonexistent: not an executable
fault_table.py|--sim /bin/true --maps nope|no scenarios/faults/nope-\*.yaml
compare_plan.py|--base /nonexistent|--base: /nonexistent: not an executable
map2c.py|scenarios/maps/office.yaml -o /nonexistent/x.c|/nonexistent/x.c: its folder does not exist
check_candump.py|can/rfseek.dbc x.log --bogus|--bogus: unknown option
check_candump.py|can/rfseek.dbc /nonexistent.log|/nonexistent.log: No such file or directory
check_dbc.py|x|usage: check_dbc.py DBC VECTORS_FILE
ref_ridge.py|/nonexistent.txt out.txt|/nonexistent.txt: No such file or directory
ref_xoshiro.py|1x|invalid literal for int()
gen_captures.py|--bogus|usage: gen_captures.py OUTDIR
LIST
# The shell scripts: a bad argument is one line on stderr, exit 1, nothing written.
while IFS='|' read -r script args want; do
    # shellcheck disable=SC2086
    bash "scripts/$script" $args >"$tmp/o" 2>"$tmp/e"
    rc=$?
    check "script-bad-arg-$script-${args%% *}" '[ $rc -eq 1 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && [ ! -s "$tmp/o" ] && [ ! -e "$tmp/id" ] && grep -q -- "$want" "$tmp/e"'
done <<LIST
fw_budget.sh||usage: fw_budget.sh ELF
fw_budget.sh|/nonexistent.elf|fw_budget.sh: /nonexistent.elf: no such file
check_core_symbols.sh|nm|usage: check_core_symbols.sh NM LIB
identity.sh|/nonexistent $tmp/id 1..1|identity.sh: /nonexistent: not an executable
identity.sh|$sim $tmp/id 5|identity.sh: SEEDS: expected A..B, got '5'
LIST
# argparse's errors: one line (not its usage as well), exit 2.
/usr/bin/python3 scripts/check_docs.py --bogus >"$tmp/o" 2>"$tmp/e"
check script-argparse-one-line '[ $? -eq 2 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && grep -q "^check_docs.py: unrecognized arguments: --bogus" "$tmp/e"'
# tests/fuzz/make_corpus.py: an option is not a folder to write into; and the committed
# seeds are what it writes today (a scenario or format change regenerates them).
(cd "$tmp" && /usr/bin/python3 "$OLDPWD/tests/fuzz/make_corpus.py" --bogus) >"$tmp/o" 2>"$tmp/e"
check fuzz-corpus-bad-arg '[ $? -eq 1 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && [ ! -e "$tmp/--bogus" ] && grep -q "^make_corpus.py: expected at most one argument" "$tmp/e"'
/usr/bin/python3 tests/fuzz/make_corpus.py "$tmp/corpus" >/dev/null 2>&1
rc=$?
stale=$(cd "$tmp/corpus" && find . -type f | while read -r f; do cmp -s "$f" "$OLDPWD/tests/fuzz/corpus/$f" || echo "$f"; done)
check fuzz-corpus-current '[ $rc -eq 0 ] && [ -d "$tmp/corpus/can" ] && [ -z "$stale" ]'

# bench_pathloss_seek.py --only-pathloss --seek: one line a row, the meta-path + pathloss
# column run with the variant: its default-office ratio is rfseek-sim's own for that seed.
/usr/bin/python3 scripts/bench_pathloss_seek.py --sim "$sim" --seeds 1 --first-seed 7 --jobs 2 \
    --only-pathloss --no-write --seek 'leg_m: 6' >"$tmp/pls" 2>"$tmp/e"
rc=$?
"$sim" scenarios/default.yaml --strategy meta-path --model pathloss --seed 7 --seek 'leg_m: 6' \
    >"$tmp/pls.json" 2>/dev/null
want=$(/usr/bin/python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print("%.2f" % (r["distance_travelled_m"] / r["shortest_path_m"]))' "$tmp/pls.json")
check pathloss-seek-only '[ $rc -eq 0 ] && [ "$(grep -c " | meta-path + pathloss | " "$tmp/pls")" -eq 9 ] && grep -q "^default office | meta-path + pathloss | .*, $want\$" "$tmp/pls"'
[ $fails -eq 0 ]
