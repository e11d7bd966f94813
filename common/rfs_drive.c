/* rfs_drive.c - differential-drive path following under pose noise (docs/MAPS.md,
 * "Drive control").
 *
 * Per update:
 *  - Pose filter. The estimate is carried forward by the base's wheel speeds (the
 *    commands, ramped at the acceleration limit: dead reckoning) and, when a new
 *    localisation pose has arrived, moved pose_gain of the way towards it (the pose itself
 *    carried forward from its timestamp to now). A pose further than POSE_RESET_M or
 *    POSE_RESET_RAD from the estimate, or after a gap of POSE_STALE_US, replaces it.
 *  - Segment. The robot follows the line from the previous waypoint (or the point the
 *    path was planned from) A to the waypoint approached B: progress u along AB, cross-track error c.
 *    A waypoint other than the goal is passed when the robot crosses the perpendicular
 *    at B (u >= |AB|) or comes within SWITCH_DIST of it. The goal is reached within
 *    goal_tol.
 *  - Steering. The carrot is the point lookahead ahead of the robot's projection on the
 *    line AB, on the goal's leg at most the goal itself; e is the heading error to it.
 *    The carrot never lies on the next leg, so corners are not cut.
 *  - Turning on the spot once |e| exceeds turn_in_place, until |e| < turn_out (the
 *    hysteresis keeps small heading errors from stopping the robot): omega = 3 e, wheels
 *    at most v_max / 2 and slow enough to stop within the remaining angle.
 *  - Otherwise v = clamp(sqrt(2 (a/2) d + v_corner^2), 0.05 m/s, v_max) times
 *    (1 - |e| / turn_in_place)^2, omega = 2.5 e. d is the distance left along AB to B
 *    (to half the goal tolerance from the goal); v_corner = v_max (1 - turn /
 *    turn_in_place)^2 for the turn between AB and the next leg, at most what stops within
 *    the next leg (0 at the goal and for turns it will make on the spot).
 *  - BLOCKED is judged on the localisation pose's distance to the waypoint.
 *  - Both wheel targets are scaled together to v_max, then each wheel moves towards its
 *    target by at most accel * dt. At the goal both wheels ramp to 0 and the goal is
 *    REACHED when they are 0.
 */
#include "rfs_drive.h"

#include <string.h>

#define TWO_PI_Q16 ((int64_t)2 * RFS_Q16_PI)
/* A waypoint other than the goal also counts as passed within this distance. */
#define SWITCH_DIST_MM 20
/* Slowest forward speed when heading is right, mm/s (stops within 1.3 mm). */
#define V_CREEP 50
/* Steering gains, 1/s in Q16.16. */
#define K_HEADING RFS_Q16_FRAC(5, 2)
#define K_TURN RFS_Q16_INT(3)
/* Longest dt used for the acceleration limit and the dead reckoning (a late update
 * must not jump). */
#define DT_MAX_US 200000
/* A pose this far from the estimate replaces it (relocalised, kidnapped, or the first
 * after a long gap), metres and radians Q16.16. */
#define POSE_RESET_M RFS_Q16_FRAC(1, 2)
#define POSE_RESET_RAD RFS_Q16_FRAC(1, 2)
/* A pose this long after the previous one replaces the estimate. */
#define POSE_STALE_US 1000000
/* Longest goal timeout accepted (11.6 days): the time limit adds the path's time to it. */
#define TIMEOUT_MAX_US ((int64_t)1000000000000)
/* Segments shorter than this have no direction: steer at their end point, mm. */
#define SEG_MIN_MM 10

/* Q16 metres to millimetres (int64, exact to 1/65 mm, rounded). */
static int64_t q16_to_mm(int64_t v)
{
    return (v * 1000 + (v >= 0 ? 32768 : -32768)) / 65536;
}

