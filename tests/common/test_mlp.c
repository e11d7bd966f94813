/* test_mlp.c - the MLP internal model (common/rfs_mlp, paper section 5.2.2).
 *
 * The reference is a double-precision MLP written here from the paper and PyBrain's
 * BackpropTrainer (online updates, m = momentum * m + rate * (t - y) * dy/dw, w += m),
 * trained on the same samples with the same initial weights and the same sample order:
 * it repeats the documented random draws (rfs_rng_u32 / rfs_rng_below from an rng with
 * the same seed). The field is a known log-distance path loss with 4 dB Gaussian noise
 * (the paper's measured noise), so "fits within the noise" is checked against the truth.
 * The upper bound over a box (docs/MODELS.md) is checked against predict() at every point of a
 * grid over each box, against the same network evaluated in double precision, and through
 * the seeker's grid search against a brute-force scan of the lattice.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_gridmax.h"
#include "rfs_mlp.h"
#include "seek_world.h"

#define N_SAMPLES 10000u
#define HID 100
#define SRC_X 14.0
#define SRC_Y 9.0
#define AREA_W 20.0
#define AREA_H 15.0
#define NOISE_DB 4.0

static double true_field(double x, double y)
{
    double d = hypot(x - SRC_X, y - SRC_Y);
    return -30.0 - 20.0 * log10(d + 1.0);
}

static double q16_to_d(int32_t v)
{
    return (double)v / 65536.0;
}

static int32_t d_to_q16(double v)
{
    return (int32_t)lround(v * 65536.0);
}

/* Samples of the field at uniform random positions, value + N(0, 4 dB), in store units. */
static void make_samples(rfs_sample_t *s, uint32_t n, uint64_t seed)
{
    rfs_rng_t r;
    rfs_rng_seed(&r, seed);
    for (uint32_t i = 0; i < n; ++i) {
        int16_t xc = (int16_t)rfs_rng_below(&r, (uint32_t)(AREA_W * 100.0) + 1u);
        int16_t yc = (int16_t)rfs_rng_below(&r, (uint32_t)(AREA_H * 100.0) + 1u);
        double u1 = ((double)rfs_rng_u32(&r) + 1.0) / 4294967297.0;
        double u2 = (double)rfs_rng_u32(&r) / 4294967296.0;
        double z = sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
        double v = true_field(xc / 100.0, yc / 100.0) + NOISE_DB * z;
        s[i].x_cm = xc;
        s[i].y_cm = yc;
        s[i].v_q6 = (int16_t)lround(v * 64.0);
    }
}

/* ---- the double-precision reference ------------------------------------------------ */

typedef struct ref_mlp {
    double w[HID][2], b[HID], v[HID], c;
    double mw[HID][2], mb[HID], mv[HID], mc;
    double mx, sx, my, sy, mt, st;
} ref_mlp_t;

static double ref_weight(rfs_rng_t *r)
{
    uint32_t a = rfs_rng_u32(r);
    uint32_t b = rfs_rng_u32(r);
    double s = (double)(a & 0xFFFFu) + (double)(a >> 16) + (double)(b & 0xFFFFu) +
               (double)(b >> 16);
    return (s / 65536.0 - 2.0) * sqrt(3.0);
}

static void mean_std(const double *v, uint32_t n, double *mean, double *sd)
{
    double s = 0.0, ss = 0.0;
    for (uint32_t i = 0; i < n; ++i) {
        s += v[i];
    }
    *mean = s / n;
    for (uint32_t i = 0; i < n; ++i) {
        ss += (v[i] - *mean) * (v[i] - *mean);
    }
    *sd = sqrt(ss / n);
}

static double ref_forward(const ref_mlp_t *m, double xs, double ys, double *h)
{
    double o = m->c;
    for (int j = 0; j < HID; ++j) {
        double a = m->w[j][0] * xs + m->w[j][1] * ys + m->b[j];
        h[j] = 1.0 / (1.0 + exp(-a));
        o += m->v[j] * h[j];
    }
    return o;
}

/* The epoch order as rfs_mlp.h specifies it: a 4-round Feistel network on 2h bits with
 * cycle walking, keys drawn per epoch. Written here from that text. */
static uint32_t spec_mix(uint32_t x)
{
    x *= 0x9E3779B1u;
    x ^= x >> 15;
    x *= 0x85EBCA6Bu;
    x ^= x >> 13;
    return x;
}

static uint32_t spec_half_bits(uint32_t n)
{
    uint32_t h = 1;
    while ((1u << (2 * h)) < n) {
        h++;
    }
    return h;
}

static uint32_t spec_perm(const uint32_t key[4], uint32_t h, uint32_t n, uint32_t p)
{
    uint32_t mask = (1u << h) - 1u, i = p;
    do {
        uint32_t l = i >> h, r = i & mask;
        for (int k = 0; k < 4; ++k) {
            uint32_t t = l ^ (spec_mix(key[k] ^ r) & mask);
            l = r;
            r = t;
        }
        i = (l << h) | r;
    } while (i >= n);
    return i;
}

