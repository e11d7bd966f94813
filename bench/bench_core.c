/* bench_core.c - the worst-case control iteration of the core, for `make bench`.
 *
 * Worst case (docs/PERFORMANCE.md, "Core: the worst-case iteration"): 10,000 samples all
 * within the ridge radius, a relearn, and a grid search over a 40 x 20 m map at the
 * 0.25 m lattice (12,800 points). Modes:
 *   bench_core iter          run the iteration once (for callgrind: Ir of rfs_seek_step)
 *   bench_core time N        run it N times, print the median wall time in microseconds
 *   bench_core dump FILE     write the samples and the query point for the sklearn twin
 * The store keeps cell sums as the Linux port's does (docs/MODELS.md, "Cell sums");
 * `bench_core --scan MODE` runs without them, visiting every sample as the
 * microcontroller image does.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <valgrind/callgrind.h>

#include "rfs_cellsum.h"
#include "rfs_ridge.h"
#include "rfs_seek.h"

#define W_M 40
#define H_M 20
#define RES_Q16 6554 /* 0.1 m */

typedef struct bench {
    rfs_map_t map;
    uint8_t *free_bits, *legal_bits;
    rfs_seek_mem_t mem;
    rfs_ridge_t ridge;
    rfs_seek_t seek;
    rfs_rng_t rng;
    rfs_cellsum_t cellsum;
    rfs_store_index_t index;
} bench_t;

static void bench_setup(bench_t *b, bool cells)
{
    memset(b, 0, sizeof *b);
    uint16_t w = W_M * 10, h = H_M * 10;
    uint32_t bytes = rfs_map_bytes(w, h);
    b->free_bits = malloc(bytes);
    b->legal_bits = malloc(bytes);
    memset(b->free_bits, 0xFF, bytes);
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    if (rfs_map_init(&b->map, &mc, w, h, RES_Q16, 0, 0, b->free_bits, NULL, b->legal_bits) != 0) {
        fprintf(stderr, "bench_core: map init failed\n");
        exit(1);
    }
    uint32_t lpts = (uint32_t)b->map.lw * b->map.lh;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.eps_amp = 0; /* force the greedy branch: the grid search */
    cfg.eps_floor = 0;
    b->mem.samples = calloc(cfg.store.capacity, sizeof(rfs_sample_t));
    b->mem.pending_cap = 256;
    b->mem.pending = calloc(256, sizeof(rfs_pending_t));
    b->mem.plan_work_bytes = lpts;
    b->mem.plan_work = calloc(lpts, 1);
    b->mem.plan_queue_cap = lpts;
    b->mem.plan_queue = calloc(lpts, sizeof(uint32_t));
    b->mem.visited_bytes = b->mem.reach_bytes = rfs_reach_bytes(&b->map);
    b->mem.visited = calloc(b->mem.visited_bytes, 1);
    b->mem.reach = calloc(b->mem.reach_bytes, 1);
    if (cells) {
        uint32_t n = rfs_cellsum_cells(W_M * 100, H_M * 100, 5);
        if (rfs_cellsum_init(&b->cellsum, 0, 0, W_M * 100, H_M * 100, 5,
                             calloc(n, sizeof(rfs_cellsum_cell_t)), n,
                             calloc(2u * cfg.store.capacity, sizeof(uint16_t)),
                             cfg.store.capacity) != 0) {
            fprintf(stderr, "bench_core: cell sums init failed\n");
            exit(1);
        }
        b->index = rfs_cellsum_index(&b->cellsum);
        b->mem.index = &b->index;
    }
    rfs_ridge_cfg_t rc = rfs_ridge_cfg_default();
    rfs_ridge_init(&b->ridge, &rc);
    if (rfs_seek_init(&b->seek, &cfg, &b->map, rfs_ridge_model(&b->ridge), &rfs_target_rssi,
                      &b->mem) != 0) {
        fprintf(stderr, "bench_core: seek init failed\n");
        exit(1);
    }
    rfs_rng_seed(&b->rng, 42);
    /* 10,000 samples within 5 m of (20, 10), values from a plane plus noise. */
    rfs_rng_t r;
    rfs_rng_seed(&r, 7);
    for (uint32_t k = 0; k < cfg.store.capacity; ++k) {
        int32_t dx, dy;
        do {
            dx = (int32_t)rfs_rng_below(&r, 900) - 450;
            dy = (int32_t)rfs_rng_below(&r, 900) - 450;
        } while (dx * dx + dy * dy > 450 * 450);
        rfs_sample_t s;
        s.x_cm = (int16_t)(2000 + dx);
        s.y_cm = (int16_t)(1000 + dy);
        s.v_q6 = (int16_t)((-60 * 64) + dx / 4 - dy / 8 + (int32_t)rfs_rng_below(&r, 512) - 256);
        rfs_store_offer(&b->seek.store, s, &r);
    }
}

