/* bench_models.c - instruction counts of every internal model on the Cortex-M4 image
 * (issues 8 and 10): a full relearn, the heaviest slice of a sliced relearn, one grid
 * search, one prediction, the state size; models_work.c holds the workload and the run.
 *
 *   qemu-system-arm -M netduinoplus2 -nographic -monitor none -serial null \
 *       -semihosting-config enable=on,target=native -icount shift=7 \
 *       -kernel bench_models.elf [-append "N [quick]"]
 *
 * N samples (default 10,000, the paper's maximum); "quick" drops the timing-only extras
 * (the check run of tests/firmware/bench_models.sh). Prints raw SysTick ticks
 * (bench_clock.h); tests/firmware/bench_models.sh converts them to instructions. Exit
 * status 0, or 1 after a line "error_<what>".
 */
#include <stdint.h>

#include "bench_clock.h"
#include "models_work.h"
#include "semihost.h"

/* One model state at a time (a union of the states) plus the samples, maps and seeker:
 * about 170 KB of the emulator's 192 KB. */
static rfs_mw_mem_t s_mem;

/* The words after the image name: N, then optionally "quick". */
static int parse(const char *cmd, uint32_t *n, uint32_t *flags)
{
    const char *p = cmd;
    while (*p != '\0' && *p != ' ') {
        p++; /* the image name */
    }
    while (*p == ' ') {
        p++;
    }
    if (*p == '\0') {
        return 0;
    }
    uint32_t v = 0;
    const char *d = p;
    while (*p >= '0' && *p <= '9' && v <= RFS_MW_MAX_SAMPLES) {
        v = v * 10u + (uint32_t)(*p++ - '0');
    }
    if (p == d || (*p != '\0' && *p != ' ') || v < 1u || v > RFS_MW_MAX_SAMPLES) {
        return -1;
    }
    *n = v;
    while (*p == ' ') {
        p++;
    }
    const char *q = "quick";
    const char *w = p;
    while (*q != '\0' && *w == *q) {
        ++w;
        ++q;
    }
    if (*p != '\0') {
        if (*q != '\0' || (*w != '\0' && *w != ' ')) {
            return -1;
        }
        *flags |= RFS_MW_QUICK;
    }
    return 0;
}

int main(void)
{
    rfs_bc_start();
    static char cmd[128];
    uint32_t n = RFS_MW_MAX_SAMPLES, flags = 0;
    if (rfs_sh_cmdline(cmd, sizeof cmd) == 0 && parse(cmd, &n, &flags) != 0) {
        rfs_sh_puts("bench_models: -append: expected \"N [quick]\" with N in 1..10000\n");
        rfs_sh_exit(1);
    }
    rfs_sh_exit(rfs_mw_run(&s_mem, n, flags) == 0 ? 0 : 1);
}
