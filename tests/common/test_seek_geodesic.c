/* test_seek_geodesic.c - meta-path's geodesic epsilon step against a double-precision
 * reference, and the search tree grown in slices while a leg is driven (a leg cut short,
 * a short leg keeping its tree) (common/rfs_seek_meta.c, rfs_seek.c; docs/STRATEGIES.md,
 * docs/PERFORMANCE.md "Planning in slices").
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ref_geom.h"
#include "seek_run.h"

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
        cmocka_unit_test(test_eps_geodesic_distribution),
        cmocka_unit_test(test_plan_slices_on_the_leg),
        cmocka_unit_test(test_plan_leg_cut_short),
        cmocka_unit_test(test_plan_short_leg_keeps_tree),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
