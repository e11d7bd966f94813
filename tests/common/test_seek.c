/* test_seek.c - the meta-algorithm: epsilon schedule, novelty, line search, staleness,
 * and a closed-loop run against a double-precision world (unicycle + path loss). */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


#include "ref_geom.h"
#include "rfs_gridmax.h"
#include "seek_world.h"

static void test_epsilon_schedule(void **state)
{
    (void)state;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    double a = log(9.0 / 4.0) / 5.0; /* epsilon(5) = 0.5, paper section 2 */
    for (uint32_t n = 0; n <= 200; ++n) {
        double ref = 0.9 * exp(-a * n) + 0.1;
        assert_true(fabs(D(rfs_seek_epsilon(&cfg, n)) - ref) < 5e-5);
    }
    assert_true(fabs(D(rfs_seek_epsilon(&cfg, 0)) - 1.0) < 5e-5);
    assert_true(fabs(D(rfs_seek_epsilon(&cfg, 5)) - 0.5) < 5e-5);
    assert_true(fabs(D(rfs_seek_epsilon(&cfg, 1000000)) - 0.1) < 5e-5);
}

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

/* Feed pose + one measurement at time t (both fresh), then step. */
static void feed(world_t *t, int64_t t_us, double x, double y, double th, int8_t dbm,
                 rfs_seek_out_t *out)
{
    rfs_pose_t p = pose_at(t_us, x, y, th);
    rfs_seek_on_pose(&t->seek, &p, &t->rng);
    rfs_seek_on_rssi(&t->seek, 0, t_us, dbm, &t->rng);
    rfs_seek_step(&t->seek, t_us, &t->rng, out);
}

/* One period in a radio dead zone (issue 10): a pose at (x, y) and a receiver report, both
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

/* With epsilon forced to 1, every goal after the initial move is novel: at least the
 * novelty radius from every position the robot reported. */
static void test_epsilon_goals_are_novel(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 12, 12, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.eps_amp = 0;
    cfg.eps_floor = RFS_Q16_ONE;
    seek_make(&t, cfg, 7);
    /* Report a trajectory: a line from (2, 6) to (10, 6), 5 cm apart. */
    double xs[200], ys[200];
    int np = 0;
    rfs_seek_out_t out;
    int64_t now = 0;
    for (double x = 2.0; x <= 10.0; x += 0.05) {
        xs[np] = x;
        ys[np] = 6.0;
        now += 10000;
        rfs_pose_t p = pose_at(now, x, 6.0, 0);
        rfs_seek_on_pose(&t.seek, &p, &t.rng);
        np++;
    }
    int decisions = 0;
    for (int k = 0; k < 40; ++k) {
        now += 10000;
        rfs_pose_t p = pose_at(now, 10.0, 6.0, 0);
        rfs_seek_on_pose(&t.seek, &p, &t.rng);
        rfs_seek_on_rssi(&t.seek, 0, now, -50, &t.rng);
        rfs_seek_step(&t.seek, now, &t.rng, &out);
        if (out.decided && out.decision.kind == RFS_SEEK_EPSILON) {
            decisions++;
            double gx = D(out.decision.goal_x), gy = D(out.decision.goal_y);
            for (int i = 0; i < np; ++i) {
                assert_true(hypot(gx - xs[i], gy - ys[i]) >= 0.5 - 1e-4);
            }
        }
        if (out.decided) {
            rfs_drive_stop(&t.seek.drive, now); /* end the goal: decide again next step */
        }
    }
    assert_true(decisions >= 30);
    world_free(&t);
}

/* A model with a fixed maximum, for testing the step choice independently of learning. */
typedef struct fixed_model {
    double mx, my;
} fixed_model_t;

static void fm_reset(void *self)
{
    (void)self;
}

static rfs_fit_result_t fm_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                               rfs_rng_t *rng)
{
    (void)self; (void)in; (void)budget; (void)rng;
    return RFS_FIT_DONE;
}

static bool fm_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *v)
{
    const fixed_model_t *m = self;
    *v = Q(-hypot(D(x) - m->mx, D(y) - m->my));
    return true;
}

static const rfs_model_ops_t fm_ops = {
    .name = "fixed", .reset = fm_reset, .fit = fm_fit, .predict = fm_predict,
};

