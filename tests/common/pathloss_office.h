/* pathloss_office.h - the fixture of the path-loss model's tests (test_pathloss.c,
 * test_pathloss_use.c, test_pathloss_warm.c): the office (office_map.h), samples valued by
 * the model with a known source, P0, n and W plus Gaussian noise, whole or sliced fits from
 * a fresh model, and a seeker driven in a double world on it.
 */
#ifndef PATHLOSS_OFFICE_H
#define PATHLOSS_OFFICE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "office_map.h"
#include "ref_pathloss.h"
#include "rfs_pathloss.h"
#include "rfs_reach.h"
#include "rfs_seek.h"
#include "rfs_test.h"

#define NS 2000

typedef struct fixture {
    uint8_t free_bits[MH * ((MW + 7) / 8)];
    uint8_t wall_bits[MH * ((MW + 7) / 8)];
    uint8_t legal_bits[MH * ((MW + 7) / 8)];
    rfs_map_t map;
    rfs_sample_t s[NS];
    rfs_pathloss_t pl;
    ref_pl_t ref;
} fixture_t;

static inline int setup(void **state)
{
    fixture_t *f = calloc(1, sizeof(*f));
    assert_non_null(f);
    office_map_init(f->free_bits, f->wall_bits, f->legal_bits, &f->map);
    *state = f;
    return 0;
}

static inline int teardown(void **state)
{
    free(*state);
    return 0;
}

