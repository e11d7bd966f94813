#!/usr/bin/env bash
# run_lint.sh - cppcheck and clang-tidy over common/, firmware/ and host_sim/ (make lint;
# the check set and its reasons are in docs/RELIABILITY.md). Prints the findings and one
# PASS/FAIL line per tool; exits non-zero when either finds anything.
#   scripts/lint/run_lint.sh BUILD [cppcheck|clang-tidy]...
# BUILD must hold the generated LCM headers (BUILD/gen, from `make`).
set -uo pipefail
case "${1:-}" in -h | --help) sed -n '2,/^[^#]/s/^# \{0,1\}//p' "$0"; exit 0 ;; esac
build=${1:?usage: run_lint.sh BUILD [cppcheck|clang-tidy]...}
shift
tools=("$@")
[ ${#tools[@]} -gt 0 ] || tools=(cppcheck clang-tidy)
jobs=${LINT_JOBS:-2}
rc=0
out=$(mktemp); trap 'rm -f "$out"' EXIT

# Clang-tidy checks: the static analyzer (minus the C11 Annex K advice: memcpy/snprintf are
# what the core may use), bugprone (minus style-only ones), and the CERT C rules on
# conversions, float loop counters, rand() and string/char sign.
TIDY_CHECKS='-*,clang-analyzer-*,-clang-analyzer-security.insecureAPI.DeprecatedOrUnsafeBufferHandling,bugprone-*,-bugprone-easily-swappable-parameters,-bugprone-narrowing-conversions,-bugprone-reserved-identifier,-bugprone-implicit-widening-of-multiplication-result,cert-err34-c,cert-flp30-c,cert-msc30-c,cert-str34-c,misc-redundant-expression,readability-function-size'

# Function size (docs/ARCHITECTURE.md, "For contributors"): at most 100 lines in the core,
# 120 elsewhere, counted by clang-tidy's readability-function-size.
size_of() {
    case $1 in
        common/*) echo 100 ;;
        *) echo 120 ;;
    esac
}

# Per-file compile flags, as the Makefiles use them.
flags_of() {
    case $1 in
        common/*) echo "-std=c11 -ffreestanding -Icommon" ;;
        firmware/port/linux/*) echo "-std=c11 -D_DEFAULT_SOURCE -Icommon -Ifirmware -Ifirmware/port/linux -I$build/gen $(pkg-config --cflags yaml-0.1 libpng 2>/dev/null)" ;;
        firmware/port/*) echo "-std=c11 -ffreestanding --target=arm-none-eabi -mcpu=cortex-m4 -mthumb -mfloat-abi=soft -isystem /usr/lib/arm-none-eabi/include -Icommon -Ifirmware -Ifirmware/port/stm32f4 -Ifirmware/port/qemu" ;;
        firmware/*) echo "-std=c11 -Icommon -Ifirmware" ;;
        *.cpp) echo "-std=c++17 -Icommon -Ifirmware -Ifirmware/port/linux -Ihost_sim" ;;
        *) echo "-std=c11 -D_DEFAULT_SOURCE -Icommon -Ifirmware -Ifirmware/port/linux -Ihost_sim -I$build/gen" ;;
    esac
}

files=$(find common firmware host_sim -name '*.c' -o -name '*.cpp' | sort)

for tool in "${tools[@]}"; do
    start=$(date +%s)
    case $tool in
    cppcheck)
        # RFS_ASSERT is shown to cppcheck as assert() (scripts/lint/cppcheck_assert.h).
        cppcheck --enable=warning,portability,performance --std=c11 --inline-suppr -q \
            --suppress=missingIncludeSystem --error-exitcode=1 -j "$jobs" \
            -DRFS_ASSERT_H --include=scripts/lint/cppcheck_assert.h \
            -Icommon -Ifirmware -Ifirmware/port/linux -Ihost_sim -I"$build/gen" \
            --template='{file}:{line}: {severity} {id}: {message}' common firmware host_sim >"$out" 2>&1
        status=$?
        ;;
    clang-tidy)
        # One clang-tidy per file, $jobs at a time; findings only (-quiet), every finding an error.
        logs=$(mktemp -d)
        export -f flags_of size_of
        export build TIDY_CHECKS logs
        printf '%s\n' $files | xargs -P "$jobs" -n 1 bash -c \
            'clang-tidy -quiet --checks="$TIDY_CHECKS" --warnings-as-errors="*" \
                 --config="{CheckOptions: [{key: readability-function-size.LineThreshold, value: $(size_of "$0")}]}" \
                 "$0" -- $(flags_of "$0") \
                 >"$logs/$(echo "$0" | tr / _).log" 2>/dev/null || echo "$0" >>"$logs/failed"'
        cat "$logs"/*.log >"$out" 2>/dev/null
        status=0
        [ -e "$logs/failed" ] && status=1
        rm -rf "$logs"
        ;;
    *) echo "run_lint.sh: unknown tool '$tool' (cppcheck or clang-tidy)" >&2; exit 2 ;;
    esac
    secs=$(($(date +%s) - start))
    n=$(grep -cE '(warning|error|style|performance|portability)[: ]' "$out")
    if [ $status -eq 0 ]; then
        echo "PASS lint $tool: 0 findings over $(echo "$files" | wc -l) files (${secs} s)"
    else
        cat "$out"
        echo "FAIL lint $tool: $n findings (${secs} s)"
        rc=1
    fi
done
exit $rc
