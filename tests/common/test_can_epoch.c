/* test_can_epoch.c - the CAN receiver's follow_epoch mode (common/rfs_can.h; docs/CAN.md,
 * "Time on the bus"): senders stamping in an epoch of their own, hours away from the
 * receiver's clock, with 100 ppm of drift, a lagging stream, a restart of the senders, a
 * reset of the receiver and the 32-bit wrap of the stamps. Expected times are worked by
 * hand from the documented rule (age 0 at the first frame, a frame from the future made
 * age 0, older ones pulled back by floor(elapsed / 2048) us) or from the senders' true
 * latencies; the mode off is checked against the plain window rule. */
#include "rfs_test.h"

#include <string.h>

#include "rfs_can.h"

/* A bus: the receiver and the senders' counters; the senders' clock reads
 * epoch_us + t + t * ppm / 10^6 at the receiver's time t. */
typedef struct bus {
    rfs_can_rx_t rx;
    rfs_can_tx_t tx;
    int64_t epoch_us;
    int64_t ppm;
    uint8_t seq;
} bus_t;

static void bus_init(bus_t *b, bool follow, int64_t epoch_us, int64_t ppm)
{
    memset(b, 0, sizeof *b);
    rfs_can_rx_cfg_t c = rfs_can_rx_cfg_default();
    c.follow_epoch = follow;
    assert_int_equal(rfs_can_rx_init(&b->rx, &c), 0);
    rfs_can_tx_init(&b->tx);
    b->epoch_us = epoch_us;
    b->ppm = ppm;
}

/* The senders' time at receiver time t (exact in int64 for |t| < 2^43). */
static int64_t sender_us(const bus_t *b, int64_t t)
{
    return b->epoch_us + t + t * b->ppm / 1000000;
}

/* One frame of each time-bearing kind, arriving at now stamped `stamp` (senders' time). */
static rfs_can_err_t send_rssi(bus_t *b, int64_t now, int64_t stamp, rfs_can_msg_t *m)
{
    const rfs_can_rssi_t r = {.src = 0, .dbm = -60, .seq = b->seq++, .t_us32 = rfs_can_wrap_time(stamp)};
    rfs_can_frame_t f;
    rfs_can_tx_rssi(&b->tx, &r, &f);
    return rfs_can_rx_frame(&b->rx, &f, now, m);
}

static rfs_can_err_t send_pose(bus_t *b, int64_t now, int64_t stamp, rfs_can_msg_t *m)
{
    const rfs_can_pose_t p = {.x_mm = 1000, .y_mm = 2000, .theta_q13 = 0, .t_us32 = rfs_can_wrap_time(stamp)};
    rfs_can_frame_t xy, th;
    rfs_can_tx_pose(&b->tx, &p, &xy, &th);
    assert_int_equal(rfs_can_rx_frame(&b->rx, &xy, now, m), RFS_CAN_OK);
    return rfs_can_rx_frame(&b->rx, &th, now, m);
}

static rfs_can_err_t send_receiver(bus_t *b, int64_t now, int64_t stamp, rfs_can_msg_t *m)
{
    const rfs_can_receiver_t r = {.t_us32 = rfs_can_wrap_time(stamp)};
    rfs_can_frame_t f;
    rfs_can_tx_receiver(&b->tx, &r, &f);
    return rfs_can_rx_frame(&b->rx, &f, now, m);
}

/* 3 h 17 min ahead of the receiver: 11,820,123,456 us. */
#define HOURS_AHEAD 11820123456LL