static void ref_train(ref_mlp_t *m, const rfs_sample_t *s, uint32_t n, rfs_rng_t *rng)
{
    static double xs[N_SAMPLES], ys[N_SAMPLES], ts[N_SAMPLES];
    const double rate = 0.01, mom = 0.1;
    memset(m, 0, sizeof *m);
    for (uint32_t i = 0; i < n; ++i) {
        xs[i] = s[i].x_cm / 100.0;
        ys[i] = s[i].y_cm / 100.0;
        ts[i] = s[i].v_q6 / 64.0;
    }
    mean_std(xs, n, &m->mx, &m->sx);
    mean_std(ys, n, &m->my, &m->sy);
    mean_std(ts, n, &m->mt, &m->st);
    for (uint32_t i = 0; i < n; ++i) {
        xs[i] = (xs[i] - m->mx) / m->sx;
        ys[i] = (ys[i] - m->my) / m->sy;
        ts[i] = (ts[i] - m->mt) / m->st;
    }
    for (int j = 0; j < HID; ++j) {
        m->w[j][0] = ref_weight(rng);
        m->w[j][1] = ref_weight(rng);
        m->b[j] = ref_weight(rng);
    }
    for (int j = 0; j < HID; ++j) {
        m->v[j] = ref_weight(rng);
    }
    m->c = ref_weight(rng);
    uint32_t h = spec_half_bits(n);
    for (int epoch = 0; epoch < 3; ++epoch) {
        uint32_t key[4];
        for (int k = 0; k < 4; ++k) {
            key[k] = rfs_rng_u32(rng);
        }
        for (uint32_t p = 0; p < n; ++p) {
            uint32_t i = spec_perm(key, h, n, p);
            double hid[HID];
            double e = ts[i] - ref_forward(m, xs[i], ys[i], hid);
            for (int j = 0; j < HID; ++j) {
                double ld = rate * e * m->v[j] * hid[j] * (1.0 - hid[j]);
                m->mv[j] = mom * m->mv[j] + rate * e * hid[j];
                m->v[j] += m->mv[j];
                m->mw[j][0] = mom * m->mw[j][0] + ld * xs[i];
                m->w[j][0] += m->mw[j][0];
                m->mw[j][1] = mom * m->mw[j][1] + ld * ys[i];
                m->w[j][1] += m->mw[j][1];
                m->mb[j] = mom * m->mb[j] + ld;
                m->b[j] += m->mb[j];
            }
            m->mc = mom * m->mc + rate * e;
            m->c += m->mc;
        }
    }
}

static double ref_predict(const ref_mlp_t *m, double x, double y)
{
    double h[HID];
    double o = ref_forward(m, (x - m->mx) / m->sx, (y - m->my) / m->sy, h);
    return o * m->st + m->mt;
}

/* ---- tests --------------------------------------------------------------------------- */

static rfs_sample_t g_samples[N_SAMPLES];
static rfs_mlp_t g_mlp, g_mlp2;

static void sigmoid_error_within_documented_bound(void **state)
{
    (void)state;
    double worst = 0.0;

    for (int32_t a = -20 * 65536; a <= 20 * 65536; a += 7) {
        double got = q16_to_d(rfs_mlp_sigmoid(a));
        double want = 1.0 / (1.0 + exp(-q16_to_d(a)));
        worst = fmax(worst, fabs(got - want));
    }
    double extremes = fabs(q16_to_d(rfs_mlp_sigmoid(INT32_MIN))) +
                      fabs(q16_to_d(rfs_mlp_sigmoid(INT32_MAX)) - 1.0);

    assert_true(worst <= 1.94e-5);
    assert_true(worst > 1e-6); /* the bound is tight, not vacuous */
    assert_true(extremes == 0.0);
}

/* The specified epoch order visits every sample exactly once, for sizes around the
 * powers of 4 where the Feistel domain is tightest or loosest. */
static void specified_order_is_a_permutation(void **state)
{
    (void)state;
    const uint32_t sizes[] = {1, 2, 3, 4, 5, 16, 17, 255, 256, 257, 4096, 4097, 10000};
    static uint8_t seen[N_SAMPLES];
    rfs_rng_t r;
    rfs_rng_seed(&r, 12);

    for (unsigned t = 0; t < sizeof sizes / sizeof sizes[0]; ++t) {
        uint32_t n = sizes[t], key[4], fixed = 0;
        for (int k = 0; k < 4; ++k) {
            key[k] = rfs_rng_u32(&r);
        }
        memset(seen, 0, n);
        for (uint32_t p = 0; p < n; ++p) {
            uint32_t i = spec_perm(key, spec_half_bits(n), n, p);
            assert_true(i < n);
            seen[i]++;
            fixed += i == p ? 1u : 0u;
        }
        for (uint32_t i = 0; i < n; ++i) {
            assert_int_equal(seen[i], 1);
        }
        if (n >= 256) {
            assert_true(fixed < n / 16); /* shuffled, not the identity */
        }
    }
}

static void init_rejects_bad_configuration(void **state)
{
    (void)state;
    rfs_mlp_cfg_t good = rfs_mlp_cfg_default();
    rfs_mlp_cfg_t c;

    assert_int_equal(rfs_mlp_init(&g_mlp, &good), 0);
    c = good; c.hidden = 0;
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), -1);
    c = good; c.hidden = RFS_MLP_MAX_HIDDEN + 1;
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), -1);
    c = good; c.epochs = 0;
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), -1);
    c = good; c.rate_q30 = 0;
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), -1);
    c = good; c.momentum_q30 = 1 << 30;
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), -1);
    c = good; c.max_samples = RFS_MLP_MAX_SAMPLES + 1;
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), -1);
}

