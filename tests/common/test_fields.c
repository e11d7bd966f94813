/* test_fields.c - one path-loss fit per source and the target on the predicted fields
 * (common/rfs_fields).
 *
 * Data: an office built here (30 x 16 m, 0.1 m cells: a corridor between two rows of
 * rooms, doors 1 m wide), two sources on lattice points, and each source's samples at
 * random legal positions valued by the log-distance + walls model with known P0, n and W
 * (optionally plus a known offset in one area). Expected values come from that truth in
 * double precision (walls by the core's counting rule, which the model shares with the
 * simulator): the bridging f of the two true fields, the shrinkage of the offset.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "office_map.h"
#include "rfs_fields.h"
#include "rfs_models.h"

#define NS 3000
#define Q(v) ((rfs_q16_t)lround((v) * 65536.0))
#define D(q) ((double)(q) / 65536.0)

/* The truth: sources on lattice points (0.125 + 0.25 i), P0, n, W. */
static const double SX[2] = {5.125, 25.125}, SY[2] = {3.125, 13.125};
static const double P0 = -20.0, N_EXP = 3.0, W_DB = 5.0;

typedef struct fixture {
    uint8_t free_bits[MH * ((MW + 7) / 8)];
    uint8_t wall_bits[MH * ((MW + 7) / 8)];
    uint8_t legal_bits[MH * ((MW + 7) / 8)];
    rfs_map_t map;
    rfs_sample_t s[2][NS];
    rfs_fields_mem_t mem;
    rfs_fields_t fl;
    rfs_fields_t fl2;
} fixture_t;

static void alloc_mem(rfs_fields_mem_t *m, const rfs_map_t *map, const rfs_fields_cfg_t *c)
{
    rfs_fields_mem_size(map, c, &m->points, &m->cells);
    m->f = calloc(m->points, sizeof(int16_t));
    assert_non_null(m->f);
    for (int k = 0; k < 2; ++k) {
        m->walls[k] = calloc(m->points, 1);
        m->rsum[k] = calloc(m->cells, sizeof(int32_t));
        m->rcount[k] = calloc(m->cells, sizeof(uint16_t));
        assert_true(m->walls[k] && m->rsum[k] && m->rcount[k]);
    }
}

static void free_mem(rfs_fields_mem_t *m)
{
    free(m->f);
    for (int k = 0; k < 2; ++k) {
        free(m->walls[k]);
        free(m->rsum[k]);
        free(m->rcount[k]);
    }
}

static int setup(void **state)
{
    fixture_t *f = calloc(1, sizeof(*f));
    assert_non_null(f);
    office_map_init(f->free_bits, f->wall_bits, f->legal_bits, &f->map);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    alloc_mem(&f->mem, &f->map, &c);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture_t *f = *state;
    free_mem(&f->mem);
    free(f);
    return 0;
}

/* The true signal of source k at (x, y), dBm. */
static double truth(const rfs_map_t *m, int k, double x, double y)
{
    double d = hypot(x - SX[k], y - SY[k]);
    int w = rfs_map_walls_crossed(m, Q(x), Q(y), Q(SX[k]), Q(SY[k]));
    return P0 - 10.0 * N_EXP * log10(d < 1.0 ? 1.0 : d) - W_DB * w;
}

static double bridge_ref(double r1, double r2)
{
    return -fabs(r1 - r2) - fabs(r1 + r2);
}

/* NS samples of source k at random legal centimetre positions, valued by the truth plus
 * `off` dB inside [ox0, ox1] x [oy0, oy1]; with off != 0 half of them lie in that box. */
static void make_samples(rfs_sample_t *s, int k, const rfs_map_t *m, uint64_t seed, double off,
                         double ox0, double oy0, double ox1, double oy1)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    for (int i = 0; i < NS;) {
        int xc = (int)rfs_rng_below(&r, 3001), yc = (int)rfs_rng_below(&r, 1601);
        if (off != 0.0 && i >= NS / 2) {
            xc = (int)lround(ox0 * 100) + (int)rfs_rng_below(&r, (uint32_t)lround((ox1 - ox0) * 100) + 1);
            yc = (int)lround(oy0 * 100) + (int)rfs_rng_below(&r, (uint32_t)lround((oy1 - oy0) * 100) + 1);
        }
        double x = xc / 100.0, y = yc / 100.0;
        if (!rfs_map_point_legal(m, Q(x), Q(y))) {
            continue;
        }
        double v = truth(m, k, x, y);
        if (x >= ox0 && x <= ox1 && y >= oy0 && y <= oy1) {
            v += off;
        }
        s[i].x_cm = (int16_t)xc;
        s[i].y_cm = (int16_t)yc;
        s[i].v_q6 = (int16_t)lround(v * 64.0);
        ++i;
    }
}

