/* test_seek.c - the decision loop (common/rfs_seek.c): configuration and names,
 * staleness and the receiver heartbeat, backing off after no goal or a null move, the
 * in-leg recheck, and a closed-loop run against a double-precision world (unicycle + path
 * loss).
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "seek_run.h"

static void test_defaults_are_the_papers(void **state)
{
    (void)state;
    rfs_seek_cfg_t c = rfs_seek_cfg_default();
    assert_int_equal(c.step, 65536);
    assert_int_equal(c.initial_step_max, 2 * 65536);
    assert_int_equal(c.error_threshold, 3 * 65536);
    assert_int_equal(c.novelty_radius, 32768);
    assert_int_equal(c.store.capacity, 10000);
    rfs_ridge_cfg_t r = rfs_ridge_cfg_default();
    assert_int_equal(r.radius, 5 * 65536);
    assert_int_equal(r.alpha, 65536);
}

/* One period in a radio dead zone (docs/FAULTS.md): a pose at (x, y) and a receiver report, both
 * stamped t and accepted (the stamps only grow), then a step; no packet. */
static void feed_report(world_t *t, int64_t t_us, double x, double y, rfs_seek_out_t *out)
{
    rfs_pose_t p = pose_at(t_us, x, y, 0);
    assert_true(rfs_seek_on_pose(&t->seek, &p, &t->rng));
    assert_true(rfs_seek_on_receiver(&t->seek, t_us));
    rfs_seek_step(&t->seek, t_us, &t->rng, out);
}

/* The heartbeat tests' start: a 10 x 10 m room, the default seeker (seed 11), and 1 s at
 * 20 Hz of packets and receiver reports at (5, 5). Returns the time reached. */
static int64_t heartbeat_start(world_t *t, rfs_seek_out_t *out)
{
    world_make(t, 10, 10, 0, 0);
    seek_make(t, rfs_seek_cfg_default(), 11);
    int64_t now = 0;
    for (int k = 0; k < 20; ++k) {
        now += 50000;
        assert_true(rfs_seek_on_receiver(&t->seek, now));
        feed(t, now, 5.0, 5.0, 0, -40, out);
    }
    return now;
}

/* Inputs stop: the wheels are commanded to zero within 200 ms, and driving resumes when
 * they return. */
static void test_stale_inputs_stop_wheels(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 10, 10, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    seek_make(&t, cfg, 11);
    rfs_seek_out_t out;
    int64_t now = 0;
    int moving = 0;
    for (int k = 0; k < 20; ++k) { /* 1 s at 20 Hz with fresh inputs */
        now += 50000;
        feed(&t, now, 5.0, 5.0, 0, -40, &out);
        moving += (out.left_mm_s != 0 || out.right_mm_s != 0);
    }
    assert_true(moving > 0);
    int64_t last_input = now;
    bool stopped = false;
    while (now < last_input + 200000) { /* no more inputs */
        now += 50000;
        rfs_seek_step(&t.seek, now, &t.rng, &out);
        if (out.left_mm_s == 0 && out.right_mm_s == 0 &&
            (out.faults & RFS_SEEK_FAULT_POSE_STALE)) {
            stopped = true;
        }
    }
    assert_true(stopped);
    assert_int_equal(out.left_mm_s, 0);
    assert_int_equal(out.right_mm_s, 0);
    assert_int_equal(out.state, RFS_SEEK_STALE);
    world_free(&t);
}

/* Dead zones (docs/STRATEGIES.md, "Dead zones"): the receiver reports itself up every
 * period, with no packet. Twin seekers, same seed and the same poses: A keeps getting
 * packets, B only receiver reports after the first second. Until A decides anew, B must
 * drive exactly as A (the goal and the drive law do not depend on the packets), with no
 * stale flag. */
static void test_heartbeat_keeps_goal_without_packets(void **state)
{
    (void)state;
    world_t a, b;
    rfs_seek_out_t oa, ob;
    (void)heartbeat_start(&a, &oa); /* the twins share nothing: one after the other */
    int64_t now = heartbeat_start(&b, &ob);
    /* The robot stands still, so the initial goal (>= 0.5 m away) is still being driven. */
    assert_int_equal(ob.state, RFS_SEEK_DRIVING);
    assert_int_equal(ob.decision.kind, RFS_SEEK_INITIAL);
    double gx = D(ob.decision.goal_x), gy = D(ob.decision.goal_y);
    assert_true(hypot(gx - 5.0, gy - 5.0) > 0.2);
    int moving = 0;
    for (int k = 0; k < 60; ++k) { /* 3 s: B hears nothing, its receiver is up */
        now += 50000;
        feed_report(&b, now, 5.0, 5.0, &ob);
        feed(&a, now, 5.0, 5.0, 0, -40, &oa);
        assert_int_equal(ob.faults & RFS_SEEK_FAULT_RSSI_STALE, 0);
        assert_int_equal(ob.state, RFS_SEEK_DRIVING);
        assert_false(ob.decided);
        assert_false(oa.decided);
        assert_int_equal(ob.left_mm_s, oa.left_mm_s);
        assert_int_equal(ob.right_mm_s, oa.right_mm_s);
        moving += (ob.left_mm_s != 0 || ob.right_mm_s != 0);
    }
    assert_int_equal(moving, 60);
    /* The goal is reached with no packet for 3 s: the next decision has no 1 s mean
     * (decide() skips the relearn comparison; with no model yet it learns one from the
     * stored samples, as without a mean) and gives a new goal. */
    for (int k = 0; k < 20 && !ob.decided; ++k) { /* the wheels ramp down, then it ends */
        now += 50000;
        feed_report(&b, now, gx, gy, &ob);
        assert_int_equal(ob.faults & RFS_SEEK_FAULT_RSSI_STALE, 0);
    }
    assert_true(ob.decided);
    assert_int_equal(ob.decision.prev, RFS_DRIVE_REACHED);
    assert_false(ob.decision.mean_valid);
    assert_int_equal(ob.decision.iteration, 1);
    assert_int_equal(ob.faults & (RFS_SEEK_FAULT_RSSI_STALE | RFS_SEEK_FAULT_NO_GOAL), 0);
    assert_true(hypot(D(ob.decision.goal_x) - gx, D(ob.decision.goal_y) - gy) > 0.2);
    world_free(&a);
    world_free(&b);
}