static inline double gauss(rfs_rng_t *r)
{
    double u1 = ((double)rfs_rng_u32(r) + 1.0) / 4294967297.0;
    double u2 = (double)rfs_rng_u32(r) / 4294967296.0;
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

typedef struct truth {
    double sx, sy, p0, n, w, noise;
} truth_t;

/* Sample s at (xc, yc) cm valued by the truth t: P0 - 10 n log10(max(d, 1 m)) - W walls
 * (rfs_map_walls_crossed to the source; none without a map) plus Gaussian noise of sd
 * sigma dB drawn from r. */
static inline void truth_sample(const rfs_map_t *map, const truth_t *t, int xc, int yc,
                                double sigma, rfs_rng_t *r, rfs_sample_t *s)
{
    const rfs_q16_t qx = (rfs_q16_t)lround(xc / 100.0 * 65536.0);
    const rfs_q16_t qy = (rfs_q16_t)lround(yc / 100.0 * 65536.0);
    const rfs_q16_t qsx = (rfs_q16_t)lround(t->sx * 65536.0);
    const rfs_q16_t qsy = (rfs_q16_t)lround(t->sy * 65536.0);
    const double d = hypot(xc / 100.0 - t->sx, yc / 100.0 - t->sy);
    const int k = map != NULL ? rfs_map_walls_crossed(map, qx, qy, qsx, qsy) : 0;
    const double v = t->p0 - 10.0 * t->n * log10(d < 1.0 ? 1.0 : d) - t->w * k + sigma * gauss(r);
    s->x_cm = (int16_t)xc;
    s->y_cm = (int16_t)yc;
    s->v_q6 = (int16_t)lround(v * 64.0);
}

/* n samples at random legal points of the map (or anywhere in [0, 30] x [0, 16] m when
 * map is NULL), valued by the model with the truth's parameters; walls counted from the
 * sample's exact position to the source. */
static inline void make_samples(rfs_sample_t *s, int n, const rfs_map_t *map, const truth_t *t,
                                uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    for (int i = 0; i < n;) {
        int xc = (int)rfs_rng_below(&r, 3001), yc = (int)rfs_rng_below(&r, 1601);
        rfs_q16_t qx = (rfs_q16_t)lround(xc / 100.0 * 65536.0);
        rfs_q16_t qy = (rfs_q16_t)lround(yc / 100.0 * 65536.0);
        if (map != NULL && !rfs_map_point_legal(map, qx, qy)) {
            continue;
        }
        truth_sample(map, t, xc, yc, t->noise, &r, &s[i]);
        ++i;
    }
}

/* The estimator without its strong prior: a prior of weight 1 and every sample counted
 * (bin_cap at its maximum), for checks against the truth that generated the data. */
static inline rfs_pathloss_cfg_t weak_cfg(void)
{
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    c.prior_weight = RFS_Q16_ONE;
    c.w_prior_weight = RFS_Q16_ONE;
    c.bin_cap = UINT16_MAX;
    return c;
}

static inline ref_pl_cfg_t weak_ref(void)
{
    ref_pl_cfg_t c = ref_pl_cfg_default();
    c.prior_weight = 1.0;
    c.w_prior_weight = 1.0;
    c.bin_cap = UINT16_MAX;
    return c;
}

static inline rfs_pathloss_est_t fit_in_with(fixture_t *f, const rfs_pathloss_cfg_t *c,
                                             const rfs_model_fit_in_t *in, uint32_t budget, int *calls);

static inline rfs_pathloss_est_t fit_with(fixture_t *f, const rfs_pathloss_cfg_t *c, int n,
                                          const rfs_map_t *map, uint32_t budget, int *calls)
{
    rfs_model_fit_in_t in = {.samples = f->s, .n = (uint16_t)n, .map = map};
    return fit_in_with(f, c, &in, budget, calls);
}

/* A whole (budget 0) or sliced fit of `in` from a fresh model. */
static inline rfs_pathloss_est_t fit_in_with(fixture_t *f, const rfs_pathloss_cfg_t *c,
                                             const rfs_model_fit_in_t *in, uint32_t budget, int *calls)
{
    assert_int_equal(rfs_pathloss_init(&f->pl, c), 0);
    rfs_model_t m = rfs_pathloss_model(&f->pl);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_fit_result_t r;
    int k = 0;
    do {
        r = m.ops->fit(m.self, in, budget, &rng);
        ++k;
    } while (r == RFS_FIT_MORE && k < 100000);
    assert_int_equal(r, RFS_FIT_DONE);
    if (calls != NULL) {
        *calls = k;
    }
    rfs_pathloss_est_t e;
    assert_true(rfs_pathloss_estimate(&f->pl, &e));
    return e;
}

static inline rfs_pathloss_est_t fit_default(fixture_t *f, int n, const rfs_map_t *map, uint32_t budget,
                                             int *calls)
{
    rfs_pathloss_cfg_t c = rfs_pathloss_cfg_default();
    return fit_with(f, &c, n, map, budget, calls);
}

/* n and W away from the default prior (3, 5 dB), so that recovering them means something. */
static const truth_t k_office = {15.125, 3.375, -35.0, 2.6, 6.5, 0.3};

/* The seeker's working memory on map (a store of capacity samples, 256 pending, the
 * planner's lattice-sized buffers, the reachability bits), from the heap. */
static inline void office_seek_mem(const rfs_map_t *map, uint16_t capacity, rfs_seek_mem_t *mem)
{
    const uint32_t lpts = (uint32_t)map->lw * map->lh;
    memset(mem, 0, sizeof(*mem));
    mem->samples = calloc(capacity, sizeof(rfs_sample_t));
    mem->pending = calloc(256, sizeof(rfs_pending_t));
    mem->pending_cap = 256;
    mem->plan_work = calloc(lpts, 1);
    mem->plan_work_bytes = lpts;
    mem->plan_queue_cap = lpts;
    mem->plan_queue = calloc(lpts, sizeof(uint32_t));
    mem->visited_bytes = rfs_reach_bytes(map);
    mem->visited = calloc(mem->visited_bytes, 1);
    mem->reach_bytes = mem->visited_bytes;
    mem->reach = calloc(mem->reach_bytes, 1);
    assert_true(mem->samples != NULL && mem->pending != NULL && mem->plan_work != NULL &&
                mem->plan_queue != NULL && mem->visited != NULL && mem->reach != NULL);
}

static inline void office_seek_mem_free(rfs_seek_mem_t *mem)
{
    free(mem->samples);
    free(mem->pending);
    free(mem->plan_work);
    free(mem->plan_queue);
    free(mem->visited);
    free(mem->reach);
}

/* The seeker sk in a double world on the office: a differential-drive robot (0.23 m track,
 * 5 ms steps) from (2, 8) m; every 5 ms an RSSI of -40 - 30 log10(d) - 5 dB a wall + 4 dB
 * noise (noise rng) from the source at (15.125, 3.375) m, a pose every 100 ms and a
 * control period every 50 ms, until the robot is within 1.5 m of the source or 600 s
 * pass. Returns that distance, or -1 when not reached; *travel (if not NULL) the metres
 * driven. */
static inline double office_seek_run(const rfs_map_t *map, rfs_seek_t *sk, rfs_rng_t *rng,
                                     rfs_rng_t *noise, double *travel)
{
    const double sx = 15.125, sy = 3.375;
    const rfs_q16_t qsx = (rfs_q16_t)lround(sx * 65536.0), qsy = (rfs_q16_t)lround(sy * 65536.0);
    double x = 2.0, y = 8.0, th = 0, vl = 0, vr = 0, moved = 0;
    for (int ms = 0; ms < 600000; ms += 5) {
        int64_t now = (int64_t)ms * 1000;
        double v = (vl + vr) / 2e3, w = (vr - vl) / 1e3 / 0.23;
        x += v * cos(th) * 0.005;
        y += v * sin(th) * 0.005;
        moved += fabs(v) * 0.005;
        th = atan2(sin(th + w * 0.005), cos(th + w * 0.005));
        double d = fmax(hypot(x - sx, y - sy), 1.0);
        int k = rfs_map_walls_crossed(map, (rfs_q16_t)lround(x * 65536.0),
                                      (rfs_q16_t)lround(y * 65536.0), qsx, qsy);
        double dbm = -40 - 30 * log10(d) - 5.0 * k + 4 * gauss(noise);
        rfs_seek_on_rssi(sk, 0, now, (int8_t)lround(fmax(dbm, -127)), rng);
        if (ms % 100 == 0) {
            rfs_pose_t p = {now, (rfs_q16_t)lround(x * 65536.0), (rfs_q16_t)lround(y * 65536.0),
                            (rfs_q16_t)lround(th * 65536.0)};
            rfs_seek_on_pose(sk, &p, rng);
        }
        if (ms % 50 == 0) {
            rfs_seek_out_t out;
            rfs_seek_step(sk, now, rng, &out);
            vl = out.left_mm_s;
            vr = out.right_mm_s;
        }
        if (hypot(x - sx, y - sy) < 1.5) {
            if (travel != NULL) {
                *travel = moved;
            }
            return hypot(x - sx, y - sy);
        }
    }
    if (travel != NULL) {
        *travel = moved;
    }
    return -1.0;
}

#endif /* PATHLOSS_OFFICE_H */
