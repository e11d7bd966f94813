/* test_seek_stall.c - meta-path's answers to a stall (common/rfs_seek_meta.c,
 * docs/STRATEGIES.md "Stalls"): ruling out a refuted or swept estimate (refute_r,
 * refute_reached, local_refute, floor_gap) and the bounded local search round it
 * (local_r, local_gap), each against a reference computed here in double precision.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ref_geom.h"
#include "rfs_seek_internal.h"
#include "seek_run.h"

/* refute_r (docs/STRATEGIES.md, "Stalls"): a model that knows its maximum, predicts -60
 * dB everywhere, records the places ruled out that each fit is given, and moves its
 * maximum to the next point of a 1.5 m x 2 m grid at every fit. The robot, teleported
 * onto every goal, stands at the maximum at each decision after the first greedy one.
 * The places expected are kept here in double: the maximum when the robot stands within
 * half a step of it and the 1 s mean is weaker than -60 dB by more than 6 dB, the
 * latest RFS_MODEL_MAX_EXCL of them. */
typedef struct refute_model {
    fixed_model_t base; /* first: the fixed_* operations read it */
    int fits;
    int nexcl;           /* what the latest fit was given */
    double ex[RFS_MODEL_MAX_EXCL], ey[RFS_MODEL_MAX_EXCL], r;
    double want_x[64], want_y[64]; /* every refutation expected so far, oldest first */
    int nwant;
    double mean;         /* the scripted 1 s mean */
    bool silent;         /* no packet at the decisions, the receiver up */
    bool reached;        /* cfg.refute_reached: every decision at the maximum rules it out */
    bool mismatch;       /* a fit was given other places than expected */
} refute_model_t;

static void refute_point(int k, double *x, double *y)
{
    *x = 2.125 + 1.5 * (double)(k % 11);
    *y = 2.125 + 2.0 * (double)((k / 11) % 3);
}

static rfs_fit_result_t refute_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                   rfs_rng_t *rng)
{
    (void)budget;
    (void)rng;
    refute_model_t *m = self;
    /* The double rule at the query point (the robot), against the maximum held (reset
     * has just invalidated the model: any fit but the first had one). */
    if (m->fits > 0 &&
        hypot(D(in->qx) - D(m->base.mx), D(in->qy) - D(m->base.my)) <= 0.5 &&
        (m->silent || m->reached || -60.0 - m->mean > 6.0) && m->nwant < 64) {
        m->want_x[m->nwant] = D(m->base.mx);
        m->want_y[m->nwant] = D(m->base.my);
        m->nwant++;
    }
    int expect = m->nwant < (int)RFS_MODEL_MAX_EXCL ? m->nwant : (int)RFS_MODEL_MAX_EXCL;
    m->nexcl = in->nexcl;
    m->r = D(in->excl_r);
    if (in->nexcl != expect) {
        m->mismatch = true;
    }
    for (int e = 0; e < in->nexcl && e < expect; ++e) {
        m->ex[e] = in->excl_x_cm[e] / 100.0;
        m->ey[e] = in->excl_y_cm[e] / 100.0;
        /* Slots fill in order, then the oldest is overwritten: any order, the latest ones. */
        bool found = false;
        for (int w = m->nwant - expect; w < m->nwant; ++w) {
            found = found || (fabs(m->ex[e] - m->want_x[w]) < 0.0051 &&
                              fabs(m->ey[e] - m->want_y[w]) < 0.0051); /* to the cm */
        }
        m->mismatch = m->mismatch || !found;
    }
    m->fits++;
    double x, y;
    refute_point(m->fits, &x, &y);
    m->base.mx = Q(x);
    m->base.my = Q(y);
    m->base.valid = true;
    return RFS_FIT_DONE;
}

/* The refute worlds: a 20 x 10 m room, meta-path with every decision after the first
 * greedy, the seeker on model m (cleared) with cfg's refute settings. */
static void refute_world(world_t *t, rfs_seek_cfg_t cfg, refute_model_t *m)
{
    static const rfs_model_ops_t ops = {
        .name = "refute", .reset = fixed_reset, .fit = refute_fit, .predict = fixed_predict,
        .argmax = fixed_argmax,
    };
    world_make(t, 20.0, 10.0, 0, 0);
    cfg.eps_amp = 0;
    cfg.eps_floor = 0;
    cfg.local_r = 0; /* the robot stays at each maximum (no sweep round it) */
    seek_make(t, cfg, 5);
    memset(m, 0, sizeof *m);
    rfs_model_t model = { &ops, m };
    assert_int_equal(rfs_seek_init(&t->seek, &cfg, &t->map, model, &rfs_target_rssi, &t->mem), 0);
}

