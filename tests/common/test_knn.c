/* test_knn.c - nearest-neighbour regression models (common/rfs_knn).
 *
 * References come from scikit-learn (KNeighborsRegressor(n_neighbors=k, weights='uniform')
 * and RadiusNeighborsRegressor(radius=r)) run through /usr/bin/python3 on
 * tests/common/ref_knn.py, with the same samples and queries written to a temporary file.
 * Queries whose answer depends on tie-breaking (k-th and (k+1)-th distances within
 * 1e-5 m, or a distance within 1e-5 m of the radius) are skipped; the script says which.
 * The attached index (rfs_knn_index_attach()) is checked against the plain scan, ties at
 * the k-th distance included. Run from the repository root (as `make test` does).
 */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rfs_knn.h"
#include "rfs_knn_index.h"

#define MAXS 10000u
#define MAXQ 600u

static rfs_sample_t g_s[MAXS];
static rfs_knn_t g_knn, g_knn2;
static double g_qx[MAXQ], g_qy[MAXQ], g_ref[MAXQ];
static int g_amb[MAXQ];

static int32_t d_to_q16(double v)
{
    return (int32_t)lround(v * 65536.0);
}

/* Write samples and queries, run scikit-learn, read its predictions into g_ref/g_amb. */
static void sklearn_reference(const char *mode, double param, uint32_t n, uint32_t nq)
{
    char in[] = "/tmp/rfs_knn_in_XXXXXX";
    char out[] = "/tmp/rfs_knn_out_XXXXXX";
    int fi = mkstemp(in), fo = mkstemp(out);
    assert_true(fi >= 0 && fo >= 0);
    close(fo);
    FILE *f = fdopen(fi, "w");
    assert_non_null(f);
    if (strcmp(mode, "knn") == 0) {
        fprintf(f, "knn %d\n%u\n", (int)param, n);
    } else {
        fprintf(f, "radius %.9f\n%u\n", param, n);
    }
    for (uint32_t i = 0; i < n; ++i) {
        fprintf(f, "%.2f %.2f %.6f\n", g_s[i].x_cm / 100.0, g_s[i].y_cm / 100.0,
                g_s[i].v_q6 / 64.0);
    }
    fprintf(f, "%u\n", nq);
    for (uint32_t i = 0; i < nq; ++i) {
        fprintf(f, "%.9f %.9f\n", g_qx[i], g_qy[i]);
    }
    fclose(f);
    char cmd[256];
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/common/ref_knn.py %s %s", in, out);
    int rc = system(cmd);
    assert_int_equal(rc, 0);
    f = fopen(out, "r");
    assert_non_null(f);
    for (uint32_t i = 0; i < nq; ++i) {
        char word[64];
        assert_int_equal(fscanf(f, "%63s %d", word, &g_amb[i]), 2);
        g_ref[i] = strtod(word, NULL); /* "nan" parses to NaN */
    }
    fclose(f);
    unlink(in);
    unlink(out);
}

/* Queries on the 0.25 m lattice are exactly representable in Q16.16 (as the grid
 * search uses them); the reference gets the same values. */
static void make_queries(uint32_t nq, double x0, double x1, double y0, double y1, uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    uint32_t nx = (uint32_t)((x1 - x0) * 4.0) + 1u, ny = (uint32_t)((y1 - y0) * 4.0) + 1u;
    for (uint32_t i = 0; i < nq; ++i) {
        g_qx[i] = x0 + rfs_rng_below(&r, nx) * 0.25;
        g_qy[i] = y0 + rfs_rng_below(&r, ny) * 0.25;
    }
}

/* Uniform random samples over [0, w] x [0, h] metres, targets a smooth field + noise. */
static void make_uniform(uint32_t n, uint32_t w_cm, uint32_t h_cm, uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    for (uint32_t i = 0; i < n; ++i) {
        g_s[i].x_cm = (int16_t)rfs_rng_below(&r, w_cm + 1u);
        g_s[i].y_cm = (int16_t)rfs_rng_below(&r, h_cm + 1u);
        g_s[i].v_q6 = (int16_t)(-60 * 64 + (int32_t)rfs_rng_below(&r, 40 * 64) +
                                g_s[i].x_cm / 8);
    }
}

