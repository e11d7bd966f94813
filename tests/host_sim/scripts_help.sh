#!/usr/bin/env bash
# scripts_help.sh - every program in scripts/ answers --help: exit status 0, a usage text on
# stdout that names the program or says "usage", and nothing written where it runs (each
# runs in an empty folder of its own). One PASS/FAIL line per program.
#   tests/host_sim/scripts_help.sh [PYTHON]      (default /usr/bin/python3)
set -uo pipefail
py=${1:-/usr/bin/python3}
root=$(cd "$(dirname "$0")/../.." && pwd)
rc=0
for f in "$root"/scripts/*.sh "$root"/scripts/*.py "$root"/scripts/lint/run_lint.sh; do
    name=${f#"$root"/}
    base=$(basename "$f")
    d=$(mktemp -d)
    case "$f" in
        *.py) run=("$py" "$f") ;;
        *) run=(bash "$f") ;;
    esac
    out=$(cd "$d" && timeout 60 "${run[@]}" --help 2>"$d.err" </dev/null)
    st=$?
    left=$(ls -A "$d")
    why=""
    [ -x "$f" ] || why="not executable"
    [ $st -eq 0 ] || why="exit status $st: $(head -c 200 "$d.err" | tr '\n' ' ')"
    [ -z "$why" ] && [ -z "$out" ] && why="nothing on stdout"
    [ -z "$why" ] && ! grep -qiE "usage|${base%.*}" <<<"$out" && why="neither its name nor 'usage' in: $(head -1 <<<"$out")"
    [ -z "$why" ] && [ -n "$left" ] && why="wrote $(echo $left)"
    if [ -z "$why" ]; then echo "PASS help $name"; else echo "FAIL help $name: $why"; rc=1; fi
    rm -rf "$d" "$d.err"
done
exit $rc