static int refute_case(double mean, bool on, bool reached, int decisions, refute_model_t *m)
{
    world_t t;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    assert_int_equal(cfg.refute_r, cfg.step); /* the preset's */
    cfg.refute_r = on ? cfg.refute_r : 0;
    cfg.refute_reached = reached;
    refute_world(&t, cfg, m);
    m->mean = mean;
    m->reached = reached;
    field_t f = { .kind = 2, .scripted = mean };
    run_t r = { .x = 4.125, .y = 5.125 };
    rfs_seek_out_t out;
    int refuted = 0;
    for (int k = 0; k < decisions; ++k) {
        assert_true(next_decision(&t, &r, &f, 500000, 5000000, &out));
        refuted += out.decision.refuted ? 1 : 0;
    }
    world_free(&t);
    return refuted;
}

/* The same model in silence: packets (-60 dBm) for the first 1.5 s only, then the
 * receiver's reports alone, every 10 ms; the robot teleported onto each goal 0.5 s after
 * it is decided. Returns the decisions that ruled a place out. */
static int refute_silent(refute_model_t *m, int decisions)
{
    world_t t;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    refute_world(&t, cfg, m);
    m->silent = true;
    double x = 4.125, y = 5.125, gx = x, gy = y;
    int64_t arrive = -1;
    int refuted = 0, decided = 0;
    for (int64_t now = 10000; decided < decisions && now < 600000000; now += 10000) {
        if (arrive >= 0 && now >= arrive) {
            x = gx;
            y = gy;
            arrive = -1;
        }
        if (now < 1500000) {
            rfs_seek_on_rssi(&t.seek, 0, now, -60, &t.rng);
        }
        assert_true(rfs_seek_on_receiver(&t.seek, now));
        if (now % 50000 == 0) {
            rfs_seek_out_t out;
            rfs_pose_t p = { now, Q(x), Q(y), 0 };
            rfs_seek_on_pose(&t.seek, &p, &t.rng);
            rfs_seek_step(&t.seek, now, &t.rng, &out);
            if (out.decided) {
                decided++;
                refuted += out.decision.refuted ? 1 : 0;
                assert_true(!out.decision.refuted || !out.decision.mean_valid);
                gx = D(out.decision.goal_x);
                gy = D(out.decision.goal_y);
                arrive = now + 500000;
            }
        }
    }
    assert_int_equal(decided, decisions);
    world_free(&t);
    return refuted;
}

static void test_refute_rules_out_the_argmax(void **state)
{
    (void)state;
    refute_model_t m;
    /* 7 dB weaker at every maximum: ruled out at each decision there, 32 kept. */
    int refuted = refute_case(-67.0, true, false, 40, &m);
    assert_false(m.mismatch);
    assert_true(m.fits >= 39);
    assert_int_equal(refuted, m.nwant);
    assert_true(m.nwant >= 37); /* every decision after the initial move and the first leg */
    assert_int_equal(m.nexcl, (int)RFS_MODEL_MAX_EXCL);
    assert_true(fabs(m.r - 1.0) < 1e-9);
    /* 6 dB stronger (relearnt, nothing ruled out), 5 dB weaker (relearnt, within twice the
     * threshold), or the option off: nothing. */
    const double means[3] = {-54.0, -65.0, -67.0};
    for (int c = 0; c < 3; ++c) {
        refuted = refute_case(means[c], c != 2, false, 12, &m);
        assert_int_equal(refuted, 0);
        assert_true(c == 2 || m.nwant == 0);
        assert_int_equal(m.nexcl, 0);
        assert_true(m.fits >= 11); /* every miss relearns */
    }
    /* Silence at the maximum, the receiver up: ruled out, the model relearnt for it. */
    refuted = refute_silent(&m, 12);
    assert_false(m.mismatch);
    assert_int_equal(refuted, m.nwant);
    assert_true(m.nwant >= 9);
    assert_true(m.fits >= m.nwant);
}