static void epoch_hours_away_is_followed_from_the_first_frame(void **state)
{
    (void)state;
    bus_t b;
    rfs_can_msg_t m;
    bus_init(&b, true, HOURS_AHEAD, 0);

    /* The first frame (captured 2 ms before it arrives at 5 s) sets the offset: age 0. */
    assert_int_equal(send_rssi(&b, 5000000, sender_us(&b, 4998000), &m), RFS_CAN_OK);
    assert_int_equal(m.rssi_t_us, 5000000);
    /* 20 ms of latency reads 18 ms; 50 ms elapsed pull it back by floor(50000 / 2048) = 24. */
    assert_int_equal(send_rssi(&b, 5050000, sender_us(&b, 5030000), &m), RFS_CAN_OK);
    assert_int_equal(m.rssi_t_us, 5032000 + 24);
    /* A pose with 0.5 ms of latency reads 1,524 us ahead: the offset moves, its age is 0. */
    assert_int_equal(send_pose(&b, 5100000, sender_us(&b, 5099500), &m), RFS_CAN_OK);
    assert_int_equal(m.kind, RFS_CAN_MSG_POSE);
    assert_int_equal(m.pose.t_us, 5100000);
    /* Now read against the pose's 0.5 ms: 2 ms of latency is 1.5 ms of age, less 24. */
    assert_int_equal(send_rssi(&b, 5150000, sender_us(&b, 5148000), &m), RFS_CAN_OK);
    assert_int_equal(m.rssi_t_us, 5148500 + 24);
    /* 1 ms of latency reads 1,000 - 500 - 24 = 476 us of age; the allowance kept
     * 50,000 - 24 * 2048 = 848 us, so 50,848 us give 24 again. */
    assert_int_equal(send_receiver(&b, 5200000, sender_us(&b, 5199000), &m), RFS_CAN_OK);
    assert_int_equal(m.receiver_t_us, 5199524 + 24);
    assert_int_equal(rfs_can_rx_dropped_total(&b.rx), 0u);
    assert_int_equal(b.rx.resyncs, 0u);

    /* The mode off: the same first frame is 17.7 minutes old once unwrapped. */
    bus_init(&b, false, HOURS_AHEAD, 0);
    assert_int_equal(send_rssi(&b, 5000000, sender_us(&b, 4998000), &m), RFS_CAN_E_STALE);
}

/* Two simulated hours of 100 Hz RSSI (3 ms of latency), 20 Hz poses (1 ms) and 10 Hz
 * heartbeats (3 ms), the receiver's clock crossing 2^32 us. Ages are checked against
 * the latencies: the pose, the fastest, reads about 0, the others about 2 ms. */
static void drift_of_100_ppm_drops_nothing(int64_t ppm)
{
    bus_t b;
    rfs_can_msg_t m;
    bus_init(&b, true, HOURS_AHEAD, ppm);
    const int64_t t0 = 4294967296LL - 3600000000LL;
    int64_t pose_age_max = 0, rssi_age_min = INT64_MAX, rssi_age_max = 0;
    uint32_t n = 0;
    for (int64_t now = t0; now < t0 + 7200000000LL; now += 10000) {
        const int64_t k = (now - t0) / 10000;
        assert_int_equal(send_rssi(&b, now, sender_us(&b, now - 3000), &m), RFS_CAN_OK);
        if (k > 0) { /* the first frame sets the offset: age 0 */
            rssi_age_min = now - m.rssi_t_us < rssi_age_min ? now - m.rssi_t_us : rssi_age_min;
            rssi_age_max = now - m.rssi_t_us > rssi_age_max ? now - m.rssi_t_us : rssi_age_max;
        }
        n++;
        if (k % 5 == 0) {
            assert_int_equal(send_pose(&b, now, sender_us(&b, now - 1000), &m), RFS_CAN_OK);
            pose_age_max = now - m.pose.t_us > pose_age_max ? now - m.pose.t_us : pose_age_max;
            assert_true(m.pose.t_us <= now);
            n++;
        }
        if (k % 10 == 5) {
            assert_int_equal(send_receiver(&b, now, sender_us(&b, now - 3000), &m), RFS_CAN_OK);
            assert_true(now - m.receiver_t_us >= 1900 && now - m.receiver_t_us <= 2100);
            n++;
        }
    }
    /* 100 ppm is 5 us per 50 ms of poses; the pull-back allows 24. */
    assert_true(pose_age_max <= 30);
    assert_true(rssi_age_min >= 1900 && rssi_age_max <= 2100);
    assert_int_equal(rfs_can_rx_dropped_total(&b.rx), 0u);
    assert_int_equal(b.rx.resyncs, 0u);
    assert_int_equal(n, 720000u + 144000u + 72000u);
}