/* Neither packets nor receiver reports: the wheels are at zero within 200 ms of the last
 * input, with the RSSI fault flag (docs/FIRMWARE.md, "Safety"), while poses keep coming;
 * and again when the reports stop after a stretch of reports without packets. */
static void test_no_packet_no_heartbeat_stops_wheels(void **state)
{
    (void)state;
    world_t t;
    rfs_seek_out_t out;
    int64_t now = heartbeat_start(&t, &out);
    assert_true(out.left_mm_s != 0 || out.right_mm_s != 0);
    for (int phase = 0; phase < 2; ++phase) {
        /* phase 0: both stop at once; phase 1: 1 s of reports only, then they stop. */
        int64_t last_input = now;
        if (phase == 1) {
            for (int k = 0; k < 20; ++k) {
                now += 50000;
                feed_report(&t, now, 5.0, 5.0, &out);
                assert_int_equal(out.faults & RFS_SEEK_FAULT_RSSI_STALE, 0);
                assert_true(out.left_mm_s != 0 || out.right_mm_s != 0);
            }
            last_input = now;
        }
        int64_t stopped_at = -1;
        for (int k = 0; k < 10; ++k) { /* 500 ms of poses only */
            now += 50000;
            rfs_pose_t p = pose_at(now, 5.0, 5.0, 0);
            rfs_seek_on_pose(&t.seek, &p, &t.rng);
            rfs_seek_step(&t.seek, now, &t.rng, &out);
            bool zero = out.left_mm_s == 0 && out.right_mm_s == 0;
            if (zero && (out.faults & RFS_SEEK_FAULT_RSSI_STALE) && stopped_at < 0) {
                stopped_at = now;
            }
            if (stopped_at >= 0) { /* and they stay stopped */
                assert_true(zero);
                assert_int_equal(out.state, RFS_SEEK_STALE);
                assert_int_equal(out.faults & RFS_SEEK_FAULT_POSE_STALE, 0);
            }
        }
        assert_true(stopped_at > last_input);
        assert_true(stopped_at - last_input <= 200000);
        /* Inputs return (packets): the interrupted goal is driven again (the first
         * period restarts the drive's ramp at zero). */
        for (int k = 0; k < 2; ++k) {
            now += 50000;
            feed(&t, now, 5.0, 5.0, 0, -40, &out);
            assert_int_equal(out.state, RFS_SEEK_DRIVING);
            assert_false(out.decided);
        }
        assert_true(out.left_mm_s != 0 || out.right_mm_s != 0);
    }
    world_free(&t);
}

/* A receiver report is no measurement: a seeker that only ever hears reports has no
 * sample, no 1 s mean at any decision, and never relearns; it explores (the initial move,
 * then epsilon moves with no model). */
static void test_heartbeat_never_makes_a_mean(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 10, 10, 0, 0);
    seek_make(&t, rfs_seek_cfg_default(), 5);
    rfs_seek_out_t out;
    int64_t now = 0;
    unsigned decisions = 0, moving = 0;
    double x = 5.0, y = 5.0, gx = 5.0, gy = 5.0;
    for (int k = 0; k < 400; ++k) { /* 20 s; the robot jumps to a goal once it moves */
        now += 50000;
        feed_report(&t, now, x, y, &out);
        assert_int_equal(out.faults & RFS_SEEK_FAULT_RSSI_STALE, 0);
        if (out.left_mm_s != 0 || out.right_mm_s != 0) {
            moving++;
            x = gx;
            y = gy;
        }
        if (out.decided) {
            assert_false(out.decision.mean_valid);
            assert_false(out.decision.model_valid);
            assert_false(out.decision.relearned);
            assert_int_equal(out.decision.kind, decisions == 0 ? RFS_SEEK_INITIAL : RFS_SEEK_EPSILON);
            decisions++;
            gx = D(out.decision.goal_x);
            gy = D(out.decision.goal_y);
        }
    }
    assert_true(decisions >= 3);
    assert_true(moving > 0);
    assert_int_equal(t.seek.store.count, 0);
    rfs_q16_t mean;
    assert_false(rfs_rssi_mean(&t.seek.win[0], now, &mean));
    world_free(&t);
}

/* silence_floor (docs/STRATEGIES.md, "Stalls"): the robot drives along y = 5 at 0.5 m/s,
 * poses and receiver reports at 20 Hz, packets (-60 dBm, 100 Hz) for the first second
 * only. From the first pose more than a window (1 s) after the last packet every pose
 * adds a -100 dBm sample where the robot is; the expected count and positions are kept
 * here. When the reports stop too (inputs stale) or the option is off: none. */
