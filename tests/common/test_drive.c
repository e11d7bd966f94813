/* test_drive.c - rfs_drive in closed loop with unicycle kinematics integrated in double
 * here: v = (l + r) / 2, omega = (r - l) / b, 1 ms Euler sub-steps, control at 50 Hz.
 * Checks: goals are reached (within goal_tol, wheels stopped), wheel speeds never exceed
 * v_max, no wheel changes faster than accel * dt, intermediate waypoints are passed,
 * timeouts and blocked robots are reported once; with localisation noise (Gaussian, at
 * 10 Hz, drawn here) the robot still stays near the polyline without dithering, and the
 * pose filter's error matches the first-order filter's theory.
 */
#include "rfs_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rfs_drive.h"

#define DT_US 20000

typedef struct sim {
    double x, y, th;      /* metres, radians */
    double min_wp_dist[RFS_PLAN_MAX_WAYPOINTS];
    int16_t l, r;         /* last command, mm/s */
    int violations_speed;
    int violations_accel;
    double travelled;
    double max_off_path;  /* largest distance from the start -> waypoints polyline */
    double x0, y0;        /* where the path started */
    double max_off_x, max_off_y; /* where the robot was furthest off */
    int64_t t;
    /* Localisation noise: a pose every pose_us with Gaussian errors (0: exact poses). */
    double sigma_xy, sigma_th;
    int64_t pose_us;
    rfs_pose_t meas;      /* the last pose published */
    uint64_t rng;
    double turn_s;        /* time turning on the spot (|v| < 20 mm/s, |omega| > 0.05 rad/s) */
} sim_t;

/* Standard normal draw (xorshift64 + Box-Muller), reproducible. */
static double gauss(sim_t *s)
{
    double u[2];
    for (int i = 0; i < 2; i++) {
        s->rng ^= s->rng << 13;
        s->rng ^= s->rng >> 7;
        s->rng ^= s->rng << 17;
        u[i] = ((s->rng >> 11) + 0.5) / 9007199254740992.0;
    }
    return sqrt(-2.0 * log(u[0])) * cos(2.0 * M_PI * u[1]);
}

static double seg_dist(double px, double py, double ax, double ay, double bx, double by)
{
    double dx = bx - ax, dy = by - ay;
    double l2 = dx * dx + dy * dy;
    double u = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0.0;
    u = u < 0 ? 0 : (u > 1 ? 1 : u);
    return hypot(px - ax - u * dx, py - ay - u * dy);
}

static double path_dist(const sim_t *s, const rfs_path_t *p)
{
    double best = 1e9, ax = s->x0, ay = s->y0;
    for (int k = 0; k < p->n; k++) {
        double bx = p->x[k] / 65536.0, by = p->y[k] / 65536.0;
        best = fmin(best, seg_dist(s->x, s->y, ax, ay, bx, by));
        ax = bx;
        ay = by;
    }
    return best;
}

static rfs_q16_t q16(double v)
{
    return (rfs_q16_t)llround(v * 65536.0);
}

static rfs_pose_t pose_of(const sim_t *s)
{
    rfs_pose_t p;
    double th = atan2(sin(s->th), cos(s->th));
    p.t_us = s->t;
    p.x = q16(s->x);
    p.y = q16(s->y);
    p.theta = q16(th);
    return p;
}

/* The pose the drive sees at s->t: exact, or the last noisy pose published. */
static rfs_pose_t observed(sim_t *s)
{
    if (s->pose_us == 0) {
        return pose_of(s);
    }
    if (s->t % s->pose_us == 0) {
        double th = s->th + s->sigma_th * gauss(s);
        s->meas.t_us = s->t;
        s->meas.x = q16(s->x + s->sigma_xy * gauss(s));
        s->meas.y = q16(s->y + s->sigma_xy * gauss(s));
        s->meas.theta = q16(atan2(sin(th), cos(th)));
    }
    return s->meas;
}