static void drift_slow_senders_drops_nothing(void **state)
{
    (void)state;
    drift_of_100_ppm_drops_nothing(-100);
}

static void drift_fast_senders_drops_nothing(void **state)
{
    (void)state;
    drift_of_100_ppm_drops_nothing(100);
}

/* One tick of 10 ms at now: RSSI (1 ms of latency), a pose every 50 ms (2 ms, lag_us
 * more), a heartbeat every 100 ms (1 ms); senders' clock shifted by jump_us. Counts the
 * results by stream. */
typedef struct tally {
    uint32_t rssi_ok, pose_ok, pose_dropped, hb_ok, dropped;
    int64_t pose_age; /* of the latest accepted pose */
} tally_t;

static void tick(bus_t *b, int64_t now, int64_t lag_us, int64_t jump_us, tally_t *n)
{
    rfs_can_msg_t m;
    const int64_t s = sender_us(b, now) + jump_us;
    rfs_can_err_t e = send_rssi(b, now, s - 1000, &m);
    n->rssi_ok += e == RFS_CAN_OK;
    n->dropped += e != RFS_CAN_OK;
    if (now % 50000 == 0) {
        e = send_pose(b, now, s - 2000 - lag_us, &m);
        n->pose_ok += e == RFS_CAN_OK;
        n->pose_dropped += e != RFS_CAN_OK;
        n->dropped += e != RFS_CAN_OK;
        if (e == RFS_CAN_OK) {
            n->pose_age = now - m.pose.t_us;
        }
    }
    if (now % 100000 == 30000) {
        e = send_receiver(b, now, s - 1000, &m);
        n->hb_ok += e == RFS_CAN_OK;
        n->dropped += e != RFS_CAN_OK;
    }
}

static void a_lagging_stream_is_dropped_and_not_absorbed(void **state)
{
    (void)state;
    bus_t b;
    tally_t n = {0};
    bus_init(&b, true, 5 * 3600000000LL, 0);
    for (int64_t now = 1000000; now < 20000000; now += 10000) {
        tick(&b, now, 0, 0, &n);
    }
    assert_int_equal(n.dropped, 0u);
    assert_true(n.pose_age >= 976 && n.pose_age <= 1000); /* 2 ms less the RSSI's 1 ms, less a pull of <= 24 */

    /* pose_past (docs/FAULTS.md): poses stamped 1 s late for 30 s, RSSI on time. */
    tally_t f = {0};
    for (int64_t now = 20000000; now < 50000000; now += 10000) {
        tick(&b, now, 1000000, 0, &f);
    }
    assert_int_equal(f.pose_dropped, 600u); /* every pose of the 30 s, 20 a second: */
    assert_int_equal(b.rx.dropped[RFS_CAN_E_STALE] + b.rx.dropped[RFS_CAN_E_REPEAT], 600u);
    assert_int_equal(b.rx.dropped[RFS_CAN_E_REPEAT], 37u); /* the last counter, every 16th */
    assert_int_equal(f.pose_ok, 0u);
    assert_int_equal(f.rssi_ok, 3000u);
    assert_int_equal(f.hb_ok, 300u);
    assert_int_equal(b.rx.resyncs, 0u);

    /* The fault over: poses on time again, read as before. */
    tally_t a = {0};
    for (int64_t now = 50000000; now < 52000000; now += 10000) {
        tick(&b, now, 0, 0, &a);
    }
    assert_int_equal(a.dropped, 0u);
    assert_int_equal(a.pose_ok, 40u);
    assert_true(a.pose_age >= 976 && a.pose_age <= 1000);
    assert_int_equal(b.rx.resyncs, 0u);
}

