"""checks.py - the PASS/FAIL lines of the Python test scripts (the twin of checks.sh).

    sys.path.insert(0, <this directory>); from checks import check, exit_status

scripts/run_tests.sh (TEST_SCRIPTS of the Makefile) counts the output lines that begin
"PASS " and "FAIL " and fails a script on any FAIL line or a non-zero exit; a script
using these exits with exit_status(): 1 after any failed check, otherwise 0.
"""

_failed = [0]  # FAIL lines printed so far (a list: changed in place by check)


def check(name, ok, detail=""):
    """One check: prints "PASS name", or "FAIL name: detail" and counts it."""
    print(("PASS " if ok else "FAIL ") + name + ("" if ok else ": " + detail))
    _failed[0] += 0 if ok else 1


def exit_status():
    """The exit status so far: 1 after any failed check, otherwise 0."""
    return 1 if _failed[0] else 0
