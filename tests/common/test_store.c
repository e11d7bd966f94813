/* test_store.c - interpolation, pending queue, drops, saturation and reservoir
 * uniformity of the sample store (paper sections 2 and 5.2). References are double
 * interpolation and a chi-square test.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_store.h"

#define CAP 10000u
#define PCAP 64u

typedef struct fixture {
    rfs_store_t s;
    rfs_sample_t samples[CAP];
    rfs_pending_t pending[PCAP];
    rfs_rng_t rng;
} fixture_t;

static int setup(void **state)
{
    fixture_t *f = calloc(1, sizeof *f);
    if (f == NULL) {
        return -1;
    }
    rfs_store_cfg_t c = rfs_store_cfg_default();
    if (rfs_store_init(&f->s, &c, f->samples, f->pending, PCAP) != 0) {
        free(f);
        return -1;
    }
    rfs_rng_seed(&f->rng, 99u);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    free(*state);
    return 0;
}

static rfs_pose_t pose(int64_t t, double x, double y)
{
    rfs_pose_t p = {.t_us = t, .x = (rfs_q16_t)lround(x * 65536.0),
                    .y = (rfs_q16_t)lround(y * 65536.0), .theta = 0};
    return p;
}

static void test_defaults_and_init(void **state)
{
    (void)state;
    assert_int_equal(sizeof(rfs_sample_t), 6); /* at most 6 bytes a sample (docs/FIXED_POINT.md) */
    rfs_store_cfg_t c = rfs_store_cfg_default();
    assert_int_equal(c.capacity, 10000);
    assert_int_equal(c.max_gap_us, 500000);
    rfs_store_t s;
    rfs_sample_t smp[4];
    rfs_pending_t pend[4];
    assert_int_equal(rfs_store_init(&s, &c, smp, pend, 4), 0);
    assert_int_equal(rfs_store_init(&s, &c, NULL, pend, 4), -1);
    assert_int_equal(rfs_store_init(&s, &c, smp, NULL, 4), -1);
    assert_int_equal(rfs_store_init(&s, &c, smp, pend, 0), -1);
    c.capacity = 0;
    assert_int_equal(rfs_store_init(&s, &c, smp, pend, 4), -1);
    c = rfs_store_cfg_default();
    c.max_gap_us = 0;
    assert_int_equal(rfs_store_init(&s, &c, smp, pend, 4), -1);
    c.max_gap_us = 60000001;
    assert_int_equal(rfs_store_init(&s, &c, smp, pend, 4), -1);
}

/* Hand values: poses (0 m, 0 m) at 0 s and (1 m, 2 m) at 0.1 s; a measurement at
 * 25 ms lies at (0.25 m, 0.5 m) = (25 cm, 50 cm). */
static void test_interpolation_hand(void **state)
{
    fixture_t *f = *state;
    rfs_pose_t p0 = pose(0, 0.0, 0.0), p1 = pose(100000, 1.0, 2.0);
    assert_true(rfs_store_add_pose(&f->s, &p0, &f->rng));
    assert_true(rfs_store_add_pose(&f->s, &p1, &f->rng));
    rfs_store_add_value(&f->s, 25000, RFS_Q16_INT(-47), &f->rng);
    assert_int_equal(f->s.count, 1);
    assert_int_equal(f->s.samples[0].x_cm, 25);
    assert_int_equal(f->s.samples[0].y_cm, 50);
    assert_int_equal(f->s.samples[0].v_q6, -47 * 64);
    rfs_q16_t x, y;
    assert_true(rfs_store_position_at(&f->s, 75000, &x, &y));
    assert_int_equal(x, 49152);  /* 0.75 m */
    assert_int_equal(y, 98304);  /* 1.5 m */
    assert_false(rfs_store_position_at(&f->s, 100001, &x, &y));
    assert_false(rfs_store_position_at(&f->s, -1, &x, &y));
}

/* Random pose tracks (10 Hz with jitter, +-300 m) and measurements at random times,
 * against double interpolation rounded to the centimetre. */