rfs_drive_cfg_t rfs_drive_cfg_default(void)
{
    rfs_drive_cfg_t c;
    c.wheel_base_mm = 230;               /* Kobuki: 0.23 m */
    c.v_max_mm_s = 700;                  /* Kobuki: 0.7 m/s */
    c.accel_mm_s2 = 1000;                /* yocs_velocity_smoother, TurtleBot: accel_lim_v 1.0 */
    c.goal_tol = RFS_Q16_FRAC(1, 10);    /* 0.1 m */
    c.turn_in_place = RFS_Q16_FRAC(3, 4); /* 0.75 rad (43 degrees) */
    c.turn_out = RFS_Q16_FRAC(1, 5);     /* 0.2 rad (11 degrees) */
    c.lookahead = RFS_Q16_FRAC(2, 5);    /* 0.4 m */
    c.pose_gain = RFS_Q16_FRAC(1, 8);
    c.timeout_us = 30000000;             /* 30 s */
    c.stall_us = 5000000;                /* 5 s */
    c.progress_min = RFS_Q16_FRAC(1, 10); /* 0.1 m per 5 s */
    return c;
}

int rfs_drive_init(rfs_drive_t *d, const rfs_drive_cfg_t *cfg)
{
    if (d == 0 || cfg == 0 || cfg->wheel_base_mm < 10 || cfg->wheel_base_mm > 10000 ||
        cfg->v_max_mm_s <= 0 || cfg->v_max_mm_s > 10000 || cfg->accel_mm_s2 <= 0 ||
        cfg->accel_mm_s2 > 100000 || cfg->goal_tol <= 0 || cfg->timeout_us <= 0 ||
        cfg->timeout_us > TIMEOUT_MAX_US ||
        cfg->turn_in_place <= 0 || cfg->turn_in_place > RFS_Q16_PI || cfg->turn_out <= 0 ||
        cfg->turn_out > cfg->turn_in_place || cfg->lookahead <= 0 ||
        cfg->lookahead > RFS_Q16_INT(100) || cfg->pose_gain <= 0 ||
        cfg->pose_gain > RFS_Q16_ONE || cfg->stall_us <= 0 || cfg->progress_min < 0) {
        return -1;
    }
    memset(d, 0, sizeof(*d));
    d->cfg = *cfg;
    d->status = RFS_DRIVE_IDLE;
    return 0;
}

void rfs_drive_set_path(rfs_drive_t *d, const rfs_path_t *path, int64_t now_us)
{
    if (path != &d->path) {
        d->path = *path;
    }
    if (d->path.n > RFS_PLAN_MAX_WAYPOINTS) {
        d->path.n = RFS_PLAN_MAX_WAYPOINTS;
    }
    d->next = 0;
    d->status = d->path.n > 0 ? RFS_DRIVE_RUNNING : RFS_DRIVE_IDLE;
    d->start_us = now_us;
    d->last_us = now_us; /* from rest: no acceleration step owed for the time before */
    /* The time limit grows with the path: the time to drive it at half the top speed.
     * Scaling: length <= 2^31 Q16 = 3.3e7 mm, times 2e6 < 2^56. */
    uint64_t len_mm = (uint64_t)q16_to_mm(d->path.length > 0 ? d->path.length : 0);
    d->limit_us = d->cfg.timeout_us +
                  (int64_t)rfs_udiv64(len_mm * 2000000u, (uint64_t)d->cfg.v_max_mm_s);
    d->stall_ref_us = now_us;
    d->stall_ref_dist = INT32_MAX;
    /* The first leg starts where the path was planned from, so it is the segment the
     * planner checked; a path without a start (built by hand) starts where the robot is
     * at the next update. */
    d->have_origin = d->path.has_start;
    d->ox = d->path.x0;
    d->oy = d->path.y0;
    d->turning = false;
}

void rfs_drive_stop(rfs_drive_t *d, int64_t now_us)
{
    d->last_us = now_us;
    d->status = RFS_DRIVE_IDLE;
    d->path.n = 0;
    d->left_mm_s = 0; /* the base itself slows at its own rate: base_left/right */
    d->right_mm_s = 0;
}

bool rfs_drive_at_rest(const rfs_drive_t *d)
{
    return d->base_left == 0 && d->base_right == 0;
}

bool rfs_drive_estimate(const rfs_drive_t *d, rfs_pose_t *out)
{
    *out = d->est;
    out->t_us = d->est_us;
    return d->have_est;
}

