/* test_app.c - the application loop (firmware/rfs_app.h) on the host: configuration and
 * map checks, the safety stops (input lost, bus-off, reset) against the requirement of
 * safety (zero wheels within 200 ms), CAN in and out through common/rfs_can.h's own
 * decoders, and the receiver heartbeat: a radio dead zone is driven through
 * with it, stops within 200 ms without it, and a heartbeat from the future stops the
 * wheels as a packet from the future does. */
#include "rfs_test.h"

#include <string.h>

#include "rfs_app.h"
#include "rfs_can.h"

#include "app_fixture.h"

/* Feed 10 Hz poses at (5, 5) and 200/s packets up to t_end, stepping at 20 Hz; returns the
 * number of steps with non-zero wheels. The robot is held in place: it turns or drives
 * towards its goal without reaching it. */
static int run(int64_t t0, int64_t t_end, bool poses, bool rssi, rfs_app_out_t *last)
{
    int moving = 0;
    for (int64_t t = t0; t < t_end; t += 5000) {
        if (poses && t % 100000 == 0) {
            const rfs_pose_t p = {.t_us = t, .x = RFS_Q16_INT(5), .y = RFS_Q16_INT(5), .theta = 0};
            rfs_app_on_pose(&s_app, &p, t);
        }
        if (rssi) {
            rfs_app_on_rssi(&s_app, 0, t, (int8_t)(-60 - (t / 5000) % 3), t);
        }
        if (t % RFS_APP_PERIOD_US == 0) {
            rfs_app_step(&s_app, t, last);
            moving += (last->left_mm_s != 0 || last->right_mm_s != 0);
        }
    }
    return moving;
}

/* A dead zone: 10 Hz poses at (5, 5), no packets, and, when `heartbeat`, a
 * receiver heartbeat stamped `hb_lead` after its arrival once per control period just
 * before the step (as the sniffer's capture loop sends it). Returns the moving steps. */
static int run_dead_zone(int64_t t0, int64_t t_end, bool heartbeat, int64_t hb_lead,
                         rfs_app_out_t *last)
{
    int moving = 0;
    for (int64_t t = t0; t < t_end; t += 5000) {
        if (t % 100000 == 0) {
            const rfs_pose_t p = {.t_us = t, .x = RFS_Q16_INT(5), .y = RFS_Q16_INT(5), .theta = 0};
            rfs_app_on_pose(&s_app, &p, t);
        }
        if (t % RFS_APP_PERIOD_US == 0) {
            if (heartbeat) {
                rfs_app_on_receiver(&s_app, t + hb_lead, t);
            }
            rfs_app_step(&s_app, t, last);
            moving += (last->left_mm_s != 0 || last->right_mm_s != 0);
        }
    }
    return moving;
}

/* Drive for 2 s with packets, then enter a dead zone (no packets) with or without
 * heartbeats; *moving_late counts the moving steps from 200 ms after the last packet. */
static void drive_then_dead_zone(bool heartbeat, int *moving_late, rfs_app_out_t *o)
{
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    run(0, 2000000, true, true, o);
    assert_true(o->left_mm_s != 0 || o->right_mm_s != 0); /* driving when the packets stop */
    /* The last packet is stamped 1.995 s; 200 ms later is 2.195 s. */
    run_dead_zone(2000000, 2200000, heartbeat, 0, o);
    *moving_late = run_dead_zone(2200000, 4000000, heartbeat, 0, o);
}

static void test_dead_zone_heartbeat_keeps_driving(void **state)
{
    (void)state;
    rfs_app_out_t o;
    int moving = 0;

    drive_then_dead_zone(true, &moving, &o);

    /* 36 steps in [2.2, 4.0) s: the robot is held in place, so it never reaches its goal
     * and drives on every step once the inputs are fresh. */
    assert_int_equal(moving, 36);
    assert_false(o.faults & (RFS_APP_FAULT_RSSI_LOST | RFS_SEEK_FAULT_RSSI_STALE));
    assert_int_equal(s_app.stats.receiver, 40u); /* one per period from 2.0 s to 3.95 s */
    assert_int_equal(s_app.stats.rejected, 0u);
}