/* refute_r after a failed recheck, with sliced fits (fit_budget) and up to ten
 * background slices after each period (rfs_seek_background): the robot, teleported onto
 * each maximum, fails the leg's recheck there (7 dB weaker) and brakes; the decision at
 * rest rules out the maximum the leg was driven to. fit_early must not change that: the
 * relearn it begins while the base brakes would otherwise replace the model the rule
 * asks (its maximum moved on) before the decision. Returns the refuted decisions after
 * an abandoned leg; *abandoned counts those legs. */
static int refute_abandoned(bool early, int *abandoned)
{
    world_t t;
    refute_model_t m;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.recheck_adapt = false;
    cfg.fit_budget = 100u;
    cfg.fit_early = early;
    refute_world(&t, cfg, &m);
    m.mean = -67.0;
    field_t f = { .kind = 2, .scripted = -67.0 };
    run_t r = { .x = 4.125, .y = 5.125 };
    int refuted = 0, decided = 0;
    *abandoned = 0;
    while (decided < 24) {
        assert_true(r.t_us < 600000000);
        if (!run_tick(&t, &r, &f)) {
            continue;
        }
        rfs_pose_t p = { r.t_us, Q(r.x), Q(r.y), 0 };
        rfs_seek_on_pose(&t.seek, &p, &t.rng);
        rfs_seek_out_t out;
        rfs_seek_step(&t.seek, r.t_us, &t.rng, &out);
        (void)rfs_seek_background_n(&t.seek, &t.rng, 10u);
        if (!out.decided) {
            continue;
        }
        decided++;
        if (out.decision.prev == RFS_DRIVE_RUNNING) {
            (*abandoned)++;
            refuted += out.decision.refuted ? 1 : 0;
        }
        r.pending = true;
        r.gx = D(out.decision.goal_x);
        r.gy = D(out.decision.goal_y);
        r.arrive_us = r.t_us + 500000;
    }
    world_free(&t);
    return refuted;
}

static void test_refute_after_early_relearn(void **state)
{
    (void)state;
    int ab_off, ab_on;
    const int off = refute_abandoned(false, &ab_off), on = refute_abandoned(true, &ab_on);
    assert_true(ab_off >= 15 && ab_on >= 15);
    assert_true(off >= ab_off - 2); /* every abandoned leg at its maximum rules it out */
    assert_true(on >= ab_on - 2);
}

/* fit_early's refutation as the base brakes (rfs_seek_fit_early_begin): the robot may
 * still stop within half a step of the leg's maximum, so the rule allows for the braking
 * distance at the base's speed v, v^2 / (2 a), plus the drive's goal tolerance. The robot
 * at (4, 5) with 1 s of packets 7 dB weaker than the model's -60 dB, the maximum dist_m
 * east of it. */
static bool early_refutes(double dist_m, int32_t v_mm_s)
{
    world_t t;
    refute_model_t m;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.fit_budget = 100u;
    cfg.fit_early = true;
    refute_world(&t, cfg, &m);
    assert_int_equal(t.seek.cfg.step, RFS_Q16_ONE); /* the reference's figures */
    assert_int_equal(t.seek.drive.cfg.accel_mm_s2, 1000);
    assert_int_equal(t.seek.drive.cfg.goal_tol, RFS_Q16_FRAC(1, 10));
    for (int64_t now = 0; now <= 1000000; now += 10000) {
        if (now % 50000 == 0) {
            rfs_pose_t p = { now, Q(4.0), Q(5.0), 0 };
            assert_true(rfs_seek_on_pose(&t.seek, &p, &t.rng));
        }
        assert_true(rfs_seek_on_rssi(&t.seek, 0, now, -67, &t.rng));
    }
    assert_true(t.seek.store.count > 0u);
    m.base.mx = Q(4.0 + dist_m);
    m.base.my = Q(5.0);
    m.base.valid = true;
    t.seek.drive.base_left = v_mm_s;
    t.seek.drive.base_right = v_mm_s;
    rfs_seek_fit_early_begin(&t.seek, 1000000);
    assert_true(t.seek.fitting); /* the early relearn began */
    const bool refuted = t.seek.early_refuted;
    world_free(&t);
    return refuted;
}

static void test_early_refute_allows_the_braking_distance(void **state)
{
    (void)state;
    /* Reference in double: a = 1 m/s^2 and goal_tol = 0.1 m (rfs_drive_cfg_default), half
     * a step 0.5 m: at rest within 0.6 m; at 0.7 m/s within 0.5 + 0.49 / 2 + 0.1 = 0.845 m. */
    assert_true(early_refutes(0.58, 0));
    assert_false(early_refutes(0.62, 0));
    assert_true(early_refutes(0.62, 700));
    assert_true(early_refutes(0.83, 700));
    assert_false(early_refutes(0.86, 700));
    assert_true(early_refutes(0.83, -700)); /* reversing brakes as far */
}