static void silence_case(bool on, bool reports, int *floors, int *want)
{
    world_t t;
    world_make(&t, 10, 10, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.silence_floor = on ? RFS_Q16_INT(-100) : INT32_MIN;
    seek_make(&t, cfg, 3);
    double last_meas = 0, want_x[64];
    *want = 0;
    for (int64_t now = 10000; now <= 4000000; now += 10000) {
        double x = 2.0 + 0.5 * (double)now * 1e-6;
        if (now <= 1000000) {
            assert_true(rfs_seek_on_rssi(&t.seek, 0, now, -60, &t.rng));
            last_meas = (double)now;
        }
        if (now % 50000 == 0) {
            rfs_pose_t p = pose_at(now, x, 5.0, 0);
            assert_true(rfs_seek_on_pose(&t.seek, &p, &t.rng));
            if ((reports || now <= 1000000) && on && (double)now - last_meas > 1e6 &&
                *want < 64) {
                want_x[(*want)++] = x;
            }
            if (reports || now <= 1000000) {
                assert_true(rfs_seek_on_receiver(&t.seek, now));
            }
        }
    }
    *floors = 0;
    for (uint16_t k = 0; k < t.seek.store.count; ++k) {
        const rfs_sample_t *sm = &t.seek.store.samples[k];
        if (sm->v_q6 == -100 * 64) {
            /* The pose's own position (the store interpolates at the pose's stamp). */
            assert_true(abs(sm->y_cm - 500) <= 1);
            bool found = false;
            for (int w = 0; w < *want; ++w) {
                found = found || fabs(sm->x_cm / 100.0 - want_x[w]) < 0.011;
            }
            assert_true(found);
            (*floors)++;
        } else {
            assert_int_equal(sm->v_q6, -60 * 64);
        }
    }
    world_free(&t);
}

static void test_silence_floor_samples(void **state)
{
    (void)state;
    int floors, want;
    silence_case(true, true, &floors, &want);
    assert_true(want >= 35); /* 3 s of silence less the window, at 20 Hz */
    assert_true(floors >= want - 1 && floors <= want); /* the newest may wait for a pose */
    silence_case(true, false, &floors, &want);
    assert_int_equal(want, 0);
    assert_int_equal(floors, 0);
    silence_case(false, true, &floors, &want);
    assert_int_equal(floors, 0);
}

/* A pose no newer than the latest is rejected (rfs_seek_on_pose): the seeker keeps the
 * latest pose, the store counts the rejection; a newer one is taken. */
static void test_pose_order(void **state)
{
    (void)state;
    world_t t;
    rfs_seek_out_t out;
    int64_t now = heartbeat_start(&t, &out);
    rfs_pose_t same = pose_at(now, 7.0, 5.0, 0), older = pose_at(now - 1, 7.0, 5.0, 0);
    rfs_pose_t newer = pose_at(now + 1, 6.0, 5.0, 0);

    assert_false(rfs_seek_on_pose(&t.seek, &same, &t.rng));
    assert_false(rfs_seek_on_pose(&t.seek, &older, &t.rng));
    assert_int_equal(t.seek.pose.t_us, now);
    assert_int_equal(t.seek.pose.x, Q(5.0));
    assert_int_equal(t.seek.store.rejected_pose_order, 2);
    assert_true(rfs_seek_on_pose(&t.seek, &newer, &t.rng));
    assert_int_equal(t.seek.pose.x, Q(6.0));
    world_free(&t);
}

/* Report stamps follow the measurements' rules (docs/FAULTS.md): older than the newest is
 * rejected, equal accepted; a newest report further ahead than the timeout (a clock jump)
 * is stale even while packets are fresh, until the clock reaches it. */
static void test_heartbeat_stamps(void **state)
{
    (void)state;
    world_t t;
    rfs_seek_out_t out;
    int64_t now = heartbeat_start(&t, &out);
    assert_true(rfs_seek_on_receiver(&t.seek, now));          /* equal: accepted */
    assert_false(rfs_seek_on_receiver(&t.seek, now - 1));     /* older: rejected */
    assert_int_equal(t.seek.rx_rejected, 1);
    int64_t jump = now + 5000000;                             /* 5 s ahead */
    assert_true(rfs_seek_on_receiver(&t.seek, jump));
    int stale = 0;
    while (now < jump + 500000) {
        now += 50000;
        assert_false(rfs_seek_on_receiver(&t.seek, now < jump ? now : jump - 1));
        feed(&t, now, 5.0, 5.0, 0, -40, &out);
        bool flagged = (out.faults & RFS_SEEK_FAULT_RSSI_STALE) != 0;
        /* Stale exactly while the report is more than 150 ms ahead of now. */
        assert_int_equal(flagged, jump - now > 150000);
        if (flagged) {
            assert_int_equal(out.left_mm_s, 0);
            assert_int_equal(out.right_mm_s, 0);
            stale++;
        }
    }
    assert_int_equal(stale, 96); /* now = jump - 4.95 s ... jump - 0.2 s, every 50 ms */
    world_free(&t);
}

/* Closed loop: a 20 x 20 m hall, source 10 m away, path loss 40 + 30 log10(d) dB with
 * 4 dB Gaussian noise (double precision world, unicycle kinematics), 200 packets/s,
 * 10 Hz poses, 20 Hz control. The seeker must come within 1.5 m. */
static double gauss(rfs_rng_t *r)
{
    double u1 = (rfs_rng_u32(r) + 1.0) / 4294967297.0, u2 = rfs_rng_u32(r) / 4294967296.0;
    return sqrt(-2 * log(u1)) * cos(2 * M_PI * u2);
}

static void test_closed_loop_reaches_source(void **state)
{
    (void)state;
    int reached = 0;
    const int runs = 5;
    for (int seed = 1; seed <= runs; ++seed) {
        world_t t;
        world_make(&t, 20, 20, 0, 0);
        seek_make(&t, rfs_seek_cfg_default(), (uint64_t)seed);
        rfs_rng_t noise;
        rfs_rng_seed(&noise, 1000u + (uint64_t)seed);
        double x = 5, y = 10, th = 0, sx = 15, sy = 10;
        double vl = 0, vr = 0;
        int64_t now = 0;
        for (int ms = 0; ms < 600000; ms += 5) { /* 10 simulated minutes, 5 ms steps */
            now = (int64_t)ms * 1000;
            double v = (vl + vr) / 2e3, w = (vr - vl) / 1e3 / 0.23;
            x += v * cos(th) * 0.005;
            y += v * sin(th) * 0.005;
            th = atan2(sin(th + w * 0.005), cos(th + w * 0.005));
            if (ms % 5 == 0) {
                double d = fmax(hypot(x - sx, y - sy), 1.0);
                double dbm = -40 - 30 * log10(d) + 4 * gauss(&noise);
                rfs_seek_on_rssi(&t.seek, 0, now, (int8_t)lround(fmax(dbm, -127)), &t.rng);
            }
            if (ms % 100 == 0) {
                rfs_pose_t p = pose_at(now, x, y, th);
                rfs_seek_on_pose(&t.seek, &p, &t.rng);
            }
            if (ms % 50 == 0) {
                rfs_seek_out_t out;
                rfs_seek_step(&t.seek, now, &t.rng, &out);
                vl = out.left_mm_s;
                vr = out.right_mm_s;
                assert_true(fabs(vl) <= 700 && fabs(vr) <= 700);
            }
            if (hypot(x - sx, y - sy) < 1.5) {
                reached++;
                break;
            }
        }
        world_free(&t);
    }
    assert_int_equal(reached, runs);
}

/* The seeker's ridge predicts at (8, 9) m what a whole fit of its first n samples (0: all
 * it holds) at (qx, qy) does. */
static void assert_whole_ridge(world_t *t, uint16_t n, rfs_q16_t qx, rfs_q16_t qy)
{
    rfs_ridge_t whole;
    rfs_ridge_cfg_t rc = rfs_ridge_cfg_default();
    assert_int_equal(rfs_ridge_init(&whole, &rc), 0);
    const rfs_model_fit_in_t in = {.samples = t->seek.store.samples,
                                   .n = n != 0u ? n : t->seek.store.count, .qx = qx, .qy = qy};
    const rfs_model_t wm = rfs_ridge_model(&whole);
    assert_int_equal(wm.ops->fit(wm.self, &in, 0u, &t->rng), RFS_FIT_DONE);
    rfs_q16_t a, b;
    assert_true(t->seek.model.ops->predict(t->seek.model.self, Q(8), Q(9), &a));
    assert_true(wm.ops->predict(wm.self, Q(8), Q(9), &b));
    assert_int_equal(a, b);
}

/* A sliced relearn under pose noise: the robot (teleported to each goal) reports poses
 * that jitter by +-1 cm at 20 Hz, the relearn takes 500 samples a slice, one a period and
 * bg more in each period's spare time (rfs_seek_background). Each fit runs at the point
 * where its decision began, so it ends after ceil(n / (500 (bg + 1))) periods whatever
 * the pose does (a fit restarted at each new pose never ended once it needed three
 * periods), and the sliced ridge equals a whole fit of the same samples at that point.
 * Background calls with no fit waiting, or while a sliced flood rewrites the reach bits,
 * do nothing and say so. */
static void sliced_fit_run(uint32_t bg)
{
    world_t t;
    world_make(&t, 20, 20, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.fit_budget = 500;
    seek_make(&t, cfg, 5);
    assert_false(rfs_seek_background(&t.seek, &t.rng)); /* before any fit */
    assert_int_equal(rfs_seek_background_n(&t.seek, &t.rng, 5u), 0u);
    double x = 5, y = 10, gx = 5, gy = 10;
    int64_t arrive = 0, begun = -1;
    uint32_t decisions = 0, relearned = 0, compared = 0, pkt = 0, bg_slices = 0, sooner = 0;
    uint16_t n_fit = 0u; /* store.count when a fit ended in the spare time */
    for (int64_t now = 5000; now <= 120000000; now += 5000) {
        if (now >= arrive) {
            x = gx;
            y = gy;
        }
        const double d = fmax(hypot(x - 15.0, y - 10.0), 1.0);
        const double u = fmod((double)pkt++ * 0.6180339887498949, 1.0);
        rfs_seek_on_rssi(&t.seek, 0, now, (int8_t)floor(-40 - 30 * log10(d) + u), &t.rng);
        if (now % 50000 != 0) {
            continue;
        }
        const double jit = (now / 50000) % 2 == 0 ? 0.01 : -0.01;
        rfs_pose_t p = pose_at(now, x + jit, y - jit, 0);
        rfs_seek_on_pose(&t.seek, &p, &t.rng);
        const uint32_t n = t.seek.store.count;
        rfs_seek_out_t out;
        rfs_seek_step(&t.seek, now, &t.rng, &out);
        const bool waits = t.seek.state == RFS_SEEK_LEARNING;
        if (waits && begun < 0) {
            begun = now; /* the relearn's first period */
            assert_true(n > 1500u); /* long enough to need more than three slices */
        }
        if (waits && bg > 0u && !t.seek.fit_ended) {
            /* A sliced flood under way (reach bits rewritten): no slice until it ends. */
            t.seek.flooding = true;
            assert_false(rfs_seek_background(&t.seek, &t.rng));
            assert_true(t.seek.fitting && !t.seek.fit_ended);
            t.seek.flooding = false;
        }
        for (uint32_t k = 0u; k < bg; ++k) {
            const rfs_seek_state_t st = t.seek.state;
            const bool more = rfs_seek_background(&t.seek, &t.rng);
            assert_int_equal(t.seek.state, st); /* no decision, no wheel command */
            if (!waits) {
                assert_false(more);
            }
            bg_slices += more ? 1u : 0u;
        }
        if (t.seek.fit_ended && n_fit == 0u) {
            n_fit = t.seek.store.count; /* ended in the spare time: what it fitted */
        }
        if (!out.decided) {
            continue;
        }
        decisions++;
        if (begun >= 0) {
            relearned++;
            /* ceil(n / 500 (bg + 1)) periods, one more for the samples that came meanwhile
             * and one for the decision after a fit that ended in the spare time */
            const int64_t periods = (now - begun) / 50000 + 1;
            const uint32_t per = 500u * (bg + 1u);
            assert_true(periods <= (int64_t)((n + per - 1u) / per) + 1 + (bg > 0u));
            sooner += periods < (int64_t)(n + 499u) / 500 ? 1u : 0u; /* slices < periods */
            /* A whole fit of the store at the decision's start point predicts the same
             * (while the store is not full: a full one replaces samples under the slices). */
            if (t.seek.store.count < cfg.store.capacity) {
                assert_whole_ridge(&t, n_fit, out.decision.x, out.decision.y);
                compared++;
            }
            begun = -1;
        }
        n_fit = 0u;
        gx = D(out.decision.goal_x);
        gy = D(out.decision.goal_y);
        arrive = now + 1000000;
    }
    assert_true(compared >= 3u);
    assert_true(relearned >= 10u);
    assert_true(decisions >= 20u);
    assert_true(bg == 0u || (bg_slices >= 10u && sooner >= 5u));
    world_free(&t);
}

static void test_sliced_fit_ends_under_pose_noise(void **state)
{
    (void)state;
    sliced_fit_run(0u);
}

static void test_background_slices_end_fits_sooner(void **state)
{
    (void)state;
    sliced_fit_run(3u);
}

/* A robot with nowhere to go (a 0.8 m box: one legal lattice point) reports NO_GOAL, keeps
 * its wheels stopped and decides again only after a second, not at every period. */
static void test_no_goal_backs_off(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 0.8, 0.8, 0, 0);
    seek_make(&t, rfs_seek_cfg_default(), 1);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 0.4, .y = 0.4 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 0, 2000000, &out));
    assert_true(out.faults & RFS_SEEK_FAULT_NO_GOAL);
    int64_t t0 = r.t_us;
    r.pending = false;
    /* The periods in between: no decision, wheels stopped, the fault still reported. */
    for (int k = 1; k < 20; ++k) {
        r.t_us += 50000;
        rfs_pose_t p = { r.t_us, Q(0.4), Q(0.4), 0 };
        rfs_seek_on_pose(&t.seek, &p, &t.rng);
        rfs_seek_on_rssi(&t.seek, 0, r.t_us, -60, &t.rng);
        rfs_seek_step(&t.seek, r.t_us, &t.rng, &out);
        assert_false(out.decided);
        assert_int_equal(out.left_mm_s, 0);
        assert_int_equal(out.right_mm_s, 0);
        assert_true(out.faults & RFS_SEEK_FAULT_NO_GOAL);
    }
    assert_true(next_decision(&t, &r, &f, 0, 2000000, &out));
    assert_int_equal(r.t_us - t0, 1000000);
    assert_int_equal(out.decision.iteration, 1);
    world_free(&t);
}