static void test_dead_zone_without_heartbeat_stops_within_200_ms(void **state)
{
    (void)state;
    rfs_app_out_t o;
    int moving = -1;

    drive_then_dead_zone(false, &moving, &o);

    assert_int_equal(moving, 0);
    assert_true(o.faults & RFS_APP_FAULT_RSSI_LOST);
    assert_true(o.faults & RFS_SEEK_FAULT_RSSI_STALE);
    assert_int_equal(s_app.stats.receiver, 0u);
}

static void test_heartbeat_from_the_future_stops_like_a_packet(void **state)
{
    (void)state;
    /* A packet stamped 5 s ahead (a clock jump) makes the stream stale: the
     * wheels stop. A heartbeat stamped 5 s ahead must do the same. */
    rfs_app_out_t o_hb, o_pkt;
    int moving = 0;
    drive_then_dead_zone(true, &moving, &o_hb);
    assert_true(moving > 0);

    assert_int_equal(run_dead_zone(4000000, 4500000, true, 5000000, &o_hb), 0);
    assert_true(o_hb.faults & RFS_SEEK_FAULT_RSSI_STALE);
    /* Back on the right clock the heartbeats are older than the future one: rejected
     * (out of order) and the stream stays stale, as for packets. */
    const uint32_t rej = s_app.stats.rejected;
    assert_int_equal(run_dead_zone(4500000, 5000000, true, 0, &o_hb), 0);
    assert_int_equal(s_app.stats.rejected - rej, 10u);

    drive_then_dead_zone(true, &moving, &o_pkt);
    rfs_app_on_rssi(&s_app, 0, 4000000 + 5000000, -60, 4000000);
    assert_int_equal(run_dead_zone(4000000, 4500000, false, 0, &o_pkt), 0);
    assert_true(o_pkt.faults & RFS_SEEK_FAULT_RSSI_STALE);
}

static void test_init_checks_configuration_and_map(void **state)
{
    (void)state;
    rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    rfs_app_map_t m = room();
    rfs_app_map_t big = m;
    big.w = 1000; /* 125 bytes x 100 rows = 12,500 > 6,400 */

    assert_int_equal(rfs_app_init(&s_app, &c, &big), -1);
    c.target = (rfs_app_target_t)2;
    assert_int_equal(rfs_app_init(&s_app, &c, &m), -1);
    c = fx_cfg(rfs_app_cfg_default());
    c.input_timeout_us = 0;
    assert_int_equal(rfs_app_init(&s_app, &c, &m), -1);
    c = fx_cfg(rfs_app_cfg_default());
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_int_equal(rfs_app_cfg_mcu().seek.fit_budget, 0u); /* the ridge's: a whole fit */
    assert_int_equal(rfs_app_cfg_default().seek.fit_budget, 0u);
    /* sliced relearns begin as the base brakes on the MCU; replays follow their CFG */
    assert_true(rfs_app_cfg_mcu().seek.fit_early);
    assert_false(rfs_app_cfg_default().seek.fit_early);
}

/* A CONFIG frame's FitEarly (docs/CAN.md, "0x130 CONFIG"): 1 turns seek.fit_early off, 2
 * on, 0 keeps the one in force (the frames sent before the field existed); 3 is refused by
 * the decoder and counted, the configuration unchanged. */