static rfs_model_fit_in_t fit_in(fixture_t *f, uint8_t nsrc)
{
    rfs_model_fit_in_t in = {.samples = f->s[0], .n = NS, .map = &f->map, .nsources = nsrc};
    for (uint8_t k = 0; k < nsrc; ++k) {
        in.src_samples[k] = f->s[k];
        in.src_n[k] = NS;
        in.src_seen[k] = NS;
    }
    return in;
}

/* Fit to completion with `budget` units a call; the number of calls in *calls. */
static rfs_fit_result_t fit_all(rfs_fields_t *fl, const rfs_model_fit_in_t *in, uint32_t budget,
                                int *calls)
{
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 7);
    rfs_fit_result_t r;
    int n = 0;
    do {
        r = rfs_fields_ops.fit(fl, in, budget, &rng);
        n++;
    } while (r == RFS_FIT_MORE && n < 100000);
    if (calls != NULL) {
        *calls = n;
    }
    return r;
}

static void make_bridge(fixture_t *f, double off)
{
    make_samples(f->s[0], 0, &f->map, 11, off, 10.0, 6.0, 13.0, 10.0);
    make_samples(f->s[1], 1, &f->map, 12, 0.0, 0, 0, -1, -1);
}

/* Noiseless samples of both sources: each fit finds its source, the kept predictions
 * are the true f, and the best point's true f is the best of the true f over every
 * legal lattice point. */
static void test_noiseless_bridge(void **state)
{
    fixture_t *f = *state;
    make_bridge(f, 0.0);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &f->mem), 0);
    rfs_model_fit_in_t in = fit_in(f, 2);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    rfs_fields_est_t e;
    assert_true(rfs_fields_estimate(&f->fl, &e));
    assert_int_equal(e.nsources, 2);
    for (int k = 0; k < 2; ++k) {
        assert_int_equal(e.src[k].sx, Q(SX[k]));
        assert_int_equal(e.src[k].sy, Q(SY[k]));
        assert_true(fabs(D(e.src[k].n) - N_EXP) < 0.05);
        assert_true(fabs(D(e.src[k].w) - W_DB) < 0.3);
    }
    double best_true = -1e9, worst = 0.0;
    int predicted = 0, close = 0;
    for (uint16_t j = 0; j < f->map.lh; ++j) {
        for (uint16_t i = 0; i < f->map.lw; ++i) {
            if (!rfs_map_lattice_legal(&f->map, i, j)) {
                continue;
            }
            rfs_q16_t x, y, v;
            rfs_map_lattice_point(&f->map, i, j, &x, &y);
            double ft = bridge_ref(truth(&f->map, 0, D(x), D(y)), truth(&f->map, 1, D(x), D(y)));
            best_true = ft > best_true ? ft : best_true;
            if (rfs_fields_at(&f->fl, i, j, &v)) {
                predicted++;
                close += fabs(D(v) - ft) < 0.25;
                worst = fmax(worst, fabs(D(v) - ft));
            }
        }
    }
    /* The residuals take a sample's walls at its nearest lattice point: where a door's
     * edge runs between the two, a sample reads a wall off, which the kernel spreads. */
    assert_true(predicted > 6000);
    assert_true(close > 0.85 * predicted);
    assert_true(worst < W_DB);
    double at_best = bridge_ref(truth(&f->map, 0, D(e.x), D(e.y)), truth(&f->map, 1, D(e.x), D(e.y)));
    assert_true(fabs(at_best - best_true) < 0.5);
    assert_true(fabs(D(e.value) - best_true) < 0.5);
    rfs_q16_t px, py, pv;
    assert_true(rfs_fields_ops.argmax(&f->fl, &px, &py));
    assert_int_equal(px, e.x);
    assert_int_equal(py, e.y);
    assert_true(rfs_fields_ops.predict(&f->fl, e.x, e.y, &pv));
    assert_true(fabs(D(pv) - D(e.value)) < 0.01);
}

