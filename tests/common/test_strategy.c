/* test_strategy.c - the baseline strategies of issue 7 in rfs_seek: each decision rule
 * against a synthetic field computed here in double precision.
 *
 * The robot is "teleported": when the seeker decides a goal, the test moves the reported
 * pose onto the goal after a hold time, so the drive reports it reached and the seeker
 * decides again. Measurements come from the double-precision field at the reported
 * position, dithered so that a 1 s mean of int8 dBm carries the field to ~0.01 dB.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


#include "seek_world.h"

#define PI 3.14159265358979323846

/* The synthetic field, dB, in double precision. */
typedef struct field {
    int kind;            /* 0: log-distance from (sx, sy); 1: plane a + bx x + by y; 2: scripted */
    double sx, sy;       /* source, metres */
    double a, bx, by;    /* plane, dB and dB per metre */
    double scripted;     /* kind 2: the value of the current leg, whatever the position */
} field_t;

static double field_at(const field_t *f, double x, double y)
{
    if (f->kind == 0) {
        double d = hypot(x - f->sx, y - f->sy);
        return -40.0 - 30.0 * log10(d < 1.0 ? 1.0 : d);
    }
    if (f->kind == 1) {
        return f->a + f->bx * x + f->by * y;
    }
    return f->scripted;
}

/* Simulated time and the teleporting robot. */
typedef struct run {
    int64_t t_us;
    double x, y;           /* reported position, metres */
    bool pending;          /* a goal is waiting to be reached */
    double gx, gy;         /* its position */
    int64_t arrive_us;     /* when the robot appears there */
    uint32_t pkt;          /* packets sent (dither phase) */
} run_t;

/* Advance until the next decision (or max_us); packets at 100 Hz, poses and control at
 * 20 Hz; a decided goal is reached hold_us later. Returns false on timeout. */
static bool next_decision(world_t *t, run_t *r, const field_t *f, int64_t hold_us,
                          int64_t max_us, rfs_seek_out_t *out)
{
    int64_t end = r->t_us + max_us;
    while (r->t_us < end) {
        r->t_us += 10000;
        if (r->pending && r->t_us >= r->arrive_us) {
            r->x = r->gx;
            r->y = r->gy;
            r->pending = false;
        }
        /* Dither: a golden-ratio sequence, so 100 packets average to the field. */
        double v = field_at(f, r->x, r->y);
        double u = fmod((double)r->pkt++ * 0.6180339887498949, 1.0);
        int8_t dbm = (int8_t)floor(v + u);
        rfs_seek_on_rssi(&t->seek, 0, r->t_us, dbm, &t->rng);
        if (r->t_us % 50000 == 0) {
            rfs_pose_t p = { r->t_us, Q(r->x), Q(r->y), 0 };
            rfs_seek_on_pose(&t->seek, &p, &t->rng);
            rfs_seek_step(&t->seek, r->t_us, &t->rng, out);
            if (out->decided) {
                r->pending = true;
                r->gx = D(out->decision.goal_x);
                r->gy = D(out->decision.goal_y);
                r->arrive_us = r->t_us + hold_us;
                return true;
            }
        }
    }
    return false;
}

static double angle_diff_deg(double a, double b)
{
    double d = fmod(a - b + 3.0 * PI, 2.0 * PI) - PI;
    return fabs(d) * 180.0 / PI;
}

/* fd-gradient in the open: probe p + 1 m x, then p + 1 m y, each after standing one
 * window; then a 1 m step from p along the finite-difference gradient, whose direction
 * matches the double-precision finite differences and the analytic gradient. */
