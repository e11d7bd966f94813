/* rfs_drive.h - differential-drive control: from the pose and a path to wheel speeds.
 *
 * Follows the legs of a planned path with a carrot (a point a lookahead ahead on the
 * leg) on a filtered pose: localisation poses blended with dead reckoning from the
 * commanded wheel speeds. A waypoint is passed when the robot crosses its perpendicular;
 * the robot turns on the spot only when the heading error is large (with hysteresis),
 * otherwise drives forward with a proportional heading correction, braking for corners
 * and the goal; wheel speeds are limited in magnitude and in acceleration.
 * The goal ends when reached (within `goal_tol`), abandoned after `timeout_us`, or
 * abandoned as blocked when the robot has made less than `progress_min` of progress
 * over `stall_us`. Defaults are a TurtleBot 2 (Kobuki): wheel base 0.23 m, 0.7 m/s.
 */
#ifndef RFS_DRIVE_H
#define RFS_DRIVE_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_plan.h"
#include "rfs_store.h"

/// Drive configuration.
typedef struct rfs_drive_cfg {
    int32_t wheel_base_mm;     ///< distance between the wheels, mm (230)
    int32_t v_max_mm_s;        ///< top wheel speed, mm/s (700)
    int32_t accel_mm_s2;       ///< wheel acceleration limit, mm/s^2
    rfs_q16_t goal_tol;        ///< metres Q16.16: goal reached within this distance
    rfs_q16_t turn_in_place;   ///< radians Q16.16: heading error above which it turns on the spot
    rfs_q16_t turn_out;        ///< radians Q16.16: a turn on the spot ends below this error
    rfs_q16_t lookahead;       ///< metres Q16.16: the carrot's distance ahead on the leg
    rfs_q16_t pose_gain;       ///< Q16.16 in (0, 1]: weight of a new pose in the filter (1 = raw poses)
    int64_t timeout_us;        ///< a goal is abandoned after this long, plus the time to
                               ///< drive its path at half the top speed
    int64_t stall_us;          ///< window over which progress is required
    rfs_q16_t progress_min;    ///< metres Q16.16 of progress required per stall window
} rfs_drive_cfg_t;

/// Outcome of one control update.
typedef enum rfs_drive_status {
    RFS_DRIVE_IDLE = 0,    ///< no goal
    RFS_DRIVE_RUNNING,     ///< moving towards the goal
    RFS_DRIVE_REACHED,     ///< within goal_tol of the final waypoint (wheels commanded 0)
    RFS_DRIVE_TIMEOUT,     ///< abandoned: took longer than timeout_us
    RFS_DRIVE_BLOCKED,     ///< abandoned: no progress
} rfs_drive_status_t;

/// Drive state, caller-owned.
typedef struct rfs_drive {
    rfs_drive_cfg_t cfg;           ///< configuration copied at init
    rfs_path_t path;               ///< the path followed
    uint16_t next;                 ///< index of the waypoint being approached
    rfs_drive_status_t status;     ///< current status
    int64_t start_us;              ///< when the goal was set
    int64_t limit_us;              ///< abandoned this long after start_us: timeout_us plus the
                                   ///< path's length at half the top speed
    int64_t last_us;               ///< time of the last update (for acceleration limits)
    int64_t stall_ref_us;          ///< start of the current progress window
    int32_t stall_ref_dist;        ///< distance left on the leg at that time, mm
    int32_t left_mm_s;             ///< last commanded left wheel speed, mm/s
    int32_t right_mm_s;            ///< last commanded right wheel speed, mm/s
    bool turning;                  ///< turning on the spot until the heading error is small
    bool have_origin;              ///< ox, oy hold where the path started
    rfs_q16_t ox, oy;              ///< start of the first leg (the estimate at the first update)
    rfs_pose_t est;                ///< filtered pose (t_us unused)
    bool have_est;                 ///< est is valid
    int64_t est_us;                ///< time est refers to
    int64_t pose_t_us;             ///< timestamp of the last pose folded into est
    int32_t base_left, base_right; ///< the base's modelled wheel speeds, mm/s (the commands
                                   ///< ramped at accel_mm_s2: still rolling after a stop)
} rfs_drive_t;

/// Defaults: TurtleBot 2 (Kobuki) base: 0.23 m, 0.7 m/s, 1 m/s^2 (the TurtleBot velocity
/// smoother's accel_lim_v); 0.1 m goal tolerance, turn on the spot above 0.75 rad until
/// below 0.2 rad, carrot 0.4 m ahead, pose gain 1/8, 30 s timeout, blocked when less
/// than 0.1 m of progress in 5 s.
rfs_drive_cfg_t rfs_drive_cfg_default(void);

/// Initialise idle. Returns 0, or -1 on a parameter out of range (wheel base outside
/// 10 mm .. 10 m; non-positive speed, acceleration, tolerance, lookahead, pose gain or
/// timeout; timeout over 10^12 us; turn_out above turn_in_place; pose gain above 1).
int rfs_drive_init(rfs_drive_t *d, const rfs_drive_cfg_t *cfg);

/// Start following a path (copied) at time now_us; its first leg runs from the path's
/// start (x0, y0) when it has one (the planners set it), else from where the robot is at
/// the next update. path may be &d->path itself: planning straight into it saves a
/// 532-byte rfs_path_t on the caller's stack (the firmware's stack is 2.5 KB).
void rfs_drive_set_path(rfs_drive_t *d, const rfs_path_t *path, int64_t now_us);

/// One control update: wheel speeds (mm/s, saturated to the limits) for the pose.
/// Returns the status; REACHED/TIMEOUT/BLOCKED are reported once, then IDLE.
rfs_drive_status_t rfs_drive_update(rfs_drive_t *d, const rfs_pose_t *pose, int64_t now_us,
                                    int16_t *left_mm_s, int16_t *right_mm_s);

/// Advance the pose filter to now_us with the latest localisation pose (a pose already
/// folded in is not counted twice): dead reckoning from the base's wheel speeds (the
/// commands ramped at accel_mm_s2), then a new pose blended in with weight pose_gain; it
/// replaces the estimate when it is more than 0.5 m or 0.5 rad away, at least 1 s after
/// the previous pose, or older than it. rfs_drive_update calls it; call it also in
/// periods without an update so the estimate stays current.
void rfs_drive_observe(rfs_drive_t *d, const rfs_pose_t *pose, int64_t now_us);

/// The filtered pose the drive steers by (false before the first update).
bool rfs_drive_estimate(const rfs_drive_t *d, rfs_pose_t *out);

/// Drop the goal and command zero at once (safety stop; no ramp).
void rfs_drive_stop(rfs_drive_t *d, int64_t now_us);

/// Whether the base's modelled wheel speeds (base_left, base_right) are both 0: after a
/// stop the base rolls on, braking at accel_mm_s2, until this holds.
bool rfs_drive_at_rest(const rfs_drive_t *d);

#endif /* RFS_DRIVE_H */