/* The residual correction: source 0's samples read `off` dB above the truth in one
 * area. Deep inside it (beyond the kernel from the edge) the field is raised by
 * off N / (N + prior_n), N the kernel-weighted count of its samples there; far away it
 * is the path-loss fit's. One source: the target is its RSSI. */
static void test_residual_shrinks_to_samples(void **state)
{
    fixture_t *f = *state;
    const double off = 8.0;
    /* Offset samples in the corridor (y 7..9) over x 10..13; fit one source only. */
    make_samples(f->s[0], 0, &f->map, 21, off, 10.0, 6.0, 13.0, 10.0);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    c.pathloss.bin_cap = 1; /* every bin one observation: the offset area barely moves P0 */
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_rssi, &f->mem), 0);
    rfs_model_fit_in_t in = fit_in(f, 1);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    rfs_fields_est_t e;
    assert_true(rfs_fields_estimate(&f->fl, &e));
    assert_int_equal(e.src[0].sx, Q(SX[0]));
    /* Lattice point (11.625, 8.125): cells of 0.25 m, kernel 1 - d / 0.5 m. */
    uint16_t i, j;
    rfs_map_lattice_nearest(&f->map, Q(11.625), Q(8.125), &i, &j);
    double num = 0.0, den = 0.0;
    for (int n = 0; n < NS; ++n) {
        uint16_t si, sj;
        rfs_map_lattice_nearest(&f->map, Q(f->s[0][n].x_cm / 100.0), Q(f->s[0][n].y_cm / 100.0),
                                &si, &sj);
        /* Cells are one lattice step here (0.25 m). */
        double w = 1.0 - 0.25 * hypot((double)si - i, (double)sj - j) / 0.5;
        if (w <= 0.0) {
            continue;
        }
        /* Residual against the fit, walls from the sample's nearest lattice point. */
        double x = f->s[0][n].x_cm / 100.0, y = f->s[0][n].y_cm / 100.0;
        rfs_q16_t lx, ly;
        rfs_map_lattice_point(&f->map, si, sj, &lx, &ly);
        double pl = D(e.src[0].p0) -
                    10.0 * D(e.src[0].n) * log10(fmax(1.0, hypot(x - SX[0], y - SY[0]))) -
                    D(e.src[0].w) * rfs_map_walls_crossed(&f->map, lx, ly, Q(SX[0]), Q(SY[0]));
        num += w * (f->s[0][n].v_q6 / 64.0 - pl);
        den += w;
    }
    assert_true(den > 5.0);
    rfs_q16_t x, y, v;
    rfs_map_lattice_point(&f->map, i, j, &x, &y);
    double pl_here = D(e.src[0].p0) - 10.0 * D(e.src[0].n) * log10(hypot(D(x) - SX[0], D(y) - SY[0])) -
                     D(e.src[0].w) * rfs_map_walls_crossed(&f->map, x, y, Q(SX[0]), Q(SY[0]));
    double want = pl_here + num / (den + c.prior_n);
    assert_true(rfs_fields_at(&f->fl, i, j, &v));
    assert_true(fabs(D(v) - want) < 0.2);
    assert_true(D(v) - pl_here > 0.7 * off);
    /* Far from the area: the fit alone (no offset). */
    rfs_map_lattice_nearest(&f->map, Q(20.125), Q(8.125), &i, &j);
    rfs_map_lattice_point(&f->map, i, j, &x, &y);
    assert_true(rfs_fields_at(&f->fl, i, j, &v));
    assert_true(fabs(D(v) - truth(&f->map, 0, D(x), D(y))) < 0.6);
}

/* A fit sliced into calls of a small budget ends bit for bit where one call ends. */
static void test_sliced_equals_whole(void **state)
{
    fixture_t *f = *state;
    make_bridge(f, 6.0);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    rfs_fields_mem_t m2;
    alloc_mem(&m2, &f->map, &c);
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &f->mem), 0);
    assert_int_equal(rfs_fields_init(&f->fl2, &c, &rfs_target_bridge, &m2), 0);
    rfs_model_fit_in_t in = fit_in(f, 2);
    int calls = 0;
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    assert_int_equal(fit_all(&f->fl2, &in, 300, &calls), RFS_FIT_DONE);
    assert_true(calls > 20);
    rfs_fields_est_t a, b;
    assert_true(rfs_fields_estimate(&f->fl, &a));
    assert_true(rfs_fields_estimate(&f->fl2, &b));
    assert_int_equal(a.x, b.x);
    assert_int_equal(a.y, b.y);
    assert_int_equal(a.value, b.value);
    assert_int_equal(a.sigma, b.sigma);
    assert_int_equal(a.area_m2, b.area_m2);
    assert_memory_equal(f->mem.f, m2.f, f->mem.points * sizeof(int16_t));
    free_mem(&m2);
}