/* Wrap an angle into (-pi, pi]. The input must lie within +-3 pi: at every call it is the
 * sum or difference of two angles in (-pi, pi] (a fraction of one, at most); anything
 * else goes through wrap_any. */
static rfs_q16_t wrap_pi(int64_t a)
{
    if (a > RFS_Q16_PI) {
        a -= TWO_PI_Q16;
    } else if (a <= -RFS_Q16_PI) {
        a += TWO_PI_Q16;
    }
    if (a > RFS_Q16_PI) {
        a -= TWO_PI_Q16;
    } else if (a <= -RFS_Q16_PI) {
        a += TWO_PI_Q16;
    }
    return (rfs_q16_t)a;
}

/* An angle of any value (a pose's heading is not checked upstream) into (-pi, pi]. */
static rfs_q16_t wrap_any(int64_t a)
{
    return wrap_pi(a - rfs_sdiv64_round(a, TWO_PI_Q16) * TWO_PI_Q16);
}

/* Move cur towards target by at most step. */
static int32_t ramp(int32_t cur, int32_t target, int32_t step)
{
    if (target > cur + step) {
        return cur + step;
    }
    if (target < cur - step) {
        return cur - step;
    }
    return target;
}

/* Speed allowed at distance d_mm from a point to be passed at v_end: sqrt(2 (a/2) d + v_end^2).
 * Scaling and overflow: a <= 1e5 mm/s^2 and d <= 1e8 mm give at most 1e13, uint64. */
static int32_t brake_speed(int32_t accel, int64_t d_mm, int32_t v_end)
{
    if (d_mm < 0) {
        d_mm = 0;
    }
    uint64_t v2 = (uint64_t)accel * (uint64_t)d_mm + (uint64_t)v_end * (uint64_t)v_end;
    uint32_t v = rfs_isqrt64(v2);
    return v > (uint32_t)INT32_MAX ? INT32_MAX : (int32_t)v;
}

/* Dead reckoning: the pose p carried dt_us forward at the base's modelled wheel speeds
 * (the commands, ramped at the acceleration limit), along the arc's mean heading.
 * Scaling and overflow: speeds <= 1e4 mm/s and dt <= 2e5 us: v dt 65536 < 2^47 and
 * (r - l) dt 65536 < 2^48; the distance (Q16, < 2^17) times a Q16 cosine is < 2^33. */
static void dead_reckon(const rfs_drive_t *d, rfs_pose_t *p, int64_t dt_us)
{
    if (dt_us <= 0) {
        return;
    }
    dt_us = dt_us > DT_MAX_US ? DT_MAX_US : dt_us;
    int64_t v2 = (int64_t)d->base_left + d->base_right; /* 2 v, mm/s */
    int64_t dw = (int64_t)d->base_right - d->base_left; /* omega b, mm/s */
    rfs_q16_t dist = (rfs_q16_t)rfs_sdiv64_round(v2 * dt_us * 65536, 2000000000);
    rfs_q16_t dth = (rfs_q16_t)rfs_sdiv64_round(dw * dt_us * 65536,
                                               (int64_t)d->cfg.wheel_base_mm * 1000000);
    rfs_q16_t c;
    rfs_q16_t s;
    rfs_q16_sincos((rfs_q16_t)((int64_t)p->theta + dth / 2), &c, &s); /* any angle */
    p->x = rfs_sat32((int64_t)p->x + (((int64_t)dist * c + 32768) >> 16));
    p->y = rfs_sat32((int64_t)p->y + (((int64_t)dist * s + 32768) >> 16));
    p->theta = wrap_any((int64_t)p->theta + dth); /* a turn of up to 2 v_max DT_MAX / b */
}

/* to - from in microseconds without signed overflow, clamped to [-1, limit]: -1 when to
 * is before from, limit when it is at least limit later. */
static int64_t span_us(int64_t from, int64_t to, int64_t limit)
{
    if (to < from) {
        return -1;
    }
    uint64_t d = (uint64_t)to - (uint64_t)from;
    return d >= (uint64_t)limit ? limit : (int64_t)d;
}

