/* rfs_drive.c - differential-drive path following (docs/MAPS.md, "Drive control").
 *
 * Per update: advance past waypoints within SWITCH_DIST; take the bearing to the
 * waypoint being approached (CORDIC atan2) and the heading error e.
 *  - When a path starts, or |e| exceeds turn_in_place, turn on the spot until
 *    |e| < turn_in_place / 16: omega = 3 e, wheels at most v_max / 2 and slow enough to
 *    stop within the remaining angle.
 *  - Otherwise drive at v = clamp(sqrt(2 (a/2) d + v_corner^2), 0.05 m/s, v_max) times
 *    (1 - |e| / turn_in_place)^2, with omega = 2.5 e. d is the distance left to where the
 *    waypoint counts as passed (SWITCH_DIST before it, or half the goal tolerance before
 *    the goal); v_corner = v_max (1 - turn / turn_in_place)^2 for the turn at that
 *    waypoint (0 at the goal and for turns it will make on the spot). So the robot
 *    brakes for corners, arrives slowly, keeps half the acceleration for steering, and
 *    stays within 0.07 m of the planned polyline (clearance 0.25 m - radius 0.177 m).
 *  - Both wheel targets are scaled together to v_max, then each wheel moves towards its
 *    target by at most accel * dt. Within goal_tol of the goal both wheels ramp to 0 and
 *    the goal is REACHED when they are 0.
 */
#include "rfs_drive.h"

#include <string.h>

#define PI_Q16 ((rfs_q16_t)205887)
#define TWO_PI_Q16 ((int64_t)411775)
/* Waypoints other than the goal count as passed within this distance. Small, because
 * switching early cuts the corner: the robot must stay within clearance - radius
 * (0.25 - 0.177 m) of the planned, legal polyline (tested: within 0.07 m). */
#define SWITCH_DIST RFS_Q16_FRAC(1, 50)
/* Slowest forward speed when heading is right, mm/s (stops within 1.3 mm). */
#define V_CREEP 50
/* Steering gains, 1/s in Q16.16. */
#define K_HEADING RFS_Q16_FRAC(5, 2)
#define K_TURN RFS_Q16_INT(3)
/* Longest dt used for the acceleration limit (a late update must not jump). */
#define DT_MAX_US 200000

static const int32_t ATAN_Q16[16] = {51472, 30386, 16055, 8150, 4091, 2047, 1024, 512,
                                     256,   128,   64,    32,   16,   8,    4,    2};

rfs_drive_cfg_t rfs_drive_cfg_default(void)
{
    rfs_drive_cfg_t c;
    c.wheel_base_mm = 230;               /* Kobuki: 0.23 m */
    c.v_max_mm_s = 700;                  /* Kobuki: 0.7 m/s */
    c.accel_mm_s2 = 1000;                /* yocs_velocity_smoother, TurtleBot: accel_lim_v 1.0 */
    c.goal_tol = RFS_Q16_FRAC(1, 10);    /* 0.1 m */
    c.turn_in_place = RFS_Q16_FRAC(3, 4); /* 0.75 rad (43 degrees) */
    c.timeout_us = 30000000;             /* 30 s */
    c.stall_us = 5000000;                /* 5 s */
    c.progress_min = RFS_Q16_FRAC(1, 10); /* 0.1 m per 5 s */
    return c;
}