static void defaults_are_the_papers(void **state)
{
    (void)state;
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();

    assert_int_equal(c.hidden, 100);
    assert_int_equal(c.epochs, 3);
    assert_true(fabs(c.rate_q30 / 1073741824.0 - 0.01) < 1e-9);
    assert_true(fabs(c.momentum_q30 / 1073741824.0 - 0.1) < 1e-9);
    assert_int_equal(c.max_samples, 10000);
}

static void no_samples_fails_and_predicts_nothing(void **state)
{
    (void)state;
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    rfs_model_t m;
    rfs_model_fit_in_t in = {.samples = g_samples, .n = 0};
    rfs_q16_t v = 12345;
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);
    m = rfs_mlp_model(&g_mlp);

    rfs_fit_result_t r = m.ops->fit(m.self, &in, 0, &rng);
    bool ok = m.ops->predict(m.self, 0, 0, &v);

    assert_int_equal(r, RFS_FIT_FAILED);
    assert_false(ok);
    assert_int_equal(v, 12345);
    assert_string_equal(m.ops->name, "mlp");
}

static void standardisation_matches_double(void **state)
{
    (void)state;
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
    c.epochs = 1;
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 3);
    static double t[N_SAMPLES];
    double mean, sd;
    make_samples(g_samples, N_SAMPLES, 77);
    for (uint32_t i = 0; i < N_SAMPLES; ++i) {
        t[i] = g_samples[i].v_q6 / 64.0;
    }
    mean_std(t, N_SAMPLES, &mean, &sd);
    rfs_model_fit_in_t in = {.samples = g_samples, .n = N_SAMPLES};
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);

    rfs_fit_result_t r = rfs_mlp_ops.fit(&g_mlp, &in, 1, &rng);

    assert_int_equal(r, RFS_FIT_MORE);
    assert_true(fabs(q16_to_d(g_mlp.out_mean) - mean) < 2e-5);
    assert_true(fabs(q16_to_d(g_mlp.out_std) - sd) < 2e-5);
}

/* One training of the paper's configuration on 10,000 samples: fixed point and the double
 * reference with identical initial weights and order; RMS over the 0.25 m lattice of the
 * area of fixed - double, fixed - truth and double - truth. */