/* A relearn on the same samples keeps the fits and counts no wall; new samples below
 * refit_min bin the residuals again without refitting; at refit_min the source is
 * refitted. */
static void test_relearn_reuses_unchanged_fits(void **state)
{
    fixture_t *f = *state;
    make_bridge(f, 0.0);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &f->mem), 0);
    rfs_model_fit_in_t in = fit_in(f, 2);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    rfs_fields_est_t a, b;
    assert_true(rfs_fields_estimate(&f->fl, &a));
    assert_true(f->fl.walls_counted > 1000u);
    rfs_fields_ops.reset(&f->fl);
    rfs_q16_t v;
    assert_false(rfs_fields_ops.predict(&f->fl, a.x, a.y, &v));
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    assert_true(rfs_fields_estimate(&f->fl, &b));
    assert_int_equal(f->fl.walls_counted, 0u);
    assert_int_equal(b.src[0].candidates, a.src[0].candidates);
    assert_int_equal(b.x, a.x);
    assert_int_equal(b.value, a.value);
    /* One new sample of source 1: its residuals again, no refit (source 0 untouched). */
    in.src_seen[1] += 1u;
    rfs_fields_ops.reset(&f->fl);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    assert_false(f->fl.refit[1]);
    assert_true(f->fl.changed[1]);
    assert_false(f->fl.changed[0]);
    assert_true(rfs_fields_estimate(&f->fl, &b));
    assert_int_equal(b.value, a.value);
    /* refit_min new samples: refitted, the same data giving the same fit. */
    in.src_seen[1] += c.refit_min;
    rfs_fields_ops.reset(&f->fl);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    assert_true(f->fl.refit[1]);
    assert_true(rfs_fields_estimate(&f->fl, &b));
    assert_int_equal(b.src[1].sx, a.src[1].sx);
    assert_int_equal(b.value, a.value);
}

/* sigma = sqrt(2 sum rms_k^2 prior / (prior + n_k)) at the best point, n_k the kernel-
 * weighted sample count, recomputed in double from the samples; the area counts the
 * kept predictions within sigma of the best. */
static void test_uncertainty(void **state)
{
    fixture_t *f = *state;
    make_bridge(f, 6.0);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &f->mem), 0);
    rfs_model_fit_in_t in = fit_in(f, 2);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    rfs_fields_est_t e;
    assert_true(rfs_fields_estimate(&f->fl, &e));
    uint16_t bi, bj;
    rfs_map_lattice_nearest(&f->map, e.x, e.y, &bi, &bj);
    double s2 = 0.0;
    for (int k = 0; k < 2; ++k) {
        double n = 0.0;
        for (int s = 0; s < NS; ++s) {
            uint16_t si, sj;
            rfs_map_lattice_nearest(&f->map, Q(f->s[k][s].x_cm / 100.0), Q(f->s[k][s].y_cm / 100.0),
                                    &si, &sj);
            n += fmax(0.0, 1.0 - 0.25 * hypot((double)si - bi, (double)sj - bj) / 0.5);
        }
        double rms = D(e.src[k].rms);
        s2 += rms * rms * c.prior_n / (c.prior_n + n);
    }
    assert_true(fabs(D(e.sigma) - sqrt(2.0 * s2)) < 0.02 + 0.01 * sqrt(2.0 * s2));
    int within = 0;
    for (uint16_t j = 0; j < f->map.lh; ++j) {
        for (uint16_t i = 0; i < f->map.lw; ++i) {
            rfs_q16_t v;
            within += rfs_fields_at(&f->fl, i, j, &v) && D(v) >= D(e.value) - D(e.sigma) - 1.0 / 64;
        }
    }
    assert_true(fabs(D(e.area_m2) - within * 0.0625) <= 0.0625 * 2);
}

