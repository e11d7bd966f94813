/* test_mlp.c - the MLP internal model (common/rfs_mlp, paper section 5.2.2).
 *
 * The reference is a double-precision MLP written here from the paper and PyBrain's
 * BackpropTrainer (online updates, m = momentum * m + rate * (t - y) * dy/dw, w += m),
 * trained on the same samples with the same initial weights and the same sample order:
 * it repeats the documented random draws (rfs_rng_u32 / rfs_rng_below from an rng with
 * the same seed). The field is a known log-distance path loss with 4 dB Gaussian noise
 * (the paper's measured noise), so "fits within the noise" is checked against the truth.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_mlp.h"

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

    assert_true(diff_worst < 0.5); /* the bound */
    /* Measured: at most 0.0004 dB and 1.2e-4 over 32 seeds. Held much tighter than the issue asks, because a
     * wrong training step still passes 0.5 dB (momentum dropped: 0.17 dB, 0.04). */
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
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
