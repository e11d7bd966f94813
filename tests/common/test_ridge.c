/* test_ridge.c - the local ridge model against scikit-learn (paper section 5.2.1).
 *
 * The reference is scikit-learn's Ridge run by scripts/ref_ridge.py under /usr/bin/python3
 * on the same integer data (cm, Q9.6), the same radius test, predicting at the same
 * Q16.16 points. The test generates the data sets itself.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rfs_ridge.h"

/// Agreement required over the whole map, dB (docs/FIXED_POINT.md, "Local ridge model").
#define TOL_DB 0.05
/// What the arithmetic allows: slopes rounded to Q24 (3e-8 dB/m) over up to 900 m, the
/// centre rounded to Q16 (7.6e-6 m) times the slope, intercept and output roundings.
#define TIGHT_TOL_DB 3e-4

#define NSETS 120
#define NPRED_GRID 11
#define NPRED_NEAR 16
#define NPRED_FAR 8
/* The last four far points are a row crossing +16,384 m (the row prediction's fallback). */
#define FAR_ROW_X0 RFS_Q16_INT(16000)
#define FAR_ROW_DX RFS_Q16_INT(200)
#define FAR_ROW_Y RFS_Q16_INT(100)
#define NPRED (NPRED_GRID * NPRED_GRID + NPRED_NEAR + NPRED_FAR)
#define MAXN 65535

typedef struct dataset {
    uint16_t n;
    int32_t qx_cm, qy_cm;
    int32_t radius_cm;
    rfs_q16_t alpha;
    rfs_sample_t *s;
    rfs_q16_t px[NPRED], py[NPRED];
    bool none;            /* reference: no sample within the radius */
    double ref[NPRED];    /* reference predictions, dB */
} dataset_t;

static int16_t clamp16(int64_t v, int64_t lo, int64_t hi)
{
    return (int16_t)(v < lo ? lo : (v > hi ? hi : v));
}

static int32_t rand_range(rfs_rng_t *g, int32_t lo, int32_t hi)
{
    return lo + (int32_t)rfs_rng_below(g, (uint32_t)(hi - lo + 1));
}