static void test_interpolation_random(void **state)
{
    fixture_t *f = *state;
    rfs_rng_t g;
    rfs_rng_seed(&g, 7u);
    int64_t t = 1000000;
    double px = 0.0, py = 0.0;
    rfs_pose_t prev = pose(t, px, py);
    assert_true(rfs_store_add_pose(&f->s, &prev, &f->rng));
    int checked = 0;
    for (int i = 0; i < 20000; ++i) {
        int64_t dt = 50000 + rfs_rng_below(&g, 100000);
        double nx = (int32_t)rfs_rng_below(&g, 60001) / 100.0 - 300.0;
        double ny = (int32_t)rfs_rng_below(&g, 60001) / 100.0 - 300.0;
        rfs_pose_t next = pose(t + dt, nx, ny);
        /* a measurement strictly inside, sent before the pose: it waits, then is placed */
        int64_t tm = t + 1 + rfs_rng_below(&g, (uint32_t)dt - 1);
        uint16_t before = f->s.count;
        rfs_store_add_value(&f->s, tm, RFS_Q16_INT(-60), &f->rng);
        assert_int_equal(f->s.pending_count, 1);
        assert_true(rfs_store_add_pose(&f->s, &next, &f->rng));
        assert_int_equal(f->s.pending_count, 0);
        if (f->s.count != before) { /* once full, the reservoir places it anywhere */
            const rfs_sample_t *smp = &f->s.samples[f->s.count - 1];
            double a = (double)(tm - t) / (double)dt;
            double x0 = prev.x / 65536.0, y0 = prev.y / 65536.0;
            double x1 = next.x / 65536.0, y1 = next.y / 65536.0;
            double ex = (x0 + (x1 - x0) * a) * 100.0, ey = (y0 + (y1 - y0) * a) * 100.0;
            /* one rounding in Q16.16 (0.0008 cm) then to the centimetre */
            assert_true(fabs(smp->x_cm - ex) <= 0.5 + 0.001);
            assert_true(fabs(smp->y_cm - ey) <= 0.5 + 0.001);
            checked++;
        }
        prev = next;
        t += dt;
    }
    assert_int_equal(checked, CAP);
    assert_int_equal(f->s.dropped_gap + f->s.dropped_early + f->s.dropped_pending, 0);
}

/* Interpolation at the ends of its ranges: Q16.16 positions from INT32_MIN to INT32_MAX,
 * spans from 1 us to the 60 s limit, times 1 us from either pose. The reference is the host's
 * native 64-bit division rounded half away from zero, and double precision within 0.5 LSB. */
static void check_lerp_q16(rfs_q16_t a, rfs_q16_t b, int64_t span, int64_t dt)
{
    rfs_store_cfg_t c = rfs_store_cfg_default();
    c.max_gap_us = 60000000;
    rfs_store_t s;
    rfs_sample_t smp[1];
    rfs_pending_t pend[1];
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1u);
    assert_int_equal(rfs_store_init(&s, &c, smp, pend, 1), 0);
    const int64_t t0 = 123456789;
    rfs_pose_t p0 = {.t_us = t0, .x = a, .y = b, .theta = 0};
    rfs_pose_t p1 = {.t_us = t0 + span, .x = b, .y = a, .theta = 0};
    assert_true(rfs_store_add_pose(&s, &p0, &rng));
    assert_true(rfs_store_add_pose(&s, &p1, &rng));
    rfs_q16_t x = 0, y = 0;
    assert_true(rfs_store_position_at(&s, t0 + dt, &x, &y));
    int64_t n = ((int64_t)b - a) * dt;
    int64_t q = (n < 0 ? -n : n) / span, r = (n < 0 ? -n : n) % span;
    q += 2 * r >= span ? 1 : 0;
    assert_true(x == (rfs_q16_t)(a + (n < 0 ? -q : q)));
    assert_true(y == (rfs_q16_t)(b - (n < 0 ? -q : q)));
    double ex = a + ((double)b - a) * (double)dt / (double)span;
    double ey = b + ((double)a - b) * (double)dt / (double)span;
    assert_true(fabs(x - ex) <= 0.5 + 1e-6 && fabs(y - ey) <= 0.5 + 1e-6);
}

