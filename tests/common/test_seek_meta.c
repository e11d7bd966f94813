/* test_seek_meta.c - the paper's choices (common/rfs_seek_meta.c): the epsilon schedule,
 * novelty, the greedy step's line search, and the meta-path variants (docs/STRATEGIES.md,
 * "meta-path's presets"), each against a reference computed here in double
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
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