/* One data set of the given kind; kinds cover the required cases. */
static void make_set(dataset_t *d, int kind, rfs_rng_t *g)
{
    d->radius_cm = 500;
    d->alpha = RFS_Q16_ONE;
    d->qx_cm = rand_range(g, -29000, 29000);
    d->qy_cm = rand_range(g, -29000, 29000);
    uint32_t n = 1u + rfs_rng_below(g, 3000u);
    int32_t spread = 700; /* cm around the query: some samples fall outside 5 m */
    /* A plane with noise: slope up to +-6 dB/m, level -128..0 dBm. */
    int32_t gx = rand_range(g, -600, 600), gy = rand_range(g, -600, 600); /* 1/100 dB/m */
    int32_t base = rand_range(g, -8192, 0);
    int32_t noise = rand_range(g, 0, 512);
    int32_t lx = 0, ly = 0; /* direction for the collinear kinds */
    switch (kind) {
    case 1: n = 1u; spread = 300; break;                         /* one sample */
    case 2: n = 1u + rfs_rng_below(g, 200u); spread = 0; break;  /* all at one point */
    case 3: lx = 1; ly = 0; break;                               /* on a line along x */
    case 4: lx = 3; ly = -7; break;                              /* on a skew line */
    case 5: /* 10,000 samples, all inside, at the +-300 m corner, values at the extremes */
        n = 10000u;
        d->qx_cm = (rfs_rng_below(g, 2u) ? 1 : -1) * 29600;
        d->qy_cm = (rfs_rng_below(g, 2u) ? 1 : -1) * 29600;
        spread = 350;
        noise = 8192;
        break;
    case 6: /* the extreme the sums are sized for: 65,535 samples, radius 300 m */
        n = MAXN;
        d->radius_cm = 30000;
        d->qx_cm = 0;
        d->qy_cm = 0;
        spread = 32767;
        noise = 8192;
        gx = rand_range(g, -20, 20);
        gy = rand_range(g, -20, 20);
        break;
    case 7: n = 10000u; break;                                     /* full store */
    case 8: d->alpha = RFS_Q16_FRAC(1, 2); d->radius_cm = 1000; spread = 1300; break; /* alpha, radius */
    case 9: d->alpha = RFS_Q16_INT(3); n = 1u + rfs_rng_below(g, 20u); break;
    case 10: n = 2u; spread = 5; break;                           /* two close samples */
    case 11: /* a query beyond the int16 centimetre range (> 327.67 m): the general pass */
        d->qx_cm = (rfs_rng_below(g, 2u) ? 1 : -1) * (32767 + rand_range(g, 1, 400));
        d->qy_cm = rand_range(g, -32000, 32000);
        n = 2000u;
        break;
    default: break;
    }
    if (kind == 12) {
        /* The widest Cramer numerators the types allow (|num| > 2^121: the two-rounding
         * scaling path): 65,535 samples at (+-173.2 m, +-244.9 m) inside a 300 m radius,
         * values +-512 dB following the sign of x. */
        d->n = MAXN;
        d->radius_cm = 30000;
        d->qx_cm = 0;
        d->qy_cm = 0;
        for (uint32_t i = 0; i < MAXN; ++i) {
            bool east = rfs_rng_below(g, 2u) != 0;
            d->s[i].x_cm = (int16_t)(east ? 17320 : -17320);
            d->s[i].y_cm = (int16_t)(rfs_rng_below(g, 2u) ? 24494 : -24494);
            d->s[i].v_q6 = (int16_t)(east ? 32767 : -32768);
        }
        n = 0; /* samples done */
    } else {
        d->n = (uint16_t)n;
    }
    for (uint32_t i = 0; i < n; ++i) {
        int32_t ox, oy;
        if (lx != 0 || ly != 0) {
            int32_t t = rand_range(g, -70, 70);
            ox = t * lx;
            oy = t * ly;
        } else if (spread == 0) {
            ox = 0;
            oy = 0;
        } else {
            ox = rand_range(g, -spread, spread);
            oy = rand_range(g, -spread, spread);
        }
        int64_t x = (int64_t)d->qx_cm + ox, y = (int64_t)d->qy_cm + oy;
        /* value: plane (Q6) + uniform noise, clamped to -128..0 dBm */
        int64_t z = base + ((int64_t)gx * ox * 64) / 10000 + ((int64_t)gy * oy * 64) / 10000 +
                    rand_range(g, -noise, noise);
        d->s[i].x_cm = clamp16(x, -32767, 32767);
        d->s[i].y_cm = clamp16(y, -32767, 32767);
        d->s[i].v_q6 = clamp16(z, -8192, 0);
    }
    /* Prediction points: a grid over the whole +-300 m map and points near the query. */
    int k = 0;
    for (int iy = 0; iy < NPRED_GRID; ++iy) {
        for (int ix = 0; ix < NPRED_GRID; ++ix) {
            d->px[k] = RFS_Q16_INT(-300) + ix * RFS_Q16_INT(60);
            d->py[k] = RFS_Q16_INT(-300) + iy * RFS_Q16_INT(60);
            k++;
        }
    }
    /* Far outside any map, to the ends of Q16.16 (the 128-bit prediction path). */
    static const rfs_q16_t far[NPRED_FAR][2] = {
        {RFS_Q16_INT(20000), RFS_Q16_INT(20000)}, {RFS_Q16_INT(-20000), RFS_Q16_INT(15000)},
        {INT32_MAX, INT32_MIN}, {INT32_MIN, 0},
        {FAR_ROW_X0, FAR_ROW_Y}, {FAR_ROW_X0 + FAR_ROW_DX, FAR_ROW_Y},
        {FAR_ROW_X0 + 2 * FAR_ROW_DX, FAR_ROW_Y}, {FAR_ROW_X0 + 3 * FAR_ROW_DX, FAR_ROW_Y}};
    for (int j = 0; j < NPRED_FAR; ++j) {
        d->px[k] = far[j][0];
        d->py[k] = far[j][1];
        k++;
    }
    while (k < NPRED) {
        d->px[k] = (rfs_q16_t)(((int64_t)d->qx_cm * 65536) / 100) + (rfs_q16_t)rand_range(g, -655360, 655360);
        d->py[k] = (rfs_q16_t)(((int64_t)d->qy_cm * 65536) / 100) + (rfs_q16_t)rand_range(g, -655360, 655360);
        k++;
    }
}