/* Greedy step blocked by a wall: the line search picks the first legal point on the line
 * to the maximum, in front of or beyond the wall (paper section 2). */
static void test_blocked_step_line_search(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 12, 8, 6.0, 6.0); /* wall x = 6, y in [0, 6): passage above y = 6 */
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.eps_amp = 0;
    cfg.eps_floor = 0;
    seek_make(&t, cfg, 3);
    fixed_model_t fm = { 9.125, 3.125 }; /* a lattice point: the grid maximum is exact */
    t.seek.model.ops = &fm_ops;
    t.seek.model.self = &fm;
    t.seek.iteration = 1; /* skip the initial random move */
    rfs_seek_out_t out;
    /* Robot at x = 5.3: one step towards the maximum lands at 6.3, 0.2 m from the wall
     * cell [6.0, 6.1): illegal. Reference (by hand): legal points keep 0.25 m from the
     * wall, so the nearest legal points on the line are x <= 5.75 and x >= 6.35 (up to one
     * cell of discretisation); the search steps 0.1 m from 6.3 both ways, so the first
     * legal point is beyond the wall at 6.4 or 6.5. */
    feed(&t, 100000, 5.3, 3.125, 0, -50, &out);
    assert_true(out.decided);
    assert_int_equal(out.decision.kind, RFS_SEEK_GREEDY);
    assert_true(out.decision.line_search);
    assert_true(fabs(D(out.decision.max_x) - 9.125) < 1e-4);
    assert_true(fabs(D(out.decision.max_y) - 3.125) < 1e-4);
    double gx = D(out.decision.goal_x), gy = D(out.decision.goal_y);
    assert_true(fabs(gy - 3.125) < 1e-3);
    assert_true(gx >= 6.35 - 0.1 && gx <= 6.5 + 1e-3);
    /* Beyond the wall: the planned path goes round its end at y = 6 and back. */
    assert_true(D(out.decision.path_len) > 2 * (6.0 - 3.125));
    world_free(&t);
}

/* A plane c + gx x + gy y rounded to Q16 (monotone along rows), for the row shortcut. */
typedef struct plane_model {
    double c, gx, gy;
} plane_model_t;

static bool pm_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *v)
{
    const plane_model_t *m = self;
    *v = Q(m->c + m->gx * D(x) + m->gy * D(y));
    return true;
}

static int pm_monotone(const void *self)
{
    const plane_model_t *m = self;
    return m->gx > 0 ? 1 : (m->gx < 0 ? -1 : 0);
}

static const rfs_model_ops_t pm_ops = {
    .name = "plane", .reset = fm_reset, .fit = fm_fit, .predict = pm_predict,
    .row_monotone = pm_monotone,
};
static const rfs_model_ops_t pm_scan_ops = {
    .name = "plane-scan", .reset = fm_reset, .fit = fm_fit, .predict = pm_predict,
};

/* The row shortcut finds exactly the maximum the full scan finds, ties included (slopes
 * so small that whole rows round to one value), on a map with a wall; and the scan's answer is the brute-force maximum computed in double here. */
static void test_grid_max_row_shortcut(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 12, 8, 6.0, 6.0);
    seek_make(&t, rfs_seek_cfg_default(), 5);
    rfs_seek_out_t out;
    feed(&t, 100000, 3.0, 3.0, 0, -50, &out); /* first step computes reachability */
    rfs_rng_t r;
    rfs_rng_seed(&r, 99);
    for (int k = 0; k < 300; ++k) {
        plane_model_t pm;
        double scale = k % 3 == 0 ? 1e-7 : (k % 3 == 1 ? 1e-3 : 3.0);
        pm.c = -60;
        pm.gx = ((double)rfs_rng_u32(&r) / 4294967296.0 - 0.5) * scale;
        pm.gy = ((double)rfs_rng_u32(&r) / 4294967296.0 - 0.5) * scale;
        if (k % 10 == 0) {
            pm.gx = 0;
        }
        t.seek.model.self = &pm;
        rfs_q16_t ax, ay, bx, by;
        t.seek.model.ops = &pm_ops;
        assert_true(rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &ax, &ay));
        t.seek.model.ops = &pm_scan_ops;
        assert_true(rfs_gridmax_find(t.seek.map, &t.seek.model, t.seek.reach, &bx, &by));
        assert_int_equal(ax, bx);
        assert_int_equal(ay, by);
        /* Brute force in double over reachable lattice points: the value at the found
         * point is the maximum (up to the Q16 rounding of the model). */
        double best = -1e300;
        for (uint16_t j = 0; j < t.map.lh; ++j) {
            for (uint16_t i = 0; i < t.map.lw; ++i) {
                uint32_t idx = (uint32_t)j * t.map.lw + i;
                if (!((t.mem.reach[idx >> 3] >> (idx & 7)) & 1)) {
                    continue;
                }
                double x = (i + 0.5) * 0.25, y = (j + 0.5) * 0.25;
                best = fmax(best, pm.c + pm.gx * x + pm.gy * y);
            }
        }
        assert_true(pm.c + pm.gx * D(ax) + pm.gy * D(ay) >= best - 2.0 / 65536);
    }
    world_free(&t);
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

