/* test_rssi.c - the 1 s mean per source (paper section 2) against a double reference that
 * keeps every accepted measurement and averages the window by brute force.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>

#include "rfs_rssi.h"

/* The reference: every accepted measurement in arrival order, and the newest time seen
 * (pushes and queries): time only moves forward, so what left the window of the newest
 * time seen is gone for a later query into the past too (see rfs_rssi.h). */
typedef struct ref {
    int64_t *t;
    int8_t *v;
    size_t n, cap;
    uint32_t rejected;
    int64_t clock;
    int64_t window;
    int64_t last;    /* newest accepted time */
    bool any;
} ref_t;

static void ref_push(ref_t *r, int64_t t, int8_t v)
{
    if (r->any && t < r->last) {
        r->rejected++;
        return;
    }
    r->last = t;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 1024;
        r->t = realloc(r->t, r->cap * sizeof *r->t);
        r->v = realloc(r->v, r->cap * sizeof *r->v);
        assert_non_null(r->t);
        assert_non_null(r->v);
    }
    if (!r->any || t > r->clock) {
        r->clock = t;
    }
    r->any = true;
    if (t <= r->clock - r->window) {
        return; /* accepted, but the window has already passed it */
    }
    r->t[r->n] = t;
    r->v[r->n] = v;
    r->n++;
}

/* Mean over the newest `cap` accepted measurements of those with t in (now - window, now]
 * and t > clock - window. */
static int ref_mean(ref_t *r, int64_t now, int64_t window, size_t cap, double *mean)
{
    if (r->any && now > r->clock) {
        r->clock = now;
    }
    double sum = 0.0;
    size_t cnt = 0;
    size_t last = r->n > cap ? r->n - cap : 0;
    for (size_t i = r->n; i-- > last;) {
        if (r->t[i] <= now - window || r->t[i] <= r->clock - window) {
            break;
        }
        if (r->t[i] > now) {
            continue;
        }
        sum += r->v[i];
        cnt++;
    }
    if (cnt) {
        *mean = sum / (double)cnt;
    }
    return (int)cnt;
}

static void ref_free(ref_t *r)
{
    free(r->t);
    free(r->v);
}

/* The mean is rounded to nearest Q16.16: within half an LSB of the exact mean. */
static void assert_mean(rfs_rssi_t *w, ref_t *r, int64_t now)
{
    double want = 0.0;
    int n = ref_mean(r, now, (int64_t)w->cfg.window_us, RFS_RSSI_CAP, &want);
    rfs_q16_t got = 12345;
    bool ok = rfs_rssi_mean(w, now, &got);
    assert_int_equal(ok, n > 0);
    assert_int_equal(rfs_rssi_count(w, now), n);
    if (n > 0) {
        assert_true(fabs(got / 65536.0 - want) <= 0.5 / 65536.0 + 1e-12);
    } else {
        assert_int_equal(got, 12345); /* untouched */
    }
}

static void test_defaults_and_init(void **state)
{
    (void)state;
    rfs_rssi_t w;
    rfs_rssi_cfg_t c = rfs_rssi_cfg_default();
    assert_int_equal(c.window_us, 1000000u);
    assert_int_equal(rfs_rssi_init(&w, &c), 0);
    rfs_q16_t m;
    assert_false(rfs_rssi_mean(&w, 0, &m));
    c.window_us = 0;
    assert_int_equal(rfs_rssi_init(&w, &c), -1);
    c.window_us = 60000001u;
    assert_int_equal(rfs_rssi_init(&w, &c), -1);
    c.window_us = 60000000u;
    assert_int_equal(rfs_rssi_init(&w, &c), 0);
}

/* Hand values: -40, -50, -61 at 0.1, 0.5, 1.05 s: at 1.05 s the window (0.05, 1.05]
 * holds all three (mean -50.333..); at 1.5 s only -61... (0.5, 1.5] holds -61. */