static void a_restart_of_the_senders_resyncs_after_resync_us(void **state)
{
    (void)state;
    bus_t b;
    tally_t n = {0};
    bus_init(&b, true, HOURS_AHEAD, 0);
    for (int64_t now = 1000000; now < 30000000; now += 10000) {
        tick(&b, now, 0, 0, &n);
    }
    assert_int_equal(n.dropped, 0u);

    /* Every stream's clock jumps an hour at 30 s (the senders restarted in a new epoch):
     * dropped for resync_us (2 s: 200 RSSI, 40 poses, 20 heartbeats), then re-set by the
     * first frame at 32 s. */
    tally_t j = {0};
    for (int64_t now = 30000000; now < 32000000; now += 10000) {
        tick(&b, now, 0, 3600000000LL, &j);
    }
    assert_int_equal(j.dropped, 260u);
    /* Stale, or a repeated counter: the last accepted one's comes round every 16 drops. */
    assert_int_equal(b.rx.dropped[RFS_CAN_E_STALE] + b.rx.dropped[RFS_CAN_E_REPEAT], 260u);
    assert_int_equal(b.rx.resyncs, 0u);
    rfs_can_msg_t m;
    assert_int_equal(send_rssi(&b, 32000000, sender_us(&b, 32000000) + 3600000000LL - 1000, &m), RFS_CAN_OK);
    assert_int_equal(m.rssi_t_us, 32000000);
    assert_int_equal(b.rx.resyncs, 1u);
    tally_t a = {0};
    for (int64_t now = 32010000; now < 40000000; now += 10000) {
        tick(&b, now, 0, 3600000000LL, &a);
    }
    assert_int_equal(a.dropped, 0u);
    assert_true(a.pose_age >= 976 && a.pose_age <= 1000);
    assert_int_equal(b.rx.resyncs, 1u);
}

static void a_fresh_receiver_syncs_on_its_first_frame(void **state)
{
    (void)state;
    bus_t b;
    tally_t n = {0};
    bus_init(&b, true, HOURS_AHEAD, 0);
    for (int64_t now = 1000000; now < 600000000; now += 10000) {
        tick(&b, now, 0, 0, &n);
    }
    assert_int_equal(n.dropped, 0u);

    /* A watchdog reset at 600 s: the receiver starts again, its clock from 0; the senders'
     * clock goes on (its epoch is now 600 s further from the receiver's). */
    rfs_can_rx_cfg_t c = rfs_can_rx_cfg_default();
    c.follow_epoch = true;
    assert_int_equal(rfs_can_rx_init(&b.rx, &c), 0);
    b.epoch_us += 600000000LL;
    rfs_can_msg_t m;
    assert_int_equal(send_rssi(&b, 3000, sender_us(&b, 3000) - 1000, &m), RFS_CAN_OK);
    assert_int_equal(m.rssi_t_us, 3000);
    tally_t a = {0};
    for (int64_t now = 10000; now < 5000000; now += 10000) {
        tick(&b, now, 0, 0, &a);
    }
    assert_int_equal(a.dropped, 0u);
    assert_int_equal(a.pose_ok, 99u); /* 50 ms .. 4.95 s */
    assert_true(a.pose_age >= 976 && a.pose_age <= 1000);
    assert_int_equal(b.rx.resyncs, 0u);

    /* Without the mode the reset receiver drops them: 3 h 27 min away. */
    bus_init(&b, false, HOURS_AHEAD + 600000000LL, 0);
    assert_int_equal(send_rssi(&b, 3000, sender_us(&b, 3000) - 1000, &m), RFS_CAN_E_STALE);
}

static void the_32_bit_wrap_is_read_through_the_offset(void **state)
{
    (void)state;
    bus_t b;
    rfs_can_msg_t m;
    /* Senders 2 x 2^32 + 2 s ahead: their raw stamps wrap at receiver time 2^32 - 2 s,
     * the receiver's clock crosses 2^32 2 s later. */
    bus_init(&b, true, 2 * 4294967296LL + 2000000, 0);
    for (int64_t now = 4294967296LL - 5000000; now < 4294967296LL + 5000000; now += 10000) {
        const int64_t s = sender_us(&b, now) - 3000;
        assert_int_equal(send_rssi(&b, now, s, &m), RFS_CAN_OK);
        assert_int_equal(m.rssi_t_us, now); /* a constant latency: age 0 throughout */
        assert_int_equal(send_pose(&b, now, s, &m), RFS_CAN_OK);
        assert_int_equal(m.pose.t_us, now);
    }
    assert_int_equal(rfs_can_rx_dropped_total(&b.rx), 0u);
}

