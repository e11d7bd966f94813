# tests/lib/checks.sh - the PASS/FAIL lines of the test scripts (bash), sourced once near
# the top of a script:   . "$(dirname "$0")/../lib/checks.sh"
# scripts/run_tests.sh (TEST_SCRIPTS of the Makefile) counts the lines of a script's output
# that begin "PASS " and "FAIL ", and fails the script on any FAIL line or a non-zero exit;
# a script using these ends with `exit $((fails > 0))` (or `[ $fails -eq 0 ]`).

fails=0 # FAIL lines printed so far

# pass NAME: one check passed.
pass() { echo "PASS $1"; }

# fail NAME [WHY]: one check failed, printed "FAIL NAME: WHY" (or "FAIL NAME").
fail() { echo "FAIL $1${2:+: $2}"; fails=$((fails + 1)); }

# check NAME EXPR: NAME passes when the shell text EXPR succeeds. EXPR is evaluated in
# here, single-quoted by the caller; its $? is the status of the caller's last command.
check() { if eval "$2"; then pass "$1"; else fail "$1"; fi; }

# check_rc NAME STATUS: NAME passes when STATUS (a command's $?) is 0.
check_rc() { if [ "$2" = 0 ]; then pass "$1"; else fail "$1"; fi; }