/* refute_reached: the mean exactly as predicted (no relearn of its own) still rules out
 * every maximum the robot has stood at for a decision (a greedy null move), so every
 * second decision from the fourth on; without it the robot stays at the first one. */
static void test_refute_reached_moves_on(void **state)
{
    (void)state;
    refute_model_t m;
    int refuted = refute_case(-60.0, true, true, 12, &m);
    assert_false(m.mismatch);
    assert_int_equal(refuted, m.nwant);
    assert_int_equal(m.nwant, 5); /* decisions 3, 5, 7, 9, 11 */
    assert_true(m.fits >= m.nwant);
    refuted = refute_case(-60.0, true, false, 12, &m);
    assert_int_equal(refuted, 0);
    assert_int_equal(m.nexcl, 0);
    assert_true(m.fits <= 2); /* the first fit and nothing after: a parked robot */
}

/* local_r (docs/STRATEGIES.md, "Stalls"): a model whose estimate (10.3, 5.2) predicts
 * every mean exactly (no relearn, nothing refuted), every decision greedy. The first goes
 * to the estimate; from then on each goal must be, by a double-precision reference, a
 * legal lattice point within local_r (1 m) of the estimate outside the 0.5 m novelty
 * radius of every place the robot stood, with the least sum of the squared distances to
 * the robot and to the estimate; when none is left the goal is the estimate again. */
/* local_world's seeker started with local_r and local_gap (metres) on the fixed model. */
static void local_seek(world_t *t, fixed_model_t *fm, double local_r, double gap)
{
    rfs_seek_cfg_t cfg;
    local_world(t, &cfg, fm);
    cfg.local_r = Q(local_r);
    cfg.local_gap = Q(gap);
    rfs_model_t model = { fixed_ops(), fm };
    assert_int_equal(rfs_seek_init(&t->seek, &cfg, &t->map, model, &rfs_target_rssi, &t->mem), 0);
}

/* A candidate (x, y) of the local-search references: its cost, the squared distances to
 * the robot at (rx, ry) and to the estimate, lowers *best, and is *got when it is the
 * goal (gx, gy). */
static void local_score(double x, double y, double rx, double ry, double gx, double gy,
                        double *best, double *got)
{
    double c = pow(hypot(x - rx, y - ry), 2) + pow(hypot(x - LOCAL_EX, y - LOCAL_EY), 2);
    *best = c < *best ? c : *best;
    if (fabs(x - gx) < 1e-4 && fabs(y - gy) < 1e-4) {
        *got = c;
    }
}

/* The references' verdict on the goal (gx, gy): the least cost (ties within 1e-6 m^2), or
 * the estimate itself when no candidate is left. */
static bool local_verdict(double best, double got, double gx, double gy)
{
    if (best == INFINITY) {
        return fabs(gx - LOCAL_EX) < 1e-4 && fabs(gy - LOCAL_EY) < 1e-4;
    }
    return got < best + 1e-6;
}

/* The reference goal after the robot stood at the n places (px, py), the search within
 * radius of the estimate; false when no lattice point is left. Ties within 1e-6 m^2 are
 * accepted. */
static bool local_ref_ok(const world_t *t, const double *px, const double *py, int n,
                         double radius, double gx, double gy)
{
    double best = INFINITY, got = INFINITY;
    for (uint16_t j = 0; j < t->map.lh; ++j) {
        for (uint16_t i = 0; i < t->map.lw; ++i) {
            rfs_q16_t qx, qy;
            rfs_map_lattice_point(&t->map, i, j, &qx, &qy);
            double x = D(qx), y = D(qy);
            bool seen = false;
            for (int k = 0; k < n && !seen; ++k) {
                seen = hypot(x - px[k], y - py[k]) <= 0.5 + 1e-9;
            }
            if (seen || !rfs_map_lattice_legal(&t->map, i, j) ||
                hypot(x - LOCAL_EX, y - LOCAL_EY) > radius + 1e-9) {
                continue;
            }
            local_score(x, y, px[n - 1], py[n - 1], gx, gy, &best, &got);
        }
    }
    return local_verdict(best, got, gx, gy);
}

