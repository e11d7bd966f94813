/* bench_pathloss.c - instructions per relearn of the path-loss model, for callgrind
 * (`make bench-pathloss`, docs/PERFORMANCE.md "Pathloss model").
 *
 * Workload: the map MAP at the core's 0.1 m grid, N samples at random legal points of
 * it (the worst case for the bins: the whole floor visited), valued by the model with the
 * source at (SX, SY), P0 -40 dB, n 3, W 5 dB plus 4 dB Gaussian noise.
 *   bench_pathloss MAP relearn N          one whole fit (budget 0)
 *   bench_pathloss MAP slice N BUDGET     only the first fit call with that budget (the
 *                                         heaviest: it also bins), and the number of calls
 *   bench_pathloss MAP predict N          one prediction (the relearn check)
 *   bench_pathloss MAP path N             a mission: a random walk of 1 m steps from
 *                                         (8, 6) m, 40 samples a step, N steps; one
 *                                         relearn at the end from a fresh state
 *   bench_pathloss MAP pathwarm N         the same walk; a fit after N - 5 steps (not
 *                                         counted), then the relearn after N steps with
 *                                         the wall-count cache warm
 * Collection is toggled on around the measured calls only, so callgrind with
 * --collect-atstart=no counts exactly them. Prints the estimate so nothing is elided.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <valgrind/callgrind.h>

#include "lx_map.h"
#include "rfs_pathloss.h"

#define SX 27.5
#define SY 10.0

static int usage(FILE *f, int rc)
{
    fprintf(f, "usage: bench_pathloss MAP.yaml relearn|slice|predict N [BUDGET]\n"
               "  relearn N        one whole fit over N samples (1..65535)\n"
               "  slice N BUDGET   the first fit call with BUDGET (bin, candidate) units\n"
               "  predict N        one prediction after a fit\n"
               "  path N           relearn after a random walk of N 1 m steps (fresh state)\n"
               "  pathwarm N       the same, with the cache warmed 5 steps before\n");
    return rc;
}

static double gauss(rfs_rng_t *r)
{
    double u1 = ((double)rfs_rng_u32(r) + 1.0) / 4294967297.0;
    double u2 = (double)rfs_rng_u32(r) / 4294967296.0;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

static long parse(const char *s, const char *name, long lo, long hi)
{
    char *end = NULL;
    long v = strtol(s, &end, 10);
    if (*s == '\0' || *end != '\0' || v < lo || v > hi) {
        fprintf(stderr, "bench_pathloss: %s: not an integer in %ld..%ld: '%s'\n", name, lo, hi, s);
        exit(2);
    }
    return v;
}

/* The next sample position of a walk: i-th of 40 along the current 1 m step from
 * (*px, *py) to (*tx, *ty), a new step (a random legal direction) every 40 samples. */
static void walk_point(const rfs_map_t *m, long i, rfs_rng_t *r, double *px, double *py,
                       double *tx, double *ty, double *x, double *y)
{
    if (i % 40 == 0) {
        /* next 1 m step: a random legal direction */
        for (int tries = 0; tries < 1000; ++tries) {
            double a = 6.283185307179586 * (rfs_rng_u32(r) / 4294967296.0);
            *tx = *px + cos(a);
            *ty = *py + sin(a);
            if (rfs_map_segment_legal(m, (rfs_q16_t)lround(*px * 65536.0),
                                      (rfs_q16_t)lround(*py * 65536.0),
                                      (rfs_q16_t)lround(*tx * 65536.0),
                                      (rfs_q16_t)lround(*ty * 65536.0))) {
                break;
            }
            *tx = *px;
            *ty = *py;
        }
    }
    double t = (i % 40 + 1) / 40.0;
    *x = *px + (*tx - *px) * t;
    *y = *py + (*ty - *py) * t;
    if (i % 40 == 39) {
        *px = *tx;
        *py = *ty;
    }
}

/* n samples into s: along a walk from (8, 6) m, or at random legal points of the map;
 * valued by the model with the source at (SX, SY) plus noise (the header comment). */
static void make_samples(const rfs_map_t *m, bool walk, long n, rfs_rng_t *r, rfs_sample_t *s)
{
    double w_m = m->w * (m->res / 65536.0), h_m = m->h * (m->res / 65536.0);
    rfs_q16_t qsx = (rfs_q16_t)lround(SX * 65536.0), qsy = (rfs_q16_t)lround(SY * 65536.0);
    double px = 8.0, py = 6.0, tx = px, ty = py;
    for (long i = 0; i < n;) {
        double x, y;
        if (walk) {
            walk_point(m, i, r, &px, &py, &tx, &ty, &x, &y);
        } else {
            x = m->origin_x / 65536.0 + w_m * (rfs_rng_u32(r) / 4294967296.0);
            y = m->origin_y / 65536.0 + h_m * (rfs_rng_u32(r) / 4294967296.0);
        }
        rfs_q16_t qx = (rfs_q16_t)lround(x * 65536.0), qy = (rfs_q16_t)lround(y * 65536.0);
        if (!walk && !rfs_map_point_legal(m, qx, qy)) {
            continue;
        }
        double d = hypot(x - SX, y - SY);
        int k = rfs_map_walls_crossed(m, qx, qy, qsx, qsy);
        double v = -40.0 - 30.0 * log10(d < 1.0 ? 1.0 : d) - 5.0 * k + 4.0 * gauss(r);
        s[i].x_cm = (int16_t)lround(x * 100.0);
        s[i].y_cm = (int16_t)lround(y * 100.0);
        s[i].v_q6 = (int16_t)lround(v * 64.0);
        ++i;
    }
}