/* Run until the drive reports an end or max_s elapses; frozen: the robot does not move. */
static rfs_drive_status_t run(rfs_drive_t *d, sim_t *s, const rfs_path_t *path, double max_s,
                              bool frozen, int64_t *end_us)
{
    const double b = d->cfg.wheel_base_mm / 1000.0;
    for (int k = 0; k < path->n; k++) {
        s->min_wp_dist[k] = 1e9;
    }
    s->x0 = s->x;
    s->y0 = s->y;
    s->max_off_path = 0;
    while (s->t < (int64_t)(max_s * 1e6)) {
        rfs_pose_t p = observed(s);
        int16_t l;
        int16_t r;
        rfs_drive_status_t st = rfs_drive_update(d, &p, s->t, &l, &r);
        if (abs(l) > d->cfg.v_max_mm_s || abs(r) > d->cfg.v_max_mm_s) {
            s->violations_speed++;
        }
        double lim = d->cfg.accel_mm_s2 * (DT_US / 1e6) + 1.0;
        if (fabs((double)l - s->l) > lim || fabs((double)r - s->r) > lim) {
            s->violations_accel++;
        }
        s->l = l;
        s->r = r;
        if (abs(l + r) < 40 && abs(r - l) * 1e-3 / b > 0.05) {
            s->turn_s += DT_US * 1e-6;
        }
        if (st != RFS_DRIVE_RUNNING) {
            *end_us = s->t;
            return st;
        }
        for (int sub = 0; sub < DT_US / 1000; sub++) {
            if (frozen) {
                break;
            }
            double v = (l + r) / 2000.0;
            double w = (r - l) / 1000.0 / b;
            s->x += v * cos(s->th) * 1e-3;
            s->y += v * sin(s->th) * 1e-3;
            s->th += w * 1e-3;
            s->travelled += fabs(v) * 1e-3;
            double off = path_dist(s, path);
            if (off > s->max_off_path) {
                s->max_off_path = off;
                s->max_off_x = s->x;
                s->max_off_y = s->y;
            }
        }
        for (int k = 0; k < path->n; k++) {
            s->min_wp_dist[k] = fmin(s->min_wp_dist[k], hypot(s->x - path->x[k] / 65536.0,
                                                               s->y - path->y[k] / 65536.0));
        }
        s->t += DT_US;
    }
    *end_us = s->t;
    return RFS_DRIVE_RUNNING;
}

static rfs_path_t one_goal(double x, double y)
{
    rfs_path_t p;
    memset(&p, 0, sizeof(p));
    p.x[0] = q16(x);
    p.y[0] = q16(y);
    p.n = 1;
    return p;
}

static void start(rfs_drive_t *d, sim_t *s, double x, double y, double th)
{
    rfs_drive_cfg_t cfg = rfs_drive_cfg_default();
    assert_int_equal(rfs_drive_init(d, &cfg), 0);
    memset(s, 0, sizeof(*s));
    s->x = x;
    s->y = y;
    s->th = th;
}

/* A fresh drive and robot at the origin heading th (radians), given the one goal (gx, gy)
 * (metres) at t = 0; the path is returned for run(). */
static rfs_path_t start_to(rfs_drive_t *d, sim_t *s, double th, double gx, double gy)
{
    start(d, s, 0.0, 0.0, th);
    rfs_path_t p = one_goal(gx, gy);
    rfs_drive_set_path(d, &p, 0);
    return p;
}

/* The update one period after end_us (the run's last) reports IDLE; the wheel commands it
 * gives are returned in *l, *r (mm/s). */
static void expect_idle_after(rfs_drive_t *d, const sim_t *s, int64_t end_us, int16_t *l,
                              int16_t *r)
{
    rfs_pose_t pp = pose_of(s);
    assert_int_equal(rfs_drive_update(d, &pp, end_us + DT_US, l, r), RFS_DRIVE_IDLE);
}