static void train_both(uint64_t data_seed, uint64_t rng_seed, double rms[3], double *wdiff)
{
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
    rfs_rng_t rng_fix, rng_ref;
    static ref_mlp_t ref;
    make_samples(g_samples, N_SAMPLES, data_seed);
    rfs_rng_seed(&rng_fix, rng_seed);
    rfs_rng_seed(&rng_ref, rng_seed);
    rfs_model_fit_in_t in = {.samples = g_samples, .n = N_SAMPLES};
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);

    rfs_fit_result_t r = rfs_mlp_ops.fit(&g_mlp, &in, 0, &rng_fix);
    ref_train(&ref, g_samples, N_SAMPLES, &rng_ref);

    assert_int_equal(r, RFS_FIT_DONE);
    assert_int_equal(g_mlp.updates, 3 * N_SAMPLES);
    /* Both consumed exactly the same random draws. */
    assert_int_equal(rfs_rng_u32(&rng_fix), rfs_rng_u32(&rng_ref));
    double wd = fabs(g_mlp.c_q24 / 16777216.0 - ref.c);
    for (int j = 0; j < HID; ++j) {
        wd = fmax(wd, fabs(g_mlp.v_q24[j] / 16777216.0 - ref.v[j]));
        wd = fmax(wd, fabs(g_mlp.b_q24[j] / 16777216.0 - ref.b[j]));
        wd = fmax(wd, fabs(g_mlp.w_q24[j][0] / 16777216.0 - ref.w[j][0]));
        wd = fmax(wd, fabs(g_mlp.w_q24[j][1] / 16777216.0 - ref.w[j][1]));
    }
    *wdiff = wd;
    double se[3] = {0.0, 0.0, 0.0};
    int count = 0;
    for (double x = 0.0; x <= AREA_W + 1e-9; x += 0.25) {
        for (double y = 0.0; y <= AREA_H + 1e-9; y += 0.25) {
            rfs_q16_t v;
            assert_true(rfs_mlp_ops.predict(&g_mlp, d_to_q16(x), d_to_q16(y), &v));
            double fix = q16_to_d(v), dbl = ref_predict(&ref, x, y), truth = true_field(x, y);
            se[0] += (fix - dbl) * (fix - dbl);
            se[1] += (fix - truth) * (fix - truth);
            se[2] += (dbl - truth) * (dbl - truth);
            count++;
        }
    }
    for (int i = 0; i < 3; ++i) {
        rms[i] = sqrt(se[i] / count);
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Eight trainings (data and weights from different seeds). Every one agrees with the
 * double reference within 0.5 dB RMS (and far closer, weight by weight); the fit to the field is a property of the paper's
 * short training, so the median must be within the noise and every run within twice it
 * (over 32 seeds single runs were between 1.0 and 4.1 dB). */
static void training_matches_double_reference_and_fits_field(void **state)
{
    (void)state;
    enum { TRIALS = 8 };
    double diff_worst = 0.0, wdiff_worst = 0.0, fix[TRIALS], ref[TRIALS];

    for (int t = 0; t < TRIALS; ++t) {
        double rms[3], wdiff;
        train_both(1000u + (uint64_t)t, 31u * (uint64_t)t + 7u, rms, &wdiff);
        print_message("MLP trial %d rms: fixed-double %.4f dB, fixed-truth %.3f dB, "
                      "double-truth %.3f dB; largest weight difference %.2e\n", t, rms[0],
                      rms[1], rms[2], wdiff);
        wdiff_worst = fmax(wdiff_worst, wdiff);
        diff_worst = fmax(diff_worst, rms[0]);
        fix[t] = rms[1];
        ref[t] = rms[2];
    }
    qsort(fix, TRIALS, sizeof fix[0], cmp_double);
    qsort(ref, TRIALS, sizeof ref[0], cmp_double);

    assert_true(diff_worst < 0.5); /* the required bound */
    /* Measured: at most 0.0004 dB and 1.2e-4 over 32 seeds. Held much tighter than
     * required, because a wrong training step still passes 0.5 dB (momentum dropped:
     * 0.17 dB, 0.04). */
    assert_true(diff_worst < 0.01);
    assert_true(wdiff_worst < 1e-3);
    assert_true((fix[TRIALS / 2 - 1] + fix[TRIALS / 2]) / 2.0 < NOISE_DB);
    assert_true((ref[TRIALS / 2 - 1] + ref[TRIALS / 2]) / 2.0 < NOISE_DB);
    assert_true(fix[TRIALS - 1] < 2.0 * NOISE_DB);
    assert_true(ref[TRIALS - 1] < 2.0 * NOISE_DB);
}

/* fit(budget) does at most `budget` sample-updates per call and the sliced result is the
 * same network as the unsliced one. */
static void sliced_training_respects_budget_and_equals_whole(void **state)
{
    (void)state;
    const uint32_t n = 500, budget = 37;
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
    rfs_rng_t r1, r2;
    make_samples(g_samples, n, 5);
    rfs_rng_seed(&r1, 8);
    rfs_rng_seed(&r2, 8);
    rfs_model_fit_in_t in = {.samples = g_samples, .n = (uint16_t)n};
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);
    assert_int_equal(rfs_mlp_init(&g_mlp2, &c), 0);

    rfs_fit_result_t whole = rfs_mlp_ops.fit(&g_mlp, &in, 0, &r1);
    uint32_t calls = 0, total = 0, worst = 0;
    rfs_fit_result_t r;
    bool valid_while_fitting = false;
    do {
        r = rfs_mlp_ops.fit(&g_mlp2, &in, budget, &r2);
        calls++;
        total += g_mlp2.updates;
        worst = g_mlp2.updates > worst ? g_mlp2.updates : worst;
        if (r == RFS_FIT_MORE) {
            rfs_q16_t v;
            valid_while_fitting |= rfs_mlp_ops.predict(&g_mlp2, 0, 0, &v);
        }
    } while (r == RFS_FIT_MORE && calls < 1000);

    assert_int_equal(whole, RFS_FIT_DONE);
    assert_int_equal(r, RFS_FIT_DONE);
    assert_int_equal(total, 3 * n);
    assert_int_equal(worst, budget);
    assert_int_equal(calls, (3 * n + budget - 1) / budget);
    assert_false(valid_while_fitting);
    assert_memory_equal(g_mlp.v_q24, g_mlp2.v_q24, sizeof g_mlp.v_q24);
    assert_memory_equal(g_mlp.w_q24, g_mlp2.w_q24, sizeof g_mlp.w_q24);
}

/* A fit restarted by reset() starts again from fresh weights and a fresh order. */
static void reset_discards_model(void **state)
{
    (void)state;
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
    c.hidden = 10;
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 4);
    make_samples(g_samples, 50, 6);
    rfs_model_fit_in_t in = {.samples = g_samples, .n = 50};
    rfs_q16_t v;
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);
    assert_int_equal(rfs_mlp_ops.fit(&g_mlp, &in, 0, &rng), RFS_FIT_DONE);
    assert_true(rfs_mlp_ops.predict(&g_mlp, 0, 0, &v));

    rfs_mlp_ops.reset(&g_mlp);

    assert_false(rfs_mlp_ops.predict(&g_mlp, 0, 0, &v));
    assert_int_equal(rfs_mlp_ops.fit(&g_mlp, &in, 10, &rng), RFS_FIT_MORE);
    assert_int_equal(g_mlp.updates, 10);
}

/* ---- the upper bound over a box (bound op) ------------------------------------------ */

static double logistic(double a)
{
    return 1.0 / (1.0 + exp(-a));
}

/* The sigmoid is non-decreasing over every Q16 input where it is not constant (checked
 * one by one over +-17), constant 0 / 1 beyond +-16, within 1.3 LSB of the exact logistic
 * everywhere (the bound charges 2), and the constants the bound takes from the exact
 * logistic hold: max |sigmoid''| <= 6307 / 2^16, rising up to 86300 / 2^16 and falling
 * from 86320 / 2^16. */