static void test_hand_values(void **state)
{
    (void)state;
    rfs_rssi_t w;
    rfs_rssi_cfg_t c = rfs_rssi_cfg_default();
    assert_int_equal(rfs_rssi_init(&w, &c), 0);
    assert_true(rfs_rssi_push(&w, 100000, -40));
    assert_true(rfs_rssi_push(&w, 500000, -50));
    assert_true(rfs_rssi_push(&w, 1050000, -61));
    rfs_q16_t m;
    assert_true(rfs_rssi_mean(&w, 1050000, &m));
    assert_int_equal(m, -3298645); /* round(-151/3 * 65536) = round(-3298645.33) */
    assert_true(rfs_rssi_mean(&w, 1100000, &m));
    assert_int_equal(m, -55 * 65536 - 32768); /* (-50 - 61) / 2 = -55.5 */
    assert_true(rfs_rssi_mean(&w, 1500000, &m));
    assert_int_equal(m, -61 * 65536);
    assert_false(rfs_rssi_mean(&w, 2050000, &m)); /* exactly window after: excluded */
    assert_int_equal(w.accepted, 3u);
}

static void test_out_of_order_rejected_equal_accepted(void **state)
{
    (void)state;
    rfs_rssi_t w;
    rfs_rssi_cfg_t c = rfs_rssi_cfg_default();
    assert_int_equal(rfs_rssi_init(&w, &c), 0);
    assert_true(rfs_rssi_push(&w, 1000, -30));
    assert_true(rfs_rssi_push(&w, 1000, -40)); /* equal timestamp: accepted */
    assert_false(rfs_rssi_push(&w, 999, -90));  /* older: rejected, counted */
    assert_int_equal(w.rejected_order, 1u);
    assert_int_equal(w.accepted, 2u);
    rfs_q16_t m;
    assert_true(rfs_rssi_mean(&w, 1000, &m));
    assert_int_equal(m, -35 * 65536);
}

/* Random streams at 200-600 packets/s with gaps longer than the window, bursts of equal
 * timestamps, out-of-order packets, absolute times crossing 2^32 us, and queries at,
 * after and before the newest packet; compared after every packet. */
static void run_stream(uint64_t seed, int64_t t0, uint32_t mean_gap_us, uint32_t window_us)
{
    rfs_rng_t g;
    rfs_rng_seed(&g, seed);
    rfs_rssi_t w;
    rfs_rssi_cfg_t c = {.window_us = window_us};
    assert_int_equal(rfs_rssi_init(&w, &c), 0);
    ref_t r = {.window = window_us};
    int64_t t = t0;
    for (int i = 0; i < 30000; ++i) {
        uint32_t k = rfs_rng_below(&g, 1000);
        int64_t pt;
        if (k < 20) {
            pt = t - 1 - (int64_t)rfs_rng_below(&g, 100000); /* out of order */
        } else if (k < 120) {
            pt = t; /* equal timestamp */
        } else if (k < 123) {
            t += window_us + rfs_rng_below(&g, 3 * window_us); /* a gap */
            pt = t;
        } else {
            t += rfs_rng_below(&g, 2 * mean_gap_us);
            pt = t;
        }
        int8_t v = (int8_t)(-(int)rfs_rng_below(&g, 129));
        bool want = !(r.any && pt < r.last);
        ref_push(&r, pt, v);
        assert_int_equal(rfs_rssi_push(&w, pt, v), want);
        switch (rfs_rng_below(&g, 4)) {
        case 0: assert_mean(&w, &r, t); break;
        case 1: assert_mean(&w, &r, t + rfs_rng_below(&g, 2 * window_us)); break;
        case 2: assert_mean(&w, &r, t - rfs_rng_below(&g, window_us / 2)); break;
        default: break;
        }
    }
    assert_int_equal(w.rejected_order, r.rejected);
    ref_free(&r);
}

static void test_stream_250_per_s(void **state)
{
    (void)state;
    run_stream(1u, 0, 4000u, 1000000u);                      /* 250 packets/s */
}