/* rfs_seek_init's result for cfg on a 5 x 5 m world with the local ridge. */
static int init_result(rfs_seek_cfg_t cfg)
{
    world_t t;
    world_make(&t, 5.0, 5.0, 0, 0);
    uint32_t lpts = (uint32_t)t.map.lw * t.map.lh;
    uint8_t *bits = calloc(lpts, 1);
    rfs_seek_mem_t mem = { .visited = bits, .visited_bytes = lpts, .reach = bits,
                           .reach_bytes = lpts };
    rfs_ridge_cfg_t rc = rfs_ridge_cfg_default();
    rfs_ridge_init(&t.ridge, &rc);
    int rc_init = rfs_seek_init(&t.seek, &cfg, &t.map, rfs_ridge_model(&t.ridge),
                                &rfs_target_rssi, &mem);
    free(bits);
    world_free(&t);
    return rc_init;
}

/* Names round-trip; an out-of-range strategy is rejected. */
static void test_names(void **state)
{
    (void)state;
    static const char *names[] = { "meta", "meta-global", "fd-gradient", "plane-gradient",
                                   "chemotaxis", "meta-path" };
    for (int i = 0; i < 6; ++i) {
        rfs_seek_strategy_t st;
        assert_true(rfs_seek_strategy_parse(names[i], &st));
        assert_int_equal((int)st, i);
        assert_string_equal(rfs_seek_strategy_name(st), names[i]);
    }
    rfs_seek_strategy_t st;
    assert_false(rfs_seek_strategy_parse("metaa", &st));
    assert_false(rfs_seek_strategy_parse("", &st));
    assert_string_equal(rfs_seek_kind_name(RFS_SEEK_TUMBLE), "tumble");
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    assert_int_equal(cfg.strategy, RFS_SEEK_META); /* the paper's is the default */
    cfg.strategy = RFS_SEEK_STRATEGY_COUNT;
    assert_int_equal(init_result(cfg), -1);
}