static void test_config_frame_sets_fit_early(void **state)
{
    (void)state;
    const rfs_app_map_t m = room();
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_mcu()); /* fit_early on */
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    rfs_can_tx_t op;
    rfs_can_tx_init(&op);
    rfs_can_frame_t f;
    rfs_can_config_t k = {.target = 0, .strategy = RFS_SEEK_META, .model = RFS_CAN_MODEL_RIDGE,
                          .p0_min = RFS_CAN_P0_NONE, .seed = 7u, .fit_early = RFS_CAN_FIT_EARLY_KEEP};
    const struct {
        uint8_t fit_early;
        bool want;
    } steps[] = {
        {RFS_CAN_FIT_EARLY_KEEP, true}, /* the MCU's own */
        {RFS_CAN_FIT_EARLY_OFF, false}, {RFS_CAN_FIT_EARLY_KEEP, false},
        {RFS_CAN_FIT_EARLY_ON, true},   {RFS_CAN_FIT_EARLY_KEEP, true},
        {RFS_CAN_FIT_EARLY_OFF, false},
    };
    for (unsigned i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        k.fit_early = steps[i].fit_early;
        k.seed = 7u + i;
        rfs_can_tx_config(&op, &k, &f);
        assert_int_equal(rfs_app_on_can(&s_app, &f, 1000 * (int64_t)(i + 1u)), RFS_CAN_OK);
        assert_int_equal(s_app.stats.configs, i + 1u);
        assert_int_equal(s_app.cfg.seed, 7u + i);
        assert_int_equal(s_app.seek.cfg.fit_early, steps[i].want);
        assert_int_equal(s_app.cfg.seek.fit_early, steps[i].want);
    }
    /* Reserved: the decoder drops it (counted), nothing applied. */
    k.fit_early = 3u;
    k.seed = 99u;
    rfs_can_tx_config(&op, &k, &f);
    assert_int_equal(f.data[0] >> 6, 3);
    const uint32_t dropped = s_app.can_rx.dropped[RFS_CAN_E_RANGE];
    assert_int_equal(rfs_app_on_can(&s_app, &f, 10000), RFS_CAN_E_RANGE);
    assert_int_equal(s_app.can_rx.dropped[RFS_CAN_E_RANGE], dropped + 1u);
    assert_int_equal(s_app.stats.configs, 6u);
    assert_int_equal(s_app.cfg.seed, 12u);
    assert_false(s_app.seek.cfg.fit_early);

    /* The host's default (off) switched on. */
    const rfs_app_cfg_t d = fx_cfg(rfs_app_cfg_default());
    assert_int_equal(rfs_app_init(&s_app, &d, &m), 0);
    assert_false(s_app.seek.cfg.fit_early);
    k.fit_early = RFS_CAN_FIT_EARLY_ON;
    rfs_can_tx_config(&op, &k, &f);
    assert_int_equal(rfs_app_on_can(&s_app, &f, 20000), RFS_CAN_OK);
    assert_true(s_app.seek.cfg.fit_early);
}

static void test_first_step_after_reset_is_zero_and_flagged(void **state)
{
    (void)state;
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    rfs_app_out_t o;

    rfs_app_step(&s_app, 0, &o);

    assert_int_equal(o.left_mm_s, 0);
    assert_int_equal(o.right_mm_s, 0);
    assert_true(o.faults & RFS_APP_FAULT_RESET);
    assert_true(o.faults & RFS_APP_FAULT_POSE_LOST);
    rfs_app_step(&s_app, 50000, &o);
    assert_false(o.faults & RFS_APP_FAULT_RESET);

    /* Inputs fresh before the first step (they came in as the image restarted): zero all
     * the same, then driving. */
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    for (int64_t t = 0; t <= 1000000; t += 5000) {
        if (t % 100000 == 0) {
            const rfs_pose_t p = {.t_us = t, .x = RFS_Q16_INT(5), .y = RFS_Q16_INT(5), .theta = 0};
            rfs_app_on_pose(&s_app, &p, t);
        }
        rfs_app_on_rssi(&s_app, 0, t, (int8_t)(-60 - (t / 5000) % 3), t);
    }
    rfs_app_step(&s_app, 1000000, &o);
    assert_true(o.faults & RFS_APP_FAULT_RESET);
    assert_false(o.faults & (RFS_APP_FAULT_POSE_LOST | RFS_APP_FAULT_RSSI_LOST));
    assert_int_equal(o.left_mm_s, 0);
    assert_int_equal(o.right_mm_s, 0);
    assert_true(run(1000000, 3000000, true, true, &o) > 0);
}