/* Samples along a robot path: a random walk of 1 m steps with 0.05 m between samples. */
static void make_path(uint32_t n, uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    double x = 10.0, y = 5.0, dx = 0.05, dy = 0.0;
    for (uint32_t i = 0; i < n; ++i) {
        if (i % 20u == 0u) {
            uint32_t d = rfs_rng_below(&r, 4);
            dx = d == 0 ? 0.05 : (d == 1 ? -0.05 : 0.0);
            dy = d == 2 ? 0.05 : (d == 3 ? -0.05 : 0.0);
        }
        x = fmin(fmax(x + dx, 0.0), 60.0);
        y = fmin(fmax(y + dy, 0.0), 12.0);
        g_s[i].x_cm = (int16_t)lround(x * 100.0 + (double)rfs_rng_below(&r, 7) - 3.0);
        g_s[i].y_cm = (int16_t)lround(y * 100.0 + (double)rfs_rng_below(&r, 7) - 3.0);
        g_s[i].v_q6 = (int16_t)(-70 * 64 + (int32_t)rfs_rng_below(&r, 30 * 64));
    }
}

static void fit_whole(rfs_knn_t *s, const rfs_knn_cfg_t *c, uint32_t n)
{
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_model_fit_in_t in = {.samples = g_s, .n = (uint16_t)n};
    assert_int_equal(rfs_knn_init(s, c), 0);
    assert_int_equal(rfs_knn_model(s).ops->fit(s, &in, 0, &rng), RFS_FIT_DONE);
}

/* Compare every unambiguous query with scikit-learn; returns how many were compared. */
static uint32_t compare_all(const rfs_knn_t *s, uint32_t nq)
{
    uint32_t compared = 0, none = 0;
    for (uint32_t i = 0; i < nq; ++i) {
        if (g_amb[i]) {
            continue;
        }
        rfs_q16_t v = 0;
        bool ok = rfs_knn_ops.predict(s, d_to_q16(g_qx[i]), d_to_q16(g_qy[i]), &v);
        if (isnan(g_ref[i])) {
            assert_false(ok);
            none++;
        } else {
            assert_true(ok);
            double got = v / 65536.0;
            if (fabs(got - g_ref[i]) > 1e-4) {
                fail_msg("query %u (%.2f, %.2f): got %.6f, scikit-learn %.6f", i, g_qx[i],
                         g_qy[i], got, g_ref[i]);
            }
        }
        compared++;
    }
    (void)none;
    return compared;
}

static void kneighbors_matches_sklearn_uniform(void **state)
{
    (void)state;
    const uint32_t ks[] = {1, 5, 12};
    make_uniform(3000, 4000, 3000, 11);
    make_queries(500, -5.0, 45.0, -5.0, 35.0, 12);
    for (uint32_t t = 0; t < 3; ++t) {
        rfs_knn_cfg_t c = rfs_knn_cfg_default();
        c.k = (uint8_t)ks[t];
        fit_whole(&g_knn, &c, 3000);

        sklearn_reference("knn", ks[t], 3000, 500);
        uint32_t compared = compare_all(&g_knn, 500);

        assert_true(compared > 400);
    }
}

static void kneighbors_matches_sklearn_on_robot_path(void **state)
{
    (void)state;
    rfs_knn_cfg_t c = rfs_knn_cfg_default();
    make_path(MAXS, 21);
    make_queries(MAXQ, 0.0, 60.0, 0.0, 12.0, 22);
    fit_whole(&g_knn, &c, MAXS);

    sklearn_reference("knn", 5, MAXS, MAXQ);
    uint32_t compared = compare_all(&g_knn, MAXQ);

    assert_true(compared > 500);
}