/* Run scripts/ref_ridge.py on every set; fills d[i].none and d[i].ref. */
static void run_reference(dataset_t *d, int nsets)
{
    char in[] = "/tmp/rfs_ridge_in_XXXXXX";
    int fd = mkstemp(in);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    for (int k = 0; k < nsets; ++k) {
        /* alpha: exact decimal of a Q16.16 multiple of 1/16 */
        fprintf(f, "set %u %d %d %d %.17g %d\n", d[k].n, d[k].qx_cm, d[k].qy_cm,
                d[k].radius_cm, d[k].alpha / 65536.0, NPRED);
        for (uint32_t i = 0; i < d[k].n; ++i) {
            fprintf(f, "%d %d %d\n", d[k].s[i].x_cm, d[k].s[i].y_cm, d[k].s[i].v_q6);
        }
        for (int j = 0; j < NPRED; ++j) {
            fprintf(f, "%d %d\n", d[k].px[j], d[k].py[j]);
        }
    }
    assert_int_equal(fclose(f), 0);
    char out[64], cmd[256];
    snprintf(out, sizeof out, "%s.out", in);
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 scripts/ref_ridge.py %s %s", in, out);
    int rc = system(cmd);
    unlink(in);
    if (rc != 0) {
        print_error("reference failed (run from the repository root): %s\n", cmd);
    }
    assert_int_equal(rc, 0);
    f = fopen(out, "r");
    assert_non_null(f);
    for (int k = 0; k < nsets; ++k) {
        char word[8];
        long pos = ftell(f);
        if (fscanf(f, "%7s", word) == 1 && strcmp(word, "none") == 0) {
            d[k].none = true;
            continue;
        }
        fseek(f, pos, SEEK_SET);
        d[k].none = false;
        for (int j = 0; j < NPRED; ++j) {
            assert_int_equal(fscanf(f, "%lf", &d[k].ref[j]), 1);
        }
    }
    fclose(f);
    unlink(out);
}

/* Fit (budget 0 = at once, else sliced) and return the worst error against the reference
 * over the +-300 m map (the far points are checked against their own bound here). */
static double check_set(const dataset_t *d, uint32_t budget)
{
    rfs_ridge_t r;
    rfs_ridge_cfg_t cfg = rfs_ridge_cfg_default();
    cfg.radius = (rfs_q16_t)(((int64_t)d->radius_cm * 65536) / 100);
    cfg.alpha = d->alpha;
    assert_int_equal(rfs_ridge_init(&r, &cfg), 0);
    rfs_model_t m = rfs_ridge_model(&r);
    rfs_model_fit_in_t in = {
        .samples = d->s, .n = d->n, .map = NULL,
        /* the query exactly on the sample grid: cm -> Q16.16 rounds back to the same cm */
        .qx = (rfs_q16_t)lround(d->qx_cm * 655.36), .qy = (rfs_q16_t)lround(d->qy_cm * 655.36),
    };
    rfs_rng_t g;
    rfs_rng_seed(&g, 1u);
    rfs_fit_result_t res;
    int calls = 0;
    do {
        res = m.ops->fit(m.self, &in, budget, &g);
        calls++;
    } while (res == RFS_FIT_MORE && calls < 1000000);
    if (budget != 0u && d->n > budget) {
        assert_true(calls >= (int)(d->n / budget));
    }
    rfs_q16_t v;
    if (d->none) {
        assert_int_equal(res, RFS_FIT_FAILED);
        assert_false(m.ops->predict(m.self, 0, 0, &v));
        assert_false(m.ops->predict_row(m.self, 0, 0, RFS_Q16_ONE, 1, &v));
        return 0.0;
    }
    assert_int_equal(res, RFS_FIT_DONE);
    double worst = 0.0;
    for (int j = 0; j < NPRED; ++j) {
        assert_true(m.ops->predict(m.self, d->px[j], d->py[j], &v));
        double got = v / 65536.0, want = d->ref[j];
        if (want > 32767.0 || want < -32768.0) {
            assert_int_equal(v, want > 0 ? RFS_Q16_MAX : RFS_Q16_MIN); /* saturated */
            continue;
        }
        double e = fabs(got - want);
        /* The slopes' Q24 rounding grows with the distance from the centre: for the
         * points far off the map the bound is 1e-4 dB + 3.5e-8 dB per metre of |dx|+|dy|
         * (0.5 LSB of Q24 is 3e-8 dB/m); on the +-300 m map it is TIGHT_TOL_DB. */
        if (j >= NPRED_GRID * NPRED_GRID && j < NPRED_GRID * NPRED_GRID + NPRED_FAR) {
            double dist = fabs(d->px[j] / 65536.0 - d->qx_cm / 100.0) +
                          fabs(d->py[j] / 65536.0 - d->qy_cm / 100.0);
            assert_true(e <= 1e-4 + 3.5e-8 * dist);
        } else if (e > worst) {
            worst = e;
        }
        if (e > TOL_DB) {
            print_error("set n=%u q=(%d,%d) point %d: got %.6f want %.6f\n", d->n, d->qx_cm,
                        d->qy_cm, j, got, want);
        }
        assert_true(e <= TOL_DB);
    }
    /* predict_row over each grid row and the far row: the same values as point by point */
    rfs_q16_t row[NPRED_GRID];
    for (int iy = 0; iy < NPRED_GRID; ++iy) {
        const int j0 = iy * NPRED_GRID;
        assert_true(m.ops->predict_row(m.self, d->px[j0], d->py[j0], RFS_Q16_INT(60),
                                       NPRED_GRID, row));
        for (int ix = 0; ix < NPRED_GRID; ++ix) {
            rfs_q16_t v1;
            assert_true(m.ops->predict(m.self, d->px[j0 + ix], d->py[j0 + ix], &v1));
            assert_int_equal(row[ix], v1);
            double want = d->ref[j0 + ix];
            if (want <= 32767.0 && want >= -32768.0) {
                assert_true(fabs(row[ix] / 65536.0 - want) <= TIGHT_TOL_DB);
            }
        }
    }
    const int jr = NPRED_GRID * NPRED_GRID + NPRED_FAR - 4;
    assert_true(m.ops->predict_row(m.self, FAR_ROW_X0, FAR_ROW_Y, FAR_ROW_DX, 4, row));
    for (int k = 0; k < 4; ++k) {
        rfs_q16_t v1;
        assert_true(m.ops->predict(m.self, d->px[jr + k], d->py[jr + k], &v1));
        assert_int_equal(row[k], v1);
    }
    /* a long row inside the fast range that saturates for the steeper models */
    rfs_q16_t lrow[64];
    assert_true(m.ops->predict_row(m.self, RFS_Q16_INT(-15000), RFS_Q16_INT(-15000),
                                   RFS_Q16_INT(470), 64, lrow));
    for (int k = 0; k < 64; ++k) {
        rfs_q16_t v1;
        assert_true(m.ops->predict(m.self, RFS_Q16_INT(-15000) + k * RFS_Q16_INT(470),
                                   RFS_Q16_INT(-15000), &v1));
        assert_int_equal(lrow[k], v1);
    }
    return worst;
}