static void test_interpolation_q16_extremes(void **state)
{
    (void)state;
    const rfs_q16_t ends[] = {INT32_MIN, INT32_MIN + 1, -65536, -1, 0, 1, 3, 65536,
                              INT32_MAX - 1, INT32_MAX};
    const int64_t spans[] = {1, 2, 3, 7, 100000, 65537, 1 << 25, 59999999, 60000000};
    for (unsigned i = 0; i < sizeof ends / sizeof ends[0]; ++i) {
        for (unsigned j = 0; j < sizeof ends / sizeof ends[0]; ++j) {
            for (unsigned k = 0; k < sizeof spans / sizeof spans[0]; ++k) {
                int64_t sp = spans[k];
                const int64_t dts[] = {0, 1, sp / 2, (sp + 1) / 2, sp - 1, sp};
                for (unsigned m = 0; m < sizeof dts / sizeof dts[0]; ++m) {
                    check_lerp_q16(ends[i], ends[j], sp, dts[m]);
                }
            }
        }
    }
    rfs_rng_t g;
    rfs_rng_seed(&g, 11u);
    for (int i = 0; i < 300000; ++i) {
        rfs_q16_t a = (rfs_q16_t)rfs_rng_u32(&g), b = (rfs_q16_t)rfs_rng_u32(&g);
        if (i & 1) { /* short moves, as a robot makes */
            b = (rfs_q16_t)(a / 2 + (int32_t)(rfs_rng_u32(&g) >> 12) - (1 << 19));
            a /= 2;
        }
        int64_t sp = 1 + (int64_t)(rfs_rng_u32(&g) % (i & 2 ? 60000000u : 200000u));
        check_lerp_q16(a, b, sp, (int64_t)(rfs_rng_u32(&g) % (uint32_t)(sp + 1)));
    }
}

static void test_drops_counted(void **state)
{
    fixture_t *f = *state;
    /* before any pose: waits; the first pose is later, so it is early */
    rfs_store_add_value(&f->s, 500, RFS_Q16_INT(-50), &f->rng);
    assert_int_equal(f->s.pending_count, 1);
    rfs_pose_t p0 = pose(1000, 1.0, 1.0);
    assert_true(rfs_store_add_pose(&f->s, &p0, &f->rng));
    assert_int_equal(f->s.dropped_early, 1u);
    assert_int_equal(f->s.pending_count, 0);
    /* older than the first pose: dropped at once */
    rfs_store_add_value(&f->s, 999, RFS_Q16_INT(-50), &f->rng);
    assert_int_equal(f->s.dropped_early, 2u);
    /* exactly at a pose: placed at the pose */
    rfs_store_add_value(&f->s, 1000, RFS_Q16_INT(-50), &f->rng);
    assert_int_equal(f->s.count, 1);
    assert_int_equal(f->s.samples[0].x_cm, 100);
    /* a pose older than or equal to the newest: rejected */
    rfs_pose_t old = pose(1000, 5.0, 5.0);
    assert_false(rfs_store_add_pose(&f->s, &old, &f->rng));
    assert_int_equal(f->s.rejected_pose_order, 1u);
    /* newer than the newest pose: pending; more than PCAP waiting: dropped and counted */
    for (unsigned i = 0; i < PCAP + 5; ++i) {
        rfs_store_add_value(&f->s, 2000 + i, RFS_Q16_INT(-40), &f->rng);
    }
    assert_int_equal(f->s.pending_count, PCAP);
    assert_int_equal(f->s.dropped_pending, 5u);
    /* the next pose is 0.500001 s later (> 0.5 s gap): every pending one is a gap drop */
    rfs_pose_t p1 = pose(501001, 2.0, 1.0);
    assert_true(rfs_store_add_pose(&f->s, &p1, &f->rng));
    assert_int_equal(f->s.dropped_gap, PCAP);
    assert_int_equal(f->s.pending_count, 0);
    assert_int_equal(f->s.count, 1);
    /* eight more poses fill the history (8 kept) and push p1 out: 0.65 s is now early */
    for (int i = 1; i <= 8; ++i) {
        rfs_pose_t p = pose(501001 + i * 100000, 2.0, 1.0);
        assert_true(rfs_store_add_pose(&f->s, &p, &f->rng));
    }
    rfs_store_add_value(&f->s, 501001 + 50000, RFS_Q16_INT(-40), &f->rng);
    assert_int_equal(f->s.dropped_early, 3u);
    rfs_store_add_value(&f->s, 501001 + 150000, RFS_Q16_INT(-40), &f->rng);
    assert_int_equal(f->s.count, 2);
    /* exactly max_gap apart still brackets */
    rfs_pose_t pg = pose(1301001 + 500000, 4.0, 1.0);
    assert_true(rfs_store_add_pose(&f->s, &pg, &f->rng));
    rfs_store_add_value(&f->s, 1301001 + 250000, RFS_Q16_INT(-40), &f->rng);
    assert_int_equal(f->s.count, 3);
    assert_int_equal(f->s.samples[2].x_cm, 300);
    assert_int_equal(f->s.dropped_gap, PCAP);
}

