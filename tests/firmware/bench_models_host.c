/* bench_models_host.c - the host twin of the Cortex-M4 model bench
 * (firmware/port/qemu/bench_models.c): the same run (firmware/port/qemu/models_work.c) on
 * the host build of the core, with a bench_clock that only prints. Its "sum_*" lines are
 * the independent reference tests/firmware/bench_models.sh compares the image's with.
 * It also checks that the office map baked into the image (scripts/map2c.py) is the one
 * the host loader makes (firmware/port/linux/lx_map.c), the map of bench/bench_pathloss.c.
 *
 *   bench_models_host N [quick] [--office MAP.yaml]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"
#include "lx_map.h"
#include "models_work.h"
#include "rfs_app.h"

extern const rfs_app_map_t rfs_mw_office_map;

void rfs_bc_start(void)
{
}

uint64_t rfs_bc_ticks(void)
{
    return 0;
}

void rfs_bc_put_u64(uint64_t v)
{
    printf("%llu", (unsigned long long)v);
}

void rfs_bc_report(const char *name, uint64_t ticks, uint32_t count)
{
    printf("%s\t%llu\t%u\n", name, (unsigned long long)ticks, count);
}

uintptr_t rfs_bc_stack_paint(void)
{
    return 0;
}

uint32_t rfs_bc_stack_depth(uintptr_t sp)
{
    (void)sp;
    return 0;
}

static int usage(FILE *f, int rc)
{
    fprintf(f, "usage: bench_models_host N [quick] [--office MAP.yaml]\n"
               "  N       samples per workload, 1..10000\n"
               "  quick   skip the timing-only extras (as the image's check run)\n"
               "  --office MAP.yaml  also compare the baked office map with the host loader's\n");
    return rc;
}

/* 1 when the host loader's core map of yaml at 0.1 m equals the baked one, 0 when not,
 * -1 when the file cannot be loaded. */
static int same_office(const char *yaml)
{
    char err[256];
    lx_map_t hm;
    lx_core_map_t cm;
    memset(&hm, 0, sizeof hm);
    memset(&cm, 0, sizeof cm);
    if (lx_map_load(yaml, &hm, err, sizeof err) != 0 ||
        lx_map_to_core(&hm, 0.1, NULL, &cm, err, sizeof err) != 0) {
        fprintf(stderr, "bench_models_host: %s\n", err);
        lx_map_free(&hm);
        return -1;
    }
    const rfs_app_map_t *b = &rfs_mw_office_map;
    const rfs_map_t *m = &cm.map;
    const uint32_t bytes = rfs_map_bytes(b->w, b->h);
    int same = m->w == b->w && m->h == b->h && m->res == b->res && m->origin_x == b->origin_x &&
               m->origin_y == b->origin_y && m->wall != NULL &&
               memcmp(m->free, b->free, bytes) == 0 && memcmp(m->wall, b->wall, bytes) == 0;
    lx_core_map_free(&cm);
    lx_map_free(&hm);
    return same;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "--help") == 0) {
        return usage(stdout, 0);
    }
    if (argc < 2) {
        return usage(stderr, 2);
    }
    char *end = NULL;
    long n = strtol(argv[1], &end, 10);
    if (*argv[1] == '\0' || *end != '\0' || n < 1 || n > (long)RFS_MW_MAX_SAMPLES) {
        fprintf(stderr, "bench_models_host: N: not an integer in 1..10000: '%s'\n", argv[1]);
        return 2;
    }
    uint32_t flags = 0;
    const char *office = NULL;
    for (int i = 2; i < argc; ++i) {
        if (strcmp(argv[i], "quick") == 0) {
            flags |= RFS_MW_QUICK;
        } else if (strcmp(argv[i], "--office") == 0 && i + 1 < argc) {
            office = argv[++i];
        } else {
            fprintf(stderr, "bench_models_host: unknown argument '%s'\n", argv[i]);
            return usage(stderr, 2);
        }
    }
    if (office != NULL) {
        int same = same_office(office);
        if (same < 0) {
            return 1;
        }
        printf("office_map_same_as_host_loader\t0\t%d\n", same);
    }
    static rfs_mw_mem_t mem;
    return rfs_mw_run(&mem, (uint32_t)n, flags) == 0 ? 0 : 1;
}