/* The best point under lcb: the highest kept prediction less lcb times that point's sigma,
 * sigma from each source's kernel-weighted sample count in double (as test_uncertainty;
 * source 0 reads 6 dB low in one area, so its fit's rms is not 0); with lcb 0 it is the
 * highest prediction, a point the samples cover more thinly. */
static void test_lower_confidence_bound(void **state)
{
    fixture_t *f = *state;
    make_bridge(f, -6.0);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    c.lcb = RFS_Q16_INT(4);
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &f->mem), 0);
    rfs_model_fit_in_t in = fit_in(f, 2);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    rfs_fields_est_t e;
    assert_true(rfs_fields_estimate(&f->fl, &e));
    const int lw = f->map.lw, lh = f->map.lh;
    double *n = calloc((size_t)2 * lw * lh, sizeof(double));
    assert_non_null(n);
    for (int k = 0; k < 2; ++k) {
        for (int s = 0; s < NS; ++s) {
            uint16_t si, sj;
            rfs_map_lattice_nearest(&f->map, Q(f->s[k][s].x_cm / 100.0), Q(f->s[k][s].y_cm / 100.0),
                                    &si, &sj);
            for (int j = sj - 2; j <= sj + 2; ++j) {
                for (int i = si - 2; i <= si + 2; ++i) {
                    if (i >= 0 && j >= 0 && i < lw && j < lh) {
                        n[(size_t)k * lw * lh + (size_t)j * lw + i] +=
                            fmax(0.0, 1.0 - 0.25 * hypot(i - (double)si, j - (double)sj) / 0.5);
                    }
                }
            }
        }
    }
    double best = -1e9, at_pick = -1e9, top_v = -1e9;
    uint16_t bi, bj;
    rfs_map_lattice_nearest(&f->map, e.x, e.y, &bi, &bj);
    for (int j = 0; j < lh; ++j) {
        for (int i = 0; i < lw; ++i) {
            rfs_q16_t v;
            if (!rfs_fields_at(&f->fl, (uint16_t)i, (uint16_t)j, &v)) {
                continue;
            }
            double s2 = 0.0;
            for (int k = 0; k < 2; ++k) {
                double rms = D(e.src[k].rms), nk = n[(size_t)k * lw * lh + (size_t)j * lw + i];
                s2 += rms * rms * c.prior_n / (c.prior_n + nk);
            }
            double score = D(v) - 4.0 * sqrt(2.0 * s2);
            best = fmax(best, score);
            top_v = fmax(top_v, D(v));
            if (i == bi && j == bj) {
                at_pick = score;
            }
        }
    }
    free(n);
    assert_true(at_pick > best - 0.05);
    c.lcb = 0;
    assert_int_equal(rfs_fields_init(&f->fl2, &c, &rfs_target_bridge, &f->mem), 0);
    assert_int_equal(fit_all(&f->fl2, &in, 0, NULL), RFS_FIT_DONE);
    rfs_fields_est_t e0;
    assert_true(rfs_fields_estimate(&f->fl2, &e0));
    assert_true(fabs(D(e0.value) - top_v) < 0.02);
    assert_true(e0.x != e.x || e0.y != e.y);
    assert_true(D(e0.sigma) > D(e.sigma));
}

/* Spot k of the settle test: lattice point (SPX[k], SPY) in the corridor. */
static const double SPX[3] = {12.125, 15.125, 18.125}, SPY = 8.125;

/* n samples of source src at spot k (within 3 cm of it, its nearest lattice point), from
 * index at on, valued by the truth plus off dB. */
static void spot_samples(fixture_t *f, int src, int k, int at, int n, double off)
{
    for (int s = 0; s < n; ++s) {
        const int xc = (int)lround(SPX[k] * 100) - 1 + s % 3, yc = (int)lround(SPY * 100) - 1 + s / 3 % 3;
        f->s[src][at + s].x_cm = (int16_t)xc;
        f->s[src][at + s].y_cm = (int16_t)yc;
        f->s[src][at + s].v_q6 = (int16_t)lround((truth(&f->map, src, xc / 100.0, yc / 100.0) + off) * 64.0);
    }
}

static int arg_best(const double *v)
{
    return v[0] >= v[1] && v[0] >= v[2] ? 0 : v[1] >= v[2] ? 1 : 2;
}

