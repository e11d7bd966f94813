/* bench_models.c - instruction counts of the internal models, for `make bench-models`
 * (docs/PERFORMANCE.md, "Models"). Under callgrind with --instr-atstart=no only the
 * measured calls are counted.
 *
 * Workload: 10,000 samples (the paper's maximum) uniform over a 40 x 20 m area, a
 * log-distance field with 4 dB noise; the grid search predicts at every point of the
 * 0.25 m lattice of that area (160 x 80 = 12,800 points), as the core bench does.
 *   bench_models relearn MODEL        one full fit (budget 0)
 *   bench_models grid MODEL           a full fit (not counted), then a prediction at
 *                                     every lattice point (the cost of the full scan)
 *   bench_models scan MODEL           a full fit (not counted), then the grid search's
 *                                     full scan, rfs_gridmax_scan()
 *   bench_models search MODEL         a full fit (not counted), then the grid search,
 *                                     rfs_gridmax_find() (its shortcuts: rows for
 *                                     ridge, branch and bound for knn and radius); every
 *                                     lattice point of the open 40 x 20 m map reachable
 *   bench_models slice MODEL BUDGET   only the first fit call with that budget (the
 *                                     heaviest: it also standardises / copies), and the
 *                                     number of calls a whole fit takes
 * MODEL is a name of the registry (ridge, mlp, knn, radius). scan and search take an
 * optional third word `path`: the 10,000 samples then lie along a robot's path instead
 * (a random walk of 1 m legs, 200 samples per metre in runs of 20 at one position as a
 * 10 Hz pose and 200 packets/s give, targets rounded to whole dB as the receiver
 * reports them): dense and noisy, as in the simulator.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <valgrind/callgrind.h>

#include "rfs_gridmax.h"
#include "rfs_models.h"
#include "rfs_reach.h"

#define N 10000u
#define GRID_W 160
#define GRID_H 80

static void usage(FILE *f)
{
    fprintf(f, "usage: bench_models relearn MODEL | grid MODEL | scan MODEL | search MODEL |\n"
               "                    slice MODEL BUDGET\n"
               "MODEL: one of");
    for (uint32_t i = 0; i < rfs_models_count(); ++i) {
        fprintf(f, " %s", rfs_models_at(i)->name);
    }
    fprintf(f, "\n");
}

/* Samples along a robot path (see the header comment). */
static void make_path_samples(rfs_sample_t *s)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, 7);
    double x = 5.0, y = 5.0, hx = 1.0, hy = 0.0;
    for (uint32_t i = 0; i < N; i += 20u) {
        if (i % 200u == 0u) { /* a new 1 m leg: turn by up to 90 degrees, stay inside */
            double a = atan2(hy, hx) + ((double)rfs_rng_below(&r, 181) - 90.0) * 0.0174533;
            hx = cos(a);
            hy = sin(a);
            if (x + hx < 0.5 || x + hx > 39.5 || y + hy < 0.5 || y + hy > 19.5) {
                hx = -hx;
                hy = -hy;
            }
        }
        x += hx * 0.1;
        y += hy * 0.1;
        for (uint32_t k = i; k < i + 20u && k < N; ++k) {
            double u1 = ((double)rfs_rng_u32(&r) + 1.0) / 4294967297.0;
            double u2 = (double)rfs_rng_u32(&r) / 4294967296.0;
            double z = sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
            double d = hypot(x - 30.0, y - 12.0);
            s[k].x_cm = (int16_t)lround(x * 100.0);
            s[k].y_cm = (int16_t)lround(y * 100.0);
            s[k].v_q6 = (int16_t)(lround(-30.0 - 30.0 * log10(d + 1.0) + 4.0 * z) * 64);
        }
    }
}

static void make_samples(rfs_sample_t *s)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, 7);
    for (uint32_t i = 0; i < N; ++i) {
        s[i].x_cm = (int16_t)rfs_rng_below(&r, 4001);
        s[i].y_cm = (int16_t)rfs_rng_below(&r, 2001);
        double u1 = ((double)rfs_rng_u32(&r) + 1.0) / 4294967297.0;
        double u2 = (double)rfs_rng_u32(&r) / 4294967296.0;
        double z = sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
        double d = hypot(s[i].x_cm / 100.0 - 30.0, s[i].y_cm / 100.0 - 12.0);
        s[i].v_q6 = (int16_t)lround((-30.0 - 20.0 * log10(d + 1.0) + 4.0 * z) * 64.0);
    }
}

/* The grid search (rfs_gridmax.h) over an open 40 x 20 m map (0.1 m cells, no walls)
 * whose 0.25 m lattice is the 160 x 80 points above, every point marked reachable; only
 * the search itself is counted. */