static void radius_matches_sklearn(void **state)
{
    (void)state;
    const double radii[] = {1.0, 2.5};
    make_uniform(2000, 6000, 2000, 31);
    make_queries(500, -2.0, 62.0, -2.0, 22.0, 32);
    for (uint32_t t = 0; t < 2; ++t) {
        rfs_knn_cfg_t c = rfs_knn_cfg_radius_default();
        c.radius = d_to_q16(radii[t]);
        fit_whole(&g_knn, &c, 2000);

        sklearn_reference("radius", radii[t], 2000, 500);
        uint32_t compared = compare_all(&g_knn, 500);

        uint32_t empty = 0;
        for (uint32_t i = 0; i < 500; ++i) {
            empty += isnan(g_ref[i]) ? 1u : 0u;
        }
        assert_true(compared > 400);
        assert_true(empty > 0); /* the no-neighbour case was exercised */
    }
}

/* A 300 m wide sample cloud needs cells wider than the configured 1 m (64 per side). */
static void wide_extent_and_clamped_queries(void **state)
{
    (void)state;
    rfs_knn_cfg_t c = rfs_knn_cfg_default();
    make_uniform(1500, 30000, 500, 41);
    make_queries(400, -50.0, 350.0, -20.0, 25.0, 42);
    fit_whole(&g_knn, &c, 1500);

    sklearn_reference("knn", 5, 1500, 400);
    uint32_t compared = compare_all(&g_knn, 400);

    assert_true(g_knn.cell_cm > 100);
    assert_true(g_knn.gw <= RFS_KNN_GRID);
    assert_true(compared > 350);
}

static void fewer_samples_than_k_averages_all(void **state)
{
    (void)state;
    rfs_knn_cfg_t c = rfs_knn_cfg_default();
    g_s[0] = (rfs_sample_t){100, 100, -50 * 64};
    g_s[1] = (rfs_sample_t){900, -300, -41 * 64};
    g_s[2] = (rfs_sample_t){-2000, 50, -30 * 64 + 16};
    fit_whole(&g_knn, &c, 3);
    rfs_q16_t v;

    bool ok = rfs_knn_ops.predict(&g_knn, RFS_Q16_INT(7), RFS_Q16_INT(-3), &v);

    assert_true(ok);
    /* (-50 - 41 - 29.75) / 3 = -40.25 */
    assert_int_equal(v, d_to_q16(-40.25));
}

static void sliced_fit_respects_budget_and_equals_whole(void **state)
{
    (void)state;
    rfs_knn_cfg_t c = rfs_knn_cfg_default();
    const uint32_t budget = 97;
    make_path(4000, 51);
    fit_whole(&g_knn, &c, 4000);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_model_fit_in_t in = {.samples = g_s, .n = 4000};
    assert_int_equal(rfs_knn_init(&g_knn2, &c), 0);

    uint32_t calls = 0, worst = 0, total = 0;
    rfs_fit_result_t r;
    do {
        r = rfs_knn_ops.fit(&g_knn2, &in, budget, &rng);
        worst = g_knn2.updates > worst ? g_knn2.updates : worst;
        total += g_knn2.updates;
        calls++;
    } while (r == RFS_FIT_MORE && calls < 100000);

    assert_int_equal(r, RFS_FIT_DONE);
    assert_int_equal(worst, budget);
    assert_true(calls > 100);
    /* copy, count and place each sample once; clear, sum and close each cell once */
    assert_int_equal(total, 3u * 4000u + 3u * g_knn2.gw * g_knn2.gh + 1u);
    assert_memory_equal(g_knn.pts, g_knn2.pts, sizeof g_knn.pts);
    for (int32_t i = 0; i < 50; ++i) {
        rfs_q16_t a, b;
        rfs_q16_t x = RFS_Q16_INT(i), y = RFS_Q16_FRAC(i * 13 % 120, 10);
        assert_true(rfs_knn_ops.predict(&g_knn, x, y, &a));
        assert_true(rfs_knn_ops.predict(&g_knn2, x, y, &b));
        assert_int_equal(a, b);
    }
}