/* The settle phase: candidates are the cells measured settle_n times (only the three
 * spots: the other samples lie about 0.4 to a cell), ranked by what was measured there
 * (the truth plus each spot's offset, in double: 4.3 and 5.7 dB apart); the tour's best
 * point is the first candidate not measured settle_conf times; after more samples at it
 * the next; once held, the best measured. Exploring, the best point is the prediction's, none of them. */
static void test_settle_tour(void **state)
{
    fixture_t *f = *state;
    make_bridge(f, 0.0);
    const double off[3] = {0.0, 5.0, 10.0};
    double ref[3];
    for (int k = 0; k < 3; ++k) {
        for (int src = 0; src < 2; ++src) {
            spot_samples(f, src, k, NS - 200 + 40 * k, 40, off[k]);
        }
        ref[k] = bridge_ref(truth(&f->map, 0, SPX[k], SPY) + off[k], truth(&f->map, 1, SPX[k], SPY) + off[k]);
    }
    const int first = arg_best(ref);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    c.settle_k = 3;
    c.settle_n = 8;
    c.settle_conf = 64;
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &f->mem), 0);
    rfs_model_fit_in_t in = fit_in(f, 2);
    rfs_fields_est_t e;
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    assert_true(rfs_fields_estimate(&f->fl, &e));
    for (int k = 0; k < 3; ++k) {
        assert_false(fabs(D(e.x) - SPX[k]) < 0.1 && fabs(D(e.y) - SPY) < 0.1);
    }
    in.settle = RFS_MODEL_TOUR;
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    assert_true(rfs_fields_estimate(&f->fl, &e));
    assert_true(fabs(D(e.x) - SPX[first]) < 1e-3 && fabs(D(e.y) - SPY) < 1e-3);
    /* 40 more samples at the first, 2 dB low: measured enough, 1 dB lower on average (f:
     * 2 dB), still the best measured: the tour moves on, the hold stays. */
    for (int src = 0; src < 2; ++src) {
        spot_samples(f, src, first, NS - 80, 40, off[first] - 2.0);
        in.src_seen[src] += 40;
    }
    double rank[3] = {ref[0], ref[1], ref[2]};
    rank[first] = -1e9;
    const int second = arg_best(rank);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    assert_true(rfs_fields_estimate(&f->fl, &e));
    assert_true(fabs(D(e.x) - SPX[second]) < 1e-3);
    in.settle = RFS_MODEL_HOLD;
    ref[first] -= 2.0;
    assert_int_equal(arg_best(ref), first);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    assert_true(rfs_fields_estimate(&f->fl, &e));
    assert_true(fabs(D(e.x) - SPX[arg_best(ref)]) < 1e-3);
}

/* Draws land on kept predictions, the best point with its share e^0 / sum e^(-d / T). */
static void test_draws(void **state)
{
    fixture_t *f = *state;
    make_bridge(f, 0.0);
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &f->mem), 0);
    rfs_model_fit_in_t in = fit_in(f, 2);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_DONE);
    rfs_fields_est_t e;
    assert_true(rfs_fields_estimate(&f->fl, &e));
    double total = 0.0, best_v = -1e9;
    for (uint16_t j = 0; j < f->map.lh; ++j) {
        for (uint16_t i = 0; i < f->map.lw; ++i) {
            rfs_q16_t v;
            if (rfs_fields_at(&f->fl, i, j, &v)) {
                best_v = fmax(best_v, D(v));
            }
        }
    }
    for (uint16_t j = 0; j < f->map.lh; ++j) {
        for (uint16_t i = 0; i < f->map.lw; ++i) {
            rfs_q16_t v;
            if (rfs_fields_at(&f->fl, i, j, &v)) {
                total += exp(-(best_v - D(v)) / 3.0);
            }
        }
    }
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 3);
    const int n = 20000;
    int at_best = 0;
    for (int t = 0; t < n; ++t) {
        rfs_q16_t x, y, v;
        uint16_t i, j;
        assert_true(rfs_fields_ops.sample(&f->fl, &rng, &x, &y));
        rfs_map_lattice_nearest(&f->map, x, y, &i, &j);
        assert_true(rfs_fields_at(&f->fl, i, j, &v));
        at_best += x == e.x && y == e.y;
    }
    double p = 1.0 / total, sd = sqrt(n * p * (1.0 - p));
    assert_true(fabs(at_best - n * p) < 5.0 * sd + 0.02 * n * p);
}