void rfs_drive_observe(rfs_drive_t *d, const rfs_pose_t *pose, int64_t now_us)
{
    int64_t dt = d->have_est ? span_us(d->est_us, now_us, POSE_STALE_US) : -1;
    if (dt > 0) {
        dead_reckon(d, &d->est, dt);
        /* The base follows the commands within the acceleration limit (after a safety
         * stop it is still rolling while the command is already 0). */
        int32_t step = (int32_t)rfs_udiv64((uint64_t)d->cfg.accel_mm_s2 * (uint64_t)dt, 1000000u);
        d->base_left = ramp(d->base_left, d->left_mm_s, step);
        d->base_right = ramp(d->base_right, d->right_mm_s, step);
    }
    if (dt >= 0) {
        d->est_us = now_us;
    }
    bool fresh = !d->have_est || pose->t_us != d->pose_t_us;
    if (!fresh) {
        return; /* no new pose: dead reckoning only */
    }
    /* A pose after a gap (or out of order, or the first) replaces the estimate. */
    bool reset = !d->have_est || dt < 0 ||
                 span_us(d->pose_t_us, pose->t_us, POSE_STALE_US) >= POSE_STALE_US;
    d->pose_t_us = pose->t_us;
    rfs_pose_t m = *pose;
    m.theta = wrap_any(m.theta);
    int64_t age = span_us(pose->t_us, now_us, DT_MAX_US);
    dead_reckon(d, &m, age > 0 ? age : 0);
    int64_t ex = (int64_t)m.x - d->est.x;
    int64_t ey = (int64_t)m.y - d->est.y;
    rfs_q16_t eth = wrap_pi((int64_t)m.theta - d->est.theta);
    if (reset || ex > POSE_RESET_M || ex < -POSE_RESET_M || ey > POSE_RESET_M ||
        ey < -POSE_RESET_M || rfs_q16_abs(eth) > POSE_RESET_RAD) {
        d->est = m;
        d->est_us = now_us;
        d->have_est = true;
        return;
    }
    rfs_q16_t k = d->cfg.pose_gain;
    d->est.x = (rfs_q16_t)(d->est.x + ((ex * k + 32768) >> 16));
    d->est.y = (rfs_q16_t)(d->est.y + ((ey * k + 32768) >> 16));
    d->est.theta = wrap_pi((int64_t)d->est.theta + (((int64_t)eth * k + 32768) >> 16));
}

/* The leg being followed, millimetres relative to its start A: direction (dx, dy) of
 * length len, the robot's progress u along it and its cross-track offset c (left +). */
typedef struct leg {
    int64_t ax, ay;     /* A, mm */
    int64_t dx, dy;     /* B - A, mm */
    int64_t len;        /* |AB|, mm */
    int64_t px, py;     /* robot - A, mm */
    int64_t u, c;       /* progress and cross-track, mm */
} leg_t;

/* Geometry of the leg into waypoint d->next for the estimated pose.
 * Scaling and overflow: Q16 coordinates differ by < 2^32, i.e. < 6.6e7 mm; products of
 * two such differences < 4.4e15 in int64. */
static void leg_of(const rfs_drive_t *d, leg_t *g)
{
    rfs_q16_t axq = d->next == 0 ? d->ox : d->path.x[d->next - 1];
    rfs_q16_t ayq = d->next == 0 ? d->oy : d->path.y[d->next - 1];
    g->ax = q16_to_mm(axq);
    g->ay = q16_to_mm(ayq);
    g->dx = q16_to_mm((int64_t)d->path.x[d->next] - axq);
    g->dy = q16_to_mm((int64_t)d->path.y[d->next] - ayq);
    g->px = q16_to_mm((int64_t)d->est.x - axq);
    g->py = q16_to_mm((int64_t)d->est.y - ayq);
    g->len = (int64_t)rfs_isqrt64((uint64_t)(g->dx * g->dx + g->dy * g->dy));
    if (g->len < SEG_MIN_MM) {
        /* No direction: passed at once; the offset is the distance to B. */
        g->u = g->len;
        g->c = (int64_t)rfs_isqrt64((uint64_t)((g->dx - g->px) * (g->dx - g->px) +
                                               (g->dy - g->py) * (g->dy - g->py)));
        return;
    }
    g->u = rfs_sdiv64_round(g->px * g->dx + g->py * g->dy, g->len);
    g->c = rfs_sdiv64_round(g->dx * g->py - g->dy * g->px, g->len);
}