static void test_against_sklearn(void **state)
{
    (void)state;
    /* fixture: NSETS data sets of every kind */
    static dataset_t sets[NSETS];
    rfs_rng_t g;
    rfs_rng_seed(&g, 20260521u);
    size_t total = 0;
    for (int k = 0; k < NSETS; ++k) {
        sets[k].s = malloc(sizeof(rfs_sample_t) * MAXN);
        assert_non_null(sets[k].s);
        make_set(&sets[k], k < 13 ? k : (k % 15 < 13 ? k % 15 : 0), &g);
        total += sets[k].n;
    }
    run_reference(sets, NSETS);
    /* act + assert: at once and sliced, every prediction within TOL_DB */
    double worst = 0.0, worst_sliced = 0.0;
    int fitted = 0;
    for (int k = 0; k < NSETS; ++k) {
        double e = check_set(&sets[k], 0u);
        double es = check_set(&sets[k], 97u);
        worst = e > worst ? e : worst;
        worst_sliced = es > worst_sliced ? es : worst_sliced;
        fitted += sets[k].none ? 0 : 1;
    }
    printf("ridge vs scikit-learn: %d sets (%d fitted, %zu samples), worst %.3g dB, sliced %.3g dB\n",
           NSETS, fitted, total, worst, worst_sliced);
    assert_true(fitted >= 100);
    assert_true(worst <= TIGHT_TOL_DB);
    assert_true(worst_sliced <= TIGHT_TOL_DB);
    for (int k = 0; k < NSETS; ++k) {
        free(sets[k].s);
    }
}

/* A hand-solvable case (independent of scikit-learn): two samples 2 m apart along x,
 * values -40 and -60 dB. Centred x = +-1 m: w = sum(xc yc) / (sum(xc^2) + alpha)
 * = (-10 - 10) / (2 + 1) = -20/3 dB/m; intercept at the mean position = -50 dB. */