/* Straight ahead, behind, and random goals from random headings: all reached. */
static void test_reaches_goals(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    srand(4);
    for (int k = 0; k < 40; k++) {
        double th = (k == 0) ? 0.0 : (k == 1 ? 0.0 : (rand() / (double)RAND_MAX) * 6.283 - 3.1416);
        double gx = (k == 0) ? 3.0 : (k == 1 ? -2.0 : (rand() / (double)RAND_MAX) * 8.0 - 4.0);
        double gy = (k <= 1) ? 0.0 : (rand() / (double)RAND_MAX) * 8.0 - 4.0;
        rfs_path_t p = start_to(&d, &s, th, gx, gy);
        rfs_drive_status_t st = run(&d, &s, &p, 60.0, false, &end);
        assert_int_equal(st, RFS_DRIVE_REACHED);
        assert_true(hypot(s.x - gx, s.y - gy) <= 0.1 + 1e-3);
        assert_int_equal(s.l, 0);
        assert_int_equal(s.r, 0);
        assert_int_equal(s.violations_speed, 0);
        assert_int_equal(s.violations_accel, 0);
        /* Not much longer than the straight line (turning on the spot travels ~0). */
        assert_true(s.travelled <= hypot(gx, gy) * 1.15 + 0.3);
        /* The time is physically plausible: at least distance / v_max. */
        assert_true(end / 1e6 >= (hypot(gx, gy) - 0.1) / 0.7);
        /* REACHED is reported once, then IDLE with wheels at 0. */
        int16_t l;
        int16_t r;
        expect_idle_after(&d, &s, end, &l, &r);
        assert_int_equal(l, 0);
        assert_int_equal(r, 0);
    }
    /* Straight 3 m: the top speed is reached and the run takes about the ideal time of a
     * trapezoid profile (accelerate at 1 m/s^2, cruise at 0.7 m/s, brake at 0.5 m/s^2). */
    rfs_path_t p = start_to(&d, &s, 0.0, 3.0, 0.0);
    assert_int_equal(run(&d, &s, &p, 60.0, false, &end), RFS_DRIVE_REACHED);
    double ideal = 0.7 / 1.0 + 0.7 / 0.5 + (3.0 - 0.7 * 0.7 / 2 - 0.7 * 0.7 / 1.0) / 0.7;
    assert_true(end / 1e6 > ideal - 0.5 && end / 1e6 < ideal + 1.0);
}

/* A path with a right-angle corner: the corner waypoint is passed closely. */
static void test_follows_waypoints(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    start(&d, &s, 0.0, 0.0, 0.0);
    rfs_path_t p;
    memset(&p, 0, sizeof(p));
    p.x[0] = q16(3.0);
    p.y[0] = q16(0.0);
    p.x[1] = q16(3.0);
    p.y[1] = q16(3.0);
    p.x[2] = q16(1.0);
    p.y[2] = q16(4.0);
    p.n = 3;
    rfs_drive_set_path(&d, &p, 0);
    assert_int_equal(run(&d, &s, &p, 60.0, false, &end), RFS_DRIVE_REACHED);
    /* Corners are not cut by more than the clearance margin allows: the clearance is
     * 0.25 m and the Kobuki's radius 0.177 m, so the robot must stay within 0.07 m of
     * the planned (legal) polyline. */
    print_message("corner distances %.3f %.3f, max off path %.3f m\n", s.min_wp_dist[0],
                  s.min_wp_dist[1], s.max_off_path);
    assert_true(s.min_wp_dist[0] < 0.1);
    assert_true(s.min_wp_dist[1] < 0.1);
    assert_true(s.max_off_path < 0.07);
    assert_true(hypot(s.x - 1.0, s.y - 4.0) <= 0.1 + 1e-3);
    assert_int_equal(s.violations_speed, 0);
    assert_int_equal(s.violations_accel, 0);
}

/* A random polyline of five waypoints from the origin, legs 0.3-3.3 m, turns up to 150
 * degrees; the start heading in *th0. */
static rfs_path_t random_polyline(double *th0)
{
    *th0 = (rand() / (double)RAND_MAX) * 6.283 - 3.1416;
    rfs_path_t p;
    memset(&p, 0, sizeof(p));
    double x = 0, y = 0, h = (rand() / (double)RAND_MAX) * 6.283;
    for (int w = 0; w < 5; w++) {
        double len = 0.3 + (rand() / (double)RAND_MAX) * 3.0;
        x += len * cos(h);
        y += len * sin(h);
        p.x[w] = q16(x);
        p.y[w] = q16(y);
        p.length += q16(len);
        h += ((rand() / (double)RAND_MAX) * 2.0 - 1.0) * 2.6;
    }
    p.n = 5;
    return p;
}

/* The robot standing for us microseconds with the drive idle (its pose filter settles,
 * as it does before a mission's first goal). */
static void settle(rfs_drive_t *d, sim_t *s, int64_t us)
{
    int64_t until = s->t + us;
    for (; s->t < until; s->t += DT_US) {
        rfs_pose_t p = observed(s);
        int16_t l, r;
        (void)rfs_drive_update(d, &p, s->t, &l, &r);
    }
}