/* Pose times at the ends of int64 (fuzzed or corrupt input): the gap is detected
 * without overflow, and poses 1 us apart still interpolate. */
static void test_int64_extreme_times(void **state)
{
    fixture_t *f = *state;
    rfs_pose_t p0 = pose(INT64_MIN, 0.0, 0.0), p1 = pose(INT64_MAX - 2, 1.0, 0.0);
    assert_true(rfs_store_add_pose(&f->s, &p0, &f->rng));
    rfs_store_add_value(&f->s, 0, RFS_Q16_INT(-50), &f->rng);
    assert_int_equal(f->s.pending_count, 1);
    assert_true(rfs_store_add_pose(&f->s, &p1, &f->rng));
    assert_int_equal(f->s.dropped_gap, 1u);
    rfs_pose_t p2 = pose(INT64_MAX, 3.0, 0.0);
    assert_true(rfs_store_add_pose(&f->s, &p2, &f->rng));
    rfs_store_add_value(&f->s, INT64_MAX - 1, RFS_Q16_INT(-50), &f->rng);
    assert_int_equal(f->s.count, 1);
    assert_int_equal(f->s.samples[0].x_cm, 200);
    rfs_store_add_value(&f->s, INT64_MAX, RFS_Q16_INT(-50), &f->rng);
    assert_int_equal(f->s.samples[1].x_cm, 300);
}

/* Two sources interleaving out of time order in the pending queue. */
static void test_pending_unsorted(void **state)
{
    fixture_t *f = *state;
    rfs_pose_t p0 = pose(0, 0.0, 0.0);
    assert_true(rfs_store_add_pose(&f->s, &p0, &f->rng));
    rfs_store_add_value(&f->s, 150000, RFS_Q16_INT(-10), &f->rng); /* after p1 */
    rfs_store_add_value(&f->s, 50000, RFS_Q16_INT(-20), &f->rng);  /* before p1 */
    rfs_pose_t p1 = pose(100000, 1.0, 0.0);
    assert_true(rfs_store_add_pose(&f->s, &p1, &f->rng));
    assert_int_equal(f->s.count, 1);
    assert_int_equal(f->s.samples[0].x_cm, 50);
    assert_int_equal(f->s.pending_count, 1);
    rfs_pose_t p2 = pose(200000, 3.0, 0.0);
    assert_true(rfs_store_add_pose(&f->s, &p2, &f->rng));
    assert_int_equal(f->s.count, 2);
    assert_int_equal(f->s.samples[1].x_cm, 200);
    assert_int_equal(f->s.samples[1].v_q6, -10 * 64);
}

/* Values saturate to Q9.6 and positions to int16 centimetres. */
static void test_saturation(void **state)
{
    fixture_t *f = *state;
    rfs_pose_t p0 = pose(0, 400.0, -400.0);
    assert_true(rfs_store_add_pose(&f->s, &p0, &f->rng));
    rfs_store_add_value(&f->s, 0, RFS_Q16_INT(-600), &f->rng);
    rfs_store_add_value(&f->s, 0, RFS_Q16_INT(600), &f->rng);
    rfs_store_add_value(&f->s, 0, RFS_Q16_FRAC(-1281, 10), &f->rng); /* -128.1 dB */
    rfs_store_add_value(&f->s, 0, RFS_Q16_MIN, &f->rng);
    assert_int_equal(f->s.count, 4);
    assert_int_equal(f->s.samples[0].x_cm, 32767);
    assert_int_equal(f->s.samples[0].y_cm, -32768);
    assert_int_equal(f->s.samples[0].v_q6, -32768);
    assert_int_equal(f->s.samples[1].v_q6, 32767);
    assert_int_equal(f->s.samples[2].v_q6, -8198); /* round(-128.1 * 64) = -8198.4 */
    assert_int_equal(f->s.samples[3].v_q6, -32768);
}