static void sigmoid_monotone_for_the_bound(void **state)
{
    (void)state;
    const int32_t lim = 17 * 65536;
    double worst = 0.0, curv_peak = 0.0;
    int32_t prev = rfs_mlp_sigmoid(-lim - 1), drops = 0;
    for (int32_t a = -lim; a <= lim; ++a) {
        int32_t s = rfs_mlp_sigmoid(a);
        drops += s < prev;
        prev = s;
        worst = fmax(worst, fabs((double)s - 65536.0 * logistic(a / 65536.0)));
    }
    uint32_t off = 0;
    for (int64_t a = INT32_MIN; a <= INT32_MAX; a += 9973) {
        int32_t s = rfs_mlp_sigmoid((int32_t)a);
        off += (a <= -16 * 65536 && s != 0) || (a >= 16 * 65536 && s != 65536);
    }
    bool rise = true, fall = true;
    double c_prev = 0.0;
    for (int32_t i = 0; i <= 20 * 4096; ++i) {
        double t = i / 4096.0, s = logistic(t), c = fabs(s * (1 - s) * (1 - 2 * s));
        curv_peak = fmax(curv_peak, c);
        rise = rise && (t > 86300.0 / 65536.0 || c >= c_prev);
        fall = fall && (t - 1.0 / 4096.0 < 86320.0 / 65536.0 || c <= c_prev);
        c_prev = c;
    }

    assert_int_equal(drops, 0);
    assert_int_equal(off, 0);
    assert_int_equal(rfs_mlp_sigmoid(INT32_MIN), 0);
    assert_int_equal(rfs_mlp_sigmoid(INT32_MAX), 65536);
    assert_true(worst <= 1.3);
    assert_true(curv_peak <= 6307.0 / 65536.0 && curv_peak > 6306.0 / 65536.0);
    assert_true(rise && fall);
}

/* The network of a state in double precision, from its weights and constants. */
static void dbl_inputs(const rfs_mlp_t *m, double x, double y, double *xs, double *ys)
{
    *xs = (x * 100.0 - m->mean_x_q16 / 65536.0) * (m->inv_sx_q24 / 16777216.0);
    *ys = (y * 100.0 - m->mean_y_q16 / 65536.0) * (m->inv_sy_q24 / 16777216.0);
}

static double dbl_output(const rfs_mlp_t *m, double o)
{
    return m->out_mean / 65536.0 + o * (m->out_std / 65536.0);
}

static double dbl_predict(const rfs_mlp_t *m, double x, double y)
{
    double xs, ys, o = m->c_q24 / 16777216.0;
    dbl_inputs(m, x, y, &xs, &ys);
    for (uint16_t j = 0; j < m->cfg.hidden; ++j) {
        double a = (m->w_q24[j][0] * xs + m->w_q24[j][1] * ys + m->b_q24[j]) / 16777216.0;
        o += m->v_q24[j] / 16777216.0 * logistic(a);
    }
    return dbl_output(m, o);
}

/* Plain interval arithmetic in double: every unit at its best end at once. */
static double dbl_interval_bound(const rfs_mlp_t *m, double x0, double y0, double x1,
                                 double y1)
{
    double xa, ya, xb, yb, o = m->c_q24 / 16777216.0;
    dbl_inputs(m, x0, y0, &xa, &ya);
    dbl_inputs(m, x1, y1, &xb, &yb);
    for (uint16_t j = 0; j < m->cfg.hidden; ++j) {
        double w0 = m->w_q24[j][0], w1 = m->w_q24[j][1], b = m->b_q24[j];
        double lo = (fmin(w0 * xa, w0 * xb) + fmin(w1 * ya, w1 * yb) + b) / 16777216.0;
        double hi = (fmax(w0 * xa, w0 * xb) + fmax(w1 * ya, w1 * yb) + b) / 16777216.0;
        o += m->v_q24[j] / 16777216.0 * logistic(m->v_q24[j] >= 0 ? hi : lo);
    }
    return dbl_output(m, o);
}

static double urand01(rfs_rng_t *r)
{
    return (double)rfs_rng_u32(r) / 4294967296.0;
}

/* A uniform weight in [-scale, scale] as Q8.24, saturated to the int32 range. */
static int32_t random_q24(double scale, rfs_rng_t *r)
{
    double w = (urand01(r) * 2 - 1) * scale * 16777216.0;
    return (int32_t)lround(fmax(fmin(w, (double)INT32_MAX), (double)-INT32_MAX));
}

/* Random weights of a given scale on the standardisation of the state's last fit:
 * exercises saturated units (weights up to the Q8.24 limit) and both bounds. */
static void random_weights(rfs_mlp_t *m, double scale, uint16_t hidden, rfs_rng_t *r)
{
    m->cfg.hidden = hidden;
    for (uint16_t j = 0; j < hidden; ++j) {
        m->w_q24[j][0] = random_q24(scale, r);
        m->w_q24[j][1] = random_q24(scale, r);
        m->b_q24[j] = random_q24(scale, r);
        m->v_q24[j] = random_q24(fmin(scale, 100.0), r);
    }
    m->c_q24 = random_q24(1.0, r);
}

/* One random box: a point, a lattice step, 1 m, a 16-point tile (3.75 m), 10 m or more
 * than the area, anywhere from 3 m outside the samples' area to 3 m beyond it. */
static void mlp_random_box(rfs_rng_t *r, double *x0, double *y0, double *x1, double *y1)
{
    static const double sides[] = {0.0, 0.25, 1.0, 3.75, 3.75, 10.0, 30.0};
    double bw = sides[rfs_rng_below(r, 7)], bh = sides[rfs_rng_below(r, 7)];
    *x0 = -3.0 + urand01(r) * (AREA_W + 6.0);
    *y0 = -3.0 + urand01(r) * (AREA_H + 6.0);
    *x1 = *x0 + bw;
    *y1 = *y0 + bh;
}

