#!/usr/bin/env bash
# bench_models.sh check|bench BUILD - the internal models on the Cortex-M4 image
# (BUILD/firmware/bench_models.elf under qemu-system-arm -M netduinoplus2 -icount shift=7;
# firmware/port/qemu/bench_models.c, models_work.c).
#
#   check  (make test) 1,000 samples, the image's "sum_*" lines (samples, predictions after
#          a whole and after a sliced relearn, the grid search's maximum, pathloss's argmax)
#          must equal the host twin's (BUILD/tests/bench_models_host: the same run on the
#          host build of the core) bit for bit; the baked office map must be the host
#          loader's; every registered model's heaviest fit slice at its registry budget
#          (rfs_models_entry_t.mcu_fit_budget) must stay under the 200 ms deadline,
#          33,600,000 instructions at 168 MHz (exact counts under -icount, not wall time).
#          PASS/FAIL lines, non-zero exit on a failure.
#   bench  (make bench-models-m4) 10,000 samples; SysTick ticks converted to instructions
#          with the image's 1,000-NOP calibration (21.504 ticks per instruction: each
#          instruction advances qemu's virtual clock 2^7 ns, SysTick counts 168 MHz), the
#          table of docs/PERFORMANCE.md, "Models on the Cortex-M4". Further arguments
#          MODEL:BUDGET (up to 8) add sliced relearns at those budgets (how the registry
#          budgets were chosen), e.g. bench BUILD mlp:600 mlp:800.
set -euo pipefail
mode=${1:-}
B=${2:-build}
shift 2 || shift $#
if [ "$mode" = --help ]; then sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
elf=$B/firmware/bench_models.elf
run_image() { # run_image APPEND OUT: the image's console into OUT, its exit status returned
    timeout "$3" qemu-system-arm -M netduinoplus2 -nographic -monitor none -serial null \
        -semihosting-config enable=on,target=native -icount shift=7 -kernel "$elf" \
        -append "$1" >"$2" 2>&1
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

case "$mode" in
check)
    # 1,000 samples: enough that every model's registry budget slices its fit (the MLP's
    # 3 epochs are 3,000 sample-updates), about 3 s.
    n=1000
    fail=0
    pass() { echo "PASS bench_models_m4 $1"; }
    bad() { echo "FAIL bench_models_m4 $1"; fail=1; }
    if run_image "$n quick" "$tmp/m4" 60; then pass "image runs ($n samples)"; else
        bad "image exit status $? ($n samples)"; sed 's/^/  /' "$tmp/m4" | tail -5; fi
    if "$B/tests/bench_models_host" "$n" quick --office scenarios/maps/office.yaml >"$tmp/host"; then
        pass "host twin runs"; else bad "host twin exit status $?"; fi
    grep '^sum_' "$tmp/m4" | cut -f1,3 | sort >"$tmp/m4.sums" || true
    grep '^sum_' "$tmp/host" | cut -f1,3 | sort >"$tmp/host.sums" || true
    models=$(awk -F'\t' '$1 ~ /^sum_whole_/ {n++} END {print n + 0}' "$tmp/host.sums")
    # Every registered model has its sums on both ends (host twin: the registry's count).
    if [ "$models" -ge 5 ] && [ "$(wc -l <"$tmp/host.sums")" -ge $((models * 4)) ]; then
        pass "host twin covers $models models"; else bad "host twin printed $models models"; fi
    if diff "$tmp/host.sums" "$tmp/m4.sums" >"$tmp/diff"; then
        pass "Cortex-M4 predictions equal the host core's bit for bit ($(wc -l <"$tmp/m4.sums") sums)"
    else
        bad "Cortex-M4 and host differ (< host, > Cortex-M4):"; sed 's/^/  /' "$tmp/diff"
    fi
    # A sliced relearn (the firmware's budget) must learn the whole fit's model.
    if awk -F'\t' '$1 ~ /^sum_whole_/ {m = substr($1, 11); w[m] = $2}
                   $1 ~ /^sum_sliced_/ {m = substr($1, 12); sub(/_[0-9]+$/, "", m); s[m] = $2; n++}
                   END { if (n == 0) exit 1; for (m in s) if (s[m] != w[m]) exit 1 }' "$tmp/m4.sums"; then
        pass "sliced relearn equals the whole relearn on the Cortex-M4"; else
        bad "a sliced relearn differs from the whole one on the Cortex-M4"; fi
    # The 200 ms safety deadline at every model's registry budget (0: one whole fit), from
    # the exact instruction count of its heaviest slice; every model the host twin runs has one.
    if awk -F'\t' -v models="$models" '
        $1 == "calib_empty" { e = $2 } $1 == "calib_nop1000" { per = ($2 - e) / 1000 }
        NF == 3 { v[$1] = $2 }
        $1 ~ /^mcu_budget_/ { m = substr($1, 12); b[m] = $3; order[++k] = m }
        END {
            if (per <= 0 || k != models) { print "  " k " models with a registry budget of " models; exit 1 }
            for (i = 1; i <= k; i++) {
                m = order[i]; w = "slice_worst_" m "_" b[m]
                if (!(w in v)) { print "  " m ": no relearn measured at budget " b[m]; bad = 1; continue }
                ins = int((v[w] - e) / per + 0.5)
                printf "  %-9s budget %5d: heaviest slice %10d instructions, %5.1f %% of 33,600,000 (200 ms at 168 MHz)\n", m, b[m], ins, ins / 336000
                if (ins >= 33600000) bad = 1
            }
            exit bad
        }' "$tmp/m4" >"$tmp/deadline"; then
        pass "every model's heaviest slice at its registry budget meets the 200 ms deadline"
        cat "$tmp/deadline"
    else
        bad "a model's heaviest slice at its registry budget misses the 200 ms deadline:"
        cat "$tmp/deadline"
    fi
    if grep -q $'^office_map_same_as_host_loader\t0\t1$' "$tmp/host"; then
        pass "baked office map equals the host loader's (bench_pathloss's map)"; else
        bad "baked office map differs from the host loader's"; fi
    exit $fail
    ;;