/* Distance from pose p to waypoint i, millimetres. */
static int64_t pose_dist_mm(const rfs_drive_t *d, const rfs_pose_t *p, uint16_t i)
{
    int64_t x = q16_to_mm((int64_t)d->path.x[i] - p->x);
    int64_t y = q16_to_mm((int64_t)d->path.y[i] - p->y);
    return (int64_t)rfs_isqrt64((uint64_t)(x * x + y * y));
}

/* Distance from the estimate to waypoint i, millimetres. */
static int64_t dist_mm(const rfs_drive_t *d, uint16_t i)
{
    return pose_dist_mm(d, &d->est, i);
}

/* Skip the waypoints passed, each one restarting the stall reference: one by crossing its
 * perpendicular (a second leg whose perpendicular is also behind the robot waits for the
 * next update, so a short leg is not skipped into a corner), any within SWITCH_DIST. The
 * leg into the waypoint approached in *g. */
static void advance(rfs_drive_t *d, leg_t *g, int64_t now_us)
{
    uint16_t last = (uint16_t)(d->path.n - 1u);
    bool crossed = false;
    leg_of(d, g);
    while (d->next < last &&
           ((!crossed && g->u >= g->len) || dist_mm(d, d->next) < SWITCH_DIST_MM)) {
        crossed = crossed || g->u >= g->len;
        d->next++;
        leg_of(d, g);
        d->stall_ref_us = now_us;
        d->stall_ref_dist = INT32_MAX;
    }
}

/* Stall check with rem_mm from the localisation pose (not the dead-reckoned estimate,
 * which runs ahead of a wedged robot) to the waypoint: true when the robot came less than
 * progress_min closer over the last stall_us. */
static bool stalled(rfs_drive_t *d, int64_t rem_mm, int64_t now_us)
{
    const rfs_drive_cfg_t *c = &d->cfg;
    int32_t rem = (int32_t)(rem_mm > INT32_MAX ? INT32_MAX : (rem_mm < 0 ? 0 : rem_mm));
    bool blocked = false;
    if (d->stall_ref_dist == INT32_MAX) {
        d->stall_ref_dist = rem;
        d->stall_ref_us = now_us;
    } else if (now_us >= d->stall_ref_us &&
               (uint64_t)now_us - (uint64_t)d->stall_ref_us >= (uint64_t)c->stall_us) {
        blocked = (int64_t)d->stall_ref_dist - rem < q16_to_mm(c->progress_min);
        d->stall_ref_us = now_us;
        d->stall_ref_dist = rem;
    }
    return blocked;
}

/* Turning on the spot towards heading error e (radians Q16.16): omega * wheel_base / 2,
 * mm/s, capped at v_max / 2 and at a wheel speed that can stop within the remaining arc
 * |e| * b / 2 at half the acceleration limit (no overshoot). */
static int32_t turn_speed(const rfs_drive_cfg_t *c, rfs_q16_t e)
{
    int32_t half_base = c->wheel_base_mm / 2;
    int32_t w_mm = (int32_t)(((int64_t)rfs_q16_mul(K_TURN, e) * half_base) >> 16);
    int32_t cap = c->v_max_mm_s / 2;
    int32_t arc_mm = (int32_t)(((int64_t)rfs_q16_abs(e) * half_base) >> 16);
    int32_t vb = brake_speed(c->accel_mm_s2, arc_mm, 0);
    cap = vb < cap ? vb : cap;
    return w_mm > cap ? cap : (w_mm < -cap ? -cap : w_mm);
}

/* Corner speed at the waypoint approached, mm/s, for the leg g: v_max (1 - theta /
 * turn_in_place)^2 for a turn of theta between the leg and the next one, at most what can
 * stop within the next leg; 0 from turn_in_place on, where the robot will turn on the
 * spot, and at the goal. */
