/* hs_motor.c - motor-controller model (see hs_motor.h). */
#include "hs_motor.h"

hs_motor_cfg_t hs_motor_cfg_default(void)
{
    hs_motor_cfg_t c;
    c.wheel_base_m = 0.23;  // Kobuki wheel base (kobuki_description)
    c.v_max_m_s = 0.7;      // Kobuki maximum translational speed
    c.accel_m_s2 = 1.0;     // our choice, above the core's drive limit so it never binds first
    c.timeout_us = 200000;  // wheels stop 200 ms after the last command
    return c;
}

int hs_motor_init(hs_motor_t *m, const hs_motor_cfg_t *cfg)
{
    if (!(cfg->wheel_base_m > 0.0) || !(cfg->v_max_m_s > 0.0) || !(cfg->accel_m_s2 > 0.0) ||
        cfg->timeout_us <= 0) {
        return -1;
    }
    *m = (hs_motor_t){0};
    m->cfg = *cfg;
    return 0;
}

static double clampd(double v, double lim)
{
    return v > lim ? lim : (v < -lim ? -lim : v);
}

void hs_motor_command(hs_motor_t *m, int64_t t_us, int left_mm_s, int right_mm_s)
{
    m->cmd_l = clampd(left_mm_s / 1000.0, m->cfg.v_max_m_s);
    m->cmd_r = clampd(right_mm_s / 1000.0, m->cfg.v_max_m_s);
    m->last_cmd_us = t_us;
    m->have_cmd = true;
    m->timed_out = false;
}

/// Move v towards target by at most a*dt; returns the mean speed over the interval.
static double ramp(double *v, double target, double a, double dt)
{
    double v0 = *v, dv = target - v0, lim = a * dt;
    if (dv > lim) {
        dv = lim;
    } else if (dv < -lim) {
        dv = -lim;
    }
    *v = v0 + dv;
    return v0 + 0.5 * dv; // linear ramp: exact mean whether or not it reaches the target
}

void hs_motor_update(hs_motor_t *m, int64_t now_us, double dt_s, double *v_m_s,
                     double *omega_rad_s)
{
    double tl = m->cmd_l, tr = m->cmd_r;
    if (!m->have_cmd || now_us - m->last_cmd_us > m->cfg.timeout_us) {
        if (m->have_cmd && !m->timed_out) {
            m->timed_out = true;
            m->timeouts++;
        }
        tl = 0.0;
        tr = 0.0;
    }
    double ml = ramp(&m->vl, tl, m->cfg.accel_m_s2, dt_s);
    double mr = ramp(&m->vr, tr, m->cfg.accel_m_s2, dt_s);
    *v_m_s = 0.5 * (ml + mr);
    *omega_rad_s = (mr - ml) / m->cfg.wheel_base_m;
}
