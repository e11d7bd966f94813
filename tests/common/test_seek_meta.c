/* test_seek_meta.c - the paper's choices (common/rfs_seek_meta.c): the epsilon schedule,
 * novelty, the greedy step's line search, and the meta-path variants (docs/STRATEGIES.md,
 * "meta-path's preset improvements"), each against a reference computed here in double
 * precision.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ref_geom.h"
#include "seek_run.h"

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

/* A model with a fixed maximum (a cone), for testing the step choice independently of learning. */
typedef struct cone_model {
    double mx, my;
} cone_model_t;

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
    const cone_model_t *m = self;
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
    cone_model_t fm = { 9.125, 3.125 }; /* a lattice point: the grid maximum is exact */
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
    /* Round the wall the plan needs the search tree from the robot (plan_budget): the
     * robot stands while it grows, 640 of the 48 x 32 lattice points a period, and the
     * decision is made again each period until its plans find their points closed. */
    int waited = 0;
    for (int64_t now = 150000; !out.decided && waited < 10; now += 50000, waited++) {
        assert_int_equal(out.state, RFS_SEEK_LEARNING);
        assert_int_equal(out.left_mm_s, 0);
        assert_int_equal(out.right_mm_s, 0);
        feed(&t, now, 5.3, 3.125, 0, -50, &out);
    }
    assert_true(out.decided);
    assert_true(waited >= 1 && waited <= 3); /* 1,536 points: 3 slices at most */
    assert_int_equal(out.decision.plan_wait, waited);
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
    rfs_model_t model = { fixed_ops(), &fm };
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
    eps_sample_case(true, fixed_ops(), 10.5, false, DRAW_AHEAD); /* the model does not draw */
}

/* A model that also answers near (rfs_model_ops_t.near): the point (nx, ny) unless the
 * seeker's refuse() does; it keeps the question it was asked. */
typedef struct near_model {
    fixed_model_t base; /* first: the fixed_* operations read it */
    rfs_q16_t nx, ny;
    rfs_model_near_t q;
    int asked;
} near_model_t;

static bool fixed_near(const void *self, const rfs_model_near_t *q, rfs_q16_t *x, rfs_q16_t *y)
{
    near_model_t *m = (near_model_t *)(uintptr_t)self;
    m->q = *q;
    m->asked++;
    if (q->refuse != NULL && q->refuse(q->ctx, m->nx, m->ny)) {
        return false;
    }
    *x = m->nx;
    *y = m->ny;
    return m->base.valid;
}

static const rfs_model_ops_t k_near_ops = {
    .name = "near", .reset = fixed_reset, .fit = fixed_fit, .predict = fixed_predict,
    .argmax = fixed_argmax, .near = fixed_near,
};

/* near_t (docs/STRATEGIES.md, "Stalls"): with the estimate at (38.125, 5.125), 34 m from
 * the robot (within 2 m of its start, (4.125, 5.125)), the greedy goal is the model's nearer place, the whole
 * straight way (its length in double); the estimate instead when it is nearer than
 * near_min, when near_t is 0, and when the place is refused: the start (visited), within
 * 4 steps of the estimate, or behind a wall (x = 7 m, y < 8.5 m) whose way round is longer
 * than 1.3 x straight + 2 steps (round over the wall's end plus the clearance, in double).
 * The question: the
 * robot, the estimate, near_t and 5 steps. */
enum { NEAR_AHEAD = 0, NEAR_CLOSE_MAX = 1, NEAR_OFF = 2, NEAR_AT_START = 3, NEAR_BY_MAX = 4,
       NEAR_WALLED = 5 };

