/* test_status_est.c - the estimates in the LCM seeker status: lx_lcm_pub_status_est()
 * puts the decision's last fields (samples, the flags, plan_wait), the path-loss estimate
 * and then the per-node model's bridging point at the end of rfseek.seeker_status_t, read
 * back here from the recorded bytes by hand (big-endian, the .lcm field order) rather than
 * by the generated decoder;
 * lx_lcm_pub_status() leaves them zero; the receiver drops a status whose estimate is not
 * finite, negative where it cannot be, or set without its valid flag. */
#include "rfs_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lx_lcm.h"
#include "rfseek_seeker_status_t.h"

/// Bytes of the path-loss estimate: est_valid + 7 doubles.
#define EST_BYTES (1 + 7 * 8)
/// Bytes of the bridging point at the end of the message: bridge_valid + 5 doubles.
#define BRIDGE_BYTES (1 + 5 * 8)

typedef struct rx {
    int statuses;
    int bads;
    char bad[200];
} rx_t;

static void on_status(void *c, int64_t t, const rfs_seek_out_t *o)
{
    (void)t, (void)o;
    ((rx_t *)c)->statuses++;
}

static void on_bad(void *c, const char *why)
{
    rx_t *r = c;
    snprintf(r->bad, sizeof r->bad, "%s", why);
    r->bads++;
}