static void test_local_search_round_the_estimate(void **state)
{
    (void)state;
    world_t t;
    fixed_model_t fm;
    local_seek(&t, &fm, 1.0, 0.0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.0, .y = 5.0 };
    double px[64] = { 4.0 }, py[64] = { 5.0 };
    int n = 1, local = 0;
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
    px[n] = D(out.decision.goal_x);
    py[n++] = D(out.decision.goal_y);
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_true(fabs(D(out.decision.goal_x) - LOCAL_EX) < 1e-4); /* not yet stood at */
    px[n] = LOCAL_EX;
    py[n++] = LOCAL_EY;
    while (n < 40) {
        assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
        assert_int_equal(out.decision.kind, RFS_SEEK_GREEDY);
        double gx = D(out.decision.goal_x), gy = D(out.decision.goal_y);
        assert_true(local_ref_ok(&t, px, py, n, 1.0, gx, gy));
        if (fabs(gx - LOCAL_EX) < 1e-4 && fabs(gy - LOCAL_EY) < 1e-4) {
            break; /* every point round the estimate stood near: back at it */
        }
        assert_true(hypot(gx - LOCAL_EX, gy - LOCAL_EY) <= 1.0 + 1e-9);
        px[n] = gx;
        py[n++] = gy;
        local++;
    }
    assert_true(local >= 4 && n < 40);
    world_free(&t);
}

/* local_refute (docs/STRATEGIES.md, "Stalls"), local_r 1 m: the local goals follow the
 * double reference until it has no point left; that decision goes to the estimate and,
 * with the option, rules it out (one place, at (1030, 520) cm) and the next decision
 * relearns; without it nothing is ruled out and the next decision keeps the model. */
static void refute_sweep(bool on)
{
    world_t t;
    fixed_model_t fm;
    local_seek(&t, &fm, 1.0, 0.0);
    t.seek.cfg.local_refute = on;
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.0, .y = 5.0 };
    double px[64] = { 4.0 }, py[64] = { 5.0 };
    int n = 1;
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    px[n] = D(out.decision.goal_x);
    py[n++] = D(out.decision.goal_y);
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    px[n] = LOCAL_EX;
    py[n++] = LOCAL_EY;
    bool ended = false;
    while (n < 64 && !ended) {
        assert_int_equal(t.seek.nexcl, 0);
        assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
        double gx = D(out.decision.goal_x), gy = D(out.decision.goal_y);
        assert_true(local_ref_ok(&t, px, py, n, 1.0, gx, gy));
        ended = fabs(gx - LOCAL_EX) < 1e-4 && fabs(gy - LOCAL_EY) < 1e-4;
        px[n] = gx;
        py[n++] = gy;
    }
    assert_true(ended && n >= 8);
    assert_int_equal(t.seek.nexcl, on ? 1 : 0);
    if (on) {
        assert_int_equal(t.seek.excl_x_cm[0], (int)lround(LOCAL_EX * 100));
        assert_int_equal(t.seek.excl_y_cm[0], (int)lround(LOCAL_EY * 100));
    }
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.relearned, on);
    world_free(&t);
}

static void test_local_refute_rules_out_the_swept(void **state)
{
    (void)state;
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    assert_false(cfg.local_refute); /* the paper's meta */
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    assert_true(cfg.local_refute);
    refute_sweep(true);
    refute_sweep(false);
}

/* local_gap (docs/STRATEGIES.md, "Stalls"), local_r 2 m: every local goal must be, by a
 * double-precision reference, the legal lattice point within local_r of the estimate
 * with no lattice point within the 0.5 m novelty radius of a place stood at lying within
 * local_gap of it, nearest the robot-estimate midpoint. When the search ends (back at
 * the estimate) every legal lattice point within local_r lies within novelty radius +
 * local_gap of a place stood at, and the sweep took fewer goals than without the gap.
 * Returns the local goals taken. */