static void test_two_points_closed_form(void **state)
{
    (void)state;
    rfs_sample_t s[2] = {{-100, 0, -40 * 64}, {100, 0, -60 * 64}};
    rfs_ridge_t r;
    rfs_ridge_cfg_t cfg = rfs_ridge_cfg_default();
    assert_int_equal(rfs_ridge_init(&r, &cfg), 0);
    rfs_model_fit_in_t in = {.samples = s, .n = 2, .qx = 0, .qy = 0, .map = NULL};
    assert_int_equal(rfs_ridge_ops.fit(&r, &in, 0u, NULL), RFS_FIT_DONE);
    assert_int_equal(r.n_used, 2);
    rfs_q16_t v;
    assert_true(rfs_ridge_ops.predict(&r, 0, 0, &v));
    assert_true(fabs(v / 65536.0 - (-50.0)) <= 1.0 / 65536.0);
    assert_true(rfs_ridge_ops.predict(&r, RFS_Q16_INT(3), RFS_Q16_INT(7), &v));
    assert_true(fabs(v / 65536.0 - (-50.0 - 20.0)) <= 2.0 / 65536.0);
    assert_true(fabs(r.wx_q24 / 16777216.0 - (-20.0 / 3.0)) <= 1.0 / 16777216.0);
    assert_int_equal(r.wy_q24, 0);
    /* a row: -50 - 20/3 * x at x = -1, 0, 1, 2 m; an empty row is fine */
    rfs_q16_t row[4];
    assert_true(rfs_ridge_ops.predict_row(&r, -RFS_Q16_ONE, RFS_Q16_INT(9), RFS_Q16_ONE, 4, row));
    for (int k = 0; k < 4; ++k) {
        assert_true(fabs(row[k] / 65536.0 - (-50.0 - 20.0 / 3.0 * (k - 1))) <= 1.5 / 65536.0);
    }
    assert_true(rfs_ridge_ops.predict_row(&r, 0, 0, RFS_Q16_ONE, 0, row));
}

static void test_radius_inclusive_and_reset(void **state)
{
    (void)state;
    /* samples at exactly 5 m (included), 5.01 m (excluded) */
    rfs_sample_t s[3] = {{500, 0, -10 * 64}, {0, -501, -90 * 64}, {-300, 400, -10 * 64}};
    rfs_ridge_t r;
    rfs_ridge_cfg_t cfg = rfs_ridge_cfg_default();
    assert_int_equal(rfs_ridge_init(&r, &cfg), 0);
    rfs_model_t m = rfs_ridge_model(&r);
    rfs_model_fit_in_t in = {.samples = s, .n = 3, .qx = 0, .qy = 0, .map = NULL};
    assert_int_equal(m.ops->fit(m.self, &in, 0u, NULL), RFS_FIT_DONE);
    assert_int_equal(r.n_used, 2);
    rfs_q16_t v;
    assert_true(m.ops->predict(m.self, 0, 0, &v));
    /* both used samples are -10 dB: a flat model at -10 */
    assert_int_equal(v, RFS_Q16_INT(-10));
    m.ops->reset(m.self);
    assert_false(m.ops->predict(m.self, 0, 0, &v));
    assert_null(m.ops->argmax);
    assert_string_equal(m.ops->name, "ridge");
}

/* A sample 655.36 m away (u^2 + v^2 just above 2^32) must not wrap into the radius. */
static void test_far_sample_not_wrapped_into_radius(void **state)
{
    (void)state;
    /* query (-300 m, -300 m); sample at (+327.67 m, -111.51 m): u = 62,767 cm,
     * v = 18,849 cm, u^2 + v^2 = 2^32 + 13,794 cm^2 (655.36 m) */
    rfs_sample_t s[2] = {{-30000, -30000, -20 * 64}, {32767, -11151, -120 * 64}};
    rfs_ridge_t r;
    rfs_ridge_cfg_t cfg = rfs_ridge_cfg_default();
    assert_int_equal(rfs_ridge_init(&r, &cfg), 0);
    rfs_model_fit_in_t in = {.samples = s, .n = 2, .qx = RFS_Q16_INT(-300),
                             .qy = RFS_Q16_INT(-300), .map = NULL};
    assert_int_equal(rfs_ridge_ops.fit(&r, &in, 0u, NULL), RFS_FIT_DONE);
    assert_int_equal(r.n_used, 1);
    rfs_q16_t v;
    assert_true(rfs_ridge_ops.predict(&r, 0, 0, &v));
    assert_int_equal(v, RFS_Q16_INT(-20));
}