/* Random polylines: all reached, the robot never more than 0.07 m off the polyline. */
static void test_random_polylines(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    srand(11);
    double worst = 0;
    for (int k = 0; k < 20; k++) {
        double th0;
        rfs_path_t p = random_polyline(&th0);
        start(&d, &s, 0.0, 0.0, th0);
        rfs_drive_set_path(&d, &p, 0);
        assert_int_equal(run(&d, &s, &p, 120.0, false, &end), RFS_DRIVE_REACHED);
        double gx = p.x[4] / 65536.0, gy = p.y[4] / 65536.0;
        assert_true(hypot(s.x - gx, s.y - gy) <= 0.1 + 1e-3);
        assert_int_equal(s.violations_speed, 0);
        assert_int_equal(s.violations_accel, 0);
        worst = fmax(worst, s.max_off_path);
        if (getenv("DRIVE_DEBUG")) {
            print_message("path %d: off %.3f at (%.2f, %.2f), end (%.2f, %.2f)\n", k, s.max_off_path,
                          s.max_off_x, s.max_off_y, gx, gy);
        }
    }
    print_message("worst distance off the polyline %.3f m\n", worst);
    assert_true(worst < 0.07);
}

/* A base far wider than the Kobuki's (1 m): steering while driving asks the outer wheel
 * for more than v_max, so both wheels are scaled down; no command above v_max. */
static void test_wide_base_keeps_the_speed_limit(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    srand(11);
    for (int k = 0; k < 20; k++) {
        double th0;
        rfs_path_t p = random_polyline(&th0);
        start(&d, &s, 0.0, 0.0, th0);
        rfs_drive_cfg_t cfg = rfs_drive_cfg_default();
        cfg.wheel_base_mm = 1000;
        assert_int_equal(rfs_drive_init(&d, &cfg), 0);
        rfs_drive_set_path(&d, &p, 0);
        assert_int_equal(run(&d, &s, &p, 120.0, false, &end), RFS_DRIVE_REACHED);
        assert_int_equal(s.violations_speed, 0);
        assert_int_equal(s.violations_accel, 0);
    }
}

/* The same polylines with the simulator's default localisation noise (5 cm per axis,
 * 0.02 rad, 10 Hz) and with twice that: every goal reached (none abandoned), the true
 * robot within clearance - radius (0.25 - 0.177 m) of the polyline at 5 cm, and no more
 * turning on the spot than with exact poses (no dithering at the waypoints). */
static void test_noisy_polylines(void **state)
{
    (void)state;
    const double sig[2] = {0.05, 0.10};
    for (int n = 0; n < 2; n++) {
        rfs_drive_t d;
        sim_t s;
        int64_t end;
        double worst = 0, worst_end = 0, turn_exact = 0, turn_noisy = 0;
        srand(11);
        for (int k = 0; k < 20; k++) {
            double th0;
            rfs_path_t p = random_polyline(&th0);
            double gx = p.x[4] / 65536.0, gy = p.y[4] / 65536.0;
            start(&d, &s, 0.0, 0.0, th0);
            rfs_drive_set_path(&d, &p, 0);
            assert_int_equal(run(&d, &s, &p, 120.0, false, &end), RFS_DRIVE_REACHED);
            turn_exact += s.turn_s;
            start(&d, &s, 0.0, 0.0, th0);
            s.sigma_xy = sig[n];
            s.sigma_th = 0.02;
            s.pose_us = 100000;
            s.rng = 0x9E3779B97F4A7C15ull + (uint64_t)k;
            settle(&d, &s, 2000000);
            rfs_drive_set_path(&d, &p, s.t);
            assert_int_equal(run(&d, &s, &p, 120.0, false, &end), RFS_DRIVE_REACHED);
            assert_int_equal(s.violations_speed, 0);
            assert_int_equal(s.violations_accel, 0);
            turn_noisy += s.turn_s;
            worst = fmax(worst, s.max_off_path);
            worst_end = fmax(worst_end, hypot(s.x - gx, s.y - gy));
        }
        print_message("noise %.2f m: worst off the polyline %.3f m, worst end %.3f m, turning "
                      "%.1f s (exact poses %.1f s)\n", sig[n], worst, worst_end, turn_noisy,
                      turn_exact);
        if (n == 0) {
            assert_true(worst < 0.25 - 0.177);
        }
        /* REACHED is judged on the estimate, whose error is sigma sqrt(k / (2 - k)). */
        double k = d.cfg.pose_gain / 65536.0;
        assert_true(worst_end <= 0.1 + 3.0 * sig[n] * sqrt(k / (2.0 - k)));
        assert_true(turn_noisy <= 1.2 * turn_exact + 1.0);
    }
}

/* An update at the pose's time with pose p: the estimate is p itself (replaced, not
 * blended). */