/* The meta-path preset: its improvements are on, every other strategy keeps the paper's
 * rule, and a negative recheck distance is refused. */
static void test_meta_path_preset(void **state)
{
    (void)state;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    assert_int_equal(cfg.recheck_dist, 0);
    assert_false(cfg.eps_by_travel);
    assert_false(cfg.eps_geodesic);
    assert_false(cfg.eps_sample);
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    assert_int_equal(cfg.strategy, RFS_SEEK_META_PATH);
    assert_int_equal(cfg.recheck_dist, cfg.step);
    assert_true(cfg.eps_by_travel);
    assert_true(cfg.eps_geodesic);
    assert_true(cfg.eps_sample);
    assert_int_equal(cfg.refute_r, cfg.step);
    assert_int_equal(cfg.silence_floor, RFS_Q16_INT(-100));
    assert_true(cfg.recheck_silent);
    rfs_seek_cfg_t per = cfg;
    rfs_seek_cfg_per_source(&per); /* a fit per node: its own floor, no source to rule out */
    assert_int_equal(per.refute_r, 0);
    assert_int_equal(per.silence_floor, INT32_MIN);
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META);
    assert_int_equal(cfg.recheck_dist, 0);
    assert_false(cfg.eps_by_travel);
    assert_false(cfg.eps_geodesic);
    assert_false(cfg.eps_sample);
    assert_int_equal(cfg.refute_r, 0);
    assert_int_equal(cfg.silence_floor, INT32_MIN);
    assert_false(cfg.recheck_silent);
    cfg.refute_r = -1;
    assert_int_equal(init_result(cfg), -1);
    cfg.refute_r = 0;
    cfg.recheck_dist = -1;
    assert_int_equal(init_result(cfg), -1);
}