/* The smallest radius init accepts (one Q16.16 step, below half a centimetre): only
 * samples exactly at the query (to the centimetre) are used; no division by zero. */
static void test_tiny_radius(void **state)
{
    (void)state;
    rfs_sample_t s[3] = {{100, 200, -30 * 64}, {101, 200, -90 * 64}, {100, 200, -40 * 64}};
    rfs_ridge_t r;
    rfs_ridge_cfg_t cfg = rfs_ridge_cfg_default();
    cfg.radius = 1;
    assert_int_equal(rfs_ridge_init(&r, &cfg), 0);
    rfs_model_fit_in_t in = {.samples = s, .n = 3, .qx = RFS_Q16_INT(1), .qy = RFS_Q16_INT(2),
                             .map = NULL};
    assert_int_equal(rfs_ridge_ops.fit(&r, &in, 0u, NULL), RFS_FIT_DONE);
    assert_int_equal(r.n_used, 2);
    rfs_q16_t v;
    assert_true(rfs_ridge_ops.predict(&r, RFS_Q16_INT(50), 0, &v));
    assert_int_equal(v, RFS_Q16_INT(-35));
    /* the same beyond +-327.67 m (the general pass) */
    in.qx = RFS_Q16_INT(400);
    assert_int_equal(rfs_ridge_ops.fit(&r, &in, 0u, NULL), RFS_FIT_FAILED);
}

static void test_init_validation(void **state)
{
    (void)state;
    rfs_ridge_t r;
    rfs_ridge_cfg_t c = rfs_ridge_cfg_default();
    assert_int_equal(c.radius, RFS_Q16_INT(5));
    assert_int_equal(c.alpha, RFS_Q16_ONE);
    assert_int_equal(rfs_ridge_init(&r, &c), 0);
    assert_false(r.valid);
    c.radius = 0;
    assert_int_equal(rfs_ridge_init(&r, &c), -1);
    c.radius = RFS_Q16_INT(300) + 1;
    assert_int_equal(rfs_ridge_init(&r, &c), -1);
    c = rfs_ridge_cfg_default();
    c.alpha = -1;
    assert_int_equal(rfs_ridge_init(&r, &c), -1);
    assert_int_equal(rfs_ridge_init(NULL, &c), -1);
}

/* A sliced fit that sees a new query point restarts rather than mixing sums. */
static void test_sliced_restart_on_new_query(void **state)
{
    (void)state;
    rfs_sample_t s[4] = {{0, 0, -20 * 64}, {100, 0, -30 * 64}, {1000, 0, -70 * 64},
                         {1100, 0, -80 * 64}};
    rfs_ridge_t r;
    rfs_ridge_cfg_t cfg = rfs_ridge_cfg_default();
    assert_int_equal(rfs_ridge_init(&r, &cfg), 0);
    rfs_model_fit_in_t in = {.samples = s, .n = 4, .qx = 0, .qy = 0, .map = NULL};
    assert_int_equal(rfs_ridge_ops.fit(&r, &in, 1u, NULL), RFS_FIT_MORE);
    in.qx = RFS_Q16_INT(10);
    rfs_fit_result_t res;
    while ((res = rfs_ridge_ops.fit(&r, &in, 1u, NULL)) == RFS_FIT_MORE) {
    }
    assert_int_equal(res, RFS_FIT_DONE);
    assert_int_equal(r.n_used, 2); /* only the two samples near x = 10 m */
    /* closed form as in the two-point test: xc = -0.5, +0.5 m; w = -5/(0.5+1) dB/m */
    rfs_q16_t v;
    assert_true(rfs_ridge_ops.predict(&r, RFS_Q16_FRAC(21, 2), 0, &v));
    assert_true(fabs(v / 65536.0 - (-75.0)) <= 1.0 / 65536.0);
    assert_true(fabs(r.wx_q24 / 16777216.0 - (-5.0 / 1.5)) <= 1.0 / 16777216.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_validation),
        cmocka_unit_test(test_two_points_closed_form),
        cmocka_unit_test(test_radius_inclusive_and_reset),
        cmocka_unit_test(test_far_sample_not_wrapped_into_radius),
        cmocka_unit_test(test_tiny_radius),
        cmocka_unit_test(test_sliced_restart_on_new_query),
        cmocka_unit_test(test_against_sklearn),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