static void expect_replaced(rfs_drive_t *d, const rfs_pose_t *p)
{
    int16_t l, r;
    (void)rfs_drive_update(d, p, p->t_us, &l, &r);
    rfs_pose_t e;
    (void)rfs_drive_estimate(d, &e);
    assert_int_equal(e.x, p->x);
    assert_int_equal(e.y, p->y);
}

/* The pose filter on a robot standing still with noisy poses: its error's standard
 * deviation is sigma sqrt(k / (2 - k)) for gain k, the first-order filter's theory
 * (e_n = (1 - k) e_n-1 + k w_n), within 15 %; a pose 1 m away replaces the estimate. */
static void test_pose_filter(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    start(&d, &s, 1.0, 2.0, 0.5);
    s.sigma_xy = 0.05;
    s.sigma_th = 0.02;
    s.pose_us = 100000;
    s.rng = 12345;
    double sx = 0, sth = 0;
    long n = 0;
    for (s.t = 0; s.t < 400000000; s.t += DT_US) {
        rfs_pose_t p = observed(&s);
        int16_t l, r;
        assert_int_equal(rfs_drive_update(&d, &p, s.t, &l, &r), RFS_DRIVE_IDLE);
        rfs_pose_t e;
        assert_true(rfs_drive_estimate(&d, &e));
        if (s.t >= 5000000 && s.t % s.pose_us == 0) {
            sx += pow(e.x / 65536.0 - 1.0, 2) + pow(e.y / 65536.0 - 2.0, 2);
            sth += pow(e.theta / 65536.0 - 0.5, 2);
            n++;
        }
    }
    double k = d.cfg.pose_gain / 65536.0, f = sqrt(k / (2.0 - k));
    double rx = sqrt(sx / (2.0 * n)), rth = sqrt(sth / n);
    print_message("filter: %.4f m (theory %.4f), %.4f rad (theory %.4f)\n", rx, 0.05 * f, rth,
                  0.02 * f);
    assert_true(fabs(rx / (0.05 * f) - 1.0) < 0.15);
    assert_true(fabs(rth / (0.02 * f) - 1.0) < 0.15);
    /* Relocalised 1 m away: the next update steers by the new pose. */
    rfs_pose_t far = {s.t, q16(2.0), q16(2.0), q16(0.5)};
    expect_replaced(&d, &far);
}

/* Exact poses at 10 Hz while driving: between poses the estimate is dead-reckoned from the
 * commanded wheel speeds and stays within 2 mm of the truth. */
static void test_dead_reckoning(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    srand(5);
    double th0;
    rfs_path_t p = random_polyline(&th0);
    start(&d, &s, 0.0, 0.0, th0);
    s.pose_us = 100000;
    rfs_drive_set_path(&d, &p, 0);
    double worst = 0;
    while (s.t < 60000000) {
        double x = s.x, y = s.y; /* where the robot is at the update */
        rfs_drive_status_t st = run(&d, &s, &p, (s.t + DT_US) / 1e6, false, &end);
        rfs_pose_t e;
        (void)rfs_drive_estimate(&d, &e);
        worst = fmax(worst, hypot(e.x / 65536.0 - x, e.y / 65536.0 - y));
        if (st != RFS_DRIVE_RUNNING) {
            break;
        }
    }
    print_message("dead reckoning: worst %.4f m\n", worst);
    assert_true(worst < 0.002);
}

/* The time limit grows with the path: a 10 m path at a 2 s timeout is driven to the end
 * (2 s + 10 m at half the top speed = 30.6 s). */
static void test_time_limit_grows(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    rfs_drive_cfg_t cfg = rfs_drive_cfg_default();
    cfg.timeout_us = 2000000;
    assert_int_equal(rfs_drive_init(&d, &cfg), 0);
    memset(&s, 0, sizeof(s));
    rfs_path_t p = one_goal(10.0, 0.0);
    p.length = q16(10.0);
    rfs_drive_set_path(&d, &p, 0);
    assert_int_equal(d.limit_us, 2000000 + 10000 * 2000000LL / 700);
    assert_int_equal(run(&d, &s, &p, 60.0, false, &end), RFS_DRIVE_REACHED);
    assert_true(end > 2000000 && end < d.limit_us);
}

/* A path planned straight into the drive's own path buffer (no stack copy) works. */
static void test_set_path_in_place(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    start(&d, &s, 0.0, 0.0, 0.0);
    d.path = one_goal(2.0, 1.0);
    rfs_drive_set_path(&d, &d.path, 0);
    rfs_path_t p = one_goal(2.0, 1.0);
    assert_int_equal(run(&d, &s, &p, 60.0, false, &end), RFS_DRIVE_REACHED);
    assert_true(hypot(s.x - 2.0, s.y - 1.0) <= 0.1 + 1e-3);
}