static void test_wheels_stop_within_200_ms_of_lost_inputs_and_resume(void **state)
{
    (void)state;
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    rfs_app_out_t o;
    assert_true(run(0, 2000000, true, true, &o) > 0);
    assert_true(o.left_mm_s != 0 || o.right_mm_s != 0); /* driving when the poses stop */

    /* Poses stop after the one at 1.9 s; RSSI continues. From 2.1 s on: zero. */
    run(2000000, 2100000, false, true, &o);
    assert_int_equal(run(2100000, 3000000, false, true, &o), 0);
    assert_true(o.faults & RFS_APP_FAULT_POSE_LOST);
    assert_int_equal(o.left_mm_s, 0);

    /* Poses return: driving resumes. */
    assert_true(run(3000000, 6000000, true, true, &o) > 0);

    /* RSSI stops after 5.995 s, poses continue: zero from 6.195 s. */
    run(6000000, 6200000, true, false, &o);
    assert_int_equal(run(6200000, 7000000, true, false, &o), 0);
    assert_true(o.faults & RFS_APP_FAULT_RSSI_LOST);
}

/* The received-time watchdog alone (rfs_app.h: input_timeout_us, 150 ms of local time):
 * every input is stamped 100 ms ahead of its arrival, so when one stream stops arriving the
 * seeker's own staleness rule (its stamps 150 ms old) waits until 250 ms after the last
 * arrival; the wheels must be zero from 150 ms on, flagged by the watchdog only. */
static void watchdog_case(bool poses_stop)
{
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    const int64_t lead = 100000, stop = 2000000;
    const uint16_t lost = poses_stop ? RFS_APP_FAULT_POSE_LOST : RFS_APP_FAULT_RSSI_LOST;
    rfs_app_out_t o;
    int64_t last_rx = -1;
    int checked = 0, watchdog_only = 0;
    for (int64_t t = 0; t < stop + 400000; t += 5000) {
        const bool pose_on = !poses_stop || t < stop, rssi_on = poses_stop || t < stop;
        if (pose_on && t % 100000 == 0) {
            const rfs_pose_t p = {.t_us = t + lead, .x = RFS_Q16_INT(5), .y = RFS_Q16_INT(5), .theta = 0};
            rfs_app_on_pose(&s_app, &p, t);
            last_rx = poses_stop ? t : last_rx;
        }
        if (rssi_on) {
            rfs_app_on_rssi(&s_app, 0, t + lead, (int8_t)(-60 - (t / 5000) % 3), t);
            last_rx = poses_stop ? last_rx : t;
        }
        if (t % RFS_APP_PERIOD_US != 0) {
            continue;
        }
        rfs_app_step(&s_app, t, &o);
        if (t == stop - RFS_APP_PERIOD_US) {
            assert_true(o.left_mm_s != 0 || o.right_mm_s != 0); /* driving when it stops */
        }
        if (t >= stop && t - last_rx > c.input_timeout_us) {
            assert_true(o.faults & lost);
            assert_int_equal(o.left_mm_s, 0);
            assert_int_equal(o.right_mm_s, 0);
            checked++;
            watchdog_only += (o.faults & (RFS_SEEK_FAULT_POSE_STALE | RFS_SEEK_FAULT_RSSI_STALE)) == 0u;
            assert_int_equal(o.state, RFS_SEEK_STALE); /* held: not DRIVING, whoever stopped */
        } else if (t >= stop) {
            assert_false(o.faults & lost);
        }
    }
    assert_true(checked >= 5);
    assert_true(watchdog_only >= 1); /* the seeker alone would still have driven then */
}

static void test_receive_watchdog_stops_inputs_stamped_ahead(void **state)
{
    (void)state;
    watchdog_case(true);
    watchdog_case(false);
}

/* The room's default configuration, inputs on for its first 2 s; *o the last step's. */
static void drive_two_seconds(rfs_app_out_t *o)
{
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    run(0, 2000000, true, true, o);
}

static void test_bus_off_stops_at_once_and_recovers(void **state)
{
    (void)state;
    rfs_app_out_t o;
    drive_two_seconds(&o);
    assert_true(o.left_mm_s != 0 || o.right_mm_s != 0);

    rfs_app_set_bus_off(&s_app, true);
    assert_int_equal(run(2000000, 2500000, true, true, &o), 0);
    assert_true(o.faults & RFS_APP_FAULT_BUS_OFF);
    assert_int_equal(o.state, RFS_SEEK_STALE);
    rfs_app_set_bus_off(&s_app, false);
    assert_true(run(2500000, 5000000, true, true, &o) > 0);
    assert_false(o.faults & RFS_APP_FAULT_BUS_OFF);
}