static bool grid_search(const rfs_models_entry_t *e, void *state, bool pruned, rfs_q16_t *mx,
                        rfs_q16_t *my)
{
    enum { W = 400, H = 200 };
    static uint8_t free_bits[W / 8 * H], legal_bits[W / 8 * H];
    memset(free_bits, 0xFF, sizeof free_bits);
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    static rfs_map_t map;
    if (rfs_map_init(&map, &mc, W, H, RFS_Q16_ONE / 10 + 1, 0, 0, free_bits, NULL,
                     legal_bits) != 0) {
        return false;
    }
    uint32_t bits = rfs_reach_bytes(&map);
    uint8_t *reach = malloc(bits);
    if (reach == NULL) {
        return false;
    }
    memset(reach, 0xFF, bits); /* every point reachable */
    rfs_model_t model = {.ops = e->ops, .self = state};
    CALLGRIND_START_INSTRUMENTATION;
    bool ok = pruned ? rfs_gridmax_find(&map, &model, reach, mx, my)
                     : rfs_gridmax_scan(&map, &model, reach, mx, my);
    CALLGRIND_STOP_INSTRUMENTATION;
    free(reach);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "--help") == 0) {
        usage(stdout);
        return 0;
    }
    if (argc < 3) {
        usage(stderr);
        return 2;
    }
    const rfs_models_entry_t *e = rfs_models_lookup(argv[2]);
    if (e == NULL) {
        fprintf(stderr, "bench_models: MODEL: unknown model '%s'\n", argv[2]);
        return 2;
    }
    long budget = 0;
    if (strcmp(argv[1], "slice") == 0) {
        char *end = NULL;
        budget = argc >= 4 ? strtol(argv[3], &end, 10) : 0;
        if (argc < 4 || *end != '\0' || budget < 1 || budget > 1000000) {
            fprintf(stderr, "bench_models: BUDGET: not an integer in 1..1000000\n");
            return 2;
        }
    } else if (strcmp(argv[1], "relearn") != 0 && strcmp(argv[1], "grid") != 0 &&
               strcmp(argv[1], "scan") != 0 && strcmp(argv[1], "search") != 0) {
        usage(stderr);
        return 2;
    }
    rfs_sample_t *s = malloc(N * sizeof *s);
    void *state = aligned_alloc(RFS_MODELS_STATE_ALIGN, (e->state_bytes + 7u) & ~7u);
    if (s == NULL || state == NULL || e->init_default(state) != 0) {
        fprintf(stderr, "bench_models: setup failed\n");
        return 1;
    }
    bool path = argc >= 4 && strcmp(argv[3], "path") == 0;
    if (path) {
        make_path_samples(s);
    } else {
        make_samples(s);
    }
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 42);
    rfs_model_fit_in_t in = {.samples = s, .n = N, .qx = RFS_Q16_INT(20), .qy = RFS_Q16_INT(10),
                             .map = NULL};
    int64_t check = 0;
    if (strcmp(argv[1], "relearn") == 0) {
        CALLGRIND_START_INSTRUMENTATION;
        rfs_fit_result_t r = e->ops->fit(state, &in, 0u, &rng);
        CALLGRIND_STOP_INSTRUMENTATION;
        check = r;
    } else if (strcmp(argv[1], "slice") == 0) {
        uint32_t calls = 1;
        CALLGRIND_START_INSTRUMENTATION;
        rfs_fit_result_t r = e->ops->fit(state, &in, (uint32_t)budget, &rng);
        CALLGRIND_STOP_INSTRUMENTATION;
        while (r == RFS_FIT_MORE) {
            r = e->ops->fit(state, &in, (uint32_t)budget, &rng);
            calls++;
        }
        printf("calls %u\n", calls);
        check = r;
    } else if (strcmp(argv[1], "scan") == 0 || strcmp(argv[1], "search") == 0) {
        e->ops->fit(state, &in, 0u, &rng);
        rfs_q16_t mx = 0, my = 0;
        bool ok = grid_search(e, state, strcmp(argv[1], "search") == 0, &mx, &my);
        printf("max %d %d\n", mx, my);
        check = ok;
    } else {
        e->ops->fit(state, &in, 0u, &rng);
        rfs_q16_t best = RFS_Q16_MIN;
        CALLGRIND_START_INSTRUMENTATION;
        for (int j = 0; j < GRID_H; ++j) {
            for (int i = 0; i < GRID_W; ++i) {
                rfs_q16_t v;
                if (e->ops->predict(state, i * 16384 + 8192, j * 16384 + 8192, &v) && v > best) {
                    best = v;
                }
            }
        }
        CALLGRIND_STOP_INSTRUMENTATION;
        check = best;
    }
    printf("check %lld\n", (long long)check);
    free(state);
    free(s);
    return 0;
}