int rfs_drive_init(rfs_drive_t *d, const rfs_drive_cfg_t *cfg)
{
    if (d == 0 || cfg == 0 || cfg->wheel_base_mm <= 0 || cfg->v_max_mm_s <= 0 ||
        cfg->v_max_mm_s > 10000 || cfg->accel_mm_s2 <= 0 || cfg->accel_mm_s2 > 100000 ||
        cfg->goal_tol <= 0 || cfg->timeout_us <= 0 || cfg->turn_in_place <= 0 ||
        cfg->stall_us <= 0 || cfg->progress_min < 0) {
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
    d->last_us = now_us;
    d->stall_ref_us = now_us;
    d->stall_ref_dist = RFS_Q16_MAX;
    /* From rest, face the first waypoint before driving off (no departure at an angle). */
    d->turning = true;
}

void rfs_drive_stop(rfs_drive_t *d, int64_t now_us)
{
    d->status = RFS_DRIVE_IDLE;
    d->path.n = 0;
    d->left_mm_s = 0;
    d->right_mm_s = 0;
    d->last_us = now_us;
}

/* atan2(y, x) in Q16.16 radians, (-pi, pi]; 0 for (0, 0). CORDIC vectoring.
 * Scaling and overflow: inputs (any int64 within +-2^33) are shifted so the larger
 * magnitude lies in [2^27, 2^28); the CORDIC gain 1.65 keeps |x|, |y| below 2^29.
 * Error about 2^-14 rad from the table rounding and the 16 iterations. */
static rfs_q16_t atan2_q16(int64_t y, int64_t x)
{
    if (x == 0 && y == 0) {
        return 0;
    }
    int64_t ax = x < 0 ? -x : x;
    int64_t ay = y < 0 ? -y : y;
    int64_t mx = ax > ay ? ax : ay;
    while (mx >= ((int64_t)1 << 28)) {
        x /= 2;
        y /= 2;
        mx >>= 1;
    }
    while (mx < ((int64_t)1 << 27)) {
        x *= 2;
        y *= 2;
        mx <<= 1;
    }
    int32_t xi = (int32_t)x;
    int32_t yi = (int32_t)y;
    int32_t base = 0;
    if (xi < 0) {
        base = yi >= 0 ? PI_Q16 : -PI_Q16;
        xi = -xi;
        yi = -yi;
    }
    int32_t z = 0;
    for (int i = 0; i < 16; i++) {
        int32_t xs = xi >> i;
        int32_t ys = yi >> i;
        if (yi > 0) {
            xi += ys;
            yi -= xs;
            z += ATAN_Q16[i];
        } else {
            xi -= ys;
            yi += xs;
            z -= ATAN_Q16[i];
        }
    }
    int64_t a = (int64_t)base + z;
    if (a > PI_Q16) {
        a -= TWO_PI_Q16;
    } else if (a <= -PI_Q16) {
        a += TWO_PI_Q16;
    }
    return (rfs_q16_t)a;
}

/* Wrap an angle difference into (-pi, pi]. */
static rfs_q16_t wrap_pi(int64_t a)
{
    while (a > PI_Q16) {
        a -= TWO_PI_Q16;
    }
    while (a <= -PI_Q16) {
        a += TWO_PI_Q16;
    }
    return (rfs_q16_t)a;
}


/* Q16 metres to millimetres (int64, exact to 1/65 mm, rounded). */
static int64_t q16_to_mm(int64_t v)
{
    return (v * 1000 + (v >= 0 ? 32768 : -32768)) / 65536;
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
 * Scaling and overflow: a <= 1e5 mm/s^2 and d <= 3.3e7 mm give at most 3.3e12, uint64. */
static int32_t brake_speed(int32_t accel, int64_t d_mm, int32_t v_end)
{
    if (d_mm < 0) {
        d_mm = 0;
    }
    uint64_t v2 = (uint64_t)accel * (uint64_t)d_mm + (uint64_t)v_end * (uint64_t)v_end;
    uint32_t v = rfs_isqrt64(v2);
    return v > (uint32_t)INT32_MAX ? INT32_MAX : (int32_t)v;
}

/* The waypoint driven to: those passed (within SWITCH_DIST) are skipped, each one
 * restarting the stall reference. Returns the distance to it, metres Q16.16. */
static rfs_q16_t next_waypoint(rfs_drive_t *d, const rfs_pose_t *pose, int64_t now_us)
{
    uint16_t last = (uint16_t)(d->path.n - 1u);
    rfs_q16_t dn = rfs_q16_dist(pose->x, pose->y, d->path.x[d->next], d->path.y[d->next]);
    while (d->next < last && dn < SWITCH_DIST) {
        d->next++;
        dn = rfs_q16_dist(pose->x, pose->y, d->path.x[d->next], d->path.y[d->next]);
        d->stall_ref_us = now_us;
        d->stall_ref_dist = dn;
    }
    return dn;
}

/* Stall check at distance dn (metres Q16.16) from the waypoint: true when the robot came
 * less than progress_min closer over the last stall_us. */
static bool stalled(rfs_drive_t *d, rfs_q16_t dn, int64_t now_us)
{
    const rfs_drive_cfg_t *c = &d->cfg;
    bool blocked = false;
    if (d->stall_ref_dist == RFS_Q16_MAX) {
        d->stall_ref_dist = dn;
        d->stall_ref_us = now_us;
    } else if (now_us >= d->stall_ref_us &&
               (uint64_t)now_us - (uint64_t)d->stall_ref_us >= (uint64_t)c->stall_us) {
        blocked = (int64_t)d->stall_ref_dist - dn < c->progress_min;
        d->stall_ref_us = now_us;
        d->stall_ref_dist = dn;
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

/* Corner speed at the next waypoint, mm/s, for the approach (ex, ey) (metres Q16.16):
 * v_max (1 - theta / turn_in_place)^2 for a turn of theta between the approach and the
 * next leg; 0 from turn_in_place on, where the robot will turn on the spot, and at the
 * goal. */
static int32_t corner_speed(const rfs_drive_t *d, int64_t ex, int64_t ey)
{
    const rfs_drive_cfg_t *c = &d->cfg;
    if (d->next >= (uint16_t)(d->path.n - 1u)) {
        return 0;
    }
    int64_t ux = q16_to_mm(ex);
    int64_t uy = q16_to_mm(ey);
    int64_t wx = q16_to_mm((int64_t)d->path.x[d->next + 1] - d->path.x[d->next]);
    int64_t wy = q16_to_mm((int64_t)d->path.y[d->next + 1] - d->path.y[d->next]);
    rfs_q16_t theta = rfs_q16_abs(atan2_q16(ux * wy - uy * wx, ux * wx + uy * wy));
    if (theta >= c->turn_in_place) {
        return 0;
    }
    rfs_q16_t f = rfs_q16_div(c->turn_in_place - theta, c->turn_in_place);
    return (int32_t)(((int64_t)rfs_q16_mul(f, f) * c->v_max_mm_s) >> 16);
}

/* Wheel speed targets (mm/s) towards the waypoint at distance dn (metres Q16.16). */
static void steer(rfs_drive_t *d, const rfs_pose_t *pose, rfs_q16_t dn, int32_t *tl,
                  int32_t *tr)
{
    const rfs_drive_cfg_t *c = &d->cfg;
    int64_t ex = (int64_t)d->path.x[d->next] - pose->x;
    int64_t ey = (int64_t)d->path.y[d->next] - pose->y;
    rfs_q16_t e = wrap_pi((int64_t)atan2_q16(ey, ex) - pose->theta);
    int32_t v = 0;
    int32_t w_mm = 0; /* omega * wheel_base / 2, mm/s */
    /* Hysteresis: once turning on the spot, keep turning until the error is below
     * turn_in_place / 16, so the robot never drives off while rotating. */
    if (rfs_q16_abs(e) > c->turn_in_place) {
        d->turning = true;
    } else if (rfs_q16_abs(e) < c->turn_in_place / 16) {
        d->turning = false;
    }
    if (d->turning) {
        w_mm = turn_speed(c, e);
    } else {
        int32_t v_end = corner_speed(d, ex, ey);
        /* Brake to v_end where the waypoint counts as passed (or at half the goal
         * tolerance), not at the waypoint itself: no overshoot at corners. */
        bool corner = d->next < (uint16_t)(d->path.n - 1u);
        rfs_q16_t stop_at = corner ? SWITCH_DIST : c->goal_tol / 2;
        v = brake_speed(c->accel_mm_s2, q16_to_mm((int64_t)dn - stop_at), v_end);
        v = v < V_CREEP ? V_CREEP : v;
        v = v > c->v_max_mm_s ? c->v_max_mm_s : v;
        /* Fade the forward speed in as the heading error closes, so the switch from
         * turning on the spot is smooth. */
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
    /* Scaling: accel (mm/s^2, <= 1e5) * dt (us, <= 2e5) < 2^35, / 1e6 without libgcc. */
    int32_t step = (int32_t)rfs_udiv64((uint64_t)c->accel_mm_s2 * (uint64_t)dt, 1000000u);
    int32_t tl = 0;
    int32_t tr = 0;
    rfs_drive_status_t result = d->status;

    if (d->status == RFS_DRIVE_RUNNING) {
        rfs_q16_t dn = next_waypoint(d, pose, now_us);
        bool at_goal = d->next == (uint16_t)(d->path.n - 1u) && dn <= c->goal_tol;
        if (now_us > d->start_us && (uint64_t)now_us - (uint64_t)d->start_us > (uint64_t)c->timeout_us) {
            result = RFS_DRIVE_TIMEOUT;
        } else if (at_goal) {
            if (d->left_mm_s == 0 && d->right_mm_s == 0) {
                result = RFS_DRIVE_REACHED;
            }
        } else {
            if (stalled(d, dn, now_us)) {
                result = RFS_DRIVE_BLOCKED;
            }
            steer(d, pose, dn, &tl, &tr);
        }
    }
    if (result != RFS_DRIVE_RUNNING) {
        tl = 0;
        tr = 0;
    }
    d->left_mm_s = ramp(d->left_mm_s, tl, step);
    d->right_mm_s = ramp(d->right_mm_s, tr, step);
    *left_mm_s = rfs_sat16(d->left_mm_s);
    *right_mm_s = rfs_sat16(d->right_mm_s);
    if (result == RFS_DRIVE_REACHED || result == RFS_DRIVE_TIMEOUT || result == RFS_DRIVE_BLOCKED) {
        d->status = RFS_DRIVE_IDLE;
    }
    return result;
}