/* No model, no bound. After fits on several data sets and on random networks (weights
 * from 0.05 to 2000, saturating at the Q8.24 limit of 128), for many boxes: predict() at
 * every point of a 17 x 17 grid over the box (for a tile exactly its 0.25 m lattice) and
 * at 30 random points is at most the bound, bit for bit; the bound of a single point is
 * its prediction; and the bound is at least the double-precision network's maximum over
 * those points. */
static void bound_holds_at_every_point_of_a_box(void **state)
{
    (void)state;
    static const uint32_t ns[] = {300, 2000, 6000};
    static const double scales[] = {0.05, 0.5, 2.0, 20.0, 2000.0};
    rfs_rng_t r;
    rfs_rng_seed(&r, 808);
    uint32_t boxes = 0, points = 0, exact = 0;
    for (uint32_t net = 0; net < 8; ++net) {
        rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
        rfs_rng_t rng;
        rfs_rng_seed(&rng, 50u + net);
        uint32_t n = ns[net % 3u];
        make_samples(g_samples, n, 900u + net);
        rfs_model_fit_in_t in = {.samples = g_samples, .n = (uint16_t)n};
        rfs_q16_t none;
        assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);
        assert_false(rfs_mlp_ops.bound(&g_mlp, 0, 0, Q(1.0), Q(1.0), &none));
        assert_int_equal(rfs_mlp_ops.fit(&g_mlp, &in, 0, &rng), RFS_FIT_DONE);
        if (net >= 3u) {
            random_weights(&g_mlp, scales[net - 3u], (uint16_t)(1u + rfs_rng_below(&r, 100)),
                           &r);
        }
        for (uint32_t b = 0; b < 40; ++b) {
            double dx0, dy0, dx1, dy1;
            mlp_random_box(&r, &dx0, &dy0, &dx1, &dy1);
            if (b % 8u == 0u) {
                dx1 = dx0;
                dy1 = dy0;
            }
            rfs_q16_t x0 = d_to_q16(dx0), y0 = d_to_q16(dy0), x1 = d_to_q16(dx1);
            rfs_q16_t y1 = d_to_q16(dy1), ub, v;

            assert_true(rfs_mlp_ops.bound(&g_mlp, x0, y0, x1, y1, &ub));

            double dmax = -1e300;
            for (uint32_t q = 0; q < 17u * 17u + 30u; ++q) {
                rfs_q16_t qx, qy;
                if (q < 17u * 17u) {
                    qx = (rfs_q16_t)(x0 + ((int64_t)x1 - x0) * (q % 17u) / 16);
                    qy = (rfs_q16_t)(y0 + ((int64_t)y1 - y0) * (q / 17u) / 16);
                } else {
                    qx = (rfs_q16_t)(x0 + (int64_t)(urand01(&r) * ((double)x1 - x0)));
                    qy = (rfs_q16_t)(y0 + (int64_t)(urand01(&r) * ((double)y1 - y0)));
                }
                assert_true(rfs_mlp_ops.predict(&g_mlp, qx, qy, &v));
                if (v > ub) {
                    fail_msg("net %u box [%.4f, %.4f] x [%.4f, %.4f]: predict (%.4f, %.4f) = "
                             "%d > bound %d", net, dx0, dx1, dy0, dy1, q16_to_d(qx),
                             q16_to_d(qy), v, ub);
                }
                dmax = fmax(dmax, dbl_predict(&g_mlp, q16_to_d(qx), q16_to_d(qy)));
                points++;
            }
            /* The fixed-point network is within 0.01 target units of the double one
             * here (weights up to 2000 only on random nets: 0.05 allowed). */
            assert_true(q16_to_d(ub) >= dmax - (net >= 3u ? 0.05 : 0.01));
            if (x0 == x1 && y0 == y1) {
                assert_true(rfs_mlp_ops.predict(&g_mlp, x0, y0, &v));
                assert_int_equal(ub, v);
                exact++;
            }
            boxes++;
        }
    }
    assert_int_equal(boxes, 8u * 40u);
    assert_int_equal(points, boxes * (17u * 17u + 30u));
    assert_true(exact >= 8u * 5u);
}

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* On a smooth fit (the paper's configuration, 10,000 samples of the log-distance field),
 * the bound of a 1 m box is within 1 dB of the box's maximum (the double network's, over a
 * 21 x 21 grid) and of a 3.75 m tile within 10 dB, and far below plain interval arithmetic
 * (computed here in double) on tiles: the linear relaxation is what prunes. */