static int32_t corner_speed(const rfs_drive_t *d, const leg_t *g)
{
    const rfs_drive_cfg_t *c = &d->cfg;
    if (d->next >= (uint16_t)(d->path.n - 1u)) {
        return 0;
    }
    int64_t wx = q16_to_mm((int64_t)d->path.x[d->next + 1] - d->path.x[d->next]);
    int64_t wy = q16_to_mm((int64_t)d->path.y[d->next + 1] - d->path.y[d->next]);
    rfs_q16_t theta = rfs_q16_abs(rfs_q16_atan2(g->dx * wy - g->dy * wx, g->dx * wx + g->dy * wy));
    if (theta >= c->turn_in_place) {
        return 0;
    }
    rfs_q16_t f = rfs_q16_div(c->turn_in_place - theta, c->turn_in_place);
    int32_t v = (int32_t)(((int64_t)rfs_q16_mul(f, f) * c->v_max_mm_s) >> 16);
    /* No faster than can stop within the next leg (a short last leg to the goal). */
    int32_t vs = brake_speed(c->accel_mm_s2, (int64_t)rfs_isqrt64((uint64_t)(wx * wx + wy * wy)), 0);
    return vs < v ? vs : v;
}

/* Heading error to the carrot of leg g (radians Q16.16): the point lookahead ahead of
 * the robot's projection on the line AB; the waypoint itself on a leg too short to
 * have a direction, or once past the goal. */
static rfs_q16_t carrot_error(const rfs_drive_t *d, const leg_t *g)
{
    bool goal = d->next == (uint16_t)(d->path.n - 1u);
    int64_t tx;
    int64_t ty;
    if (g->len < SEG_MIN_MM || (goal && g->u >= g->len)) {
        tx = g->dx - g->px;
        ty = g->dy - g->py;
    } else {
        int64_t along = (g->u > 0 ? g->u : 0) + q16_to_mm(d->cfg.lookahead);
        /* On the goal's leg the carrot stops at the goal: a point beyond it is one the
         * planner never checked, and a robot beside a short last leg would steer past the
         * goal and stop within goal_tol of it on the far side. */
        along = goal && along > g->len ? g->len : along;
        tx = rfs_sdiv64_round(along * g->dx, g->len) - g->px;
        ty = rfs_sdiv64_round(along * g->dy, g->len) - g->py;
    }
    return wrap_pi((int64_t)rfs_q16_atan2(ty, tx) - d->est.theta);
}

/* Wheel speed targets (mm/s) for leg g. */
static void steer(rfs_drive_t *d, const leg_t *g, int32_t *tl, int32_t *tr)
{
    const rfs_drive_cfg_t *c = &d->cfg;
    rfs_q16_t e = carrot_error(d, g);
    int32_t v = 0;
    int32_t w_mm = 0; /* omega * wheel_base / 2, mm/s */
    if (rfs_q16_abs(e) > c->turn_in_place) {
        d->turning = true;
    } else if (rfs_q16_abs(e) < c->turn_out) {
        d->turning = false;
    }
    if (d->turning) {
        w_mm = turn_speed(c, e);
    } else {
        /* Brake to the corner speed where the waypoint counts as passed (its
         * perpendicular), or to a stop half the goal tolerance from the goal. */
        bool corner = d->next < (uint16_t)(d->path.n - 1u);
        int64_t left = corner ? g->len - g->u : dist_mm(d, d->next) - q16_to_mm(c->goal_tol / 2);
        v = brake_speed(c->accel_mm_s2, left, corner_speed(d, g));
        v = v < V_CREEP ? V_CREEP : v;
        v = v > c->v_max_mm_s ? c->v_max_mm_s : v;
        /* Fade the forward speed in as the heading error closes. */
        rfs_q16_t fade = rfs_q16_div(c->turn_in_place - rfs_q16_abs(e), c->turn_in_place);
        v = (int32_t)(((int64_t)rfs_q16_mul(fade, fade) * v) >> 16);
        w_mm = (int32_t)(((int64_t)rfs_q16_mul(K_HEADING, e) * (c->wheel_base_mm / 2)) >> 16);
    }
    *tl = v - w_mm;
    *tr = v + w_mm;
    int32_t m = *tl < 0 ? -*tl : *tl;
    int32_t mr = *tr < 0 ? -*tr : *tr;
    m = mr > m ? mr : m;
    if (m > c->v_max_mm_s) {
        /* Scale both wheels: the curvature is kept, the speed drops. */
        *tl = (int32_t)rfs_sdiv64_round((int64_t)*tl * c->v_max_mm_s, m);
        *tr = (int32_t)rfs_sdiv64_round((int64_t)*tr * c->v_max_mm_s, m);
    }
}