static void init_rejects_bad_configuration_and_defaults_are_sklearns(void **state)
{
    (void)state;
    rfs_knn_cfg_t good = rfs_knn_cfg_default(), c;
    rfs_knn_cfg_t rad = rfs_knn_cfg_radius_default();

    assert_int_equal(good.k, 5);
    assert_int_equal(good.mode, RFS_KNN_KNEIGHBORS);
    assert_int_equal(rad.mode, RFS_KNN_RADIUS);
    assert_int_equal(rad.radius, RFS_Q16_ONE);
    assert_int_equal(rfs_knn_init(&g_knn, &good), 0);
    c = good; c.k = 0;
    assert_int_equal(rfs_knn_init(&g_knn, &c), -1);
    c = good; c.k = RFS_KNN_MAX_K + 1;
    assert_int_equal(rfs_knn_init(&g_knn, &c), -1);
    c = good; c.radius = 0;
    assert_int_equal(rfs_knn_init(&g_knn, &c), -1);
    c = good; c.cell = RFS_Q16_FRAC(1, 100);
    assert_int_equal(rfs_knn_init(&g_knn, &c), -1);
    c = good; c.max_samples = 0;
    assert_int_equal(rfs_knn_init(&g_knn, &c), -1);
    c = good; c.mode = (rfs_knn_mode_t)7;
    assert_int_equal(rfs_knn_init(&g_knn, &c), -1);
}

static void no_samples_fails_and_reset_discards(void **state)
{
    (void)state;
    rfs_knn_cfg_t c = rfs_knn_cfg_radius_default();
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_model_fit_in_t none = {.samples = g_s, .n = 0};
    rfs_q16_t v;
    assert_int_equal(rfs_knn_init(&g_knn, &c), 0);
    rfs_model_t m = rfs_knn_model(&g_knn);

    assert_int_equal(m.ops->fit(m.self, &none, 0, &rng), RFS_FIT_FAILED);
    assert_false(m.ops->predict(m.self, 0, 0, &v));
    assert_string_equal(m.ops->name, "radius");
    g_s[0] = (rfs_sample_t){0, 0, 64};
    rfs_model_fit_in_t one = {.samples = g_s, .n = 1};
    assert_int_equal(m.ops->fit(m.self, &one, 0, &rng), RFS_FIT_DONE);
    assert_true(m.ops->predict(m.self, RFS_Q16_FRAC(1, 2), 0, &v));
    assert_int_equal(v, RFS_Q16_ONE);
    m.ops->reset(m.self);
    assert_false(m.ops->predict(m.self, 0, 0, &v));
}

/* --- The attached finer index (rfs_knn_index_attach()) against the plain scan ---------- */

static rfs_knn_index_t g_ix;

/* Samples in n / 40 clusters on a 10 cm lattice, many at one position (a robot that
 * stands still), the rest scattered: exact ties at the k-th distance are common. */
static void make_clustered(uint32_t n, uint32_t w_cm, uint32_t h_cm, uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    uint32_t nc = n / 40u + 1u;
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t c = rfs_rng_below(&r, nc);
        rfs_rng_t rc;
        rfs_rng_seed(&rc, seed * 1000u + c);
        int32_t cx = (int32_t)rfs_rng_below(&rc, w_cm / 10u + 1u) * 10;
        int32_t cy = (int32_t)rfs_rng_below(&rc, h_cm / 10u + 1u) * 10;
        uint32_t spread = rfs_rng_below(&r, 3) * 10u; /* 0: the cluster's own position */
        g_s[i].x_cm = (int16_t)(cx + (int32_t)rfs_rng_below(&r, 2u * spread + 1u) - (int32_t)spread);
        g_s[i].y_cm = (int16_t)(cy + (int32_t)rfs_rng_below(&r, 2u * spread + 1u) - (int32_t)spread);
        g_s[i].v_q6 = (int16_t)(-80 * 64 + (int32_t)rfs_rng_below(&r, 50 * 64));
    }
}

