/* bench_models.c - instruction counts of every internal model on the Cortex-M4 image:
 * a full relearn, the heaviest slice of a sliced relearn, one grid
 * search, one prediction, the state size; models_work.c holds the workload and the run.
 *
 *   qemu-system-arm -M netduinoplus2 -nographic -monitor none -serial null \
 *       -semihosting-config enable=on,target=native -icount shift=7 \
 *       -kernel bench_models.elf [-append "N [quick] [MODEL:BUDGET ...]"]
 *
 * N samples (default 10,000, the paper's maximum); "quick" drops the timing-only extras
 * (the check run of tests/firmware/bench_models.sh); MODEL:BUDGET (up to 8, e.g.
 * "mlp:700") also measures MODEL's sliced relearn at BUDGET work units per call, beside
 * its registry budget (how the per-model mcu_fit_budget values were chosen). Prints raw SysTick ticks
 * (bench_clock.h); tests/firmware/bench_models.sh converts them to instructions. Exit
 * status 0, or 1 after a line "error_<what>".
 */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "bench_clock.h"
#include "models_work.h"
#include "rfs_models.h"
#include "semihost.h"

/* One model state at a time (a union of the states) plus the samples, maps and seeker:
 * about 170 KB of the emulator's 192 KB. */
static rfs_mw_mem_t s_mem;

/* The digits of [p, end) as a decimal in 1..max, or 0 when not (empty, other bytes,
 * out of range). */
static uint32_t number(const char *p, const char *end, uint32_t max)
{
    uint32_t v = 0;
    if (p == end) {
        return 0;
    }
    for (; p < end; ++p) {
        if (*p < '0' || *p > '9' || v > max / 10u) {
            return 0;
        }
        v = v * 10u + (uint32_t)(*p - '0');
    }
    return v <= max ? v : 0u;
}

/* true when [p, end) spells the NUL-terminated s. */
static bool word_is(const char *p, const char *end, const char *s)
{
    while (p < end && *s != '\0' && *p == *s) {
        ++p;
        ++s;
    }
    return p == end && *s == '\0';
}

/* The words after the image name: N, then any of "quick" and MODEL:BUDGET (a registry
 * name, a budget in 1..1000000 work units; at most RFS_MW_MAX_EXTRA). Returns 0, or -1
 * with *why naming the word that is wrong. */
static int parse(const char *cmd, uint32_t *n, uint32_t *flags, rfs_mw_mem_t *mem,
                 const char **why)
{
    const char *p = cmd;
    while (*p != '\0' && *p != ' ') {
        p++; /* the image name */
    }
    for (uint32_t word = 0;; ++word) {
        while (*p == ' ') {
            p++;
        }
        if (*p == '\0') {
            return 0;
        }
        const char *w = p, *colon = NULL;
        while (*p != '\0' && *p != ' ') {
            if (*p == ':' && colon == NULL) {
                colon = p;
            }
            p++;
        }
        if (word == 0u) {
            *n = number(w, p, RFS_MW_MAX_SAMPLES);
            if (*n == 0u) {
                *why = "N: expected samples in 1..10000";
                return -1;
            }
        } else if (word_is(w, p, "quick")) {
            *flags |= RFS_MW_QUICK;
        } else if (colon != NULL) {
            char name[24];
            const uint32_t len = (uint32_t)(colon - w);
            if (len >= sizeof name) {
                *why = "MODEL:BUDGET: unknown model";
                return -1;
            }
            memcpy(name, w, len);
            name[len] = '\0';
            const rfs_models_entry_t *e = rfs_models_lookup(name);
            const uint32_t b = number(colon + 1, p, 1000000u);
            if (e == NULL) {
                *why = "MODEL:BUDGET: unknown model";
                return -1;
            }
            if (b == 0u) {
                *why = "MODEL:BUDGET: budget not in 1..1000000";
                return -1;
            }
            if (mem->n_extra >= RFS_MW_MAX_EXTRA) {
                *why = "MODEL:BUDGET: more than 8 pairs";
                return -1;
            }
            mem->extra[mem->n_extra].model = e;
            mem->extra[mem->n_extra].budget = b;
            mem->n_extra++;
        } else {
            *why = "expected \"quick\" or MODEL:BUDGET after N";
            return -1;
        }
    }
}

int main(void)
{
    rfs_bc_start();
    static char cmd[256];
    uint32_t n = RFS_MW_MAX_SAMPLES, flags = 0;
    const char *why = "";
    if (rfs_sh_cmdline(cmd, sizeof cmd) == 0 && parse(cmd, &n, &flags, &s_mem, &why) != 0) {
        rfs_sh_puts("bench_models: -append \"N [quick] [MODEL:BUDGET ...]\": ");
        rfs_sh_puts(why);
        rfs_sh_puts("\n");
        rfs_sh_exit(1);
    }
    rfs_sh_exit(rfs_mw_run(&s_mem, n, flags) == 0 ? 0 : 1);
}