/* The plain rule (docs/CAN.md): the stamp unwrapped to the time nearest now, dropped when
 * older than now - 1 s, later than now + 100 ms or older than the stream's newest. */
static int64_t unwrap_ref(int64_t now, uint32_t raw)
{
    const int64_t base = now - (int64_t)(uint32_t)now + (int64_t)raw; /* now >= 0 */
    for (int k = -1; k <= 1; k++) {
        const int64_t c = base + k * 4294967296LL;
        if (c - now >= -2147483648LL && c - now < 2147483648LL) {
            return c;
        }
    }
    return INT64_MIN;
}

static void the_mode_off_is_the_plain_window_rule(void **state)
{
    (void)state;
    const rfs_can_rx_cfg_t d = rfs_can_rx_cfg_default();
    assert_false(d.follow_epoch);
    assert_int_equal(d.resync_us, 2000000);
    bus_t b;
    bus_init(&b, false, 0, 0);
    rfs_can_msg_t m;
    uint32_t x = 12345u;
    int64_t last = INT64_MIN;
    int last_counter = -1;
    for (int64_t now = 4294967296LL - 60000000; now < 4294967296LL + 60000000; now += 7919) {
        x = x * 1103515245u + 12345u;
        const int64_t stamp = now + (int64_t)(x >> 8) % 2600000 - 1500000; /* -1.5 .. +1.1 s */
        const uint32_t raw = rfs_can_wrap_time(stamp);
        const int64_t t = unwrap_ref(now, raw);
        const int counter = b.tx.counter[RFS_CAN_IDX_RSSI];
        const rfs_can_err_t want = counter == last_counter ? RFS_CAN_E_REPEAT
                                   : t < now - 1000000 ? RFS_CAN_E_STALE
                                   : t > now + 100000 ? RFS_CAN_E_FUTURE
                                   : t < last         ? RFS_CAN_E_ORDER
                                                      : RFS_CAN_OK;
        assert_int_equal(send_rssi(&b, now, stamp, &m), want);
        if (want == RFS_CAN_OK) {
            assert_int_equal(m.rssi_t_us, stamp);
            last = t;
            last_counter = counter;
        }
    }
    assert_int_equal(b.rx.resyncs, 0u);
    assert_false(b.rx.have_epoch);
    assert_true(b.rx.dropped[RFS_CAN_E_STALE] > 0u && b.rx.dropped[RFS_CAN_E_FUTURE] > 0u &&
                b.rx.dropped[RFS_CAN_E_ORDER] > 0u);

    /* resync_us is checked like the windows: (0, 1 h]. */
    rfs_can_rx_cfg_t c = d;
    c.resync_us = 0;
    assert_int_equal(rfs_can_rx_init(&b.rx, &c), -1);
    c.resync_us = 3600000001LL;
    assert_int_equal(rfs_can_rx_init(&b.rx, &c), -1);
    c.resync_us = 3600000000LL;
    assert_int_equal(rfs_can_rx_init(&b.rx, &c), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(epoch_hours_away_is_followed_from_the_first_frame),
        cmocka_unit_test(drift_slow_senders_drops_nothing),
        cmocka_unit_test(drift_fast_senders_drops_nothing),
        cmocka_unit_test(a_lagging_stream_is_dropped_and_not_absorbed),
        cmocka_unit_test(a_restart_of_the_senders_resyncs_after_resync_us),
        cmocka_unit_test(a_fresh_receiver_syncs_on_its_first_frame),
        cmocka_unit_test(the_32_bit_wrap_is_read_through_the_offset),
        cmocka_unit_test(the_mode_off_is_the_plain_window_rule),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