/// A big-endian IEEE double (LCM's encoding) from 8 bytes.
static double be_double(const uint8_t *p)
{
    uint64_t u = 0;
    for (int i = 0; i < 8; i++) {
        u = (u << 8) | p[i];
    }
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

/// Publish one status (with est and bridge, or without when NULL) into a log and read its
/// bytes back.
static size_t status_bytes(const rfs_pathloss_est_t *est, const rfs_fields_est_t *bridge,
                           uint8_t *buf, size_t cap)
{
    char path[] = "/tmp/rfs_test_status_est_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    char err[200];
    lx_lcm_log_t *w = lx_lcm_log_open(path, "w", err, sizeof err);
    assert_non_null(w);
    lx_lcm_handlers_t h;
    memset(&h, 0, sizeof h);
    lx_lcm_t *l = lx_lcm_open("memq://", &h, err, sizeof err);
    assert_non_null(l);
    lx_lcm_record(l, w);
    rfs_seek_out_t out;
    memset(&out, 0, sizeof out);
    out.decision.samples = 42;
    out.decision.near = true;
    out.decision.refuted = true;
    out.decision.plan_wait = 0x1234;
    assert_int_equal(lx_lcm_pub_status_est(l, 1000, &out, est, bridge), 0);
    lx_lcm_record(l, NULL);
    lx_lcm_close(l);
    assert_int_equal(lx_lcm_log_close(w), 0);
    lx_lcm_log_t *r = lx_lcm_log_open(path, "r", err, sizeof err);
    assert_non_null(r);
    int64_t t;
    char ch[64];
    size_t len = 0;
    assert_int_equal(lx_lcm_log_next_raw(r, &t, ch, sizeof ch, buf, cap, &len), 1);
    assert_string_equal(ch, LX_LCM_CH_STATUS);
    assert_true(len <= cap && len > EST_BYTES + BRIDGE_BYTES);
    assert_int_equal(lx_lcm_log_close(r), 0);
    unlink(path);
    return len;
}

static void estimate_is_in_the_last_fields(void **state)
{
    (void)state;
    // Q16.16 values with exact double equivalents: 27.125 m, 9.875 m, n 3.0372, ...
    rfs_pathloss_est_t est;
    memset(&est, 0, sizeof est);
    est.sx = 27 * 65536 + 8192;
    est.sy = 9 * 65536 + 57344;
    est.n = 199045;   // 3.03718... = 199045 / 65536
    est.w = 338623;   // 5.16696...
    est.p0 = -1490153; // -22.7379...
    est.rms = 190971; // 2.91398...
    est.spread_m2 = 4 * 65536;
    uint8_t buf[512];
    size_t len = status_bytes(&est, NULL, buf, sizeof buf);
    const uint8_t *e = buf + len - BRIDGE_BYTES - EST_BYTES;

    assert_int_equal(e[0], 1);
    assert_true(be_double(e + 1) == 27.125);
    assert_true(be_double(e + 9) == 9.875);
    assert_true(be_double(e + 17) == 199045.0 / 65536.0);
    assert_true(be_double(e + 25) == 338623.0 / 65536.0);
    assert_true(be_double(e + 33) == -1490153.0 / 65536.0);
    assert_true(be_double(e + 41) == 190971.0 / 65536.0);
    assert_true(be_double(e + 49) == 4.0);
    // The fields before the estimate: samples (int32 big-endian), sampled, near, hedged,
    // pinned, refuted (one byte each), plan_wait (int32).
    const uint8_t *s = e - 4 - 5 - 4;
    assert_int_equal((s[0] << 24) | (s[1] << 16) | (s[2] << 8) | s[3], 42);
    const uint8_t flags[5] = {0, 1, 0, 0, 1};
    assert_memory_equal(s + 4, flags, 5);
    assert_int_equal((s[9] << 24) | (s[10] << 16) | (s[11] << 8) | s[12], 0x1234);
    // No bridging point: its fields are zero.
    for (int i = 0; i < BRIDGE_BYTES; i++) {
        assert_int_equal(e[EST_BYTES + i], 0);
    }
}

static void bridging_point_is_in_the_last_fields(void **state)
{
    (void)state;
    rfs_fields_est_t fe;
    memset(&fe, 0, sizeof fe);
    fe.x = 19 * 65536 + 32768;  // 19.5 m
    fe.y = 6 * 65536 + 16384;   // 6.25 m
    fe.value = -7208960 - 4096; // -110.0625 dB
    fe.sigma = 2 * 65536 + 8192; // 2.125 dB
    fe.area_m2 = 65536 / 4;     // 0.25 m^2
    uint8_t buf[512];
    size_t len = status_bytes(NULL, &fe, buf, sizeof buf);
    const uint8_t *b = buf + len - BRIDGE_BYTES;
    assert_int_equal(b[0], 1);
    assert_true(be_double(b + 1) == 19.5);
    assert_true(be_double(b + 9) == 6.25);
    assert_true(be_double(b + 17) == -110.0625);
    assert_true(be_double(b + 25) == 2.125);
    assert_true(be_double(b + 33) == 0.25);
    for (int i = 0; i < EST_BYTES; i++) { // no path-loss estimate
        assert_int_equal(b[i - EST_BYTES], 0);
    }
}

static void without_estimate_the_fields_are_zero(void **state)
{
    (void)state;
    uint8_t buf[512];
    size_t len = status_bytes(NULL, NULL, buf, sizeof buf);
    const uint8_t *e = buf + len - EST_BYTES - BRIDGE_BYTES;
    for (int i = 0; i < EST_BYTES + BRIDGE_BYTES; i++) {
        assert_int_equal(e[i], 0);
    }
}

/// Encode m with the generated encoder, publish it raw on memq, return what arrived.
static rx_t deliver(const rfseek_seeker_status_t *m)
{
    rx_t r;
    memset(&r, 0, sizeof r);
    lx_lcm_handlers_t h;
    memset(&h, 0, sizeof h);
    h.ctx = &r;
    h.on_status = on_status;
    h.on_bad = on_bad;
    char err[200];
    lx_lcm_t *l = lx_lcm_open("memq://", &h, err, sizeof err);
    assert_non_null(l);
    uint8_t buf[512];
    int n = rfseek_seeker_status_t_encoded_size(m);
    assert_true(n > 0 && n <= (int)sizeof buf);
    assert_int_equal(rfseek_seeker_status_t_encode(buf, 0, n, m), n);
    assert_int_equal(lx_lcm_pub_raw(l, 0, LX_LCM_CH_STATUS, buf, (size_t)n), 0);
    while (lx_lcm_handle(l, 0) == 1) {
    }
    lx_lcm_close(l);
    return r;
}

static void bad_estimates_are_dropped_with_one_line(void **state)
{
    (void)state;
    rfseek_seeker_status_t m;
    memset(&m, 0, sizeof m);
    m.reason = (char *)"greedy";
    m.est_valid = 1;
    m.est_x = 27.125;
    m.est_y = 9.875;
    m.est_n = 3.0;
    m.est_w = 5.0;
    m.est_p0 = -23.0;
    m.est_rms = 2.9;
    m.est_area = 4.0;
    rx_t r = deliver(&m);
    assert_int_equal(r.statuses, 1);
    assert_int_equal(r.bads, 0);

    rfseek_seeker_status_t b = m;
    b.est_area = NAN;
    r = deliver(&b);
    assert_int_equal(r.statuses, 0);
    assert_int_equal(r.bads, 1);
    assert_non_null(strstr(r.bad, "RFS_SEEKER_STATUS: a field is out of range or not finite"));

    b = m;
    b.est_area = -1.0; // an area cannot be negative
    r = deliver(&b);
    assert_int_equal(r.statuses, 0);
    assert_int_equal(r.bads, 1);

    b = m;
    b.est_x = 1e9; // outside Q16.16
    r = deliver(&b);
    assert_int_equal(r.bads, 1);

    b = m;
    b.est_valid = 0; // values without est_valid
    r = deliver(&b);
    assert_int_equal(r.statuses, 0);
    assert_int_equal(r.bads, 1);

    b = m;
    b.plan_wait = 65536; // rfs_seek_decision_t.plan_wait is 16 bits
    r = deliver(&b);
    assert_int_equal(r.statuses, 0);
    assert_int_equal(r.bads, 1);
    b.plan_wait = -1;
    r = deliver(&b);
    assert_int_equal(r.bads, 1);
    b.plan_wait = 65535;
    r = deliver(&b);
    assert_int_equal(r.statuses, 1);

    b = m;
    b.bridge_valid = 1;
    b.bridge_x = 19.5;
    b.bridge_f = -110.0;
    b.bridge_sigma = 2.0;
    r = deliver(&b);
    assert_int_equal(r.statuses, 1);
    b.bridge_sigma = -1.0; // a spread cannot be negative
    r = deliver(&b);
    assert_int_equal(r.bads, 1);
    b.bridge_sigma = 2.0;
    b.bridge_valid = 0; // values without bridge_valid
    r = deliver(&b);
    assert_int_equal(r.statuses, 0);
    assert_int_equal(r.bads, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(estimate_is_in_the_last_fields),
        cmocka_unit_test(bridging_point_is_in_the_last_fields),
        cmocka_unit_test(without_estimate_the_fields_are_zero),
        cmocka_unit_test(bad_estimates_are_dropped_with_one_line),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
