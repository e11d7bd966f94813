#!/usr/bin/env bash
# The DBC loads in canmatrix and decodes our encoded frames field by field.
# usage: tests/wire/dbc_test.sh BUILD
set -uo pipefail
build=${1:?usage: dbc_test.sh BUILD}
out=$build/tests/wire/can_vectors.txt
"$build/tests/wire/can_vectors" > "$out.tmp" && mv "$out.tmp" "$out" || { echo "FAIL can-vectors: encoder program failed"; exit 1; }
/usr/bin/python3 scripts/check_dbc.py can/rfseek.dbc "$out"
rc=$?
# The checker must notice a wrong byte: flip one payload nibble and expect a failure.
sed '1s/^\(100#..\)\(.\)/\1F/' "$out" > "$out.bad"
if /usr/bin/python3 scripts/check_dbc.py can/rfseek.dbc "$out.bad" > /dev/null; then
    echo "FAIL dbc-negative: a corrupted frame was not detected"; rc=1
else
    echo "PASS dbc-negative: a corrupted frame is detected"
fi
exit $rc