static void bound_tight_on_small_boxes(void **state)
{
    (void)state;
    enum { BOXES = 60 };
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
    rfs_rng_t rng, r;
    rfs_rng_seed(&rng, 7);
    rfs_rng_seed(&r, 31);
    make_samples(g_samples, N_SAMPLES, 1000);
    rfs_model_fit_in_t in = {.samples = g_samples, .n = N_SAMPLES};
    assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);
    assert_int_equal(rfs_mlp_ops.fit(&g_mlp, &in, 0, &rng), RFS_FIT_DONE);
    double gap1[BOXES], gap4[BOXES], gapi[BOXES];
    for (uint32_t b = 0; b < BOXES; ++b) {
        for (uint32_t s = 0; s < 2; ++s) {
            double side = s == 0u ? 1.0 : 3.75;
            double x0 = urand01(&r) * (AREA_W - side), y0 = urand01(&r) * (AREA_H - side);
            rfs_q16_t ub;
            assert_true(rfs_mlp_ops.bound(&g_mlp, d_to_q16(x0), d_to_q16(y0),
                                          d_to_q16(x0 + side), d_to_q16(y0 + side), &ub));
            double dmax = -1e300;
            for (uint32_t q = 0; q < 21u * 21u; ++q) {
                dmax = fmax(dmax, dbl_predict(&g_mlp, x0 + side * (q % 21u) / 20.0,
                                              y0 + side * (q / 21u) / 20.0));
            }
            if (s == 0u) {
                gap1[b] = q16_to_d(ub) - dmax;
            } else {
                gap4[b] = q16_to_d(ub) - dmax;
                gapi[b] = dbl_interval_bound(&g_mlp, x0, y0, x0 + side, y0 + side) - dmax;
            }
        }
    }
    qsort(gap1, BOXES, sizeof gap1[0], cmp_dbl);
    qsort(gap4, BOXES, sizeof gap4[0], cmp_dbl);
    qsort(gapi, BOXES, sizeof gapi[0], cmp_dbl);
    print_message("bound - max: 1 m boxes median %.3f worst %.3f dB; tiles median %.3f worst "
                  "%.3f dB; interval arithmetic on tiles median %.3f dB\n", gap1[BOXES / 2],
                  gap1[BOXES - 1], gap4[BOXES / 2], gap4[BOXES - 1], gapi[BOXES / 2]);

    assert_true(gap1[0] >= -0.01 && gap4[0] >= -0.01);
    assert_true(gap1[BOXES - 1] < 1.0);
    assert_true(gap4[BOXES - 1] < 10.0);
    assert_true(gap4[BOXES / 2] * 3.0 < gapi[BOXES / 2]);
}

/* One hidden unit with its output amplified (v = +-100, so 1 LSB of the sigmoid is 100 LSB
 * of the prediction), inputs standardised by 1 per metre: every Q16 input of each box is
 * predicted (exhaustive, up to 4,000 per box), with pre-activation ranges from a few LSB to
 * a few units around the sigmoid's middle, where the bound's small margins (the table's
 * error, the rounding of the pre-activation and of the slope) decide. With one monotone
 * unit interval arithmetic is exact, so a relaxation that undercut the maximum would show
 * (the smaller of the two is returned). */
static void bound_holds_exhaustively_on_one_unit(void **state)
{
    (void)state;
    rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
    c.hidden = 1;
    rfs_rng_t r;
    rfs_rng_seed(&r, 4711);
    uint64_t points = 0;
    for (uint32_t t = 0; t < 400; ++t) {
        assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);
        g_mlp.valid = true;
        g_mlp.inv_sx_q24 = (1 << 24) / 100;
        g_mlp.inv_sy_q24 = (1 << 24) / 100;
        g_mlp.out_std = RFS_Q16_ONE;
        g_mlp.w_q24[0][0] = random_q24(3.0, &r);
        g_mlp.w_q24[0][1] = t % 2u ? random_q24(0.5, &r) : 0;
        g_mlp.b_q24[0] = random_q24(4.0, &r);
        g_mlp.v_q24[0] = (t % 4u < 2u ? 100 : -100) * (1 << 24);
        g_mlp.c_q24 = random_q24(1.0, &r);
        rfs_q16_t x0 = d_to_q16(-3.0 + 6.0 * urand01(&r));
        rfs_q16_t x1 = x0 + (rfs_q16_t)rfs_rng_below(&r, 4001);
        rfs_q16_t y0 = d_to_q16(-1.0 + 2.0 * urand01(&r)), ub, v, hi = INT32_MIN;

        assert_true(rfs_mlp_ops.bound(&g_mlp, x0, y0, x1, y0, &ub));

        for (rfs_q16_t x = x0; x <= x1; ++x) {
            assert_true(rfs_mlp_ops.predict(&g_mlp, x, y0, &v));
            hi = v > hi ? v : hi;
            if (v > ub) {
                fail_msg("net %u box [%d, %d] y %d: predict at %d = %d > bound %d", t, x0, x1,
                         y0, x, v, ub);
            }
            points++;
        }
        assert_int_equal(ub, hi); /* one monotone unit: interval arithmetic is exact */
    }
    assert_true(points > 400u * 1000u);
}

/* The MLP behind a wrapper that counts predictions (how much the bound prunes). */
typedef struct counted {
    const rfs_mlp_t *m;
    uint32_t predicts;
} counted_t;

static counted_t g_counted;

static bool counted_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *v)
{
    counted_t *c = (counted_t *)(uintptr_t)self;
    c->predicts++;
    return rfs_mlp_ops.predict(c->m, x, y, v);
}

static bool counted_bound(const void *self, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                          rfs_q16_t y1, rfs_q16_t *ub)
{
    const counted_t *c = self;
    return rfs_mlp_ops.bound(c->m, x0, y0, x1, y1, ub);
}

static const rfs_model_ops_t counted_ops = {
    .name = "mlp-counted", .predict = counted_predict, .bound = counted_bound,
};