/* The fit of the mode, collection on around the measured calls: its result; the fit
 * calls in *calls. */
static rfs_fit_result_t fit_mode(const char *mode, rfs_pathloss_t *p, const rfs_model_fit_in_t *in,
                                 long n, long budget, rfs_rng_t *r, long *calls)
{
    rfs_fit_result_t res;
    *calls = 1;
    if (strcmp(mode, "slice") == 0) {
        CALLGRIND_TOGGLE_COLLECT;
        res = rfs_pathloss_ops.fit(p, in, (uint32_t)budget, r);
        CALLGRIND_TOGGLE_COLLECT;
        while (res == RFS_FIT_MORE) {
            res = rfs_pathloss_ops.fit(p, in, (uint32_t)budget, r);
            ++*calls;
        }
    } else if (strcmp(mode, "pathwarm") == 0) {
        rfs_model_fit_in_t early = *in;
        early.n = (uint16_t)(n > 200 ? n - 200 : 1);
        res = rfs_pathloss_ops.fit(p, &early, 0, r);
        CALLGRIND_TOGGLE_COLLECT;
        res = rfs_pathloss_ops.fit(p, in, 0, r);
        CALLGRIND_TOGGLE_COLLECT;
    } else if (strcmp(mode, "relearn") == 0 || strcmp(mode, "path") == 0) {
        CALLGRIND_TOGGLE_COLLECT;
        res = rfs_pathloss_ops.fit(p, in, 0, r);
        CALLGRIND_TOGGLE_COLLECT;
    } else {
        res = rfs_pathloss_ops.fit(p, in, 0, r);
    }
    return res;
}

/* The fit's figures and estimate on stdout (predict: the prediction at (8, 6) m). */
static void print_fit(const rfs_pathloss_t *p, const rfs_pathloss_est_t *e, long calls, rfs_q16_t v)
{
    uint16_t ncx, ncy;
    rfs_pathloss_surface_size(p, &ncx, &ncy);
    printf("calls %ld\n", calls);
    printf("bins %u\n", e->bins);
    printf("candidates %u\n", e->candidates);
    printf("walls_counted %u\n", e->walls_counted);
    printf("footprints_cached %u\n", e->footprints_cached);
    printf("coarse %u x %u\n", ncx, ncy);
    printf("state_bytes %zu\n", sizeof(rfs_pathloss_t));
    printf("estimate %.3f %.3f n %.3f W %.3f P0 %.3f rms %.3f spread %.1f m2 predict %.3f\n",
           e->sx / 65536.0, e->sy / 65536.0, e->n / 65536.0, e->w / 65536.0, e->p0 / 65536.0,
           e->rms / 65536.0, e->spread_m2 / 65536.0, v / 65536.0);
}

int main(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "--help") == 0) {
        return usage(stdout, 0);
    }
    if (argc < 4) {
        return usage(stderr, 2);
    }
    const char *mode = argv[2];
    long n = parse(argv[3], "N", 1, 65535);
    long budget = 0;
    if (strcmp(mode, "slice") == 0) {
        if (argc < 5) {
            return usage(stderr, 2);
        }
        budget = parse(argv[4], "BUDGET", 1, 100000000);
    } else if (strcmp(mode, "relearn") != 0 && strcmp(mode, "predict") != 0 &&
               strcmp(mode, "path") != 0 && strcmp(mode, "pathwarm") != 0) {
        return usage(stderr, 2);
    }
    char err[256];
    lx_map_t hm;
    lx_core_map_t cm;
    memset(&hm, 0, sizeof(hm));
    memset(&cm, 0, sizeof(cm));
    if (lx_map_load(argv[1], &hm, err, sizeof(err)) != 0 ||
        lx_map_to_core(&hm, 0.1, NULL, &cm, err, sizeof(err)) != 0) {
        fprintf(stderr, "bench_pathloss: %s\n", err);
        return 1;
    }
    const rfs_map_t *m = &cm.map;
    bool walk = strncmp(mode, "path", 4) == 0;
    long steps = n;
    if (walk) {
        n = steps * 40 > 65535 ? 65535 : steps * 40;
    }
    rfs_sample_t *s = malloc((size_t)n * sizeof(*s));
    rfs_pathloss_t *p = malloc(sizeof(*p));
    if (s == NULL || p == NULL) {
        fprintf(stderr, "bench_pathloss: out of memory\n");
        return 1;
    }
    rfs_rng_t r;
    rfs_rng_seed(&r, 7);
    make_samples(m, walk, n, &r, s);
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    if (rfs_pathloss_init(p, &c) != 0) {
        fprintf(stderr, "bench_pathloss: default configuration rejected\n");
        return 1;
    }
    rfs_model_fit_in_t in = {.samples = s, .n = (uint16_t)n, .map = m};
    long calls;
    rfs_fit_result_t res = fit_mode(mode, p, &in, n, budget, &r, &calls);
    rfs_q16_t v = 0;
    if (strcmp(mode, "predict") == 0) {
        CALLGRIND_TOGGLE_COLLECT;
        rfs_pathloss_ops.predict(p, RFS_Q16_INT(8), RFS_Q16_INT(6), &v);
        CALLGRIND_TOGGLE_COLLECT;
    }
    rfs_pathloss_est_t e;
    if (res != RFS_FIT_DONE || !rfs_pathloss_estimate(p, &e)) {
        fprintf(stderr, "bench_pathloss: fit failed\n");
        return 1;
    }
    print_fit(p, &e, calls, v);
    free(p);
    free(s);
    lx_core_map_free(&cm);
    lx_map_free(&hm);
    return 0;
}