/* One worst-case iteration: fresh inputs, no model (relearn), greedy grid search. With
 * the default plan_budget the period that relearns in one go leaves the choice to the
 * next (docs/PERFORMANCE.md, "Planning in slices"): the iteration is the periods, 50 ms
 * apart, until the decision; their number is returned. */
static int bench_iteration(bench_t *b, int64_t now)
{
    rfs_pose_t p = { now, 20 * 65536, 10 * 65536, 0 };
    b->seek.have_pose = false; /* accept the pose regardless of earlier iterations */
    b->seek.pose.t_us = 0;
    rfs_seek_on_pose(&b->seek, &p, &b->rng);
    rfs_seek_on_rssi(&b->seek, 0, now, -60, &b->rng);
    b->ridge.valid = false;
    b->seek.iteration = 1;
    b->seek.drive.status = RFS_DRIVE_IDLE;
    rfs_seek_out_t out;
    int periods = 0;
    do {
        rfs_seek_step(&b->seek, now + (int64_t)periods * 50000, &b->rng, &out);
        ++periods;
    } while (!out.decided && periods < 4);
    if (!out.decided || !out.decision.relearned || out.decision.kind != RFS_SEEK_GREEDY) {
        fprintf(stderr, "bench_core: the iteration was not the worst case\n");
        exit(1);
    }
    return periods;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    bool cells = true;
    if (argc >= 2 && strcmp(argv[1], "--scan") == 0) {
        cells = false;
        --argc;
        ++argv;
    }
    if (argc < 2 || strcmp(argv[1], "--help") == 0) {
        printf("usage: bench_core [--scan] iter | time N | dump FILE\n");
        return argc < 2 ? 2 : 0;
    }
    bench_t b;
    bench_setup(&b, cells);
    /* Warm-up iteration: the first one also flood-fills the reachable lattice. */
    bench_iteration(&b, 1000000);
    if (strcmp(argv[1], "iter") == 0) {
        /* Run under callgrind with --collect-atstart=no: only this iteration counts. */
        CALLGRIND_TOGGLE_COLLECT;
        int periods = bench_iteration(&b, 2000000);
        CALLGRIND_TOGGLE_COLLECT;
        printf("periods %d\n", periods);
        return 0;
    }
    if (strcmp(argv[1], "time") == 0 && argc == 3) {
        int n = atoi(argv[2]);
        if (n <= 0 || n > 100000) {
            fprintf(stderr, "bench_core: N must be 1..100000\n");
            return 2;
        }
        double *t = malloc(sizeof(double) * (size_t)n);
        for (int i = 0; i < n; ++i) {
            struct timespec a, c;
            clock_gettime(CLOCK_MONOTONIC, &a);
            bench_iteration(&b, 2000000 + (int64_t)i * 1000000);
            clock_gettime(CLOCK_MONOTONIC, &c);
            t[i] = (c.tv_sec - a.tv_sec) * 1e6 + (c.tv_nsec - a.tv_nsec) / 1e3;
        }
        qsort(t, (size_t)n, sizeof(double), cmp_double);
        printf("%.1f\n", t[n / 2]);
        free(t);
        return 0;
    }
    if (strcmp(argv[1], "dump") == 0 && argc == 3) {
        FILE *f = fopen(argv[2], "w");
        if (!f) {
            perror(argv[2]);
            return 1;
        }
        fprintf(f, "# x_m y_m v_db (query 20 10, grid 40x20 m at 0.25 m)\n");
        for (uint16_t i = 0; i < b.seek.store.count; ++i) {
            const rfs_sample_t *s = &b.seek.store.samples[i];
            fprintf(f, "%.2f %.2f %.6f\n", s->x_cm / 100.0, s->y_cm / 100.0, s->v_q6 / 64.0);
        }
        fclose(f);
        return 0;
    }
    fprintf(stderr, "bench_core: unknown mode '%s' (see --help)\n", argv[1]);
    return 2;
}