/* A query coordinate in Q16.16 anywhere around the samples' span [lo, hi] (cm) and
 * beyond it (clamped rings). */
static rfs_q16_t query_at(rfs_rng_t *r, int32_t lo_cm, int32_t hi_cm)
{
    int32_t span = hi_cm - lo_cm + 2000;
    int64_t cm_q8 = ((int64_t)lo_cm - 1000) * 256 + (int64_t)rfs_rng_below(r, (uint32_t)span * 256u);
    return (rfs_q16_t)(cm_q8 * 65536 / 25600);
}

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Whether the mean of the k nearest (brute force, exact integer distances) depends on
 * which of the samples tied at the k-th distance are taken. */
static bool tie_matters(uint32_t n, uint32_t k, rfs_q16_t x, rfs_q16_t y)
{
    int64_t qx = ((int64_t)x * 100 + 128) >> 8, qy = ((int64_t)y * 100 + 128) >> 8;
    static int64_t d2[MAXS];
    for (uint32_t i = 0; i < n; ++i) {
        int64_t dx = (int64_t)g_s[i].x_cm * 256 - qx, dy = (int64_t)g_s[i].y_cm * 256 - qy;
        d2[i] = dx * dx + dy * dy;
    }
    if (k >= n) {
        return false;
    }
    static int64_t sorted[MAXS];
    memcpy(sorted, d2, n * sizeof d2[0]);
    qsort(sorted, n, sizeof sorted[0], cmp_i64);
    int64_t kth = sorted[k - 1u];
    uint32_t less = 0, tied = 0;
    int16_t vmin = INT16_MAX, vmax = INT16_MIN;
    for (uint32_t i = 0; i < n; ++i) {
        less += d2[i] < kth ? 1u : 0u;
        if (d2[i] == kth) {
            tied++;
            vmin = g_s[i].v_q6 < vmin ? g_s[i].v_q6 : vmin;
            vmax = g_s[i].v_q6 > vmax ? g_s[i].v_q6 : vmax;
        }
    }
    return less + tied > k && vmin != vmax;
}

/* Both states fitted from g_s[0, n); g_knn2 with the index (attached before the fit, or
 * after it). Every query: same answer, same value. Returns the tie-dependent queries
 * among the first `ties_checked`. */
static uint32_t index_equals_plain(const rfs_knn_cfg_t *c, uint32_t n, uint32_t nq,
                                   uint32_t ties_checked, bool attach_first, uint64_t seed)
{
    rfs_rng_t rng, rq;
    rfs_rng_seed(&rng, 1);
    rfs_rng_seed(&rq, seed);
    rfs_model_fit_in_t in = {.samples = g_s, .n = (uint16_t)n};
    assert_int_equal(rfs_knn_init(&g_knn, c), 0);
    assert_int_equal(rfs_knn_init(&g_knn2, c), 0);
    if (attach_first) {
        rfs_knn_index_attach(&g_knn2, &g_ix);
    }
    assert_int_equal(rfs_knn_ops.fit(&g_knn, &in, 0, &rng), RFS_FIT_DONE);
    rfs_fit_result_t r;
    do {
        r = rfs_knn_ops.fit(&g_knn2, &in, 301, &rng);
    } while (r == RFS_FIT_MORE);
    assert_int_equal(r, RFS_FIT_DONE);
    if (!attach_first) {
        rfs_knn_index_attach(&g_knn2, &g_ix);
    }
    int32_t lo_x = g_knn.min_x_cm, hi_x = g_knn.max_x_cm, lo_y = g_knn.min_y_cm, hi_y = g_knn.max_y_cm;
    uint32_t ties = 0;
    for (uint32_t q = 0; q < nq; ++q) {
        const rfs_sample_t *on = &g_s[rfs_rng_below(&rq, n)];
        rfs_q16_t x = query_at(&rq, lo_x, hi_x), y = query_at(&rq, lo_y, hi_y);
        if (rfs_rng_below(&rq, 4) == 0u) { /* one in four exactly on a sample */
            x = (rfs_q16_t)((int64_t)on->x_cm * 65536 / 100);
            y = (rfs_q16_t)((int64_t)on->y_cm * 65536 / 100);
        }
        rfs_q16_t a = 12345, b = 12345;
        bool oka = rfs_knn_ops.predict(&g_knn, x, y, &a);
        bool okb = rfs_knn_ops.predict(&g_knn2, x, y, &b);
        if (oka != okb || a != b) {
            fail_msg("query %u (%d, %d) Q16: plain %d %d, indexed %d %d", q, x, y, oka, a, okb, b);
        }
        if (q < ties_checked && c->mode == RFS_KNN_KNEIGHBORS && tie_matters(n, c->k, x, y)) {
            ties++;
        }
    }
    return ties;
}

