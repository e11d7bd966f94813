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
echo "$out" | awk -F'\t' '
    $1 == "calib_empty" { e = $2 } $1 == "calib_nop1000" { per = ($2 - e) / 1000 }
    NF == 3 { name[++n] = $1; t[n] = $2; c[n] = $3 }
    function lsv(what, row,    r) {
        r = ls[row]
        printf "%s (%d plans, %d failed): %d instructions, target 500000: %s (%.1f x), 200 ms deadline 33600000: %s\n", what, v[row "_plans"], v[row "_failed"], r, r <= 500000 ? "met" : "MISSED", r / 500000, r <= 33600000 ? "met" : "MISSED"
    }
    END {
        printf "SysTick ticks per instruction: %.3f (1,000 NOPs; %d ticks of measurement overhead)\n", per, e
        printf "%-34s %14s %12s\n", "measurement", "instructions", "ms@168MHz"
        for (i = 1; i <= n; i++) {
            if (name[i] ~ /^calib/) continue
            if (t[i] == 0) { printf "%-34s %14s\n", name[i], c[i]; v[name[i]] = c[i]; continue }
            ins = (t[i] - e) / per; r = int(ins + 0.5)
            # Exact unless SysTick wrapped (every 2^24 ticks, 780,190 instructions): then
            # the count includes the few instructions of each wrap interrupt.
            if (t[i] < 16777216 && (ins - r > 0.05 || r - ins > 0.05)) bad = bad " " name[i]
            printf "%-34s %14d %12.3f\n", name[i], r, r / 168000
            if (name[i] == "worst_iteration") worst = r
            if (name[i] == "sliced_worst_period") sliced = r
            if (name[i] == "worst_eps_geodesic") geo = r
            if (name[i] == "worst_eps_straight") straight = r
            if (name[i] == "worst_eps_paper") paper = r
            if (name[i] ~ /^worst_greedy_ls_[a-z_]*[a-z]$/ && name[i] !~ /_(greedy|plans|failed|expanded|candidates|replay_goal_ok|path_cm|ridge_samples)$/) ls[name[i]] = r
        }
        printf "(counts over 780,190 instructions include ~10 instructions per SysTick wrap interrupt)\n"
        printf "worst-case control period, faithful configuration (fit in one period): %d instructions, target 500000: %s\n", worst, worst <= 500000 ? "met" : "MISSED"
        printf "worst-case control period, MCU configuration (fit_budget 2500): %d instructions, target 500000: %s\n", sliced, sliced <= 500000 ? "met" : "MISSED"
        # The meta-path epsilon decision behind a wall (bench.c geo_decision): the budget
        # of a period and the 200 ms safety deadline (33,600,000 instructions at 168 MHz).
        printf "meta-path epsilon decision behind a wall, eps_geodesic (%d plans): %d instructions, target 500000: %s (%.1f x), 200 ms deadline 33600000: %s\n", v["worst_eps_geodesic_plans"], geo, geo <= 500000 ? "met" : "MISSED", geo / 500000, geo <= 33600000 ? "met" : "MISSED"
        printf "the same decision, eps_geodesic off (%d plan): %d instructions, target 500000: %s (%.1f x), 200 ms deadline 33600000: %s\n", v["worst_eps_straight_plans"], straight, straight <= 500000 ? "met" : "MISSED", straight / 500000, straight <= 33600000 ? "met" : "MISSED"
        printf "the same decision, faithful configuration (%d plan): %d instructions, target 500000: %s (%.1f x), 200 ms deadline 33600000: %s\n", v["worst_eps_paper_plans"], paper, paper <= 500000 ? "met" : "MISSED", paper / 500000, paper <= 33600000 ? "met" : "MISSED"
        # The greedy decision of the paper next to the wall (bench.c ls_decision): its line
        # search plans every legal candidate until one plans.
        lsv("the faithful greedy step behind a wall, line search", "worst_greedy_ls_wall")
        lsv("the same beside a closed room north of the wall", "worst_greedy_ls_room_first")
        lsv("the next decision, from that goal (a null move, repeated every 1 s)", "worst_greedy_ls_room")
        lsv("the same 2 cm short of that goal (the drive stops within 0.1 m)", "worst_greedy_ls_room_worst")
        for (k in v) if (k ~ /^worst_greedy_ls_.*_(greedy|replay_goal_ok)$/ && v[k] != 1) badgeo = badgeo " " k
        # The epsilon rows count only if the period decided an epsilon goal after a
        # relearn and the replay of its draws kept the same goal (else the plan count
        # would describe another decision, e.g. after a change to rfs_seek.c).
        for (k in v) if (k ~ /^worst_eps_.*_(eps_relearn|replay_goal_ok)$/ && v[k] != 1) badgeo = badgeo " " k
        if (badgeo != "") { printf "epsilon and line-search scenario checks failed:%s\n", badgeo; exit 1 }
        if (bad != "") { printf "non-integral instruction counts:%s\n", bad; exit 1 }
    }'
scripts/fw_budget.sh "$B/firmware/firmware.elf"