bench)
    if ! run_image "10000${*:+ $*}" "$tmp/m4" 900; then
        echo "bench_models.sh: the image failed:"; tail -5 "$tmp/m4"; exit 1
    fi
    awk -F'\t' '
    $1 == "calib_empty" { e = $2; next }
    $1 == "calib_nop1000" { per = ($2 - e) / 1000; next }
    NF == 3 { v[$1] = $2; c[$1] = $3; if ($2 == 0) val[$1] = $3 }
    NF == 3 && $1 ~ /^relearn_/ { model[++nm] = substr($1, 9) }
    NF == 3 && $1 ~ /^slices_/ { sl[++ns] = substr($1, 8) }
    function ins(name, r) { # exact instructions of one measured region
        r = (v[name] - e) / per; ri = int(r + 0.5)
        if (v[name] < 16777216 && (r - ri > 0.05 || ri - r > 0.05)) bad = bad " " name
        return ri
    }
    function ms(i) { return sprintf("%.2f", i / 168000) }
    function fits(i, lim) { return i <= lim ? "yes" : "NO" }
    END {
        if (per == 0) { print "bench_models.sh: no calibration lines"; exit 1 }
        printf "SysTick ticks per instruction: %.3f (1,000 NOPs; %d ticks of measurement overhead)\n", per, e
        printf "Cortex-M4 instructions (168 MHz: 200 ms = 33,600,000; issue-6 period budget 500,000)\n"
        printf "%-9s %7s %14s %9s %14s %10s %12s %8s\n", "model", "state B", "full relearn", "ms", "grid search", "ms", "(points)", "predict"
        for (k = 1; k <= nm; k++) {
            m = model[k]
            g = ("argmax_" m in v) ? "argmax_" m : "grid_" m
            printf "%-9s %7d %14.0f %9s %14.0f %10s %12s %8d\n", m, val["state_bytes_" m], ins("relearn_" m), ms(ins("relearn_" m)),
                ins(g), ms(ins(g)), (g ~ /^argmax/ ? "(argmax)" : "(" val["points_" m] ")"), ins("predict_" m)
            if (g ~ /^argmax/ && ("grid_" m in v))
                printf "%-9s %7s %14s %9s %14.0f %10s %12s   rfs_gridmax_find, for reference\n", "", "", "", "", ins("grid_" m), ms(ins("grid_" m)), "(" val["points_" m] ")"
        }
        printf "\nsliced relearn: heaviest slice (exact), slices, all slices (to ~calls/20); registry = mcu_fit_budget\n"
        printf "%-9s %7s %14s %9s %7s %14s %8s %6s %6s\n", "model", "budget", "heaviest slice", "ms", "slices", "all slices", "200 ms", "50 %", "500 k"
        for (k = 1; k <= ns; k++) {
            s = sl[k]; m = s; sub(/_[0-9]+$/, "", m); b = s; sub(/.*_/, "", b)
            w = ins("slice_worst_" s)
            t = int((v["slice_total_" s] - c["slice_total_" s] * e) / per + 0.5)
            printf "%-9s %7d %14.0f %9s %7d %14.0f %8s %6s %6s%s\n", m, b, w, ms(w), val["slices_" s], t, fits(w, 33600000), fits(w, 16800000), fits(w, 500000),
                (b == val["mcu_budget_" m] ? "  registry" : "")
        }
        printf "\nat the registry budgets (the firmware'"'"'s MCU configuration), 200 ms = 33,600,000 instructions;\n"
        printf "the decision runs in the period of the last slice: last slice + grid search (argmax for pathloss)\n"
        for (k = 1; k <= nm; k++) {
            m = model[k]; s = m "_" val["mcu_budget_" m]
            if (!(("slice_worst_" s) in v)) { printf "  %-9s no registry budget measured\n", m; continue }
            w = ins("slice_worst_" s)
            printf "  %-9s budget %5d: heaviest slice %10.0f instructions = %6s ms, %4.1f %% of the deadline: %s\n", m, val["mcu_budget_" m], w, ms(w), w / 336000,
                w < 33600000 ? "meets 200 ms" : "MISSES 200 ms"
            g = ("argmax_" m in v) ? "argmax_" m : "grid_" m
            d = ins("slice_last_" s) + ins(g)
            printf "  %-9s %12s last slice + %-6s %10.0f instructions = %6s ms, %4.1f %% of the deadline: %s\n", "", "", (g ~ /^argmax/ ? "argmax" : "grid"), d, ms(d), d / 336000,
                d < 33600000 ? "meets 200 ms" : "MISSES 200 ms"
        }
        printf "\n160 x 80 predictions, bench/bench_models.c loop (instructions per point):\n"
        for (k = 1; k <= nm; k++) {
            n = "predict12800_" model[k]
            if (n in v) printf "  %-9s %14.0f %8.0f\n", model[k], ins(n), ins(n) / 12800
        }
        if ("walls_pathloss" in v) printf "pathloss wall counts (office, wall blocks; models_work.c walls_bench): %d counts, %.0f instructions, %.0f a count\n", c["walls_pathloss"], ins("walls_pathloss"), ins("walls_pathloss") / c["walls_pathloss"]
        printf "stack (painted): "
        for (k = 1; k <= nm; k++) printf "%s relearn %d B grid %d B; ", model[k], val["stack_relearn_" model[k]], val["stack_grid_" model[k]]
        printf "\nstate union %d B (rfs_models_max_state_bytes); counts over 780,190 instructions include the 5 instructions of each SysTick wrap interrupt\n", val["state_bytes_max"]
        if (bad != "") { printf "non-integral instruction counts:%s\n", bad; exit 1 }
    }' "$tmp/m4"
    ;;
*)
    echo "usage: tests/firmware/bench_models.sh check|bench BUILD" >&2
    exit 2
    ;;
esac