static int32_t fastest(const rfs_app_out_t *o)
{
    const int32_t l = o->left_mm_s < 0 ? -o->left_mm_s : o->left_mm_s;
    const int32_t r = o->right_mm_s < 0 ? -o->right_mm_s : o->right_mm_s;
    return l > r ? l : r;
}

/* A stop the seeker did not make (one period of bus-off; its inputs stay fresh) is a stop
 * for the drive too: the wheels start again from rest at the acceleration limit (1 m/s^2:
 * at most 50 mm/s a period), not at the speed the drive had before. */
static void test_an_application_stop_restarts_the_drive_from_rest(void **state)
{
    (void)state;
    rfs_app_out_t o;
    drive_two_seconds(&o);
    assert_true(fastest(&o) > 100);

    rfs_app_set_bus_off(&s_app, true);
    run(2000000, 2050000, true, true, &o);
    assert_int_equal(fastest(&o), 0);
    rfs_app_set_bus_off(&s_app, false);
    int32_t prev = 0;
    for (int64_t t = 2050000; t < 2300000; t += RFS_APP_PERIOD_US) {
        run(t, t + RFS_APP_PERIOD_US, true, true, &o);
        assert_true(fastest(&o) <= prev + 50);
        prev = fastest(&o);
    }
    assert_true(run(2300000, 5000000, true, true, &o) > 0); /* and it drives again */
}

static void test_frames_decode_with_the_protocol_decoders(void **state)
{
    (void)state;
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    rfs_app_out_t o;
    memset(&o, 0, sizeof o);
    o.left_mm_s = -123;
    o.right_mm_s = 456;
    o.state = RFS_SEEK_DRIVING;
    o.faults = RFS_APP_FAULT_RSSI_LOST;
    o.decision.iteration = 77;
    o.decision.kind = RFS_SEEK_EPSILON;
    rfs_can_frame_t f[2];

    assert_int_equal(rfs_app_frames(&s_app, &o, f), 2);

    rfs_can_wheel_t w;
    rfs_can_status_t st;
    uint8_t ctr = 99;
    assert_int_equal(rfs_can_unpack_wheel(&f[0], &w, &ctr), RFS_CAN_OK);
    assert_int_equal(f[0].id, 0x100);
    assert_int_equal(w.left_mm_s, -123);
    assert_int_equal(w.right_mm_s, 456);
    assert_int_equal(w.flags, RFS_CAN_WHEEL_STOP); /* a safety stop holds */
    assert_int_equal(ctr, 0);
    assert_int_equal(rfs_can_unpack_status(&f[1], &st, &ctr), RFS_CAN_OK);
    assert_int_equal(st.state, 3);
    assert_int_equal(st.kind, 3);
    assert_int_equal(st.iteration, 77);
    assert_int_equal(st.faults, RFS_SEEK_FAULT_RSSI_STALE);
    rfs_app_frames(&s_app, &o, f);
    assert_int_equal(rfs_can_unpack_wheel(&f[0], &w, &ctr), RFS_CAN_OK);
    assert_int_equal(ctr, 1); /* rolling counter */
    /* A baseline's kinds in the 2-bit Kind field (docs/CAN.md, "0x180 STATUS"): gradient
     * and run as 2 (greedy), probe and tumble as 3 (epsilon), not their low two bits. */
    const struct { rfs_seek_kind_t k; uint8_t want; } kinds[] = {
        {RFS_SEEK_NONE, 0}, {RFS_SEEK_INITIAL, 1}, {RFS_SEEK_GREEDY, 2}, {RFS_SEEK_EPSILON, 3},
        {RFS_SEEK_PROBE, 3}, {RFS_SEEK_GRADIENT, 2}, {RFS_SEEK_RUN, 2}, {RFS_SEEK_TUMBLE, 3},
    };
    for (unsigned i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
        o.decision.kind = kinds[i].k;
        rfs_app_frames(&s_app, &o, f);
        assert_int_equal(rfs_can_unpack_status(&f[1], &st, &ctr), RFS_CAN_OK);
        assert_int_equal(st.kind, kinds[i].want);
    }
}