static void near_case(int what, double nx, double ny, bool expect)
{
    world_t t;
    world_make(&t, 40.0, 10.0, what == NEAR_WALLED ? 7.0 : 0.0, 8.5);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    assert_int_equal(cfg.near_t, 0); /* an option, off in the preset */
    cfg.near_t = what == NEAR_OFF ? 0 : Q(8.0);
    cfg.near_min = Q(30.0);
    cfg.eps_amp = 0;
    cfg.eps_floor = 0; /* every decision after the first is greedy */
    seek_make(&t, cfg, 5);
    near_model_t nm = { { false, Q(what == NEAR_CLOSE_MAX ? 24.125 : 38.125), Q(5.125) },
                        Q(nx), Q(ny), { 0 }, 0 };
    rfs_model_t model = { &k_near_ops, &nm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.125, .y = 5.125 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 0, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_INITIAL);
    r.x = r.gx; /* arrive at once; the start stays visited */
    r.y = r.gy;
    r.pending = false;
    if (!next_decision(&t, &r, &f, 0, 5000000, &out)) {
        fail_msg("case %d: no decision", what);
    }
    const rfs_seek_decision_t *d = &out.decision;
    assert_int_equal(d->kind, RFS_SEEK_GREEDY);
    assert_int_equal(d->near, expect);
    const double gx = expect ? nx : D(nm.base.mx), gy = expect ? ny : D(nm.base.my);
    if (what == NEAR_WALLED) {
        const double round = hypot(7.0 - r.x, 8.75 - r.y) + hypot(nx - 7.0, 8.75 - ny);
        assert_true(round > 1.3 * hypot(nx - r.x, ny - r.y) + 2.0);
    }
    if (fabs(D(d->goal_x) - gx) > 1e-4 || fabs(D(d->goal_y) - gy) > 1e-4) {
        fail_msg("case %d: goal (%.3f, %.3f), expected (%.3f, %.3f)", what, D(d->goal_x),
                 D(d->goal_y), gx, gy);
    }
    if (expect) {
        assert_true(fabs(D(d->path_len) - hypot(nx - r.x, ny - r.y)) < 0.01);
    }
    const bool asked = what != NEAR_OFF && what != NEAR_CLOSE_MAX;
    assert_int_equal(nm.asked > 0, asked);
    if (asked) {
        assert_true(fabs(D(nm.q.x) - r.x) < 0.01 && fabs(D(nm.q.y) - r.y) < 0.01);
        assert_true(nm.q.ax == nm.base.mx && nm.q.ay == nm.base.my);
        assert_true(nm.q.temp == Q(8.0) && nm.q.d0 == Q(5.0));
    }
    world_free(&t);
}

static void test_near_goes_to_the_nearer_place(void **state)
{
    (void)state;
    near_case(NEAR_AHEAD, 12.125, 3.125, true);
    near_case(NEAR_CLOSE_MAX, 12.125, 3.125, false);
    near_case(NEAR_OFF, 12.125, 3.125, false);
    near_case(NEAR_AT_START, 4.125, 5.125, false);
    near_case(NEAR_BY_MAX, 35.125, 3.125, false);
    near_case(NEAR_WALLED, 9.125, 2.125, false);
    near_case(NEAR_AHEAD, 9.125, 2.125, true); /* the same place without the wall */
}

/* at_tol (docs/STRATEGIES.md, "Stalls"): the drive's goal tolerance is at_tol (3 cm in
 * the preset) on a greedy leg to the model's known argmax and on a local search's goal,
 * and the drive's own (10 cm) on an epsilon goal, under the paper's meta (at_tol 0) and
 * for a fit per source (bridging). */