/* One update of a running goal: the status, wheel targets in *tl, *tr. */
static rfs_drive_status_t follow(rfs_drive_t *d, const rfs_pose_t *pose, int64_t now_us,
                                 int32_t *tl, int32_t *tr)
{
    const rfs_drive_cfg_t *c = &d->cfg;
    if (!d->have_origin) {
        d->ox = d->est.x;
        d->oy = d->est.y;
        d->have_origin = true;
    }
    leg_t g;
    advance(d, &g, now_us);
    bool goal = d->next == (uint16_t)(d->path.n - 1u);
    int64_t tol = q16_to_mm(c->goal_tol);
    bool at_goal = goal && dist_mm(d, d->next) <= tol;
    if (now_us > d->start_us && (uint64_t)now_us - (uint64_t)d->start_us > (uint64_t)d->limit_us) {
        return RFS_DRIVE_TIMEOUT;
    }
    if (at_goal) {
        return d->left_mm_s == 0 && d->right_mm_s == 0 ? RFS_DRIVE_REACHED : RFS_DRIVE_RUNNING;
    }
    rfs_drive_status_t st = stalled(d, pose_dist_mm(d, pose, d->next), now_us) ? RFS_DRIVE_BLOCKED
                                                                             : RFS_DRIVE_RUNNING;
    steer(d, &g, tl, tr);
    return st;
}

rfs_drive_status_t rfs_drive_update(rfs_drive_t *d, const rfs_pose_t *pose, int64_t now_us,
                                    int16_t *left_mm_s, int16_t *right_mm_s)
{
    const rfs_drive_cfg_t *c = &d->cfg;
    /* Difference without signed overflow at extreme timestamps (clamped to [0, DT_MAX]). */
    int64_t dt = now_us <= d->last_us ? 0
               : ((uint64_t)now_us - (uint64_t)d->last_us > (uint64_t)DT_MAX_US
                      ? DT_MAX_US
                      : (int64_t)((uint64_t)now_us - (uint64_t)d->last_us));
    d->last_us = now_us;
    rfs_drive_observe(d, pose, now_us);
    /* Scaling: accel (mm/s^2, <= 1e5) * dt (us, <= 2e5) < 2^35, / 1e6 without libgcc. */
    int32_t step = (int32_t)rfs_udiv64((uint64_t)c->accel_mm_s2 * (uint64_t)dt, 1000000u);
    int32_t tl = 0;
    int32_t tr = 0;
    rfs_drive_status_t result = d->status;
    if (d->status == RFS_DRIVE_RUNNING) {
        result = follow(d, pose, now_us, &tl, &tr);
    }
    if (result != RFS_DRIVE_RUNNING) {
        tl = 0;
        tr = 0;
    }
    d->left_mm_s = ramp(d->left_mm_s, tl, step);
    d->right_mm_s = ramp(d->right_mm_s, tr, step);
    d->base_left = ramp(d->base_left, d->left_mm_s, step);
    d->base_right = ramp(d->base_right, d->right_mm_s, step);
    *left_mm_s = rfs_sat16(d->left_mm_s);
    *right_mm_s = rfs_sat16(d->right_mm_s);
    if (result == RFS_DRIVE_REACHED || result == RFS_DRIVE_TIMEOUT || result == RFS_DRIVE_BLOCKED) {
        d->status = RFS_DRIVE_IDLE;
    }
    return result;
}