static bool gap_ref_ok(const world_t *t, const double *px, const double *py, int n,
                       double gap, double gx, double gy)
{
    double best = INFINITY, got = INFINITY;
    for (uint16_t j = 0; j < t->map.lh; ++j) {
        for (uint16_t i = 0; i < t->map.lw; ++i) {
            rfs_q16_t qx, qy;
            rfs_map_lattice_point(&t->map, i, j, &qx, &qy);
            double x = D(qx), y = D(qy);
            if (!rfs_map_lattice_legal(&t->map, i, j) ||
                hypot(x - LOCAL_EX, y - LOCAL_EY) > 2.0 + 1e-9) {
                continue;
            }
            bool near = false; /* a visited lattice point within gap */
            for (uint16_t b = 0; b < t->map.lh && !near; ++b) {
                for (uint16_t a = 0; a < t->map.lw && !near; ++a) {
                    rfs_q16_t vx, vy;
                    rfs_map_lattice_point(&t->map, a, b, &vx, &vy);
                    if (hypot(D(vx) - x, D(vy) - y) > gap + 1e-9) {
                        continue;
                    }
                    for (int k = 0; k < n && !near; ++k) {
                        near = hypot(D(vx) - px[k], D(vy) - py[k]) <= 0.5 + 1e-9;
                    }
                }
            }
            if (near) {
                continue;
            }
            local_score(x, y, px[n - 1], py[n - 1], gx, gy, &best, &got);
        }
    }
    return local_verdict(best, got, gx, gy);
}

static int gap_sweep(double gap)
{
    world_t t;
    fixed_model_t fm;
    local_seek(&t, &fm, 2.0, gap);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.0, .y = 5.0 };
    double px[128] = { 4.0 }, py[128] = { 5.0 };
    int n = 1, local = 0;
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    px[n] = D(out.decision.goal_x);
    py[n++] = D(out.decision.goal_y);
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_true(fabs(D(out.decision.goal_x) - LOCAL_EX) < 1e-4);
    px[n] = LOCAL_EX;
    py[n++] = LOCAL_EY;
    bool ended = false;
    while (n < 128 && !ended) {
        assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
        assert_int_equal(out.decision.kind, RFS_SEEK_GREEDY);
        double gx = D(out.decision.goal_x), gy = D(out.decision.goal_y);
        assert_true(gap_ref_ok(&t, px, py, n, gap, gx, gy));
        ended = fabs(gx - LOCAL_EX) < 1e-4 && fabs(gy - LOCAL_EY) < 1e-4;
        if (!ended) {
            px[n] = gx;
            py[n++] = gy;
            local++;
        }
    }
    assert_true(ended);
    for (uint16_t j = 0; j < t.map.lh; ++j) { /* the sweep's cover */
        for (uint16_t i = 0; i < t.map.lw; ++i) {
            rfs_q16_t qx, qy;
            rfs_map_lattice_point(&t.map, i, j, &qx, &qy);
            if (!rfs_map_lattice_legal(&t.map, i, j) ||
                hypot(D(qx) - LOCAL_EX, D(qy) - LOCAL_EY) > 2.0 + 1e-9) {
                continue;
            }
            double dmin = INFINITY;
            for (int k = 0; k < n; ++k) {
                double d = hypot(D(qx) - px[k], D(qy) - py[k]);
                dmin = d < dmin ? d : dmin;
            }
            assert_true(dmin <= 0.5 + gap + 1e-9);
        }
    }
    world_free(&t);
    return local;
}

static void test_local_gap_spaces_the_sweep(void **state)
{
    (void)state;
    int plain = gap_sweep(0.0), spaced = gap_sweep(0.5);
    print_message("local_gap 0.5 m: %d local goals sweep 2 m round the estimate, %d without\n",
                  spaced, plain);
    assert_true(spaced >= 4 && spaced * 3 < plain * 2);
}

/* floor_gap (docs/STRATEGIES.md, "Stalls"): a fixed model whose fit reports its source
 * power `gap` dB above its floor and records the places ruled out it is given. The
 * greedy decision after the initial move, with the floor_gap rule at 1 dB: a fit 0.5 dB
 * above the floor explores (epsilon, away from the estimate) and rules the estimate out
 * (the next decision relearns, given that one place at refute_r); 1.5 dB, or the rule
 * off, goes greedy to the estimate and rules nothing out. */
typedef struct floor_model {
    fixed_model_t base; /* first: the fixed_* operations read it */
    double gap;         /* dB above the floor */
    int fits, nexcl;    /* fits, and the places the latest one was given */
    double ex, ey, r;   /* the latest place ruled out and its radius, metres */
} floor_model_t;