/* recheck_dist: a greedy leg whose 1 s mean departs from the model by more than the
 * threshold after recheck_dist of travel is abandoned (prev = running) and the next
 * decision relearns and goes greedy again without an epsilon draw; with recheck_dist 0
 * (the paper) the same leg runs to its end. epsilon is fixed at 0.5 so that an
 * unforced decision is greedy only about half the time. */
static rfs_seek_cfg_t recheck_cfg(double recheck_m)
{
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.recheck_dist = Q(recheck_m);
    cfg.recheck_adapt = false; /* the fixed 3 dB rule; the adaptive one: test_recheck_adapt */
    cfg.eps_by_travel = false;
    cfg.eps_amp = 0;
    cfg.eps_floor = RFS_Q16_HALF;
    return cfg;
}

static void run_recheck(double recheck_m, int *jumps, int *jumps_abandoned, int *normal_eps)
{
    world_t t;
    world_make(&t, 30.0, 30.0, 0, 0);
    seek_make(&t, recheck_cfg(recheck_m), 9);
    field_t f = { .kind = 1, .a = -80.0, .bx = 0.5, .by = 0.5 };
    run_t r = { .x = 5.0, .y = 5.0 };
    rfs_seek_out_t out;
    *jumps = *jumps_abandoned = *normal_eps = 0;
    bool jumped = false;
    for (int k = 0; k < 80; ++k) {
        assert_true(next_decision(&t, &r, &f, 1500000, 60000000, &out));
        const rfs_seek_decision_t *d = &out.decision;
        if (d->prev == RFS_DRIVE_RUNNING) {
            /* Abandoned by a failed check: relearnt, greedy without a draw. */
            assert_true(recheck_m > 0.0);
            assert_true(d->relearned);
            assert_int_equal(d->kind, RFS_SEEK_GREEDY);
            *jumps_abandoned += jumped;
        } else if (k > 1) {
            *normal_eps += d->kind == RFS_SEEK_EPSILON;
        }
        /* Every third greedy leg: the field jumps by 12 dB while it is driven (the
         * teleported robot appears at the goal, 1 m away, with a 1 s mean 12 dB off). */
        jumped = d->kind == RFS_SEEK_GREEDY && k % 3 == 0 && d->prev != RFS_DRIVE_RUNNING;
        *jumps += jumped;
        f.a = jumped ? -68.0 : -80.0;
    }
    world_free(&t);
}

static void test_recheck_abandons_leg(void **state)
{
    (void)state;
    int jumps, ab, ne;
    run_recheck(0.5, &jumps, &ab, &ne);
    assert_true(jumps >= 5);
    assert_int_equal(ab, jumps); /* every leg driven through a jump is abandoned */
    assert_true(ne >= 10);       /* unforced decisions still explore */
    run_recheck(0.0, &jumps, &ab, &ne);
    assert_true(jumps >= 5);
    assert_int_equal(ab, 0);     /* the paper's rule runs every leg to its end */
}

/* fit_early: legs driven through a 12 dB jump fail their recheck (as run_recheck) and the
 * relearn, a sliced ridge (300 samples a slice, three more slices after each period),
 * begins as the base brakes; without rechecks the jump fails the check within
 * RFS_SEEK_EARLY_GOAL of the goal and the relearn begins there. Each such decision waits
 * fewer periods at rest than without fit_early, and after a failed recheck its model is a
 * whole fit of the samples the slices saw, at the pose where the check failed. */
typedef struct early_run {
    int abandoned;        /* decisions after a failed recheck */
    int began_moving;     /* relearns begun while the base still rolled */
    int waited;           /* periods those decisions stood at rest */
    int compared;         /* models checked against a whole fit */
    int at_goal;          /* relearning decisions at a goal reached */
    int goal_began;       /* of them, begun before the goal was reached */
    int goal_waited;      /* periods they stood at rest */
} early_run_t;