/* A goal that cannot be reached in time: TIMEOUT after timeout_us, once. */
static void test_timeout(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    rfs_drive_cfg_t cfg = rfs_drive_cfg_default();
    cfg.timeout_us = 2000000;
    assert_int_equal(rfs_drive_init(&d, &cfg), 0);
    memset(&s, 0, sizeof(s));
    rfs_path_t p = one_goal(10.0, 0.0);
    rfs_drive_set_path(&d, &p, 0);
    assert_int_equal(run(&d, &s, &p, 60.0, false, &end), RFS_DRIVE_TIMEOUT);
    assert_true(end > 2000000 && end <= 2000000 + DT_US);
    int16_t l;
    int16_t r;
    expect_idle_after(&d, &s, end, &l, &r);
    /* Abandoned: the wheels ramp down within the acceleration limit. */
    assert_true(l < s.l && l >= s.l - 21);
}

/* A robot that cannot move (against a wall): BLOCKED after the stall window, with poses at
 * 10 Hz as localisation publishes them. */
static void test_blocked(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    rfs_path_t p = start_to(&d, &s, 0.0, 5.0, 0.0);
    s.pose_us = 100000; /* poses at 10 Hz: the estimate runs ahead, the judgement does not */
    assert_int_equal(run(&d, &s, &p, 60.0, true, &end), RFS_DRIVE_BLOCKED);
    assert_true(end >= d.cfg.stall_us && end <= d.cfg.stall_us + 2 * DT_US);
    /* Moving normally it is not blocked. */
    p = start_to(&d, &s, 0.0, 5.0, 0.0);
    assert_int_equal(run(&d, &s, &p, 60.0, false, &end), RFS_DRIVE_REACHED);
}

/* Stop: zero at once, idle. */
static void test_stop(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    rfs_path_t p = start_to(&d, &s, 0.0, 5.0, 0.0);
    assert_int_equal(run(&d, &s, &p, 1.0, false, &end), RFS_DRIVE_RUNNING);
    assert_true(s.l > 500);
    rfs_drive_stop(&d, end);
    int16_t l;
    int16_t r;
    expect_idle_after(&d, &s, end, &l, &r);
    assert_int_equal(l, 0);
    assert_int_equal(r, 0);
}

/* Timestamps at the ends of int64 (clock faults, replayed garbage): no undefined
 * behaviour (this test also runs under UBSan), the estimate stays a pose it was given. */
static void test_extreme_stamps(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    start(&d, &s, 1.0, 1.0, 0.0);
    rfs_path_t p = one_goal(3.0, 1.0);
    rfs_drive_set_path(&d, &p, INT64_MIN);
    const int64_t ts[] = {INT64_MIN, INT64_MIN + 1, -1, 0, INT64_MAX - 1, INT64_MAX, 0};
    for (unsigned i = 0; i < sizeof ts / sizeof ts[0]; i++) {
        for (unsigned j = 0; j < sizeof ts / sizeof ts[0]; j++) {
            rfs_pose_t pose = {ts[i], q16(1.0), q16(1.0), INT32_MAX}; /* heading unwrapped */
            int16_t l, r;
            (void)rfs_drive_update(&d, &pose, ts[j], &l, &r);
            assert_true(abs(l) <= d.cfg.v_max_mm_s && abs(r) <= d.cfg.v_max_mm_s);
            rfs_pose_t e;
            assert_true(rfs_drive_estimate(&d, &e));
            assert_true(e.theta > -RFS_Q16_PI && e.theta <= RFS_Q16_PI);
            assert_true(llabs((long long)e.x - q16(1.0)) < q16(0.2));
        }
    }
}

/* After 3 s without poses, a pose 0.4 m from the estimate (within the 0.5 m reset radius)
 * replaces it: the robot is where localisation says, not where it was. */
static void test_pose_after_silence(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    start(&d, &s, 1.0, 1.0, 0.0);
    rfs_pose_t p0 = {0, q16(1.0), q16(1.0), 0};
    int16_t l, r;
    for (int64_t t = 0; t <= 3100000; t += DT_US) {
        (void)rfs_drive_update(&d, &p0, t, &l, &r);
    }
    rfs_pose_t p1 = {3100000, q16(1.4), q16(1.0), 0};
    expect_replaced(&d, &p1);
}