static void test_fd_gradient_direction(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 20.0, 20.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.strategy = RFS_SEEK_FD_GRADIENT;
    seek_make(&t, cfg, 7);
    field_t f = { .kind = 0, .sx = 16.0, .sy = 9.0 };
    run_t r = { .x = 6.0, .y = 5.0 };
    rfs_seek_out_t out;
    /* Probe along x. */
    assert_true(next_decision(&t, &r, &f, 100000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_PROBE);
    assert_true(fabs(D(out.decision.goal_x) - 7.0) < 1e-3);
    assert_true(fabs(D(out.decision.goal_y) - 5.0) < 1e-3);
    /* It stood still for one window before deciding (1 s, paper's averaging). */
    assert_true(r.t_us >= 1000000);
    /* Probe along y, from the x probe. */
    assert_true(next_decision(&t, &r, &f, 100000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_PROBE);
    assert_true(fabs(D(out.decision.goal_x) - 6.0) < 1e-3);
    assert_true(fabs(D(out.decision.goal_y) - 6.0) < 1e-3);
    /* The gradient step from p. */
    assert_true(next_decision(&t, &r, &f, 100000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_GRADIENT);
    double dx = D(out.decision.goal_x) - 6.0, dy = D(out.decision.goal_y) - 5.0;
    assert_true(fabs(hypot(dx, dy) - 1.0) < 2e-3);
    double m0 = field_at(&f, 6.0, 5.0);
    double fd = atan2(field_at(&f, 6.0, 6.0) - m0, field_at(&f, 7.0, 5.0) - m0);
    double analytic = atan2(9.0 - 5.0, 16.0 - 6.0);
    double got = atan2(dy, dx);
    assert_true(angle_diff_deg(got, fd) < 1.0);
    /* Finite differences over 1 m at 11 m from the source: a few degrees off the truth. */
    assert_true(angle_diff_deg(got, analytic) < 5.0);
    /* The next cycle starts at the new p with a probe along x from there. */
    assert_true(next_decision(&t, &r, &f, 100000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_PROBE);
    assert_true(fabs(D(out.decision.goal_x) - (6.0 + dx + 1.0)) < 1e-3);
    assert_true(fabs(D(out.decision.goal_y) - (5.0 + dy)) < 1e-3);
    world_free(&t);
}

/* Next to a wall, p + 1 m x is illegal: fd-gradient probes p - 1 m x instead and flips
 * the sign of that difference, so the step still climbs the field. */
static void test_fd_gradient_probe_flips_at_wall(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 10.0, 12.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.strategy = RFS_SEEK_FD_GRADIENT;
    seek_make(&t, cfg, 3);
    field_t f = { .kind = 0, .sx = 2.0, .sy = 9.0 };
    const double px = 9.3, py = 6.5;
    run_t r = { .x = px, .y = py };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 100000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_PROBE);
    assert_true(fabs(D(out.decision.goal_x) - (px - 1.0)) < 1e-3);
    assert_true(next_decision(&t, &r, &f, 100000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_PROBE);
    assert_true(fabs(D(out.decision.goal_y) - (py + 1.0)) < 1e-3);
    assert_true(next_decision(&t, &r, &f, 100000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_GRADIENT);
    double m0 = field_at(&f, px, py);
    double gx = -(field_at(&f, px - 1.0, py) - m0), gy = field_at(&f, px, py + 1.0) - m0;
    double got = atan2(D(out.decision.goal_y) - py, D(out.decision.goal_x) - px);
    assert_true(angle_diff_deg(got, atan2(gy, gx)) < 1.0);
    assert_true(angle_diff_deg(got, atan2(9.0 - py, 2.0 - px)) < 8.0);
    world_free(&t);
}

/* Ridge regression (alpha 1, unpenalised intercept, metres) in double on the stored
 * samples within 5 m of (qx, qy): the slopes scikit-learn's Ridge(alpha=1.0) gives. */
static void ridge_double(const rfs_seek_t *s, double qx, double qy, double *wx, double *wy)
{
    double n = 0, mx = 0, my = 0, mz = 0;
    long qxc = lround(qx * 100.0), qyc = lround(qy * 100.0);
    for (int pass = 0; pass < 2; ++pass) {
        double sxx = 0, sxy = 0, syy = 0, sxz = 0, syz = 0;
        for (uint16_t i = 0; i < s->store.count; ++i) {
            const rfs_sample_t *p = &s->store.samples[i];
            long u = p->x_cm - qxc, v = p->y_cm - qyc;
            if (u * u + v * v > 500L * 500L) {
                continue;
            }
            double x = p->x_cm / 100.0, y = p->y_cm / 100.0, z = p->v_q6 / 64.0;
            if (pass == 0) {
                n += 1;
                mx += x;
                my += y;
                mz += z;
                continue;
            }
            x -= mx;
            y -= my;
            z -= mz;
            sxx += x * x;
            sxy += x * y;
            syy += y * y;
            sxz += x * z;
            syz += y * z;
        }
        if (pass == 0) {
            mx /= n;
            my /= n;
            mz /= n;
            continue;
        }
        sxx += 1.0;
        syy += 1.0;
        double det = sxx * syy - sxy * sxy;
        *wx = (syy * sxz - sxy * syz) / det;
        *wy = (sxx * syz - sxy * sxz) / det;
    }
}

/* plane-gradient on a plane field: after the initial move every decision relearns and is
 * a 1 m gradient step (never epsilon, never greedy) along the gradient of the ridge plane
 * refit on the samples at that moment (checked against a double-precision ridge), which
 * climbs the field. (Its samples lie on a line, so the fit only knows the slope along it:
 * the step keeps that line - section 4.1's gradient view has no exploration to fix it.) */
static void test_plane_gradient_follows_plane(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 30.0, 30.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.strategy = RFS_SEEK_PLANE_GRADIENT;
    seek_make(&t, cfg, 11);
    field_t f = { .kind = 1, .a = -70.0, .bx = 2.0, .by = 1.0 };
    run_t r = { .x = 6.0, .y = 6.0 };
    rfs_seek_out_t out;
    /* The initial random move (paper section 2), slow enough to gather samples on it. */
    assert_true(next_decision(&t, &r, &f, 1500000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
    for (int k = 1; k <= 10; ++k) {
        assert_true(next_decision(&t, &r, &f, 1500000, 5000000, &out));
        assert_int_equal(out.decision.iteration, (uint32_t)k);
        assert_int_equal(out.decision.kind, RFS_SEEK_GRADIENT);
        assert_true(out.decision.relearned);
        double x0 = D(out.decision.x), y0 = D(out.decision.y);
        double dx = D(out.decision.goal_x) - x0, dy = D(out.decision.goal_y) - y0;
        assert_true(fabs(hypot(dx, dy) - 1.0) < 2e-3);
        double wx, wy;
        ridge_double(&t.seek, x0, y0, &wx, &wy);
        assert_true(angle_diff_deg(atan2(dy, dx), atan2(wy, wx)) < 0.5);
        assert_true(f.bx * dx + f.by * dy > 0.5); /* uphill */
    }
    world_free(&t);
}

/* chemotaxis, its rule: after a rise it runs on in the same heading (tumble_better = 0),
 * after a fall it tumbles to a different heading (tumble_worse = 1). The values are
 * scripted per leg and do not depend on the position. */
static void test_chemotaxis_run_and_tumble(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 60.0, 60.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.strategy = RFS_SEEK_CHEMOTAXIS;
    cfg.tumble_better = 0;
    cfg.tumble_worse = RFS_Q16_ONE;
    seek_make(&t, cfg, 5);
    static const double legs[] = { -60, -58, -55, -57, -54, -54, -50, -49, -52, -48, -47 };
    field_t f = { .kind = 2, .scripted = legs[0] };
    run_t r = { .x = 30.0, .y = 30.0 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1200000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_TUMBLE);
    double prev = atan2(D(out.decision.goal_y) - 30.0, D(out.decision.goal_x) - 30.0);
    for (size_t k = 1; k < sizeof legs / sizeof legs[0]; ++k) {
        double x0 = r.gx, y0 = r.gy;
        f.scripted = legs[k]; /* the leg now driven has this value */
        assert_true(next_decision(&t, &r, &f, 1200000, 5000000, &out));
        assert_true(fabs(D(out.decision.mean) - legs[k]) < 0.05);
        double dx = D(out.decision.goal_x) - x0, dy = D(out.decision.goal_y) - y0;
        assert_true(fabs(hypot(dx, dy) - 1.0) < 2e-3);
        double h = atan2(dy, dx);
        if (legs[k] > legs[k - 1]) {
            assert_int_equal(out.decision.kind, RFS_SEEK_RUN);
            assert_true(angle_diff_deg(h, prev) < 0.5);
        } else {
            assert_int_equal(out.decision.kind, RFS_SEEK_TUMBLE);
            assert_true(angle_diff_deg(h, prev) > 20.0); /* a sixteenth of a turn at least */
        }
        /* Headings are sixteenths of a turn. */
        double sixteenths = h / (2.0 * PI / 16.0);
        assert_true(fabs(sixteenths - round(sixteenths)) < 0.01);
        prev = h;
    }
    world_free(&t);
}

/* chemotaxis uses no position: the same seed and the same measured values from two
 * different start points give the same sequence of headings. */
static void test_chemotaxis_ignores_position(void **state)
{
    (void)state;
    double heads[2][12];
    for (int run = 0; run < 2; ++run) {
        world_t t;
        world_make(&t, 60.0, 60.0, 0, 0);
        rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
        cfg.strategy = RFS_SEEK_CHEMOTAXIS;
        seek_make(&t, cfg, 99);
        field_t f = { .kind = 2, .scripted = -70.0 };
        run_t r = { .x = run ? 33.0 : 25.0, .y = run ? 22.0 : 31.0 };
        rfs_seek_out_t out;
        for (int k = 0; k < 12; ++k) {
            double x0 = k ? r.gx : r.x, y0 = k ? r.gy : r.y;
            f.scripted = -70.0 + 3.0 * sin(1.7 * k); /* rises and falls */
            assert_true(next_decision(&t, &r, &f, 1200000, 5000000, &out));
            heads[run][k] = atan2(D(out.decision.goal_y) - y0, D(out.decision.goal_x) - x0);
        }
        world_free(&t);
    }
    int tumbles = 0;
    for (int k = 0; k < 12; ++k) {
        assert_true(angle_diff_deg(heads[0][k], heads[1][k]) < 0.5);
        tumbles += k > 0 && angle_diff_deg(heads[0][k], heads[0][k - 1]) > 0.5;
    }
    assert_true(tumbles > 0 && tumbles < 11); /* both runs and tumbles happened */
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
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META);
    assert_int_equal(cfg.recheck_dist, 0);
    assert_false(cfg.eps_by_travel);
    assert_false(cfg.eps_geodesic);
    assert_false(cfg.eps_sample);
    cfg.recheck_dist = -1;
    assert_int_equal(init_result(cfg), -1);
}

/* eps_by_travel: epsilon's n is the larger of the iteration and the whole steps of
 * straight travel between decision points, summed here in double precision; the
 * epsilon reported equals 0.9 e^(-a n) + 0.1 with a = ln(9/4) / 5 in double. */
static void test_eps_by_travel(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 30.0, 30.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.recheck_dist = 0; /* this test: the index alone */
    seek_make(&t, cfg, 5);
    field_t f = { .kind = 0, .sx = 24.0, .sy = 24.0 };
    run_t r = { .x = 6.0, .y = 6.0 };
    rfs_seek_out_t out;
    double travel = 0.0, px = 0.0, py = 0.0;
    int checked = 0, beyond = 0;
    for (int k = 0; k <= 30; ++k) {
        assert_true(next_decision(&t, &r, &f, 1000000, 60000000, &out));
        double x = D(out.decision.x), y = D(out.decision.y);
        if (k > 0) {
            travel += hypot(x - px, y - py);
        }
        px = x;
        py = y;
        if (k == 0) {
            continue;
        }
        double whole = floor(travel);
        if (travel - whole < 1e-3 || travel - whole > 1.0 - 1e-3) {
            continue; /* too close to a step boundary to call in fixed point */
        }
        double n = whole > (double)out.decision.iteration ? whole : (double)out.decision.iteration;
        beyond += whole > (double)out.decision.iteration;
        double want = 0.9 * exp(-log(9.0 / 4.0) / 5.0 * n) + 0.1;
        assert_true(fabs(D(out.decision.epsilon) - want) < 2e-4);
        checked++;
    }
    assert_true(checked >= 20);
    assert_true(beyond >= 5); /* the travel, not the iteration, set n in some */
    world_free(&t);
}

/* recheck_dist: a greedy leg whose 1 s mean departs from the model by more than the
 * threshold after recheck_dist of travel is abandoned (prev = running) and the next
 * decision relearns and goes greedy again without an epsilon draw; with recheck_dist 0
 * (the paper) the same leg runs to its end. epsilon is fixed at 0.5 so that an
 * unforced decision is greedy only about half the time. */
static void run_recheck(double recheck_m, int *jumps, int *jumps_abandoned, int *normal_eps)
{
    world_t t;
    world_make(&t, 30.0, 30.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.recheck_dist = Q(recheck_m);
    cfg.recheck_adapt = false; /* the fixed 3 dB rule; the adaptive one: test_recheck_adapt */
    cfg.eps_by_travel = false;
    cfg.eps_amp = 0;
    cfg.eps_floor = RFS_Q16_HALF;
    seek_make(&t, cfg, 9);
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

/* A model that knows its maximum (like the path-loss model's estimated source): a
 * constant prediction and a fixed argmax. */
typedef struct fixed_model {
    bool valid;
    rfs_q16_t mx, my;
} fixed_model_t;

static void fixed_reset(void *self)
{
    ((fixed_model_t *)self)->valid = false;
}

static rfs_fit_result_t fixed_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                  rfs_rng_t *rng)
{
    (void)in;
    (void)budget;
    (void)rng;
    ((fixed_model_t *)self)->valid = true;
    return RFS_FIT_DONE;
}

static bool fixed_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    (void)x;
    (void)y;
    *value = RFS_Q16_INT(-60);
    return ((const fixed_model_t *)self)->valid;
}

static bool fixed_argmax(const void *self, rfs_q16_t *x, rfs_q16_t *y)
{
    const fixed_model_t *m = self;
    *x = m->mx;
    *y = m->my;
    return m->valid;
}

static const rfs_model_ops_t k_fixed_ops = {
    .name = "fixed", .reset = fixed_reset, .fit = fixed_fit, .predict = fixed_predict,
    .argmax = fixed_argmax,
};

/* meta-path, a maximum the robot cannot reach (beyond a wall that seals the map): the
 * greedy goal is the reachable lattice point nearest to it (found here by brute force in
 * double over the legal lattice points on the robot's side), not an epsilon move. */
static void test_meta_path_unreachable_maximum(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 20.0, 10.0, 10.0, 10.0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.eps_amp = 0;
    cfg.eps_floor = 0; /* every decision after the first is greedy */
    seek_make(&t, cfg, 3);
    fixed_model_t fm = { false, Q(15.0), Q(5.3) };
    rfs_model_t model = { &k_fixed_ops, &fm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.0, .y = 5.0 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_GREEDY);
    assert_true(fabs(D(out.decision.max_x) - 15.0) < 1e-4);
    double best = INFINITY, bx = 0, by = 0;
    for (uint16_t j = 0; j < t.map.lh; ++j) {
        for (uint16_t i = 0; i < t.map.lw; ++i) {
            rfs_q16_t px, py;
            rfs_map_lattice_point(&t.map, i, j, &px, &py);
            if (!rfs_map_lattice_legal(&t.map, i, j) || D(px) > 10.0) {
                continue;
            }
            double d = hypot(D(px) - 15.0, D(py) - 5.3);
            if (d < best - 1e-9) {
                best = d;
                bx = D(px);
                by = D(py);
            }
        }
    }
    assert_true(fabs(D(out.decision.goal_x) - bx) < 1e-4);
    assert_true(fabs(D(out.decision.goal_y) - by) < 1e-4);
    assert_true(bx < 10.0 && bx > 9.0); /* against the wall, on the robot's side */
    world_free(&t);
}


/* A model that also draws (rfs_model_ops_t.sample): always the point (sx, sy). */
typedef struct sampling_model {
    fixed_model_t base; /* first: the fixed_* operations read it */
    rfs_q16_t sx, sy;
    int draws;
} sampling_model_t;

static bool fixed_sample(const void *self, rfs_rng_t *rng, rfs_q16_t *x, rfs_q16_t *y)
{
    (void)rng;
    sampling_model_t *m = (sampling_model_t *)(uintptr_t)self;
    m->draws++;
    *x = m->sx;
    *y = m->sy;
    return m->base.valid;
}

static const rfs_model_ops_t k_sampling_ops = {
    .name = "sampling", .reset = fixed_reset, .fit = fixed_fit, .predict = fixed_predict,
    .argmax = fixed_argmax, .sample = fixed_sample,
};

/* eps_sample (docs/STRATEGIES.md): an epsilon decision goes the whole way to the model's
 * draw, 10.5 m away here (the planned path of an open room is the straight line, its
 * length the distance in double); a draw within 1.5 steps of the robot, a draw where the
 * robot has been (the start, 2 m behind it: within the novelty radius of a past
 * position), a draw 1.25 m away (within 1.5 steps), a robot standing at the model's maximum, the option off or a model that
 * draws nothing give the novelty move (within the 8 m epsilon radius). */
enum { DRAW_AHEAD = 0, DRAW_AT_START = 1, MAX_AT_ROBOT = 2, DRAW_NEAR = 3 };

static void eps_sample_case(bool on, const rfs_model_ops_t *ops, double dx, bool expect,
                            int where)
{
    world_t t;
    world_make(&t, 20.0, 10.0, 0, 0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    assert_true(cfg.eps_sample); /* the preset's */
    cfg.eps_sample = on;
    cfg.eps_amp = 0;
    cfg.eps_floor = RFS_Q16_ONE; /* every decision after the first is epsilon */
    seek_make(&t, cfg, 5);
    sampling_model_t sm = { { false, Q(15.0), Q(5.0) }, 0, 0, 0 };
    rfs_model_t model = { ops, &sm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.125, .y = 5.125 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 0, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
    r.x = r.gx; /* arrive at once */
    r.y = r.gy;
    r.pending = false;
    sm.sx = where == DRAW_AT_START ? Q(4.125) : Q(r.x + dx);
    sm.sy = where == DRAW_AT_START ? Q(5.125) : Q(r.y);
    /* Beyond the near rule, except where the case tests it. */
    assert_true((hypot(D(sm.sx) - r.x, D(sm.sy) - r.y) >= 1.5) == (where != DRAW_NEAR));
    if (where == MAX_AT_ROBOT) {
        sm.base.mx = Q(r.x);
        sm.base.my = Q(r.y);
    }
    assert_true(next_decision(&t, &r, &f, 0, 5000000, &out));
    const rfs_seek_decision_t *d = &out.decision;
    assert_int_equal(d->kind, RFS_SEEK_EPSILON);
    assert_int_equal(d->sampled, expect);
    double len = hypot(D(d->goal_x) - D(d->x), D(d->goal_y) - D(d->y));
    if (expect) {
        assert_true(fabs(D(d->goal_x) - D(sm.sx)) < 1e-4 && fabs(D(d->goal_y) - D(sm.sy)) < 1e-4);
        assert_true(fabs(D(d->path_len) - dx) < 0.01);
        assert_true(fabs(D(d->max_x) - D(sm.sx)) < 1e-4);
    } else {
        assert_true(len <= 8.0 * sqrt(2.0) + 1e-3); /* the novelty draw's radius */
        assert_true(fabs(D(d->goal_x) - D(sm.sx)) > 1e-4 || fabs(D(d->goal_y) - D(sm.sy)) > 1e-4);
    }
    assert_int_equal(sm.draws > 0, on && ops->sample != NULL);
    world_free(&t);
}

static void test_eps_sample_goes_to_the_draw(void **state)
{
    (void)state;
    eps_sample_case(true, &k_sampling_ops, 10.5, true, DRAW_AHEAD);
    eps_sample_case(true, &k_sampling_ops, 1.25, false, DRAW_NEAR);
    eps_sample_case(true, &k_sampling_ops, 10.5, false, DRAW_AT_START);
    eps_sample_case(true, &k_sampling_ops, 10.5, false, MAX_AT_ROBOT);
    eps_sample_case(false, &k_sampling_ops, 10.5, false, DRAW_AHEAD);
    eps_sample_case(true, &k_fixed_ops, 10.5, false, DRAW_AHEAD); /* the model does not draw */
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
    rfs_model_t model = { &k_fixed_ops, &fm };
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

/* The geodesic epsilon step (cfg.eps_geodesic, docs/STRATEGIES.md) against a double-
 * precision reference. The map: 10 m x 8 m with a one-cell wall at x in [5.2, 5.3)
 * from the floor to y = 5.0; the only way to its far side is the gap above it. The robot
 * stands at the lattice point (4.625, 3.625), 0.575 m from the wall, 1.375 m below
 * its end. Every legal lattice point is a candidate (the epsilon radius, 8 m, covers the
 * map), except those within the 0.5 m novelty radius of the robot. */
#define GEO_WALL_X 5.2
#define GEO_WALL_TOP 5.0
#define GEO_RX 4.625
#define GEO_RY 3.625
/* Epsilon tries per decision (rfs_seek.c GOAL_TRIES); the last one is always kept. */
#define GEO_TRIES 6

/* The fixture's free cells, restated: the border and the wall column. */
static bool geo_free(int cx, int cy, int w, int h)
{
    if (cx <= 0 || cy <= 0 || cx >= w - 1 || cy >= h - 1) {
        return false;
    }
    return !(cx == (int)lround(GEO_WALL_X / RES) && (cy + 0.5) * RES < GEO_WALL_TOP);
}

/* rfs_map.h's rule in cell units: a cell is legal when every cell whose closed square
 * comes closer than the clearance (0.25 m = 2.5 cells) to its centre is on the map and
 * free. Offsets are whole cells, so the squared gaps are exact in double. */
static bool geo_legal_cell(int cx, int cy, int w, int h)
{
    for (int dy = -3; dy <= 3; ++dy) {
        for (int dx = -3; dx <= 3; ++dx) {
            double ex = abs(dx) > 0 ? abs(dx) - 0.5 : 0.0, ey = abs(dy) > 0 ? abs(dy) - 0.5 : 0.0;
            if (ex * ex + ey * ey >= 6.25) {
                continue;
            }
            int x = cx + dx, y = cy + dy;
            if (x < 0 || y < 0 || x >= w || y >= h || !geo_free(x, y, w, h)) {
                return false;
            }
        }
    }
    return true;
}

/* The segment p-q does not enter the obstacle's interior x0 < x < x1, y < y1 (Liang-
 * Barsky clip; touching its boundary is allowed: the taut length is an infimum). */
static bool geo_sees(double px, double py, double qx, double qy, double x0, double x1, double y1)
{
    double t0 = 0.0, t1 = 1.0, dx = qx - px, dy = qy - py;
    double pp[3] = { -dx, dx, dy }, qq[3] = { px - x0, x1 - px, y1 - py };
    for (int k = 0; k < 3; ++k) {
        if (pp[k] == 0.0) {
            if (qq[k] <= 0.0) {
                return true;
            }
            continue;
        }
        double r = qq[k] / pp[k];
        if (pp[k] < 0.0) {
            t0 = r > t0 ? r : t0;
        } else {
            t1 = r < t1 ? r : t1;
        }
    }
    return t0 >= t1; /* empty or a single touching point */
}

/* Shortest path length from the robot to (gx, gy) around the obstacle [x0, x1] x
 * (-inf, y1]: straight when it is in sight, else through its top corners a = (x0, y1),
 * b = (x1, y1) (the shortest path in a polygon bends only at reflex vertices). */
static double geo_taut(double gx, double gy, double x0, double x1, double y1)
{
    const double px = GEO_RX, py = GEO_RY;
    if (geo_sees(px, py, gx, gy, x0, x1, y1)) {
        return hypot(gx - px, gy - py);
    }
    double best = INFINITY;
    double cx[2] = { x0, x1 };
    for (int u = 0; u < 2; ++u) {
        for (int v = 0; v < 2; ++v) {
            /* robot -> corner u [-> corner v] -> goal */
            if (!geo_sees(px, py, cx[u], y1, x0, x1, y1) ||
                !geo_sees(cx[v], y1, gx, gy, x0, x1, y1)) {
                continue;
            }
            double l = hypot(cx[u] - px, y1 - py) + fabs(cx[v] - cx[u]) +
                       hypot(gx - cx[v], gy - y1);
            best = l < best ? l : best;
        }
    }
    return best;
}

/* Lattice point (i, j) is an epsilon candidate: legal, within the epsilon radius of the
 * robot's lattice point and beyond the 0.5 m novelty radius (q > 4: the robot only ever
 * stood there). Every legal lattice point is reachable: the legal cells are the floor
 * minus the inflated wall, a U of three rectangles, each at least two lattice steps
 * wide. Gives the point, metres, and its straight distance, metres. */
static bool geo_candidate(int i, int j, int w, int h, double *x, double *y, double *d)
{
    int ci = (int)lround((GEO_RX - 0.125) / 0.25), cj = (int)lround((GEO_RY - 0.125) / 0.25);
    int q = (i - ci) * (i - ci) + (j - cj) * (j - cj);
    *x = 0.125 + 0.25 * i;
    *y = 0.125 + 0.25 * j;
    *d = 0.25 * sqrt((double)q);
    return q > 4 && q <= RFS_SEEK_EPS_RADIUS * RFS_SEEK_EPS_RADIUS &&
           geo_legal_cell((int)floor(*x / RES), (int)floor(*y / RES), w, h);
}

static bool geo_far(double x, double y)
{
    return x > GEO_WALL_X + 0.1 && y < GEO_WALL_TOP;
}

/* The inflated wall: the illegal cells around the wall column, x in [5.0, 5.5), y below
 * 5.2 (the wall's cells plus 2 cells of clearance mask); a legal segment touches none
 * of their closed squares, so every legal path is at least the taut length around it. */
#define GEO_OB_X0 5.0
#define GEO_OB_X1 5.5
#define GEO_OB_Y1 5.2
/* The planner's excess over the taut length, metres: its path bends at lattice points
 * (0.25 m apart) beside the two corners instead of on them, and string pulling of the
 * octile path is greedy. Asserted below for every far candidate (measured at most 0.52 m
 * when this test was written); 0.6 m leaves margin. */
#define GEO_EXCESS 0.6

/* Far-side probability of one decision in double: proposal p ~ e^(-d) over the
 * candidates; with geodesic, kept with a = e^(-(L - d)), L the taut length plus
 * `excess` where the path bends, and the 6th try always kept:
 * P(x) = p a (1 - (1 - A)^5) / A + (1 - A)^5 p, A = sum p a. */
static double geo_far_prob(bool geodesic, double excess, int *ncand)
{
    world_t t;
    world_make(&t, 10.0, 8.0, GEO_WALL_X, GEO_WALL_TOP);
    int w = t.w, h = t.h, lw = t.map.lw, lh = t.map.lh;
    world_free(&t);
    double wsum = 0.0, wfar = 0.0, asum = 0.0, afar = 0.0;
    *ncand = 0;
    for (int j = 0; j < lh; ++j) {
        for (int i = 0; i < lw; ++i) {
            double x, y, d;
            if (!geo_candidate(i, j, w, h, &x, &y, &d)) {
                continue;
            }
            (*ncand)++;
            double wt = exp(-d), a = 1.0;
            double l = geo_taut(x, y, GEO_OB_X0, GEO_OB_X1, GEO_OB_Y1);
            if (geodesic && l > d + 1e-9) {
                a = exp(-(l + excess - d));
            }
            wsum += wt;
            asum += wt * a;
            wfar += geo_far(x, y) ? wt : 0.0;
            afar += geo_far(x, y) ? wt * a : 0.0;
        }
    }
    if (!geodesic) {
        return wfar / wsum;
    }
    double A = asum / wsum, miss = pow(1.0 - A, GEO_TRIES - 1);
    return (afar / wsum) * (1.0 - miss) / A + miss * wfar / wsum;
}

/* n epsilon decisions, each from a freshly initialised seeker at the robot's point: the
 * first decision (the initial move) finds no goal (initial_step_max below one lattice
 * step), the second is the epsilon draw (epsilon = 1). Returns the far-side count. When
 * check_plan, also plans to every far candidate and asserts taut <= L <= taut + excess,
 * with rfs_plan_path and with the search tree the geodesic decision plans with. */
static int geo_far_draws(bool geodesic, int n, bool check_plan)
{
    world_t t;
    world_make(&t, 10.0, 8.0, GEO_WALL_X, GEO_WALL_TOP);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.eps_geodesic = geodesic;
    cfg.initial_step_max = Q(0.1);
    cfg.eps_amp = 0;
    cfg.eps_floor = RFS_Q16_ONE;
    seek_make(&t, cfg, 1);
    fixed_model_t fm = { false, Q(1.0), Q(1.0) };
    rfs_model_t model = { &k_fixed_ops, &fm };
    field_t f = { .kind = 2, .scripted = -60.0 };
    int far = 0;
    for (int k = 0; k < n; ++k) {
        assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
        rfs_rng_seed(&t.rng, 1000u + (uint64_t)k);
        run_t r = { .x = GEO_RX, .y = GEO_RY };
        rfs_seek_out_t out;
        assert_true(next_decision(&t, &r, &f, 0, 5000000, &out));
        assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
        assert_true(next_decision(&t, &r, &f, 0, 5000000, &out));
        assert_int_equal(out.decision.kind, RFS_SEEK_EPSILON);
        assert_int_equal(out.faults & RFS_SEEK_FAULT_NO_GOAL, 0);
        far += geo_far(D(out.decision.goal_x), D(out.decision.goal_y));
    }
    /* Both planners the seeker uses: rfs_plan_path (pass 0) and, as the geodesic
     * decision plans, one search tree from the robot for every goal (pass 1). */
    double worst[2] = { 0.0, 0.0 };
    for (int pass = 0; check_plan && pass < 2; ++pass) {
        if (pass == 1) {
            rfs_plan_tree_begin(&t.seek.plan, Q(GEO_RX), Q(GEO_RY));
        }
        for (int j = 0; j < t.map.lh; ++j) {
            for (int i = 0; i < t.map.lw; ++i) {
                double x, y, d;
                if (!geo_candidate(i, j, t.w, t.h, &x, &y, &d) || !geo_far(x, y)) {
                    continue;
                }
                assert_true(rfs_map_lattice_legal(&t.map, (uint16_t)i, (uint16_t)j));
                rfs_path_t p;
                assert_true(pass == 0 ? rfs_plan_path(&t.seek.plan, Q(GEO_RX), Q(GEO_RY), Q(x),
                                                      Q(y), &p)
                                      : rfs_plan_tree_path(&t.seek.plan, Q(x), Q(y), &p));
                double l = geo_taut(x, y, GEO_OB_X0, GEO_OB_X1, GEO_OB_Y1);
                assert_true(D(p.length) > l - 1e-3 && D(p.length) < l + GEO_EXCESS);
                worst[pass] = D(p.length) - l > worst[pass] ? D(p.length) - l : worst[pass];
            }
        }
    }
    if (check_plan) {
        print_message("largest excess over the taut length: rfs_plan_path %.3f m, tree %.3f m\n",
                      worst[0], worst[1]);
    }
    world_free(&t);
    return far;
}

/* The far side of the wall is about a quarter of the mass under e^(-straight distance)
 * and under 5 % when a goal behind the wall counts its way round. n = 10000 draws each;
 * tolerance 4 binomial sigma. eps_geodesic off: the paper's rule, exact in double (the
 * Q0.16 weight table moves it by < 0.001). On: between the reference with the taut
 * path lengths (a lower bound of any legal path) and with taut + GEO_EXCESS wherever a
 * path bends (the planner's bound, asserted). */
static void test_eps_geodesic_distribution(void **state)
{
    (void)state;
    const int n = 10000;
    int nc;
    double p_off = geo_far_prob(false, 0.0, &nc);
    assert_int_equal(nc, 1088); /* 40 x 32 lattice - 179 illegal - 13 visited */
    double p_hi = geo_far_prob(true, 0.0, &nc), p_lo = geo_far_prob(true, GEO_EXCESS, &nc);
    assert_true(p_off > 0.2 && p_hi < 0.06 && p_lo > 0.01); /* the map separates the rules */
    double f_off = geo_far_draws(false, n, false) / (double)n;
    double f_on = geo_far_draws(true, n, true) / (double)n;
    double s_off = sqrt(p_off * (1.0 - p_off) / n);
    double s_lo = sqrt(p_lo * (1.0 - p_lo) / n), s_hi = sqrt(p_hi * (1.0 - p_hi) / n);
    if (fabs(f_off - p_off) > 4.0 * s_off || f_on < p_lo - 4.0 * s_lo || f_on > p_hi + 4.0 * s_hi) {
        print_error("far side: off %.4f (want %.4f), on %.4f (want %.4f..%.4f)\n", f_off, p_off,
                    f_on, p_lo, p_hi);
        fail();
    }
}


/* Names round-trip and the unit vector against double precision. */
static void test_names_and_unit(void **state)
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
    rfs_q16_t ux, uy;
    assert_false(rfs_seek_unit(0, 0, &ux, &uy));
    static const double g[][2] = { { 3, 4 }, { -0.001, 0.002 }, { 20000, -1 }, { -5, -12 } };
    for (size_t i = 0; i < 4; ++i) {
        assert_true(rfs_seek_unit(Q(g[i][0]), Q(g[i][1]), &ux, &uy));
        double n = hypot(D(Q(g[i][0])), D(Q(g[i][1])));
        assert_true(fabs(D(ux) - D(Q(g[i][0])) / n) < 1e-4);
        assert_true(fabs(D(uy) - D(Q(g[i][1])) / n) < 1e-4);
    }
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    assert_int_equal(cfg.strategy, RFS_SEEK_META); /* the paper's is the default */
    cfg.strategy = RFS_SEEK_STRATEGY_COUNT;
    assert_int_equal(init_result(cfg), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fd_gradient_direction),
        cmocka_unit_test(test_fd_gradient_probe_flips_at_wall),
        cmocka_unit_test(test_plane_gradient_follows_plane),
        cmocka_unit_test(test_chemotaxis_run_and_tumble),
        cmocka_unit_test(test_chemotaxis_ignores_position),
        cmocka_unit_test(test_no_goal_backs_off),
        cmocka_unit_test(test_names_and_unit),
        cmocka_unit_test(test_meta_path_preset),
        cmocka_unit_test(test_eps_by_travel),
        cmocka_unit_test(test_recheck_abandons_leg),
        cmocka_unit_test(test_recheck_adapt),
        cmocka_unit_test(test_meta_path_unreachable_maximum),
        cmocka_unit_test(test_eps_sample_goes_to_the_draw),
        cmocka_unit_test(test_null_move_backs_off),
        cmocka_unit_test(test_eps_geodesic_distribution),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
