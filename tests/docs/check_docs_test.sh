#!/usr/bin/env bash
# check_docs_test.sh - scripts/check_docs.py fails on a copy of the docs with a scenario key
# left undocumented while the key's name still appears in prose ("seed": the example
# scenario's `seed:` line removed), and on a section reference that resolves nowhere; it
# passes on the tree as it is.
#   tests/docs/check_docs_test.sh [PYTHON]      (default /usr/bin/python3)
set -uo pipefail
py=${1:-/usr/bin/python3}
root=$(cd "$(dirname "$0")/../.." && pwd)
. "$root/tests/lib/checks.sh"
w=$(mktemp -d)
trap 'rm -rf "$w"' EXIT
mkdir -p "$w/docs" "$w/host_sim" "$w/scripts"
cp "$root"/README.md "$root"/CHANGELOG.md "$w/" && cp "$root"/docs/*.md "$w/docs/" &&
    cp "$root"/host_sim/hs_scenario.c "$w/host_sim/" || fail copy
"$py" "$root/scripts/check_docs.py" --root "$w" >"$w/out" && grep -q '^PASS docs' "$w/out" &&
    pass check-docs-tree || fail check-docs-tree "$(head -3 "$w/out")"
cp "$w/docs/SIMULATOR.md" "$w/sim.md"
sed -i '/^seed: [0-9]/d' "$w/docs/SIMULATOR.md"
grep -qw seed "$w/docs/SIMULATOR.md" || fail check-docs-fixture "no prose seed left"
"$py" "$root/scripts/check_docs.py" --root "$w" >"$w/out"
check check-docs-key-only-in-prose '[ $? -eq 1 ] && grep -q "^FAIL docs: docs/SIMULATOR.md: key scenario.seed " "$w/out"'
cp "$w/sim.md" "$w/docs/SIMULATOR.md"
echo 'See docs/CAN.md, "No such section".' >>"$w/docs/FAULTS.md"
"$py" "$root/scripts/check_docs.py" --root "$w" >"$w/out"
check check-docs-missing-section '[ $? -eq 1 ] && grep -q "docs/CAN.md has no section \"No such section\"" "$w/out"'
exit $((fails > 0))