/* Pushed 0.45 m sideways 0.2 m before the goal: the robot turns back to the goal and
 * reaches it (no BLOCKED, no crawl past it); and a last leg of 2 cm after a 2 m one ends
 * within goal_tol (the corner speed allows stopping within the last leg). */
static void test_goal_after_push(void **state)
{
    (void)state;
    rfs_drive_t d;
    sim_t s;
    int64_t end;
    rfs_path_t p = start_to(&d, &s, 0.0, 3.0, 0.0);
    s.pose_us = 100000;
    assert_int_equal(run(&d, &s, &p, 2.0, false, &end), RFS_DRIVE_RUNNING);
    while (s.x < 2.8) {
        assert_int_equal(run(&d, &s, &p, (s.t + DT_US) / 1e6, false, &end), RFS_DRIVE_RUNNING);
    }
    s.y += 0.45;
    assert_int_equal(run(&d, &s, &p, 60.0, false, &end), RFS_DRIVE_REACHED);
    assert_true(hypot(s.x - 3.0, s.y) <= 0.1 + 0.01);

    start(&d, &s, 0.0, 0.0, 0.0);
    memset(&p, 0, sizeof p);
    p.x[0] = q16(2.0);
    p.x[1] = q16(2.02);
    p.n = 2;
    rfs_drive_set_path(&d, &p, 0);
    assert_int_equal(run(&d, &s, &p, 60.0, false, &end), RFS_DRIVE_REACHED);
    print_message("short last leg: ends %.3f m from the goal\n", hypot(s.x - 2.02, s.y));
    assert_true(hypot(s.x - 2.02, s.y) <= 0.1 + 0.01);
}

/* The first leg runs from the path's start when it has one: the segment the planner
 * checked, not the line from wherever the robot stands when the drive takes the path.
 * The robot starts 8 cm beside the planned start (0, 0), the goal is (6, 0); after 6 s
 * (about 3.5 m) it is on y = 0 within 1 cm. Without a start (a path built by hand) it
 * follows its own start's line to the goal, y = 0.08 (1 - x / 6), as before. */
static void test_first_leg_from_path_start(void **state)
{
    (void)state;
    for (int with = 0; with <= 1; with++) {
        rfs_drive_t d;
        sim_t s;
        start(&d, &s, 0.0, 0.08, 0.0);
        rfs_path_t p = one_goal(6.0, 0.0);
        p.has_start = with != 0;
        p.x0 = 0;
        p.y0 = 0;
        rfs_drive_set_path(&d, &p, 0);
        int64_t end_us;
        assert_int_equal(run(&d, &s, &p, 6.0, false, &end_us), RFS_DRIVE_RUNNING);
        double line = with ? 0.0 : 0.08 * (1.0 - s.x / 6.0);
        print_message("%s start: at x %.3f m, y %.4f m, the leg's line %.4f m\n",
                      with ? "with" : "without", s.x, s.y, line);
        assert_true(s.x > 2.5 && s.x < 5.0);
        assert_true(fabs(s.y - line) < 0.01);
    }
}

/* Distance from (px, py) to the closed triangle abc (0 inside). */
static double tri_dist(double px, double py, const double t[6])
{
    double s0 = (t[2] - t[0]) * (py - t[1]) - (t[3] - t[1]) * (px - t[0]);
    double s1 = (t[4] - t[2]) * (py - t[3]) - (t[5] - t[3]) * (px - t[2]);
    double s2 = (t[0] - t[4]) * (py - t[5]) - (t[1] - t[5]) * (px - t[4]);
    if ((s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0)) {
        return 0.0;
    }
    return fmin(seg_dist(px, py, t[0], t[1], t[2], t[3]),
                fmin(seg_dist(px, py, t[2], t[3], t[4], t[5]), seg_dist(px, py, t[4], t[5], t[0], t[1])));
}

/* A short last leg with the robot beside it (a plan started from a snapped lattice point,
 * or re-planned under pose noise): the robot keeps within the triangle of its own start,
 * the leg's start and the goal, give or take 3 cm, and ends within goal_tol of the goal.
 * It used to steer at a carrot on the leg's line beyond the goal and stop up to goal_tol
 * past it on the far side, unchecked space beside a wall (a Willow Garage contact). */