/* Bad configurations and arrays are refused; a fit without per-source samples fails. */
static void test_init_and_inputs(void **state)
{
    fixture_t *f = *state;
    rfs_fields_cfg_t c = rfs_fields_cfg_default();
    rfs_target_ops_t nocombine = rfs_target_bridge;
    nocombine.combine = NULL;
    assert_int_equal(rfs_fields_init(&f->fl, &c, &nocombine, &f->mem), -1);
    rfs_fields_mem_t m = f->mem;
    m.rsum[1] = NULL;
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &m), -1);
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_rssi, &m), 0); /* one source */
    rfs_fields_cfg_t bad = c;
    bad.cell = 0;
    assert_int_equal(rfs_fields_init(&f->fl, &bad, &rfs_target_bridge, &f->mem), -1);
    bad = c;
    bad.radius = 5 * c.cell; /* beyond RFS_FIELDS_KERNEL_MAX cells */
    assert_int_equal(rfs_fields_init(&f->fl, &bad, &rfs_target_bridge, &f->mem), -1);
    bad = c;
    bad.prior_n = 0;
    assert_int_equal(rfs_fields_init(&f->fl, &bad, &rfs_target_bridge, &f->mem), -1);
    bad = c;
    bad.lcb = -1;
    assert_int_equal(rfs_fields_init(&f->fl, &bad, &rfs_target_bridge, &f->mem), -1);
    bad = c;
    bad.settle_k = RFS_FIELDS_CAND + 1u;
    assert_int_equal(rfs_fields_init(&f->fl, &bad, &rfs_target_bridge, &f->mem), -1);
    bad = c;
    bad.settle_sep = 0;
    assert_int_equal(rfs_fields_init(&f->fl, &bad, &rfs_target_bridge, &f->mem), -1);
    bad = c;
    bad.pathloss.bin = 0;
    assert_int_equal(rfs_fields_init(&f->fl, &bad, &rfs_target_bridge, &f->mem), -1);
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &f->mem), 0);
    make_bridge(f, 0.0);
    rfs_model_fit_in_t in = fit_in(f, 1); /* source 1's samples missing */
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_FAILED);
    in = fit_in(f, 2);
    in.map = NULL;
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_FAILED);
    in = fit_in(f, 2);
    in.src_n[1] = 0;
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_FAILED);
    rfs_fields_est_t e;
    assert_false(rfs_fields_estimate(&f->fl, &e));
    /* Arrays too small for the map: the fit fails. */
    rfs_fields_mem_t small = f->mem;
    small.points = 100;
    assert_int_equal(rfs_fields_init(&f->fl, &c, &rfs_target_bridge, &small), 0);
    in = fit_in(f, 2);
    assert_int_equal(fit_all(&f->fl, &in, 0, NULL), RFS_FIT_FAILED);
}

/* The registry runs pathloss per source under a target of several sources only. */
static void test_registry_per_source(void **state)
{
    (void)state;
    assert_true(rfs_models_per_source(rfs_models_lookup("pathloss"), &rfs_target_bridge));
    assert_false(rfs_models_per_source(rfs_models_lookup("pathloss"), &rfs_target_rssi));
    assert_false(rfs_models_per_source(rfs_models_lookup("ridge"), &rfs_target_bridge));
    assert_false(rfs_models_per_source(NULL, &rfs_target_bridge));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_noiseless_bridge, setup, teardown),
        cmocka_unit_test_setup_teardown(test_residual_shrinks_to_samples, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sliced_equals_whole, setup, teardown),
        cmocka_unit_test_setup_teardown(test_relearn_reuses_unchanged_fits, setup, teardown),
        cmocka_unit_test_setup_teardown(test_uncertainty, setup, teardown),
        cmocka_unit_test_setup_teardown(test_lower_confidence_bound, setup, teardown),
        cmocka_unit_test_setup_teardown(test_settle_tour, setup, teardown),
        cmocka_unit_test_setup_teardown(test_draws, setup, teardown),
        cmocka_unit_test_setup_teardown(test_init_and_inputs, setup, teardown),
        cmocka_unit_test(test_registry_per_source),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