static void test_stream_across_2_32_us(void **state)
{
    (void)state;
    run_stream(2u, ((int64_t)1 << 32) - 5000000, 2500u, 1000000u); /* 400/s, wraps low word */
    run_stream(3u, ((int64_t)1 << 45) + 12345, 3000u, 60000000u); /* 60 s window, full ring */
    run_stream(4u, -((int64_t)1 << 33), 4000u, 250000u);
}

/* Above RFS_RSSI_CAP packets inside the window the mean covers the newest CAP. */
static void test_overflow_counted(void **state)
{
    (void)state;
    rfs_rssi_t w;
    rfs_rssi_cfg_t c = rfs_rssi_cfg_default();
    assert_int_equal(rfs_rssi_init(&w, &c), 0);
    ref_t r = {.window = 1000000};
    for (int i = 0; i < 700; ++i) { /* 700 packets in 0.7 s */
        int64_t t = (int64_t)i * 1000;
        int8_t v = (int8_t)(i < 188 ? -128 : -(i % 100));
        assert_true(rfs_rssi_push(&w, t, v));
        ref_push(&r, t, v);
    }
    assert_int_equal(w.overflowed, 700u - RFS_RSSI_CAP);
    assert_int_equal(rfs_rssi_count(&w, 699000), RFS_RSSI_CAP);
    assert_mean(&w, &r, 699000);
    ref_free(&r);
}

/* Extremes: a full ring of -128 dBm and of 0 dBm. */
static void test_extremes(void **state)
{
    (void)state;
    rfs_rssi_t w;
    rfs_rssi_cfg_t c = rfs_rssi_cfg_default();
    for (int pass = 0; pass < 2; ++pass) {
        assert_int_equal(rfs_rssi_init(&w, &c), 0);
        for (int i = 0; i < 2000; ++i) {
            assert_true(rfs_rssi_push(&w, INT64_MAX / 2 + i, (int8_t)(pass ? 0 : -128)));
        }
        rfs_q16_t m;
        assert_true(rfs_rssi_mean(&w, INT64_MAX / 2 + 1999, &m));
        assert_int_equal(m, pass ? 0 : -128 * 65536);
    }
}

/* Timestamps at the ends of int64 (fuzzed or corrupt input): no overflow, sane answers. */
static void test_int64_extremes(void **state)
{
    (void)state;
    rfs_rssi_t w;
    rfs_rssi_cfg_t c = rfs_rssi_cfg_default();
    assert_int_equal(rfs_rssi_init(&w, &c), 0);
    rfs_q16_t m;
    assert_true(rfs_rssi_push(&w, INT64_MIN, -50));
    assert_true(rfs_rssi_mean(&w, INT64_MIN, &m));
    assert_int_equal(m, -50 * 65536);
    assert_false(rfs_rssi_mean(&w, INT64_MIN + 1000000, &m)); /* one window later */
    assert_true(rfs_rssi_push(&w, INT64_MAX, -60));
    assert_false(rfs_rssi_mean(&w, INT64_MIN, &m)); /* the far past: nothing kept there */
    assert_true(rfs_rssi_mean(&w, INT64_MAX, &m));
    assert_int_equal(m, -60 * 65536);
    assert_true(rfs_rssi_push(&w, INT64_MAX, -70));
    assert_int_equal(rfs_rssi_count(&w, INT64_MAX), 2);
    assert_false(rfs_rssi_push(&w, INT64_MAX - 1, -70)); /* out of order */
    assert_int_equal(w.rejected_order, 1u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_and_init),
        cmocka_unit_test(test_hand_values),
        cmocka_unit_test(test_out_of_order_rejected_equal_accepted),
        cmocka_unit_test(test_stream_250_per_s),
        cmocka_unit_test(test_stream_across_2_32_us),
        cmocka_unit_test(test_overflow_counted),
        cmocka_unit_test(test_extremes),
        cmocka_unit_test(test_int64_extremes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