/* Wilson-Hilferty: chi-square quantile for df degrees of freedom at the normal quantile z. */
static double chi2_quantile(double df, double z)
{
    double a = 2.0 / (9.0 * df);
    double c = 1.0 - a + z * sqrt(a);
    return df * c * c * c;
}

/* Algorithm R keeps each of N offered samples with probability capacity / N. Over many
 * trials the counts per sample index are compared with a chi-square test (p = 0.001). */
static void test_reservoir_uniform(void **state)
{
    (void)state;
    enum { SCAP = 100, N = 1000, TRIALS = 4000 };
    static uint32_t hits[N];
    memset(hits, 0, sizeof hits);
    rfs_sample_t smp[SCAP];
    rfs_pending_t pend[1];
    rfs_store_cfg_t c = rfs_store_cfg_default();
    c.capacity = SCAP;
    rfs_rng_t g;
    rfs_rng_seed(&g, 2024u);
    for (int tr = 0; tr < TRIALS; ++tr) {
        rfs_store_t s;
        assert_int_equal(rfs_store_init(&s, &c, smp, pend, 1), 0);
        for (int i = 0; i < N; ++i) {
            rfs_sample_t one = {.x_cm = (int16_t)i, .y_cm = 0, .v_q6 = 0};
            rfs_store_offer(&s, one, &g);
        }
        assert_int_equal(s.count, SCAP);
        assert_int_equal(s.seen, N);
        for (int k = 0; k < SCAP; ++k) {
            hits[smp[k].x_cm]++;
        }
    }
    /* Each trial keeps SCAP of N without replacement: per index a binomial count with
     * p = SCAP / N, so the statistic divides by its variance T p (1 - p). */
    double p = (double)SCAP / N, expect = TRIALS * p, var = TRIALS * p * (1.0 - p), chi2 = 0.0;
    double first = 0.0, last = 0.0; /* the oldest and newest tenth, which Algorithm R must not favour */
    for (int i = 0; i < N; ++i) {
        double d = hits[i] - expect;
        chi2 += d * d / var;
        if (i < N / 10) {
            first += hits[i];
        } else if (i >= N - N / 10) {
            last += hits[i];
        }
    }
    double crit = chi2_quantile(N - 1, 3.0902); /* p = 0.001 */
    printf("reservoir chi2 = %.1f (df %d, critical %.1f)\n", chi2, N - 1, crit);
    assert_true(chi2 < crit);
    assert_true(chi2 > chi2_quantile(N - 1, -3.0902)); /* not suspiciously perfect */
    double tenth = (double)TRIALS * SCAP / 10.0;
    assert_true(fabs(first - tenth) < 4.0 * sqrt(tenth));
    assert_true(fabs(last - tenth) < 4.0 * sqrt(tenth));
}

/* Fewer samples than the capacity are all kept, in order. */
static void test_reservoir_keeps_all_below_capacity(void **state)
{
    fixture_t *f = *state;
    for (int i = 0; i < 500; ++i) {
        rfs_sample_t one = {.x_cm = (int16_t)i, .y_cm = (int16_t)-i, .v_q6 = (int16_t)(i % 64)};
        rfs_store_offer(&f->s, one, &f->rng);
    }
    assert_int_equal(f->s.count, 500);
    for (int i = 0; i < 500; ++i) {
        assert_int_equal(f->s.samples[i].x_cm, i);
        assert_int_equal(f->s.samples[i].y_cm, -i);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_and_init),
        cmocka_unit_test_setup_teardown(test_interpolation_hand, setup, teardown),
        cmocka_unit_test_setup_teardown(test_interpolation_random, setup, teardown),
        cmocka_unit_test(test_interpolation_q16_extremes),
        cmocka_unit_test_setup_teardown(test_drops_counted, setup, teardown),
        cmocka_unit_test_setup_teardown(test_pending_unsorted, setup, teardown),
        cmocka_unit_test_setup_teardown(test_int64_extreme_times, setup, teardown),
        cmocka_unit_test_setup_teardown(test_saturation, setup, teardown),
        cmocka_unit_test(test_reservoir_uniform),
        cmocka_unit_test_setup_teardown(test_reservoir_keeps_all_below_capacity, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