/* rfseekd's RFS_WHEEL_CMD copy and the WHEEL_CMD frame say Stop alike (docs/CAN.md: the
 * controller is not driving, or lost inputs, bus-off, a reset stop it; a bad frame alone
 * does not): the copy used to look at the state only. Byte 0 by hand: counter | Stop << 4. */
static void test_wheel_stop_is_the_frames(void **state)
{
    (void)state;
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    const struct { rfs_seek_state_t st; uint16_t faults; uint8_t stop; } cases[] = {
        {RFS_SEEK_DRIVING, 0, 0},
        {RFS_SEEK_DRIVING, RFS_APP_FAULT_POSE_LOST, 1},
        {RFS_SEEK_DRIVING, RFS_APP_FAULT_RSSI_LOST, 1},
        {RFS_SEEK_DRIVING, RFS_APP_FAULT_BUS_OFF, 1},
        {RFS_SEEK_DRIVING, RFS_APP_FAULT_RESET, 1},
        {RFS_SEEK_DRIVING, RFS_APP_FAULT_BAD_FRAME | RFS_SEEK_FAULT_NO_GOAL, 0},
        {RFS_SEEK_LEARNING, 0, 1},
    };
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        rfs_app_out_t o;
        memset(&o, 0, sizeof o);
        o.state = cases[i].st;
        o.faults = cases[i].faults;
        o.left_mm_s = 10;
        o.right_mm_s = -10;
        rfs_can_frame_t f[2];

        const rfs_can_wheel_t w = rfs_app_wheel(&o);
        (void)rfs_app_frames(&s_app, &o, f);

        assert_int_equal(w.flags, cases[i].stop);
        assert_int_equal(w.left_mm_s, 10);
        assert_int_equal(w.right_mm_s, -10);
        assert_int_equal(f[0].data[0], (uint8_t)(i | (unsigned)cases[i].stop << 4));
    }
}

/* rfseekd and the STM32 image send STATUS through rfs_app_frames: a baseline's kinds go
 * out as docs/CAN.md's table says (tumble as epsilon 3, gradient as greedy 2), a value
 * beyond the kinds as none, not masked to 2 bits (gradient 5 read as initial). Bytes by
 * hand, CRC-8 from scripts/check_dbc.py's crc8_j1850: state 3, relearned, prev 2 (reached),
 * iteration 77, counters 0, 1, 2. */
static void test_status_frame_maps_baseline_kinds(void **state)
{
    (void)state;
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    static const uint8_t want[3][8] = {
        {0x30, 0x27, 0x00, 0x4D, 0x00, 0x00, 0x00, 0x39},
        {0x31, 0x26, 0x00, 0x4D, 0x00, 0x00, 0x00, 0x22},
        {0x32, 0x24, 0x00, 0x4D, 0x00, 0x00, 0x00, 0x49},
    };
    const rfs_seek_kind_t kinds[3] = {RFS_SEEK_TUMBLE, RFS_SEEK_GRADIENT, (rfs_seek_kind_t)8};
    for (int i = 0; i < 3; i++) {
        rfs_app_out_t o;
        memset(&o, 0, sizeof o);
        o.state = RFS_SEEK_DRIVING;
        o.decision.iteration = 77;
        o.decision.relearned = true;
        o.decision.prev = RFS_DRIVE_REACHED;
        o.decision.kind = kinds[i];
        rfs_can_frame_t f[2];

        assert_int_equal(rfs_app_frames(&s_app, &o, f), 2);

        assert_int_equal(f[1].id, 0x180);
        assert_int_equal(f[1].dlc, 8);
        assert_memory_equal(f[1].data, want[i], 8);
    }
}