static void test_at_tol_at_the_estimate(void **state)
{
    (void)state;
    for (int meta = 0; meta < 2; ++meta) {
        world_t t;
        rfs_seek_cfg_t cfg;
        fixed_model_t fm;
        local_world(&t, &cfg, &fm);
        if (meta) {
            rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META);
            cfg.eps_amp = 0;
            cfg.eps_floor = 0;
        }
        assert_int_equal(cfg.at_tol, meta ? 0 : Q(0.03));
        rfs_model_t model = { fixed_ops(), &fm };
        assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
        field_t f = { .kind = 2, .scripted = -60.0 };
        run_t r = { .x = 4.0, .y = 5.0 };
        rfs_seek_out_t out;
        int greedy = 0, eps = 0;
        for (int k = 0; k < 16; ++k) {
            /* Every other decision epsilon: epsilon 1, then 0. */
            t.seek.cfg.eps_floor = (k % 2) ? RFS_Q16_ONE : 0;
            assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
            double tol = D(t.seek.drive.cfg.goal_tol);
            if (out.decision.kind == RFS_SEEK_GREEDY) {
                greedy++;
                assert_true(fabs(tol - (meta ? 0.1 : 0.03)) < 1e-4);
            } else if (out.decision.kind == RFS_SEEK_EPSILON) {
                eps++;
                assert_true(fabs(tol - 0.1) < 1e-4);
            }
        }
        assert_true(greedy >= 4 && eps >= 4);
        world_free(&t);
    }
    rfs_seek_cfg_t src = rfs_seek_cfg_default(); /* bridging: the drive's own tolerance */
    rfs_seek_cfg_use_strategy(&src, RFS_SEEK_META_PATH);
    rfs_seek_cfg_per_source(&src);
    assert_int_equal(src.at_tol, 0);
}

/* at_tol's stall: the robot teleported `off` metres short of the greedy goal at the
 * estimate and held there; the drive's estimate creeps but the poses do not, so the goal
 * ends blocked (no progress in 5 s) unless within at_tol. The next decision's prev: reached
 * within the drive's own 10 cm (9 cm short: blocked without the rule), blocked beyond
 * (30 cm short). */
static rfs_drive_status_t stall_short_of_goal(double off)
{
    world_t t;
    rfs_seek_cfg_t cfg;
    fixed_model_t fm;
    local_world(&t, &cfg, &fm);
    rfs_model_t model = { fixed_ops(), &fm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.0, .y = 5.0 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out)); /* the initial move */
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_GREEDY);
    assert_true(fabs(D(out.decision.goal_x) - LOCAL_EX) < 1e-4);
    r.gx = LOCAL_EX - off; /* arrives short of the goal, on the way from the west */
    r.gy = LOCAL_EY;
    assert_true(next_decision(&t, &r, &f, 1000000, 20000000, &out));
    world_free(&t);
    return out.decision.prev;
}

static void test_at_tol_stall_counts_as_reached(void **state)
{
    (void)state;
    assert_int_equal(stall_short_of_goal(0.09), RFS_DRIVE_REACHED);
    assert_int_equal(stall_short_of_goal(0.30), RFS_DRIVE_BLOCKED);
}

static void test_leg_max_cuts_the_leg(void **state)
{
    (void)state;
    world_t t;
    rfs_seek_cfg_t cfg;
    fixed_model_t fm;
    local_world(&t, &cfg, &fm);
    cfg.leg_max = Q(4.0);
    fm.mx = Q(16.3);
    rfs_model_t model = { fixed_ops(), &fm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 4.0, .y = 5.0 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    double x0 = D(out.decision.goal_x), y0 = D(out.decision.goal_y);
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    assert_int_equal(out.decision.kind, RFS_SEEK_GREEDY);
    double d = hypot(16.3 - x0, LOCAL_EY - y0);
    double ex = x0 + 4.0 * (16.3 - x0) / d, ey = y0 + 4.0 * (LOCAL_EY - y0) / d;
    assert_true(fabs(D(out.decision.goal_x) - ex) < 1e-3);
    assert_true(fabs(D(out.decision.goal_y) - ey) < 1e-3);
    assert_true(fabs(D(out.decision.path_len) - 4.0) < 1e-3);
    world_free(&t);
}

/* recheck_silent (docs/STRATEGIES.md, "Stalls"): the estimate 12 m off, (16.3, 5.2), the
 * model predicting `level` dBm everywhere. The robot hears -60 dBm until the greedy leg
 * to the estimate begins, then nothing, the receiver reporting itself up every period;
 * it walks the leg at 1 m/s. With the option, the first check (every metre) more than
 * a window (1 s) into the silence takes the -100 dBm floor as its mean: a -60 dBm
 * prediction misses by 40 dB, above both 3 dB and the running RMS (40 / sqrt(8) dB), and
 * the leg is abandoned (prev = running) 2 m along; a -110 dBm prediction (below the
 * floor) passes, as does every check without the option: the leg ends reached. Returns
 * the next decision's prev and where the robot stood. */
typedef struct level_model {
    fixed_model_t f; /* first: the fixed model's reset, fit and argmax serve */
    rfs_q16_t level;
} level_model_t;

static bool level_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    const level_model_t *m = self;
    (void)x;
    (void)y;
    *value = m->level;
    return m->f.valid;
}