/* Dead zones (issue 10): the receiver reports itself up every period, with no packet.
 * Twin seekers, same seed and the same poses: A keeps getting packets, B only receiver
 * reports after the first second. Until A decides anew, B must drive exactly as A (the
 * goal and the drive law do not depend on the packets), with no stale flag. */
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
 * input, with the RSSI fault flag (issue 6), while poses keep coming; and again when the
 * reports stop after a stretch of reports without packets. */
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

/* Report stamps follow the measurements' rules (issue 9): older than the newest is
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

/* Reference lattice legality: the legal bit of the point's cell (double geometry). */
static int ref_lat_legal(const rfs_map_t *m, int i, int j)
{
    double g = m->cfg.grid, r = m->res;
    double x = floor(g / 2) + i * g, y = floor(g / 2) + j * g;
    return rfs_map_bit(m->legal, m->stride, (uint16_t)floor(x / r), (uint16_t)floor(y / r));
}

/* Reference edge legality: every cell the closed segment touches is legal and on the map. */
static int ref_step_legal(const rfs_map_t *m, int i0, int j0, int i1, int j1)
{
    double g = m->cfg.grid, r = m->res;
    double x0 = floor(g / 2) + i0 * g, y0 = floor(g / 2) + j0 * g;
    double x1 = floor(g / 2) + i1 * g, y1 = floor(g / 2) + j1 * g;
    int clo = (int)floor(fmin(x0, x1) / r) - 1, chi = (int)floor(fmax(x0, x1) / r) + 1;
    int rlo = (int)floor(fmin(y0, y1) / r) - 1, rhi = (int)floor(fmax(y0, y1) / r) + 1;
    for (int cj = rlo; cj <= rhi; cj++) {
        for (int ci = clo; ci <= chi; ci++) {
            if (ref_touch(x0, y0, x1, y1, r, ci, cj) &&
                (ci < 0 || cj < 0 || ci >= m->w || cj >= m->h ||
                 !rfs_map_bit(m->legal, m->stride, (uint16_t)ci, (uint16_t)cj))) {
                return 0;
            }
        }
    }
    return 1;
}

static int bit_of(const uint8_t *bits, int v)
{
    return (bits[v >> 3] >> (v & 7)) & 1;
}

static int ref_map_step(void *ctx, int ui, int uj, int vi, int vj)
{
    const rfs_map_t *m = ctx;
    return ref_lat_legal(m, vi, vj) && ref_step_legal(m, ui, uj, vi, vj);
}

/* A speckled 8 x 6 m map (2.5 % of the cells occupied, no clearance: many small pockets)
 * at cell size res, and the seeker's reach bits after its first period at a random legal
 * lattice point. They decide which plans the planner refuses without a search
 * (rfs_plan_set_component), so they must be exactly the robot's component: compared with
 * a double-precision flood. With an 8-entry queue the fill overflows and marks every legal
 * point instead (still a union of whole components). */