static early_run_t run_early(bool early, double recheck_m)
{
    world_t t;
    world_make(&t, 30.0, 30.0, 0, 0);
    rfs_seek_cfg_t cfg = recheck_cfg(recheck_m);
    cfg.fit_budget = 300;
    cfg.fit_early = early;
    seek_make(&t, cfg, 9);
    field_t f = { .kind = 1, .a = -80.0, .bx = 0.5, .by = 0.5 };
    run_t r = { .x = 5.0, .y = 5.0 };
    early_run_t e = { 0 };
    bool began = false;
    int rest = 0;
    uint16_t n_fit = 0u;
    for (int k = 0; k < 60; ++k) {
        rfs_seek_out_t out = { 0 };
        while (!out.decided) {
            assert_true(r.t_us < 600000000);
            if (!run_tick(&t, &r, &f)) {
                continue;
            }
            rfs_pose_t p = { r.t_us, Q(r.x), Q(r.y), 0 };
            rfs_seek_on_pose(&t.seek, &p, &t.rng);
            rest += rfs_drive_at_rest(&t.seek.drive) && !r.pending ? 1 : 0;
            rfs_seek_step(&t.seek, r.t_us, &t.rng, &out);
            began = began || (t.seek.early && !rfs_drive_at_rest(&t.seek.drive));
            began = began || (t.seek.early && t.seek.drive.status == RFS_DRIVE_RUNNING);
            assert_true(early || !t.seek.early);
            (void)rfs_seek_background_n(&t.seek, &t.rng, 3u);
            if (t.seek.fit_ended && n_fit == 0u) {
                n_fit = t.seek.store.count;
            }
        }
        const rfs_seek_decision_t *d = &out.decision;
        if (d->prev == RFS_DRIVE_REACHED && d->relearned && k > 0) {
            e.at_goal++;
            e.goal_began += began;
            e.goal_waited += rest;
        }
        if (d->prev == RFS_DRIVE_RUNNING) {
            assert_true(d->relearned);
            e.abandoned++;
            e.began_moving += began;
            e.waited += rest;
            if (began && t.seek.store.count < cfg.store.capacity) {
                assert_whole_ridge(&t, n_fit, t.seek.fit_qx, t.seek.fit_qy);
                e.compared++;
            }
        }
        began = false;
        rest = 0;
        n_fit = 0u;
        r.pending = true;
        r.gx = D(d->goal_x);
        r.gy = D(d->goal_y);
        r.arrive_us = r.t_us + 1500000;
        const bool jumped = d->kind == RFS_SEEK_GREEDY && k % 3 == 0 && d->prev != RFS_DRIVE_RUNNING;
        f.a = jumped ? -68.0 : -80.0;
    }
    world_free(&t);
    return e;
}

static void test_fit_early_relearns_while_braking(void **state)
{
    (void)state;
    early_run_t on = run_early(true, 0.5), off = run_early(false, 0.5);
    assert_true(on.abandoned >= 5 && off.abandoned >= 5);
    assert_int_equal(off.began_moving, 0);
    assert_true(on.began_moving >= on.abandoned - 1); /* all but one seen while rolling */
    assert_true(on.compared >= 3);
    /* waits at rest per abandoned leg: fewer periods than without */
    assert_true(on.waited * off.abandoned < off.waited * on.abandoned);
    /* without rechecks the jumps are met at the goals: every relearn there begun on the
     * way (none without fit_early), shorter waits */
    on = run_early(true, 0.0);
    off = run_early(false, 0.0);
    assert_true(on.at_goal >= 5 && off.at_goal >= 5);
    assert_int_equal(on.goal_began, on.at_goal);
    assert_int_equal(off.goal_began, 0);
    assert_true(on.goal_waited * off.at_goal < off.goal_waited * on.at_goal);
}

/* recheck_adapt's rule against double precision: a running mean of the squared misses
 * moved 1/8 of the way at each check, and a check fails beyond max(3 dB, its root). Misses
 * from a seeded generator: long quiet stretches (model good to 1-2 dB), bursts of 4-8 dB
 * (a cluttered area), single 12 dB jumps. Off, the rule is the fixed 3 dB. */
static void test_recheck_adapt(void **state)
{
    (void)state;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    assert_false(cfg.recheck_adapt);
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    assert_true(cfg.recheck_adapt);
    rfs_seek_cfg_t off = rfs_seek_cfg_default();
    uint32_t r = 12345u;
    int64_t ms = 0, ms_off = 0;
    double ref = 0.0;
    int fails = 0, fails_fixed = 0, checked = 0;
    for (int k = 0; k < 4000; ++k) {
        r = r * 1664525u + 1013904223u;
        double u = (double)(r >> 8) / 16777216.0;
        int phase = (k / 200) % 3; /* quiet, burst, quiet with jumps */
        double miss = phase == 1 ? 4.0 + 4.0 * u : (k % 37 == 0 && phase == 2 ? 12.0 : 2.0 * u);
        rfs_q16_t mq = (rfs_q16_t)lround(miss * 65536.0);
        bool got = rfs_seek_recheck_miss(&cfg, &ms, mq);
        bool got_off = rfs_seek_recheck_miss(&off, &ms_off, mq);
        double mqd = mq / 65536.0;
        ref += (mqd * mqd - ref) / 8.0;
        double thr = fmax(3.0, sqrt(ref));
        assert_int_equal(got_off, mqd > 3.0);
        assert_int_equal(ms_off, 0); /* off: no state */
        if (fabs(ms / 65536.0 - ref) > 1e-3 * (1.0 + ref)) {
            fail_msg("check %d: mean square %.6f, reference %.6f", k, ms / 65536.0, ref);
        }
        if (fabs(mqd - thr) > 1e-3) {
            assert_int_equal(got, mqd > thr);
            checked++;
        }
        fails += got;
        fails_fixed += got_off;
    }
    assert_true(checked > 3900);
    /* The bursts fail the fixed rule at every check but the adaptive one only until the
     * running RMS has caught up (then about half of them, those above the RMS); the 12 dB
     * jumps in quiet stretches still fail both. */
    assert_true(4 * fails < 3 * fails_fixed);
    assert_true(fails >= 30);
}

/* A null move (the greedy goal is where the robot stands): the seeker decides again one
 * averaging window later, not at every 50 ms period, and raises no NO_GOAL fault. */