static void test_can_inputs_are_decoded_or_counted(void **state)
{
    (void)state;
    const rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_default());
    const rfs_app_map_t m = room();
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    rfs_can_tx_t tx;
    rfs_can_tx_init(&tx);
    const rfs_pose_t pose = {.t_us = 100000, .x = RFS_Q16_INT(5), .y = RFS_Q16_INT(5), .theta = 0};
    const rfs_can_pose_t cp = rfs_can_pose_from_core(&pose);
    rfs_can_frame_t xy, th, r, unknown = {0x7AB, 2, {1, 2}};
    rfs_can_tx_pose(&tx, &cp, &xy, &th);
    const rfs_can_rssi_t cr = {.src = 0, .dbm = -61, .seq = 0, .t_us32 = 100000};
    rfs_can_tx_rssi(&tx, &cr, &r);

    assert_int_equal(rfs_app_on_can(&s_app, &xy, 100000), RFS_CAN_OK);
    assert_int_equal(rfs_app_on_can(&s_app, &th, 100000), RFS_CAN_OK);
    assert_int_equal(rfs_app_on_can(&s_app, &r, 100000), RFS_CAN_OK);
    assert_int_equal(s_app.stats.poses, 1);
    assert_int_equal(s_app.stats.rssi, 1);
    assert_int_equal(rfs_app_on_can(&s_app, &unknown, 100000), RFS_CAN_E_ID);
    assert_int_equal(s_app.stats.unknown_frames, 1);
    r.data[2] ^= 0x01; /* checksum no longer matches */
    assert_int_equal(rfs_app_on_can(&s_app, &r, 100000), RFS_CAN_E_CHECKSUM);
    assert_int_equal(s_app.stats.bad_frames, 1);
    rfs_app_out_t o;
    rfs_app_step(&s_app, 100000, &o);
    assert_true(o.faults & RFS_APP_FAULT_BAD_FRAME);
    rfs_app_step(&s_app, 150000, &o);
    assert_false(o.faults & RFS_APP_FAULT_BAD_FRAME);
}

static void test_can_receiver_frames_keep_a_dead_zone_driving(void **state)
{
    (void)state;
    rfs_app_out_t o;
    int moving = 0;
    drive_then_dead_zone(false, &moving, &o); /* packets until 2 s, then nothing to 4 s */
    assert_int_equal(moving, 0);
    rfs_can_tx_t tx;
    rfs_can_tx_init(&tx);
    rfs_can_frame_t f;
    int moving_can = 0;

    /* The radio module's heartbeat frames (0x121) once per period, 4.0 .. 6.0 s. */
    for (int64_t t = 4000000; t < 6000000; t += RFS_APP_PERIOD_US) {
        if (t % 100000 == 0) {
            const rfs_pose_t p = {.t_us = t, .x = RFS_Q16_INT(5), .y = RFS_Q16_INT(5), .theta = 0};
            rfs_app_on_pose(&s_app, &p, t);
        }
        const rfs_can_receiver_t r = {rfs_can_wrap_time(t)};
        rfs_can_tx_receiver(&tx, &r, &f);
        assert_int_equal(rfs_app_on_can(&s_app, &f, t), RFS_CAN_OK);
        rfs_app_step(&s_app, t, &o);
        moving_can += (o.left_mm_s != 0 || o.right_mm_s != 0);
    }

    /* Every step but the first one out of the stale state drives: 39 of 40. */
    assert_int_equal(moving_can, 39);
    assert_int_equal(s_app.stats.receiver, 40u);
    /* Stamped beyond the CAN receiver's 100 ms future window: rejected as a packet is. */
    const rfs_can_receiver_t late = {rfs_can_wrap_time(6000000 + 100001)};
    rfs_can_tx_receiver(&tx, &late, &f);
    assert_int_equal(rfs_app_on_can(&s_app, &f, 6000000), RFS_CAN_E_FUTURE);
    assert_int_equal(s_app.stats.receiver, 40u);
    assert_int_equal(s_app.stats.bad_frames, 1u);
}

/* The image's CAN inputs from t0 to t_end of the board's clock, stamped ahead_us ahead of
 * it (the senders' own epoch): 10 Hz poses at (5, 5) (1 ms of latency) and 200/s packets
 * (2 ms), a step and its fit slices at 20 Hz. Returns the steps with non-zero wheels. */
