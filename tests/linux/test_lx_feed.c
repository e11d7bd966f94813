/* test_lx_feed.c - the live feed's publisher (firmware/port/linux/lx_feed.h) over memq://:
 * what the controller receives, and when heartbeats go out. Expected times are worked out
 * by hand from the rule "at least 50 ms after the last heartbeat" (docs/FEEDER.md). */
#include "rfs_test.h"

#include <string.h>

#include "lx_feed.h"

#define MAXN 64

typedef struct rx {
    int64_t hb_t[MAXN];
    uint32_t hb_seq[MAXN];
    int hbs;
    int64_t rssi_t[MAXN];
    uint8_t src[MAXN];
    int8_t dbm[MAXN];
    uint32_t seq[MAXN];
    int rssis;
} rx_t;

static void on_rssi(void *c, uint8_t s, int64_t t, int8_t d, uint32_t q)
{
    rx_t *r = c;
    assert_true(r->rssis < MAXN);
    r->src[r->rssis] = s;
    r->rssi_t[r->rssis] = t;
    r->dbm[r->rssis] = d;
    r->seq[r->rssis++] = q;
}

static void on_receiver(void *c, int64_t t, uint32_t q)
{
    rx_t *r = c;
    assert_true(r->hbs < MAXN);
    r->hb_t[r->hbs] = t;
    r->hb_seq[r->hbs++] = q;
}

static lx_lcm_t *open_memq(rx_t *r)
{
    memset(r, 0, sizeof(*r));
    lx_lcm_handlers_t h;
    memset(&h, 0, sizeof(h));
    h.ctx = r;
    h.on_rssi = on_rssi;
    h.on_receiver = on_receiver;
    char err[200];
    lx_lcm_t *l = lx_lcm_open("memq://", &h, err, sizeof(err));
    assert_non_null(l);
    return l;
}

static void drain(lx_lcm_t *l)
{
    while (lx_lcm_handle(l, 0) == 1) {
    }
}

static void heartbeat_rule_spaces_by_50_ms_and_never_goes_back(void **state)
{
    (void)state;
    lx_feed_hb_t hb = {0, false};
    /* the first; 10 and 49.999 ms later: not yet; 50 ms: due; from there 50.001 and
     * 99.999 ms: not; 100 ms: due; a time before the last (a clock stepped back): not;
     * 200 ms: due. */
    const int64_t t[] = {1000000, 1010000, 1049999, 1050000, 1050001, 1099999, 1100000, 1030000, 1200000};
    const bool due[] = {true, false, false, true, false, false, true, false, true};
    for (size_t i = 0; i < sizeof(t) / sizeof(t[0]); i++) {
        assert_int_equal(lx_feed_hb_due(&hb, t[i]), due[i]);
    }
    assert_true(hb.last_us == 1200000);
}

static void frames_reach_the_controller_as_sent(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    lx_feed_t f;
    lx_feed_init(&f, l);

    assert_int_equal(lx_feed_frame(&f, 0, 1700000000123456LL, -42, 4095), 0);
    assert_int_equal(lx_feed_frame(&f, 7, 1700000000123999LL, -128, 0), 0);
    assert_int_equal(lx_feed_frame(&f, 1, 1700000000124000LL, 127, 17), 0);
    drain(l);

    assert_int_equal(r.rssis, 3);
    assert_int_equal(r.hbs, 0);
    const uint8_t src[] = {0, 7, 1};
    const int64_t t[] = {1700000000123456LL, 1700000000123999LL, 1700000000124000LL};
    const int8_t dbm[] = {-42, -128, 127};
    const uint32_t seq[] = {4095, 0, 17};
    for (int i = 0; i < 3; i++) {
        assert_int_equal(r.src[i], src[i]);
        assert_true(r.rssi_t[i] == t[i]);
        assert_int_equal(r.dbm[i], dbm[i]);
        assert_int_equal(r.seq[i], seq[i]);
    }
    assert_true(f.st.rssi == 3 && f.st.heartbeats == 0 && f.st.refused == 0);
    lx_lcm_close(l);
}

static void heartbeats_go_on_through_silence(void **state)
{
    (void)state;
    rx_t r;
    lx_lcm_t *l = open_memq(&r);
    lx_feed_t f;
    lx_feed_init(&f, l);
    /* Frames every 20 ms up to 200 ms (each read proves the loop alive), then silence: the
     * reader's 25 ms waits (LX_PCAP_LIVE_TIMEOUT_MS) time out at 225, 250, ... 500 ms. */
    const int64_t t0 = 1700000000000000LL;
    int sent = 0;
    for (int64_t ms = 0; ms <= 200; ms += 20) {
        sent += lx_feed_alive(&f, t0 + ms * 1000);
    }
    for (int64_t ms = 225; ms <= 500; ms += 25) {
        sent += lx_feed_alive(&f, t0 + ms * 1000);
    }
    drain(l);

    /* 0; 60 (the first read 50 ms or more after 0); 120; 180; then 200 and 225 are too
     * soon, 250 is due; every second wait after that. */
    const int64_t want_ms[] = {0, 60, 120, 180, 250, 300, 350, 400, 450, 500};
    const int n = (int)(sizeof(want_ms) / sizeof(want_ms[0]));
    assert_int_equal(sent, n);
    assert_int_equal(r.hbs, n);
    for (int i = 0; i < n; i++) {
        assert_true(r.hb_t[i] == t0 + want_ms[i] * 1000);
        assert_int_equal(r.hb_seq[i], (uint32_t)i);
    }
    assert_true(f.st.heartbeats == (uint64_t)n && f.st.rssi == 0);
    lx_lcm_close(l);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(heartbeat_rule_spaces_by_50_ms_and_never_goes_back),
        cmocka_unit_test(frames_reach_the_controller_as_sent),
        cmocka_unit_test(heartbeats_go_on_through_silence),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
