/* hs_motor.h - the motor-controller model of the simulated base.
 *
 * Receives wheel speed commands (mm/s, as the core's rfs_seek_out_t carries them), ramps
 * each wheel towards its command at a limited acceleration, and drops the command to
 * zero when no command has arrived for `timeout_us` (200 ms), like the Kobuki base's own
 * command timeout. Wheel speeds become the body's forward speed and turn rate.
 */
#ifndef HS_MOTOR_H
#define HS_MOTOR_H

#include <stdbool.h>
#include <stdint.h>

/// Motor-controller configuration.
typedef struct hs_motor_cfg {
    double wheel_base_m;   ///< distance between the wheels, metres (TurtleBot 2: 0.23)
    double v_max_m_s;      ///< wheel speed limit, m/s (0.7)
    double accel_m_s2;     ///< wheel acceleration (and braking) limit, m/s^2 (1.0)
    int64_t timeout_us;    ///< command timeout, microseconds (200,000)
} hs_motor_cfg_t;

/// Motor-controller state.
typedef struct hs_motor {
    hs_motor_cfg_t cfg;    ///< configuration
    double cmd_l, cmd_r;   ///< latest commanded wheel speeds, m/s
    double vl, vr;         ///< actual wheel speeds, m/s
    int64_t last_cmd_us;   ///< time of the latest command
    bool have_cmd;         ///< a command has arrived
    uint32_t timeouts;     ///< times the timeout stopped the wheels
    bool timed_out;        ///< the current command has timed out
} hs_motor_t;

/// Defaults: TurtleBot 2 (Kobuki) base.
hs_motor_cfg_t hs_motor_cfg_default(void);

/// Initialise at rest. Returns 0, or -1 on a non-positive parameter.
int hs_motor_init(hs_motor_t *m, const hs_motor_cfg_t *cfg);

/// A wheel command arrived at t_us (speeds saturated to v_max).
void hs_motor_command(hs_motor_t *m, int64_t t_us, int left_mm_s, int right_mm_s);

/// Advance the wheels by dt_s seconds ending at now_us; returns the body's forward speed
/// (m/s) and turn rate (rad/s, counter-clockwise) averaged over the interval.
void hs_motor_update(hs_motor_t *m, int64_t now_us, double dt_s, double *v_m_s,
                     double *omega_rad_s);

#endif /* HS_MOTOR_H */