static rfs_fit_result_t floor_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                  rfs_rng_t *rng)
{
    floor_model_t *m = self;
    m->fits++;
    m->nexcl = in->nexcl;
    if (in->nexcl > 0) {
        m->ex = in->excl_x_cm[in->nexcl - 1] / 100.0;
        m->ey = in->excl_y_cm[in->nexcl - 1] / 100.0;
        m->r = D(in->excl_r);
    }
    return fixed_fit(self, in, budget, rng);
}

static bool floor_gap_op(const void *self, rfs_q16_t *gap)
{
    const floor_model_t *m = self;
    *gap = Q(m->gap);
    return m->base.valid;
}

static const rfs_model_ops_t floor_ops = { .name = "floor", .reset = fixed_reset,
                                           .fit = floor_fit, .predict = fixed_predict,
                                           .argmax = fixed_argmax, .floor_gap = floor_gap_op };

static void floor_case(double rule_db, double gap, bool pinned)
{
    world_t t;
    rfs_seek_cfg_t cfg;
    floor_model_t m = { .gap = gap };
    local_world(&t, &cfg, &m.base);
    cfg.floor_gap = Q(rule_db);
    rfs_model_t model = { &floor_ops, &m };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 }; /* as predicted: no relearn by a miss */
    run_t r = { .x = 4.0, .y = 5.0 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    double off = hypot(D(out.decision.goal_x) - LOCAL_EX, D(out.decision.goal_y) - LOCAL_EY);
    assert_int_equal(out.decision.pinned, pinned);
    assert_int_equal(out.decision.kind, pinned ? RFS_SEEK_EPSILON : RFS_SEEK_GREEDY);
    assert_true(pinned ? off > 2.0 : off < 1e-3);
    int fits = m.fits;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.relearned, pinned);
    assert_int_equal(m.fits, fits + (pinned ? 1 : 0));
    assert_int_equal(m.nexcl, pinned ? 1 : 0);
    if (pinned) {
        assert_true(fabs(m.ex - LOCAL_EX) < 0.006 && fabs(m.ey - LOCAL_EY) < 0.006);
        assert_true(fabs(m.r - D(cfg.refute_r)) < 1e-9 && m.r > 0.0);
    }
    world_free(&t);
}

static void test_floor_gap_rules_out_a_pinned_fit(void **state)
{
    (void)state;
    floor_case(1.0, 0.5, true);
    floor_case(1.0, 1.5, false);
    floor_case(0.0, 0.5, false);
}

/* floor_max (docs/STRATEGIES.md, "Stalls"): the same fit, pinned at every decision (0.5 dB
 * above the floor, the rule at 1 dB). Each rule-out makes the next decision greedy (it
 * relearns), so the three decisions after the initial move all draw greedy: with
 * floor_max 2 the first two rule the estimate out and explore, the third believes it and
 * goes to it, the fit given the two places; with no limit all three rule it out. */
static void floor_max_case(uint8_t floor_max, const bool pinned[3], int places)
{
    world_t t;
    rfs_seek_cfg_t cfg;
    floor_model_t m = { .gap = 0.5 };
    local_world(&t, &cfg, &m.base);
    cfg.floor_gap = Q(1.0);
    cfg.floor_max = floor_max;
    rfs_model_t model = { &floor_ops, &m };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.0, .y = 5.0 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
    for (int i = 0; i < 3; ++i) {
        assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
        double off = hypot(D(out.decision.goal_x) - LOCAL_EX, D(out.decision.goal_y) - LOCAL_EY);
        assert_int_equal(out.decision.pinned, pinned[i]);
        assert_int_equal(out.decision.kind, pinned[i] ? RFS_SEEK_EPSILON : RFS_SEEK_GREEDY);
        assert_true(pinned[i] ? off > 2.0 : off < 1e-3);
    }
    assert_int_equal(m.nexcl, places);
    world_free(&t);
}

static void test_floor_max_believes_a_fit_pinned_again(void **state)
{
    (void)state;
    floor_max_case(2u, (const bool[3]){true, true, false}, 2);
    floor_max_case(0u, (const bool[3]){true, true, true}, 2);
}

/* mean_t (docs/STRATEGIES.md, "Stalls"): a fixed model whose belief has its mean at
 * (mx, my) at temperature 2 (none at another). The greedy decision after the initial
 * move, with mean_t 2: the robot goes to the mean (the goal, hedged), and at the next
 * decision, the mean moved to the start, to the estimate (visited); mean_t 1 (no mean
 * answered), the rule off, a mean within 1.5 steps of the robot, or a wall between any two
 * of robot, mean and estimate (a wall at x = 7 m up to y = 3 or 7 m, a door above) send it
 * to the estimate. */