static void test_short_last_leg_stays_inside(void **state)
{
    (void)state;
    const double starts[][3] = {{0.05, 0.12, 0.0}, {0.1, -0.12, 0.3}, {0.2, 0.1, -0.2},
                                {-0.05, 0.15, -0.5}, {0.0, 0.1, 1.2}, {0.15, -0.08, -1.0}};
    double worst = 0;
    for (size_t k = 0; k < sizeof starts / sizeof starts[0]; k++) {
        for (int len = 0; len < 3; len++) {
            rfs_drive_t d;
            sim_t s;
            double bx = 0.2 + 0.1 * len;
            start(&d, &s, starts[k][0], starts[k][1], starts[k][2]);
            rfs_path_t p = one_goal(bx, 0.0);
            p.has_start = true; /* the leg (0, 0) -> (bx, 0) */
            rfs_drive_set_path(&d, &p, 0);
            const double tri[6] = {starts[k][0], starts[k][1], 0.0, 0.0, bx, 0.0};
            double off = 0;
            rfs_drive_status_t st = RFS_DRIVE_RUNNING;
            while (st == RFS_DRIVE_RUNNING && s.t < 20000000) {
                int64_t end;
                st = run(&d, &s, &p, (s.t + DT_US) / 1e6, false, &end);
                off = fmax(off, tri_dist(s.x, s.y, tri));
            }
            assert_int_equal(st, RFS_DRIVE_REACHED);
            assert_true(hypot(s.x - bx, s.y) <= 0.1 + 1e-3);
            worst = fmax(worst, off);
            if (getenv("DRIVE_DEBUG")) {
                print_message("start %zu leg %.1f: off %.3f, end (%.3f, %.3f)\n", k, bx, off, s.x, s.y);
            }
        }
    }
    print_message("short last legs: worst distance outside the triangle %.3f m\n", worst);
    assert_true(worst < 0.03); /* an arc that turns while driving: 0.024 m; 0.079 before */
}

static void test_init_rejects(void **state)
{
    (void)state;
    rfs_drive_t d;
    rfs_drive_cfg_t c = rfs_drive_cfg_default();
    assert_int_equal(c.wheel_base_mm, 230);
    assert_int_equal(c.v_max_mm_s, 700);
    rfs_drive_cfg_t b = c;
    b.wheel_base_mm = 0;
    assert_int_equal(rfs_drive_init(&d, &b), -1);
    b = c;
    b.v_max_mm_s = -1;
    assert_int_equal(rfs_drive_init(&d, &b), -1);
    b = c;
    b.accel_mm_s2 = 0;
    assert_int_equal(rfs_drive_init(&d, &b), -1);
    b = c;
    b.goal_tol = 0;
    assert_int_equal(rfs_drive_init(&d, &b), -1);
    b = c;
    b.timeout_us = 0;
    assert_int_equal(rfs_drive_init(&d, &b), -1);
    b = c;
    b.turn_out = b.turn_in_place + 1;
    assert_int_equal(rfs_drive_init(&d, &b), -1);
    b = c;
    b.lookahead = 0;
    assert_int_equal(rfs_drive_init(&d, &b), -1);
    b = c;
    b.pose_gain = RFS_Q16_ONE + 1;
    assert_int_equal(rfs_drive_init(&d, &b), -1);
    b = c;
    b.pose_gain = RFS_Q16_ONE; /* raw poses: allowed */
    assert_int_equal(rfs_drive_init(&d, &b), 0);
    assert_int_equal(rfs_drive_init(&d, &c), 0);
    assert_int_equal(d.status, RFS_DRIVE_IDLE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reaches_goals),
        cmocka_unit_test(test_follows_waypoints),
        cmocka_unit_test(test_random_polylines),
        cmocka_unit_test(test_wide_base_keeps_the_speed_limit),
        cmocka_unit_test(test_noisy_polylines),
        cmocka_unit_test(test_pose_filter),
        cmocka_unit_test(test_dead_reckoning),
        cmocka_unit_test(test_time_limit_grows),
        cmocka_unit_test(test_extreme_stamps),
        cmocka_unit_test(test_pose_after_silence),
        cmocka_unit_test(test_goal_after_push),
        cmocka_unit_test(test_set_path_in_place),
        cmocka_unit_test(test_timeout),
        cmocka_unit_test(test_blocked),
        cmocka_unit_test(test_stop),
        cmocka_unit_test(test_first_leg_from_path_start),
        cmocka_unit_test(test_short_last_leg_stays_inside),
        cmocka_unit_test(test_init_rejects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
