/* test_seek_baseline.c - the baseline strategies (common/rfs_seek_baseline.c,
 * docs/STRATEGIES.md): each decision rule against a synthetic field computed here in
 * double precision (seek_run.h), and the unit vector they step along.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "seek_run.h"

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

/* The unit vector against double precision. */
static void test_unit(void **state)
{
    (void)state;
    rfs_q16_t ux, uy;
    assert_false(rfs_seek_unit(0, 0, &ux, &uy));
    static const double g[][2] = { { 3, 4 }, { -0.001, 0.002 }, { 20000, -1 }, { -5, -12 } };
    for (size_t i = 0; i < 4; ++i) {
        assert_true(rfs_seek_unit(Q(g[i][0]), Q(g[i][1]), &ux, &uy));
        double n = hypot(D(Q(g[i][0])), D(Q(g[i][1])));
        assert_true(fabs(D(ux) - D(Q(g[i][0])) / n) < 1e-4);
        assert_true(fabs(D(uy) - D(Q(g[i][1])) / n) < 1e-4);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fd_gradient_direction),
        cmocka_unit_test(test_fd_gradient_probe_flips_at_wall),
        cmocka_unit_test(test_plane_gradient_follows_plane),
        cmocka_unit_test(test_chemotaxis_run_and_tumble),
        cmocka_unit_test(test_chemotaxis_ignores_position),
        cmocka_unit_test(test_unit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