typedef struct mean_model {
    fixed_model_t base; /* first: the fixed_* operations read it */
    double mx, my;      /* the belief's mean, metres (NAN: 0.5 m east of the robot) */
    const run_t *r;     /* the robot */
} mean_model_t;

static bool mean_op(const void *self, rfs_q16_t temp, rfs_q16_t *x, rfs_q16_t *y)
{
    const mean_model_t *m = self;
    *x = Q(isnan(m->mx) ? m->r->x + 0.5 : m->mx);
    *y = Q(isnan(m->mx) ? m->r->y : m->my);
    return m->base.valid && temp == RFS_Q16_INT(2);
}

static void mean_case(double rule_t, double mx, double my, double wall_top, bool hedged)
{
    static const rfs_model_ops_t ops = { .name = "mean", .reset = fixed_reset,
                                         .fit = fixed_fit, .predict = fixed_predict,
                                         .argmax = fixed_argmax, .mean = mean_op };
    world_t t;
    rfs_seek_cfg_t cfg;
    run_t r = { .x = 4.0, .y = 5.0 };
    mean_model_t m = { .mx = mx, .my = my, .r = &r };
    local_world(&t, &cfg, &m.base);
    if (wall_top > 0.0) {
        world_free(&t);
        world_make(&t, 20.0, 10.0, 7.0, wall_top);
        seek_make(&t, cfg, 5);
    }
    cfg.mean_t = Q(rule_t);
    rfs_model_t model = { &ops, &m };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    const rfs_seek_decision_t *d = &out.decision;
    assert_int_equal(d->kind, RFS_SEEK_GREEDY);
    assert_int_equal(d->hedged, hedged);
    const double gx = hedged ? mx : LOCAL_EX, gy = hedged ? my : LOCAL_EY;
    assert_true(hypot(D(d->goal_x) - gx, D(d->goal_y) - gy) < 1e-3);
    assert_true(hypot(D(d->max_x) - gx, D(d->max_y) - gy) < 1e-3);
    if (!isnan(mx)) {
        assert_true(hypot(D(d->x) - mx, D(d->y) - my) > 1.5); /* not the near rule's case */
    }
    if (hedged && wall_top == 0.0) {
        /* Then the mean at the start, 1.5 steps or more away but visited: the estimate. */
        m.mx = 4.0;
        m.my = 5.0;
        assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
        assert_int_equal(d->kind, RFS_SEEK_GREEDY);
        assert_false(d->hedged);
        assert_true(hypot(D(d->x) - 4.0, D(d->y) - 5.0) > 1.5);
        assert_true(hypot(D(d->goal_x) - LOCAL_EX, D(d->goal_y) - LOCAL_EY) < 1e-3);
    }
    world_free(&t);
}

static void test_mean_t_hedges_between_guesses(void **state)
{
    (void)state;
    mean_case(2.0, 8.5, 5.0, 0.0, true);
    mean_case(1.0, 8.5, 5.0, 0.0, false);
    mean_case(0.0, 8.5, 5.0, 0.0, false);
    mean_case(2.0, NAN, NAN, 0.0, false);
    mean_case(2.0, 8.5, 1.0, 0.0, true);
    mean_case(2.0, 8.5, 1.0, 3.0, false); /* robot to mean through the wall */
    mean_case(2.0, 5.0, 0.8, 0.0, true);
    mean_case(2.0, 5.0, 0.8, 3.0, false); /* mean to estimate through it */
    mean_case(2.0, 8.5, 8.5, 0.0, true);
    mean_case(2.0, 8.5, 8.5, 7.0, false); /* robot to estimate through it */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_refute_rules_out_the_argmax),
        cmocka_unit_test(test_refute_reached_moves_on),
        cmocka_unit_test(test_refute_after_early_relearn),
        cmocka_unit_test(test_early_refute_allows_the_braking_distance),
        cmocka_unit_test(test_local_search_round_the_estimate),
        cmocka_unit_test(test_local_refute_rules_out_the_swept),
        cmocka_unit_test(test_local_gap_spaces_the_sweep),
        cmocka_unit_test(test_floor_gap_rules_out_a_pinned_fit),
        cmocka_unit_test(test_floor_max_believes_a_fit_pinned_again),
        cmocka_unit_test(test_mean_t_hedges_between_guesses),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