/* Reachability over the lattice: 0 every point, 1 random points, 2 random rectangles,
 * 3 a single point. */
static void mlp_set_reach(world_t *t, uint32_t kind, rfs_rng_t *r)
{
    uint32_t lw = t->map.lw, lh = t->map.lh;
    memset(t->mem.reach, 0, t->mem.reach_bytes);
    for (uint32_t j = 0; j < lh; ++j) {
        for (uint32_t i = 0; i < lw; ++i) {
            uint32_t idx = j * lw + i;
            bool on = kind == 0u || (kind == 1u && rfs_rng_below(r, 10) < 3u);
            if (kind == 2u) {
                on = (i / 7u + j / 5u) % 3u == 0u && rfs_rng_below(r, 4) != 0u;
            }
            if (on) {
                t->mem.reach[idx >> 3] |= (uint8_t)(1u << (idx & 7u));
            }
        }
    }
    if (kind == 3u) {
        uint32_t idx = rfs_rng_below(r, lw * lh);
        t->mem.reach[idx >> 3] |= (uint8_t)(1u << (idx & 7u));
    }
}

/* rfs_gridmax_find with the MLP (branch and bound on its bound) finds exactly the point
 * a brute-force scan of every reachable lattice point with predict() finds (the first
 * strict maximum in row-major order), on fits and random networks and four reachability
 * patterns; with every point reachable it predicts at fewer than 60 % of them. */
static void grid_search_equals_brute_force(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, AREA_W, AREA_H, 0.0, 0.0);
    seek_make(&t, rfs_seek_cfg_default(), 5);
    uint32_t lw = t.map.lw, lh = t.map.lh, open_predicts = 0, open_trials = 0, found = 0;
    rfs_rng_t r;
    rfs_rng_seed(&r, 66);
    for (uint32_t trial = 0; trial < 12; ++trial) {
        rfs_mlp_cfg_t c = rfs_mlp_cfg_default();
        rfs_rng_t rng;
        rfs_rng_seed(&rng, 300u + trial);
        uint32_t n = trial % 3u == 0u ? N_SAMPLES : 1500u;
        make_samples(g_samples, n, 700u + trial);
        rfs_model_fit_in_t in = {.samples = g_samples, .n = (uint16_t)n};
        assert_int_equal(rfs_mlp_init(&g_mlp, &c), 0);
        assert_int_equal(rfs_mlp_ops.fit(&g_mlp, &in, 0, &rng), RFS_FIT_DONE);
        if (trial >= 9u) {
            random_weights(&g_mlp, trial == 11u ? 8.0 : 1.0, 100u, &r);
        }
        uint32_t kind = trial % 4u;
        mlp_set_reach(&t, kind, &r);
        bool want = false;
        rfs_q16_t best = 0, bx = 0, by = 0, ax = 0, ay = 0;
        for (uint32_t j = 0; j < lh; ++j) {
            for (uint32_t i = 0; i < lw; ++i) {
                uint32_t idx = j * lw + i;
                rfs_q16_t x, y, v;
                if (((t.mem.reach[idx >> 3] >> (idx & 7u)) & 1u) == 0u) {
                    continue;
                }
                rfs_map_lattice_point(&t.map, (uint16_t)i, (uint16_t)j, &x, &y);
                assert_true(rfs_mlp_ops.predict(&g_mlp, x, y, &v));
                if (!want || v > best) {
                    want = true;
                    best = v;
                    bx = x;
                    by = y;
                }
            }
        }
        g_counted.m = &g_mlp;
        g_counted.predicts = 0;
        t.seek.model = (rfs_model_t){.ops = &counted_ops, .self = &g_counted};

        bool got = rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &ax, &ay);

        assert_int_equal(got, want);
        if (ax != bx || ay != by) {
            fail_msg("trial %u: search (%.3f, %.3f), brute force (%.3f, %.3f)", trial,
                     q16_to_d(ax), q16_to_d(ay), q16_to_d(bx), q16_to_d(by));
        }
        found += got;
        if (kind == 0u) {
            open_predicts += g_counted.predicts;
            open_trials++;
        }
    }
    print_message("grid search, every point reachable: %u predictions per search of %u "
                  "points\n", open_predicts / open_trials, lw * lh);
    world_free(&t);

    assert_int_equal(found, 12);
    assert_true(open_predicts * 5u < open_trials * lw * lh * 3u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sigmoid_error_within_documented_bound),
        cmocka_unit_test(specified_order_is_a_permutation),
        cmocka_unit_test(init_rejects_bad_configuration),
        cmocka_unit_test(defaults_are_the_papers),
        cmocka_unit_test(no_samples_fails_and_predicts_nothing),
        cmocka_unit_test(standardisation_matches_double),
        cmocka_unit_test(training_matches_double_reference_and_fits_field),
        cmocka_unit_test(sliced_training_respects_budget_and_equals_whole),
        cmocka_unit_test(reset_discards_model),
        cmocka_unit_test(sigmoid_monotone_for_the_bound),
        cmocka_unit_test(bound_holds_at_every_point_of_a_box),
        cmocka_unit_test(bound_holds_exhaustively_on_one_unit),
        cmocka_unit_test(bound_tight_on_small_boxes),
        cmocka_unit_test(grid_search_equals_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
