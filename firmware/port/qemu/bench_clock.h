/* bench_clock.h - exact instruction counts on the emulator image (qemu-system-arm
 * -M netduinoplus2 -icount shift=7), shared by the bench images (bench.c, bench_models.c);
 * the emulator port (main.c) uses its decimal printer and stack painting only.
 *
 * With -icount every instruction advances the virtual clock by exactly 2^7 ns and SysTick
 * (core clock, 168 MHz in qemu's model) counts that clock, so a SysTick difference is an
 * exact function of the instructions executed: 21.504 ticks per instruction, more than
 * one, so the count is recovered exactly. rfs_bc_start() calibrates with an empty region
 * and a block of 1,000 NOPs and prints both; the scripts convert raw ticks to
 * instructions (tests/firmware/bench.sh, tests/firmware/bench_models.sh).
 *
 * Output lines on the semihosting console: "name<TAB>ticks<TAB>count\n"; ticks 0 marks a
 * plain value (count) rather than a measurement.
 */
#ifndef RFS_BENCH_CLOCK_H
#define RFS_BENCH_CLOCK_H

#include <stdint.h>

/// Start SysTick free-running (24-bit reload, wrap interrupt counted) and print the two
/// calibration lines "calib_empty" and "calib_nop1000".
void rfs_bc_start(void);

/// SysTick ticks since rfs_bc_start(), 64-bit (wraps counted).
uint64_t rfs_bc_ticks(void);

/// Print v in decimal on the semihosting console.
void rfs_bc_put_u64(uint64_t v);

/// Print one line "name<TAB>ticks<TAB>count".
void rfs_bc_report(const char *name, uint64_t ticks, uint32_t count);

/// Paint the free stack below the caller's stack pointer; returns that pointer for
/// rfs_bc_stack_depth().
uintptr_t rfs_bc_stack_paint(void);

/// Bytes of stack used below sp since rfs_bc_stack_paint() returned sp.
uint32_t rfs_bc_stack_depth(uintptr_t sp);

/// Measure the statement(s) given and print one line: ticks of the region, count.
#define RFS_BC_MEASURE(name, count, ...)               \
    do {                                               \
        const uint64_t t0_ = rfs_bc_ticks();           \
        __VA_ARGS__;                                   \
        const uint64_t t1_ = rfs_bc_ticks();           \
        rfs_bc_report((name), t1_ - t0_, (count));     \
    } while (0)

#endif /* RFS_BENCH_CLOCK_H */