static rfs_drive_status_t silent_leg(bool on, double level, double *at_x)
{
    static const rfs_model_ops_t ops = { .name = "level", .reset = fixed_reset,
                                         .fit = fixed_fit, .predict = level_predict,
                                         .argmax = fixed_argmax };
    world_t t;
    rfs_seek_cfg_t cfg;
    level_model_t m;
    local_world(&t, &cfg, &m.f);
    cfg.recheck_silent = on;
    m.f.mx = Q(16.3);
    m.level = Q(level);
    rfs_model_t model = { &ops, &m };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    double x = 4.0, y = LOCAL_EY, gx = x, gy = y;
    int decisions = 0;
    bool silence = false;
    rfs_seek_out_t out;
    for (int64_t now = 10000; now < 60000000; now += 10000) {
        if (!silence) {
            assert_true(rfs_seek_on_rssi(&t.seek, 0, now, -60, &t.rng));
        }
        if (now % 50000 != 0) {
            continue;
        }
        double dx = gx - x, dy = gy - y, d = hypot(dx, dy);
        x = d <= 0.05 ? gx : x + 0.05 * dx / d;
        y = d <= 0.05 ? gy : y + 0.05 * dy / d;
        rfs_pose_t p = pose_at(now, x, y, 0);
        assert_true(rfs_seek_on_pose(&t.seek, &p, &t.rng));
        assert_true(rfs_seek_on_receiver(&t.seek, now));
        rfs_seek_step(&t.seek, now, &t.rng, &out);
        if (!out.decided) {
            continue;
        }
        if (++decisions == 3) {
            break;
        }
        gx = D(out.decision.goal_x);
        gy = D(out.decision.goal_y);
        if (decisions == 2) {
            assert_int_equal(out.decision.kind, RFS_SEEK_GREEDY);
            assert_true(fabs(gx - 16.3) < 1e-3);
            silence = true;
        }
    }
    assert_int_equal(decisions, 3);
    *at_x = x;
    world_free(&t);
    return out.decision.prev;
}