static void reach_case(uint32_t seed, double res, bool small_queue, int *in_component, int *legal)
{
    world_t t;
    memset(&t, 0, sizeof t);
    t.w = (uint16_t)lround(8.0 / res);
    t.h = (uint16_t)lround(6.0 / res);
    uint32_t bytes = rfs_map_bytes(t.w, t.h);
    uint16_t stride = (uint16_t)((t.w + 7) / 8);
    t.free_bits = calloc(bytes, 1);
    t.wall_bits = calloc(bytes, 1);
    t.legal_bits = calloc(bytes, 1);
    uint32_t s = seed * 2654435761u;
    for (uint16_t y = 0; y < t.h; ++y) {
        for (uint16_t x = 0; x < t.w; ++x) {
            s = s * 1664525u + 1013904223u;
            rfs_map_bit_set(t.free_bits, stride, x, y, (s >> 8) % 1000u >= 25u);
        }
    }
    rfs_map_cfg_t mc = rfs_map_cfg_default();
    mc.clearance = 0;
    assert_int_equal(rfs_map_init(&t.map, &mc, t.w, t.h, Q(res), 0, 0, t.free_bits,
                                  t.wall_bits, t.legal_bits), 0);
    int si, sj;
    do {
        s = s * 1664525u + 1013904223u;
        si = (int)((s >> 8) % t.map.lw);
        s = s * 1664525u + 1013904223u;
        sj = (int)((s >> 8) % t.map.lh);
    } while (!ref_lat_legal(&t.map, si, sj));
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    seek_make(&t, cfg, seed);
    if (small_queue) {
        t.mem.plan_queue_cap = 8;
        assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, rfs_ridge_model(&t.ridge),
                                       &rfs_target_rssi, &t.mem), 0);
    }
    double g = D(t.map.cfg.grid);
    rfs_pose_t p = pose_at(100000, g / 2 + si * g, g / 2 + sj * g, 0);
    rfs_seek_out_t out;
    rfs_seek_on_pose(&t.seek, &p, &t.rng);
    rfs_seek_on_rssi(&t.seek, 0, 100000, -50, &t.rng);
    rfs_seek_step(&t.seek, 100000, &t.rng, &out);
    uint8_t *ref = calloc(t.mem.reach_bytes, 1);
    ref_flood(t.map.lw, t.map.lh, si, sj, ref_map_step, &t.map, ref);
    for (int j = 0; j < t.map.lh; j++) {
        for (int i = 0; i < t.map.lw; i++) {
            int v = j * t.map.lw + i;
            int want = small_queue ? ref_lat_legal(&t.map, i, j) : bit_of(ref, v);
            if (bit_of(t.mem.reach, v) != want) {
                fail_msg("seed %u, %.3f m cells%s: point (%d, %d) reach %d, reference %d", seed,
                         res, small_queue ? ", 8-entry queue" : "", i, j, !want, want);
            }
            *in_component += bit_of(ref, v);
            *legal += ref_lat_legal(&t.map, i, j);
        }
    }
    free(ref);
    world_free(&t);
}

static void test_reach_is_the_component(void **state)
{
    (void)state;
    int comp = 0, legal = 0;
    for (uint32_t seed = 1; seed <= 12; seed++) {
        reach_case(seed, 0.125, false, &comp, &legal); /* step patterns */
        reach_case(seed, 0.1, false, &comp, &legal);   /* the exact traversal */
    }
    print_message("robot's components %d of %d legal lattice points\n", comp, legal);
    assert_true(comp > legal / 10 && comp < legal); /* pockets exist, the fill is not trivial */
    int c2 = 0, l2 = 0;
    reach_case(3, 0.125, true, &c2, &l2);
    reach_case(4, 0.1, true, &c2, &l2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_epsilon_schedule),
        cmocka_unit_test(test_defaults_are_the_papers),
        cmocka_unit_test(test_epsilon_goals_are_novel),
        cmocka_unit_test(test_blocked_step_line_search),
        cmocka_unit_test(test_stale_inputs_stop_wheels),
        cmocka_unit_test(test_heartbeat_keeps_goal_without_packets),
        cmocka_unit_test(test_no_packet_no_heartbeat_stops_wheels),
        cmocka_unit_test(test_heartbeat_never_makes_a_mean),
        cmocka_unit_test(test_heartbeat_stamps),
        cmocka_unit_test(test_grid_max_row_shortcut),
        cmocka_unit_test(test_reach_is_the_component),
        cmocka_unit_test(test_closed_loop_reaches_source),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
