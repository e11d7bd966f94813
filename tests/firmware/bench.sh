#!/usr/bin/env bash
# bench.sh BUILD - instruction counts of the Cortex-M4 image under qemu -icount.
# With -icount shift=7 each instruction advances the virtual clock by 128 ns; SysTick
# counts the 168 MHz core clock of qemu's STM32F405 model, so 21.504 ticks elapse per
# instruction and a tick difference converts to an exact instruction count. The image
# calibrates with 1,000 NOPs; this script converts and prints the table of
# docs/PERFORMANCE.md. Flash and static RAM come from the hardware image's link.
set -euo pipefail
B=${1:-build}
out=$(timeout 300 qemu-system-arm -M netduinoplus2 -nographic -monitor none -serial null \
    -semihosting-config enable=on,target=native -icount shift=7 -kernel "$B/firmware/bench.elf" 2>&1)
# The path-loss model's relearn slices at its registry budget (rfs_app_cfg_mcu), from
# the models image on 1,000 samples (tests/firmware/bench_models.sh check's run).
models=$(timeout 300 qemu-system-arm -M netduinoplus2 -nographic -monitor none -serial null \
    -semihosting-config enable=on,target=native -icount shift=7 -kernel "$B/firmware/bench_models.elf" \
    -append "1000 quick" 2>&1 | awk -F'\t' 'NF == 3 && ($1 ~ /^calib/ || $1 ~ /pathloss/) { print "models_" $0 }')
printf '%s\n%s\n' "$out" "$models" | awk -F'\t' '
    $1 == "calib_empty" { e = $2 } $1 == "calib_nop1000" { per = ($2 - e) / 1000 }
    $1 == "models_calib_empty" { me = $2 } $1 == "models_calib_nop1000" { mper = ($2 - me) / 1000 }
    $1 ~ /^models_/ { m[substr($1, 8)] = $2; mc[substr($1, 8)] = $3; next }
    NF == 3 { name[++n] = $1; t[n] = $2; c[n] = $3 }
    function verdict(r) { return sprintf("%d instructions, target 500000: %s (%.2f x)", r, r <= 500000 ? "met" : "MISSED", r / 500000) }
    function worst_of(re, not,    k, w, wn) { w = 0; for (k in ins) if (k ~ re && (not == "" || k !~ not) && ins[k] > w) { w = ins[k]; wn = k } worst_name = wn; return w }
    END {
        printf "SysTick ticks per instruction: %.3f (1,000 NOPs; %d ticks of measurement overhead)\n", per, e
        printf "%-40s %14s %12s\n", "measurement", "instructions", "ms@168MHz"
        for (i = 1; i <= n; i++) {
            if (name[i] ~ /^calib/) continue
            if (t[i] == 0) { printf "%-40s %14s\n", name[i], c[i]; v[name[i]] = c[i]; continue }
            x = (t[i] - e) / per; r = int(x + 0.5)
            # Exact unless SysTick wrapped (every 2^24 ticks, 780,190 instructions): then
            # the count includes the few instructions of each wrap interrupt.
            if (t[i] < 16777216 && (x - r > 0.05 || r - x > 0.05)) bad = bad " " name[i]
            printf "%-40s %14d %12.3f\n", name[i], r, r / 168000
            ins[name[i]] = r
        }
        printf "(counts over 780,190 instructions include ~10 instructions per SysTick wrap interrupt)\n"
        # Every period of the faithful configuration (RFS_SEEK_META, plan_budget 640): the
        # decisions behind the wall on the leg and cut short, every period until they
        # decided, the tree slices grown on the leg, driving, the relearn decision in the
        # open, and the boot periods (first_iteration: the flood fill sliced by reach_budget).
        f = worst_of("^(first_iteration|worst_iteration|driving_iteration|worst_eps_paper|worst_greedy_ls_[a-z_]*)$|_slice$", "_first$|geodesic|straight")
        printf "worst control period, faithful meta (planning in slices, %s): %s\n", worst_name, verdict(f)
        g = worst_of("^worst_eps_(geodesic|straight)(_cut)?$|^worst_eps_(geodesic|straight)_slice$", "")
        printf "worst control period, meta-path with geodesic decisions (%s): %s\n", worst_name, verdict(g)
        w = 0; for (k in v) if (k ~ /_cut_periods$/ && v[k] > w) w = v[k]
        printf "leg cut short: the decision waits for its tree, at most %d periods (%d ms at 20 Hz), target 1000 ms: %s\n", w, 50 * w, 50 * w <= 1000 ? "met" : "MISSED"
        mb = mc["mcu_budget_pathloss"]; ms = "slice_worst_pathloss_" mb
        if (mper > 0 && (ms in m)) {
            pl = int((m[ms] - me) / mper + 0.5)
            printf "path-loss relearn slice at its registry budget (%d work units, 1,000 samples): %s; %d units a slice would meet it\n", mb, verdict(pl), int(500000 * mb / pl)
        } else { printf "path-loss relearn slice: not measured\n"; bad = bad " models_image" }
        # A driving period with the tree grown warms the path-loss model (RFS_SEEK_WARM_SLICE):
        # the drive period, the model warm slice and its recheck prediction together.
        ws = ""; for (k in m) if (k ~ /^warm_worst_pathloss_[0-9]+$/) ws = k
        wb = substr(ws, 21); dg = "driving_grown_iteration"
        if (mper > 0 && (ws in m) && (dg in ins) && ("predict_pathloss" in m) && v["driving_grown_running"] == 1) {
            wl = int((m[ws] - me) / mper + 0.5); pp = int((m["predict_pathloss"] - me) / mper + 0.5)
            printf "driving period with a path-loss warm slice (%d units, 1,000 samples: %d) + the drive, tree grown (%d) + a prediction (%d): %s\n", wb, wl, ins[dg], pp, verdict(wl + ins[dg] + pp)
            # fit_early near a goal: every driving period also asks a prediction and the 1 s
            # mean (rfs_seek_fit_early_asks), and the recheck a mean beside its prediction; when
            # the ask fails, the relearn begins (rfs_seek_fit_early_begin) with a prediction and
            # a mean of its refutation (the goal within half a step of the maximum); each mean
            # at its worst, scanning the window.
            am = ins["phase_averaging_mean_scan"]; if (ins["phase_averaging_mean"] > am) am = ins["phase_averaging_mean"]
            printf "the same near a goal with fit_early: + two more predictions and three 1 s means (%d each): %s\n", am, verdict(wl + ins[dg] + 3 * pp + 3 * am)
        } else { printf "path-loss warm slice: not measured\n"; bad = bad " models_warm" }
        printf "boot periods (reachability flood fill in slices of %d points, then the first fit, first_iteration, %d periods): %s\n", 1000, v["first_iteration_periods"], verdict(ins["first_iteration"])
        # The scenario checks: each decision relearnt and decided as described, and the
        # replay of its draws kept the same goal (else the counts describe another one).
        for (k in v) if (k ~ /^worst_greedy_ls_.*_(greedy|replay_goal_ok)$/ && v[k] != 1) badgeo = badgeo " " k
        for (k in v) if (k ~ /^worst_eps_.*_(eps_relearn|replay_goal_ok)$/ && v[k] != 1) badgeo = badgeo " " k
        if (badgeo != "") { printf "epsilon and line-search scenario checks failed:%s\n", badgeo; exit 1 }
        if (bad != "") { printf "non-integral instruction counts:%s\n", bad; exit 1 }
    }'
scripts/fw_budget.sh "$B/firmware/firmware.elf"