static void test_null_move_backs_off(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 10.0, 10.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.eps_amp = 0;
    cfg.eps_floor = 0; /* every decision after the first is greedy */
    seek_make(&t, cfg, 4);
    fixed_model_t fm = { false, 0, 0 };
    rfs_model_t model = { fixed_ops(), &fm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 5.0, .y = 5.0 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 0, 5000000, &out)); /* the initial move */
    r.x = r.gx; /* arrive at once */
    r.y = r.gy;
    r.pending = false;
    fm.mx = Q(r.x); /* the model's maximum: right here */
    fm.my = Q(r.y);
    int64_t prev = -1;
    for (int k = 0; k < 4; ++k) {
        assert_true(next_decision(&t, &r, &f, 0, 5000000, &out));
        assert_int_equal(out.decision.kind, RFS_SEEK_GREEDY);
        assert_false(out.faults & RFS_SEEK_FAULT_NO_GOAL);
        if (prev >= 0) {
            assert_int_equal(r.t_us - prev, 1000000); /* one window, not one period */
        }
        prev = r.t_us;
    }
    world_free(&t);
}

/* A goal abandoned while the robot drives at speed (a failed recheck): the base brakes
 * at its own rate, so the seeker waits until the drive's model of the base is at rest
 * before it decides; the next path then starts where the robot stands (it used to start
 * at the estimate while the robot rolled on ~0.25 m past it, docs/MAPS.md "Drive
 * control"). A double-precision unicycle whose wheels follow the commands at 1 m/s^2
 * (the Kobuki's limit, the drive's default) stands for the base; the field jumps by
 * 12 dB every 4 s so that legs are abandoned mid-way. */
static void test_abandoned_leg_decides_at_rest(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 20, 20, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.recheck_adapt = false;
    cfg.recheck_dist = Q(0.5); /* checked half-way along a 1 m leg */
    seek_make(&t, cfg, 3);
    double x = 5, y = 10, th = 0, sx = 15, sy = 3;
    double vl = 0, vr = 0, cl = 0, cr = 0, vmax_abandoned = 0;
    int abandoned = 0;
    for (int ms = 0; ms < 240000; ms += 5) {
        int64_t now = (int64_t)ms * 1000;
        /* The base: each wheel towards its command by at most 1 m/s^2 x 5 ms. */
        vl += fmax(-5.0, fmin(5.0, cl - vl));
        vr += fmax(-5.0, fmin(5.0, cr - vr));
        double v = (vl + vr) / 2e3, w = (vr - vl) / 1e3 / 0.23;
        x += v * cos(th) * 0.005;
        y += v * sin(th) * 0.005;
        th = atan2(sin(th + w * 0.005), cos(th + w * 0.005));
        double d = fmax(hypot(x - sx, y - sy), 1.0);
        double jump = (ms / 4000) % 2 ? 12.0 : 0.0;
        rfs_seek_on_rssi(&t.seek, 0, now, (int8_t)lround(-40 - 30 * log10(d) + jump), &t.rng);
        if (ms % 100 == 0) {
            rfs_pose_t p = pose_at(now, x, y, th);
            rfs_seek_on_pose(&t.seek, &p, &t.rng);
        }
        if (ms % 50 != 0) {
            continue;
        }
        double speed = fmax(fabs(vl), fabs(vr));
        rfs_seek_out_t out;
        rfs_seek_step(&t.seek, now, &t.rng, &out);
        if (out.decided && out.decision.prev == RFS_DRIVE_RUNNING) {
            /* Decided at rest, and planned from the robot's true position. */
            assert_true(speed <= 50.0);
            assert_true(rfs_drive_at_rest(&t.seek.drive));
            if (t.seek.drive.path.n > 0) {
                assert_true(t.seek.drive.path.has_start);
                assert_true(hypot(D(t.seek.drive.path.x0) - x, D(t.seek.drive.path.y0) - y) < 0.03);
            }
            abandoned++;
        }
        if (!out.decided && t.seek.drive.status != RFS_DRIVE_RUNNING && speed > 0.0) {
            /* Braking after a goal ended: the wheels are commanded to 0 meanwhile. */
            assert_int_equal(out.left_mm_s, 0);
            assert_int_equal(out.right_mm_s, 0);
            vmax_abandoned = fmax(vmax_abandoned, speed);
        }
        cl = out.left_mm_s;
        cr = out.right_mm_s;
    }
    world_free(&t);
    assert_true(abandoned >= 3);
    assert_true(vmax_abandoned >= 300.0); /* legs were abandoned at speed */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_are_the_papers),
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_meta_path_preset),
        cmocka_unit_test(test_stale_inputs_stop_wheels),
        cmocka_unit_test(test_heartbeat_keeps_goal_without_packets),
        cmocka_unit_test(test_no_packet_no_heartbeat_stops_wheels),
        cmocka_unit_test(test_heartbeat_never_makes_a_mean),
        cmocka_unit_test(test_pose_order),
        cmocka_unit_test(test_heartbeat_stamps),
        cmocka_unit_test(test_silence_floor_samples),
        cmocka_unit_test(test_no_goal_backs_off),
        cmocka_unit_test(test_null_move_backs_off),
        cmocka_unit_test(test_recheck_abandons_leg),
        cmocka_unit_test(test_fit_early_relearns_while_braking),
        cmocka_unit_test(test_recheck_adapt),
        cmocka_unit_test(test_abandoned_leg_decides_at_rest),
        cmocka_unit_test(test_closed_loop_reaches_source),
        cmocka_unit_test(test_sliced_fit_ends_under_pose_noise),
        cmocka_unit_test(test_background_slices_end_fits_sooner),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