static void test_recheck_silent_abandons_a_blind_leg(void **state)
{
    (void)state;
    double at;
    assert_int_equal(silent_leg(true, -60.0, &at), RFS_DRIVE_RUNNING);
    assert_true(at < 7.5); /* about 2 m along (the base brakes a little past it) */
    assert_int_equal(silent_leg(true, -110.0, &at), RFS_DRIVE_REACHED);
    assert_true(at > 16.0);
    assert_int_equal(silent_leg(false, -60.0, &at), RFS_DRIVE_REACHED);
    assert_true(at > 16.0);
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
/* Epsilon tries per decision (rfs_seek_meta.c GOAL_TRIES); the last one is always kept. */
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
 * comes closer than the clearance (0.25 m = 2.5 cells) to its square is on the map and
 * free. Offsets are whole cells, so the squared gaps are exact in double. */
static bool geo_legal_cell(int cx, int cy, int w, int h)
{
    for (int dy = -3; dy <= 3; ++dy) {
        for (int dx = -3; dx <= 3; ++dx) {
            double ex = ref_cell_gap(dx, 0), ey = ref_cell_gap(dy, 0);
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

/* The inflated wall: the illegal cells around the wall column, x in [4.9, 5.6), y below
 * 5.3 (the wall's cells plus 3 cells of clearance mask); a legal segment touches none
 * of their closed squares, so every legal path is at least the taut length around it. */
#define GEO_OB_X0 4.9
#define GEO_OB_X1 5.6
#define GEO_OB_Y1 5.3
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
    rfs_model_t model = { fixed_ops(), &fm };
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
    /* 40 x 32 lattice points; border cells 0..3 illegal leave 36 x 28; 38 by the wall
     * (x 5.125 and 5.375 m, y up to 5.125 m); 13 within the novelty radius, one of them
     * ((5.125, 3.625) m) by the wall. */
    assert_int_equal(nc, 36 * 28 - 38 - 12);
    double p_hi = geo_far_prob(true, 0.0, &nc), p_lo = geo_far_prob(true, GEO_EXCESS, &nc);
    assert_true(p_off > 0.2 && p_hi < 0.06 && p_lo > 0.01); /* the map separates the rules */
    double f_off = geo_far_draws(false, n, false) / (double)n;
    double f_on = geo_far_draws(true, n, true) / (double)n;
    double s_off = sqrt(p_off * (1.0 - p_off) / n);
    double s_lo = sqrt(p_lo * (1.0 - p_lo) / n), s_hi = sqrt(p_hi * (1.0 - p_hi) / n);
    print_message("far side: off %.4f (want %.4f), on %.4f (want %.4f..%.4f)\n", f_off, p_off,
                  f_on, p_lo, p_hi);
    if (fabs(f_off - p_off) > 4.0 * s_off || f_on < p_lo - 4.0 * s_lo || f_on > p_hi + 4.0 * s_hi) {
        print_error("far side: off %.4f (want %.4f), on %.4f (want %.4f..%.4f)\n", f_off, p_off,
                    f_on, p_lo, p_hi);
        fail();
    }
}


/* plan_budget: the search tree of the next decision grows while the leg is driven, from
 * the leg's end (the paper's meta) or from its next check point (meta-path, checked
 * every metre); a robot that stops there decides without waiting, every goal round the
 * wall (the argmax behind it) planned on that tree. With plan_budget 0 (the plans
 * searched within the decision) no decision ever waits. */
static void test_plan_slices_on_the_leg(void **state)
{
    (void)state;
    for (int meta_path = 0; meta_path <= 1; meta_path++) {
        int decisions = 0, round = 0;
        for (uint32_t budget = 0; budget <= RFS_SEEK_PLAN_BUDGET; budget += RFS_SEEK_PLAN_BUDGET) {
            world_t t;
            world_make(&t, 12.0, 8.0, 6.0, 6.0); /* wall x = 6, y in [0, 6) */
            rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
            if (meta_path) {
                rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
                cfg.eps_sample = false;
            }
            cfg.plan_budget = budget;
            seek_make(&t, cfg, 5);
            fixed_model_t fm = { false, Q(9.125), Q(3.125) };
            rfs_model_t model = { fixed_ops(), &fm };
            assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
            field_t f = { .kind = 2, .scripted = -60.0 };
            run_t r = { .x = 3.0, .y = 3.125 };
            rfs_seek_out_t out;
            /* Held 2 s a leg: 40 periods, 25,600 points, the 48 x 32 lattice 17 times. */
            for (int k = 0; k < 12; k++) {
                assert_true(next_decision(&t, &r, &f, 2000000, 10000000, &out));
                const rfs_seek_decision_t *d = &out.decision;
                if (budget == 0) {
                    assert_int_equal(d->plan_wait, 0);
                    continue;
                }
                decisions++;
                round += D(d->path_len) > hypot(D(d->goal_x) - D(d->x), D(d->goal_y) - D(d->y)) + 0.05;
                /* The first decision (the boot fit) and relearns wait one period; none
                 * waits for its tree. */
                assert_int_equal(d->plan_wait, k == 0 || d->relearned ? 1 : 0);
            }
            world_free(&t);
        }
        print_message("%s: %d decisions on trees grown on the leg, %d round the wall\n",
                      meta_path ? "meta-path" : "meta", decisions, round);
        assert_true(round >= 1);
    }
}

/* plan_budget, a leg cut short (docs/PERFORMANCE.md, "Planning in slices"): meta-path
 * round a wall on a 24 x 16 m map (6,144 lattice points, 10 slices of 640), every leg
 * stopped 0.6 m along its first segment until the drive calls it blocked. After the
 * initial move (whose tree grew from its end, not its check point) the next
 * decision's tree, grown from the check point 1 m along, serves the robot 0.4 m short of
 * it: no decision waits beyond its relearn period, where a tree begun at the robot
 * (counted here on a second planner) needs several slices. The path starts at the robot,
 * its length is the double-precision sum of its hops and at most twice the hop longer
 * than that tree's path. */
static void test_plan_leg_cut_short(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 24.0, 16.0, 12.0, 12.0); /* wall x = 12, y in [0, 12) */
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    rfs_seek_cfg_use_strategy(&cfg, RFS_SEEK_META_PATH);
    cfg.eps_sample = false;
    cfg.eps_floor = 0;
    cfg.eps_amp = 0;
    seek_make(&t, cfg, 7);
    fixed_model_t fm = { false, Q(18.125), Q(4.125) };
    rfs_model_t model = { fixed_ops(), &fm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    const uint32_t lpts = (uint32_t)t.map.lw * t.map.lh;
    uint8_t *work = calloc(lpts, 1);
    uint32_t *queue = calloc(lpts, sizeof *queue);
    rfs_plan_t fresh;
    assert_int_equal(rfs_plan_init(&fresh, &t.map, work, lpts, queue, lpts), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 6.0, .y = 4.125 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out));
    int cut = 0, slow_fresh = 0;
    for (int k = 0; k < 7; k++) {
        const rfs_path_t *p = &t.seek.drive.path;
        const double px = r.x, py = r.y;
        const double sx = D(p->x[0]) - px, sy = D(p->y[0]) - py, len0 = hypot(sx, sy);
        if (len0 < 1.0) {
            break; /* past the wall's end: the rest is in line of sight */
        }
        r.pending = false; /* the robot stops 0.6 m along, short of the check point */
        r.x = px + 0.6 * sx / len0;
        r.y = py + 0.6 * sy / len0;
        assert_true(next_decision(&t, &r, &f, 1000000, 20000000, &out));
        const rfs_seek_decision_t *d = &out.decision;
        assert_int_equal(d->prev, RFS_DRIVE_BLOCKED);
        if (k == 0) {
            continue; /* the initial move's tree grew from its end, 5 m on */
        }
        assert_true(d->plan_wait <= (d->relearned ? 1u : 0u));
        assert_int_equal(p->x0, Q(r.x));
        assert_int_equal(p->y0, Q(r.y));
        double sum = 0, hx = r.x, hy = r.y;
        for (uint16_t w = 0; w < p->n; w++) {
            sum += hypot(D(p->x[w]) - hx, D(p->y[w]) - hy);
            hx = D(p->x[w]);
            hy = D(p->y[w]);
        }
        assert_true(fabs(sum - D(p->length)) < 1e-3 * p->n);
        /* The same goal from a tree begun at the robot: slices until it is closed. */
        rfs_plan_tree_begin(&fresh, Q(r.x), Q(r.y));
        rfs_path_t fp;
        int slices = 0;
        bool done = rfs_plan_tree_grow(&fresh, 0u); /* seeded, sliced: never searched on demand */
        while (!rfs_plan_tree_path(&fresh, d->goal_x, d->goal_y, &fp) && !done) {
            done = rfs_plan_tree_grow(&fresh, cfg.plan_budget);
            slices++;
        }
        slow_fresh += slices >= 3;
        /* The hop (0.4 m) lengthens it by at most twice its length. */
        assert_true(fp.n > 0 && D(p->length) <= D(fp.length) + 0.8 + 1e-3);
        cut++;
        r.pending = false;
    }
    print_message("leg cut short: %d decisions without waiting for the tree, %d of them "
                  "would wait 3 or more slices for a tree begun at the robot\n", cut, slow_fresh);
    assert_true(cut >= 5 && slow_fresh >= 5);
    free(work);
    free(queue);
    world_free(&t);
}

/* plan_budget, short legs: the paper's meta stepping 0.3 m at a time (the maximum just
 * ahead, moved on after each step) keeps the tree it decided on, moved to the leg's end
 * and grown on, while that end is within half a step of its root (every other step
 * here), else begins one there; no decision waits beyond its relearn period. */
static void test_plan_short_leg_keeps_tree(void **state)
{
    (void)state;
    world_t t;
    world_make(&t, 24.0, 16.0, 12.0, 12.0);
    rfs_seek_cfg_t cfg = rfs_seek_cfg_default();
    cfg.eps_floor = 0;
    cfg.eps_amp = 0;
    seek_make(&t, cfg, 11);
    fixed_model_t fm = { false, Q(6.0), Q(4.125) };
    rfs_model_t model = { fixed_ops(), &fm };
    assert_int_equal(rfs_seek_init(&t.seek, &cfg, &t.map, model, &rfs_target_rssi, &t.mem), 0);
    field_t f = { .kind = 2, .scripted = -60.0 };
    run_t r = { .x = 6.0, .y = 4.125 };
    rfs_seek_out_t out;
    assert_true(next_decision(&t, &r, &f, 1000000, 5000000, &out)); /* the initial move */
    int kept = 0, begun = 0;
    for (int k = 0; k < 8; k++) {
        fm.mx = Q((r.pending ? r.gx : r.x) + 0.3); /* just ahead of where it decides */
        fm.my = Q(r.pending ? r.gy : r.y);
        assert_true(next_decision(&t, &r, &f, 1000000, 20000000, &out));
        const rfs_seek_decision_t *d = &out.decision;
        if (d->kind != RFS_SEEK_GREEDY) {
            continue;
        }
        assert_true(d->plan_wait <= (d->relearned ? 1u : 0u));
        assert_int_equal(d->goal_x, fm.mx);
        /* The next tree serves the leg's end: kept (seeded, its root within half a step)
         * or begun there (seeded at the next slice). */
        assert_int_equal(t.seek.plan.tree_x, d->goal_x);
        assert_int_equal(t.seek.plan.tree_y, d->goal_y);
        if (t.seek.plan.tree == 2) {
            const uint32_t root = t.seek.plan.tree_root, lw = t.map.lw;
            const double gx = D(t.map.cfg.grid) * ((root % lw) + 0.5);
            const double gy = D(t.map.cfg.grid) * ((root / lw) + 0.5);
            assert_true(hypot(gx - D(d->goal_x), gy - D(d->goal_y)) <= 0.5 + 1e-6);
            kept++;
        } else {
            assert_int_equal(t.seek.plan.tree, 1);
            begun++;
        }
    }
    print_message("short legs: %d decisions kept the tree, %d began one\n", kept, begun);
    assert_true(kept >= 3 && begun >= 2);
    world_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_epsilon_schedule),
        cmocka_unit_test(test_epsilon_goals_are_novel),
        cmocka_unit_test(test_blocked_step_line_search),
        cmocka_unit_test(test_eps_by_travel),
        cmocka_unit_test(test_meta_path_unreachable_maximum),
        cmocka_unit_test(test_eps_sample_goes_to_the_draw),
        cmocka_unit_test(test_near_goes_to_the_nearer_place),
        cmocka_unit_test(test_at_tol_at_the_estimate),
        cmocka_unit_test(test_at_tol_stall_counts_as_reached),
        cmocka_unit_test(test_leg_max_cuts_the_leg),
        cmocka_unit_test(test_recheck_silent_abandons_a_blind_leg),
        cmocka_unit_test(test_eps_geodesic_distribution),
        cmocka_unit_test(test_plan_slices_on_the_leg),
        cmocka_unit_test(test_plan_leg_cut_short),
        cmocka_unit_test(test_plan_short_leg_keeps_tree),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