static void index_predicts_as_plain_knn(void **state)
{
    (void)state;
    const uint8_t ks[] = {1, 5, 32};
    const int32_t cells_cm[] = {5, 30, 100, 300};
    uint32_t ties = 0;
    for (uint32_t t = 0; t < 12; ++t) {
        rfs_knn_cfg_t c = rfs_knn_cfg_default();
        c.k = ks[t % 3u];
        c.cell = RFS_Q16_FRAC(cells_cm[t / 3u], 100);
        make_clustered(4000, 3000, 1200, 60 + t);
        ties += index_equals_plain(&c, 4000, 1500, t < 3 ? 200 : 0, t % 2u == 0u, 70 + t);
        make_path(MAXS, 80 + t);
        (void)index_equals_plain(&c, MAXS, 800, 0, t % 2u == 1u, 90 + t);
        make_uniform(1 + t * 7, 30000, 500, 100 + t); /* fewer samples than k; wide cells */
        (void)index_equals_plain(&c, 1 + t * 7, 300, 0, true, 110 + t);
    }
    /* the k-th distance was tied between different targets, so the order mattered */
    print_message("tie-dependent queries: %u of 600\n", ties);
    assert_true(ties >= 20);
}

static void index_predicts_as_plain_radius(void **state)
{
    (void)state;
    const int32_t radii_cm[] = {10, 100, 250};
    const int32_t cells_cm[] = {5, 100, 300};
    for (uint32_t t = 0; t < 9; ++t) {
        rfs_knn_cfg_t c = rfs_knn_cfg_radius_default();
        c.radius = RFS_Q16_FRAC(radii_cm[t % 3u], 100);
        c.cell = RFS_Q16_FRAC(cells_cm[t / 3u], 100);
        make_clustered(4000, 3000, 1200, 120 + t);
        (void)index_equals_plain(&c, 4000, 2000, 0, t % 2u == 0u, 130 + t);
        make_path(MAXS, 140 + t);
        (void)index_equals_plain(&c, MAXS, 1000, 0, t % 2u == 1u, 150 + t);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(kneighbors_matches_sklearn_uniform),
        cmocka_unit_test(kneighbors_matches_sklearn_on_robot_path),
        cmocka_unit_test(radius_matches_sklearn),
        cmocka_unit_test(wide_extent_and_clamped_queries),
        cmocka_unit_test(fewer_samples_than_k_averages_all),
        cmocka_unit_test(sliced_fit_respects_budget_and_equals_whole),
        cmocka_unit_test(init_rejects_bad_configuration_and_defaults_are_sklearns),
        cmocka_unit_test(no_samples_fails_and_reset_discards),
        cmocka_unit_test(index_predicts_as_plain_knn),
        cmocka_unit_test(index_predicts_as_plain_radius),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