static int run_can(rfs_can_tx_t *tx, int64_t t0, int64_t t_end, int64_t ahead_us, rfs_app_out_t *last)
{
    int moving = 0;
    for (int64_t t = t0; t < t_end; t += 5000) {
        rfs_can_frame_t f, th;
        if (t % 100000 == 0) {
            const rfs_pose_t p = {.t_us = 0, .x = RFS_Q16_INT(5), .y = RFS_Q16_INT(5), .theta = 0};
            rfs_can_pose_t cp = rfs_can_pose_from_core(&p);
            cp.t_us32 = rfs_can_wrap_time(t + ahead_us - 1000);
            rfs_can_tx_pose(tx, &cp, &f, &th);
            (void)rfs_app_on_can(&s_app, &f, t);
            (void)rfs_app_on_can(&s_app, &th, t);
        }
        const rfs_can_rssi_t r = {.src = 0, .dbm = (int8_t)(-60 - (t / 5000) % 3), .seq = (uint8_t)(t / 5000),
                                  .t_us32 = rfs_can_wrap_time(t + ahead_us - 2000)};
        rfs_can_tx_rssi(tx, &r, &f);
        (void)rfs_app_on_can(&s_app, &f, t);
        if (t % RFS_APP_PERIOD_US == 0) {
            rfs_app_step(&s_app, t, last);
            rfs_app_background_all(&s_app);
            moving += (last->left_mm_s != 0 || last->right_mm_s != 0);
        }
    }
    return moving;
}

/* On a robot the senders stamp in their own clock and the image's counts from boot
 * (docs/CAN.md, "Time on the bus"): with the image's configuration it drives on senders
 * 3 h ahead, and again after a watchdog reset restarts its clock at 0; with one clock
 * assumed (follow_epoch off) every input is dropped and the wheels stay at zero. */
static void test_image_follows_the_senders_epoch_through_a_reset(void **state)
{
    (void)state;
    const rfs_app_map_t m = room();
    rfs_app_cfg_t c = fx_cfg(rfs_app_cfg_mcu());
    assert_true(c.follow_epoch);
    assert_false(rfs_app_cfg_default().follow_epoch);
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    rfs_can_tx_t tx;
    rfs_can_tx_init(&tx);
    rfs_app_out_t o;
    const int64_t ahead = 3LL * 3600000000LL;

    assert_true(run_can(&tx, 0, 3000000, ahead, &o) > 0);
    assert_int_equal(rfs_can_rx_dropped_total(&s_app.can_rx), 0u);
    assert_int_equal(s_app.stats.poses, 30u);

    /* A watchdog reset at 3 s: the board's clock starts again at 0, the senders' goes on. */
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_true(run_can(&tx, 0, 3000000, ahead + 3000000, &o) > 0);
    assert_int_equal(rfs_can_rx_dropped_total(&s_app.can_rx), 0u);
    assert_int_equal(s_app.can_rx.resyncs, 0u);

    c.follow_epoch = false;
    assert_int_equal(rfs_app_init(&s_app, &c, &m), 0);
    assert_int_equal(run_can(&tx, 0, 3000000, ahead + 6000000, &o), 0);
    assert_int_equal(s_app.stats.poses + s_app.stats.rssi, 0u);
    assert_int_equal(s_app.stats.bad_frames, 600u + 30u); /* every packet and pose */
    assert_true(o.faults & RFS_APP_FAULT_POSE_LOST);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_checks_configuration_and_map),
        cmocka_unit_test(test_config_frame_sets_fit_early),
        cmocka_unit_test(test_first_step_after_reset_is_zero_and_flagged),
        cmocka_unit_test(test_wheels_stop_within_200_ms_of_lost_inputs_and_resume),
        cmocka_unit_test(test_receive_watchdog_stops_inputs_stamped_ahead),
        cmocka_unit_test(test_bus_off_stops_at_once_and_recovers),
        cmocka_unit_test(test_an_application_stop_restarts_the_drive_from_rest),
        cmocka_unit_test(test_frames_decode_with_the_protocol_decoders),
        cmocka_unit_test(test_status_frame_maps_baseline_kinds),
        cmocka_unit_test(test_wheel_stop_is_the_frames),
        cmocka_unit_test(test_can_inputs_are_decoded_or_counted),
        cmocka_unit_test(test_dead_zone_heartbeat_keeps_driving),
        cmocka_unit_test(test_dead_zone_without_heartbeat_stops_within_200_ms),
        cmocka_unit_test(test_heartbeat_from_the_future_stops_like_a_packet),
        cmocka_unit_test(test_can_receiver_frames_keep_a_dead_zone_driving),
        cmocka_unit_test(test_image_follows_the_senders_epoch_through_a_reset),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
