/* test_target.c - single-source RSSI and the bridging target f = -|R1 - R2| - |R1 + R2|
 * (paper section 6) against double arithmetic on the same packets.
 */
#include "rfs_test.h"

#include <math.h>

#include "rfs_target.h"

typedef struct fixture {
    rfs_rssi_t win[2];
} fixture_t;

static void init_windows(fixture_t *f)
{
    rfs_rssi_cfg_t c = rfs_rssi_cfg_default();
    assert_int_equal(rfs_rssi_init(&f->win[0], &c), 0);
    assert_int_equal(rfs_rssi_init(&f->win[1], &c), 0);
}

static double bridge_ref(double r1, double r2)
{
    return -fabs(r1 - r2) - fabs(r1 + r2);
}

static void test_names_and_sources(void **state)
{
    (void)state;
    assert_string_equal(rfs_target_rssi.name, "rssi");
    assert_int_equal(rfs_target_rssi.nsources, 1);
    assert_string_equal(rfs_target_bridge.name, "bridge");
    assert_int_equal(rfs_target_bridge.nsources, 2);
}

static void test_rssi(void **state)
{
    (void)state;
    static fixture_t f;
    init_windows(&f);
    rfs_target_in_t in = {.win = f.win, .nsources = 1, .now_us = 1000};
    rfs_q16_t v = 0;
    /* a packet's sample is its own value, even with no mean yet */
    assert_true(rfs_target_rssi.sample(&in, 0, -73, &v));
    assert_int_equal(v, -73 * 65536);
    assert_false(rfs_target_rssi.mean(&in, &v)); /* no measurement in the window */
    assert_true(rfs_rssi_push(&f.win[0], 500, -70));
    assert_true(rfs_rssi_push(&f.win[0], 900, -75));
    assert_true(rfs_target_rssi.mean(&in, &v));
    assert_int_equal(v, -72 * 65536 - 32768); /* -72.5 */
    assert_false(rfs_target_rssi.sample(&in, 1, -73, &v)); /* no such source */
    assert_true(rfs_target_rssi.sample(&in, 0, -128, &v));
    assert_int_equal(v, -128 * 65536);
    assert_true(rfs_target_rssi.sample(&in, 0, 0, &v));
    assert_int_equal(v, 0);
}

/* Hand value: R1 = -50 (packet), R2 mean -70: f = -20 - 120 = -140 = 2 min(R1, R2). */
static void test_bridge_hand(void **state)
{
    (void)state;
    static fixture_t f;
    init_windows(&f);
    rfs_target_in_t in = {.win = f.win, .nsources = 2, .now_us = 2000000};
    rfs_q16_t v = 0;
    assert_false(rfs_target_bridge.sample(&in, 0, -50, &v)); /* source 1 has no mean */
    assert_true(rfs_rssi_push(&f.win[1], 1900000, -70));
    assert_true(rfs_target_bridge.sample(&in, 0, -50, &v));
    assert_int_equal(v, -140 * 65536);
    assert_false(rfs_target_bridge.mean(&in, &v)); /* source 0 has no mean */
    assert_true(rfs_rssi_push(&f.win[0], 1950000, -50));
    assert_true(rfs_target_bridge.mean(&in, &v));
    assert_int_equal(v, -140 * 65536);
    assert_false(rfs_target_bridge.sample(&in, 2, -50, &v));
    in.nsources = 1; /* a bridge over one window cannot be evaluated */
    assert_false(rfs_target_bridge.mean(&in, &v));
}

/* Random packets on both sources: each sample is f(packet, other's 1 s mean), each check
 * f(mean 0, mean 1), with the means and f computed in double from the same packets. */
static void test_bridge_random(void **state)
{
    (void)state;
    static fixture_t f;
    init_windows(&f);
    enum { N = 4000 };
    static int64_t ts[2][N];
    static int8_t vs[2][N];
    int cnt[2] = {0, 0};
    rfs_rng_t g;
    rfs_rng_seed(&g, 11u);
    int64_t t = 0;
    int evaluated = 0;
    for (int i = 0; i < N; ++i) {
        t += rfs_rng_below(&g, 6000);
        int src = (int)rfs_rng_below(&g, 2);
        int8_t dbm = (int8_t)(-(int)rfs_rng_below(&g, 129));
        rfs_target_in_t in = {.win = f.win, .nsources = 2, .now_us = t};
        /* reference mean of the other source over (t - 1 s, t] */
        int o = 1 - src;
        double sum = 0.0;
        int n = 0;
        for (int k = cnt[o] - 1; k >= 0 && ts[o][k] > t - 1000000; --k) {
            sum += vs[o][k];
            n++;
        }
        rfs_q16_t v;
        bool ok = rfs_target_bridge.sample(&in, (uint8_t)src, dbm, &v);
        assert_int_equal(ok, n > 0);
        if (ok) {
            double mo = sum / n;
            double want = src == 0 ? bridge_ref(dbm, mo) : bridge_ref(mo, dbm);
            /* the mean is rounded to 0.5 LSB; f has slope at most 2 in each input */
            assert_true(fabs(v / 65536.0 - want) <= 1.0 / 65536.0 + 1e-12);
            evaluated++;
        }
        assert_true(rfs_rssi_push(&f.win[src], t, dbm));
        ts[src][cnt[src]] = t;
        vs[src][cnt[src]] = dbm;
        cnt[src]++;
    }
    assert_true(evaluated > N / 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_names_and_sources),
        cmocka_unit_test(test_rssi),
        cmocka_unit_test(test_bridge_hand),
        cmocka_unit_test(test_bridge_random),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
