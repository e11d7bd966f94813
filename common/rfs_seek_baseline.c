/* rfs_seek_baseline.c - the baseline strategies the meta-algorithm is measured against
 * (docs/STRATEGIES.md, "Choosing a strategy"): fd-gradient, plane-gradient and
 * chemotaxis. Each uses the same sensors, step width, map legality and planner as the
 * paper's rule; only the decision differs. */
#include "rfs_seek_internal.h"

#include "rfs_reach.h"

/* cos(2 pi k / 16), Q16.16; sin(2 pi k / 16) = cos(2 pi (k - 4) / 16). */
static const rfs_q16_t k_cos16[16] = { 65536,  60547,  46341,  25080, 0, -25080, -46341, -60547,
                                      -65536, -60547, -46341, -25080, 0,  25080,  46341,  60547 };

static rfs_q16_t sin16(uint8_t h)
{
    return k_cos16[(h + 12u) & 15u];
}

bool rfs_seek_unit(rfs_q16_t gx, rfs_q16_t gy, rfs_q16_t *ux, rfs_q16_t *uy)
{
    int64_t x = gx, y = gy;
    if (x == 0 && y == 0) {
        return false;
    }
    /* Scale both up until the larger is at least 2^29, so the root keeps 29 bits. */
    while (x < (1 << 29) && x > -(1 << 29) && y < (1 << 29) && y > -(1 << 29)) {
        x *= 2;
        y *= 2;
    }
    uint64_t n2 = (uint64_t)(x * x) + (uint64_t)(y * y);
    uint32_t n = rfs_isqrt64(n2);
    if (n == 0u) {
        n = 1u;
    }
    int64_t a = rfs_sdiv64_round(x * 65536, (int64_t)n);
    int64_t b = rfs_sdiv64_round(y * 65536, (int64_t)n);
    /* The root is rounded down, so a component may come out a little above one. */
    *ux = (rfs_q16_t)(a > RFS_Q16_ONE ? RFS_Q16_ONE : (a < -RFS_Q16_ONE ? -RFS_Q16_ONE : a));
    *uy = (rfs_q16_t)(b > RFS_Q16_ONE ? RFS_Q16_ONE : (b < -RFS_Q16_ONE ? -RFS_Q16_ONE : b));
    return true;
}

/* (bx, by) + step * (ux, uy), metres Q16.16. Scaling: step Q16 * u Q16 = Q32 >> 16. */
static void step_point(const rfs_seek_t *s, rfs_q16_t bx, rfs_q16_t by, rfs_q16_t ux,
                       rfs_q16_t uy, rfs_q16_t *gx, rfs_q16_t *gy)
{
    *gx = rfs_sat32((int64_t)bx + (((int64_t)s->cfg.step * ux) >> 16));
    *gy = rfs_sat32((int64_t)by + (((int64_t)s->cfg.step * uy) >> 16));
}

/* A gradient step: one step from (bx, by) along the unit vector u; when that point is
 * illegal or has no path, the nearest reachable legal lattice point around it (so a
 * gradient pressed against a wall slides along it, as the map legality of section 2);
 * false when that is within a quarter step of the robot (blocked).
 * Scaling: Q16 differences squared in int64 (Q32), |d| < 2^32 on any legal map. */
static bool go_step(rfs_seek_t *s, rfs_q16_t bx, rfs_q16_t by, rfs_q16_t ux, rfs_q16_t uy,
                    int64_t now_us)
{
    rfs_q16_t gx, gy;
    step_point(s, bx, by, ux, uy, &gx, &gy);
    s->decision.goal_x = gx;
    s->decision.goal_y = gy;
    if (rfs_map_point_legal(s->map, gx, gy) && rfs_seek_go_to(s, gx, gy, now_us)) {
        return true;
    }
    uint16_t i, j;
    if (!rfs_reach_snap(s->map, s->reach, gx, gy, &i, &j)) {
        return false;
    }
    rfs_map_lattice_point(s->map, i, j, &gx, &gy);
    /* Snapped back to (nearly) where the robot stands: the step is blocked; the caller
     * takes a random step instead of deciding the same stuck step at every period. */
    int64_t dx = (int64_t)gx - s->pose.x, dy = (int64_t)gy - s->pose.y;
    int64_t q = s->cfg.step / 4;
    if (dx * dx + dy * dy < q * q) {
        return false;
    }
    s->decision.goal_x = gx;
    s->decision.goal_y = gy;
    return rfs_seek_go_to(s, gx, gy, now_us);
}

/* One step from the robot in heading h (sixteenths of a turn); the goal must be legal
 * and have a path (position is used for nothing else). */
static bool go_heading(rfs_seek_t *s, uint8_t h, int64_t now_us)
{
    rfs_q16_t gx, gy;
    step_point(s, s->pose.x, s->pose.y, k_cos16[h & 15u], sin16(h), &gx, &gy);
    s->decision.goal_x = gx;
    s->decision.goal_y = gy;
    return rfs_map_point_legal(s->map, gx, gy) && rfs_seek_go_to(s, gx, gy, now_us);
}

/* A tumble: a uniformly drawn new heading (other than the current one when `change`),
 * redrawn while it points into a wall; the sixteen headings in turn as a last resort. */
static bool go_random_heading(rfs_seek_t *s, bool change, rfs_rng_t *rng, int64_t now_us)
{
    for (int attempt = 0; attempt < 32; ++attempt) {
        uint8_t h = change ? (uint8_t)((s->heading + 1u + rfs_rng_below(rng, 15u)) & 15u)
                           : (uint8_t)rfs_rng_below(rng, 16u);
        if (go_heading(s, h, now_us)) {
            s->heading = h;
            return true;
        }
    }
    for (uint8_t h = 0; h < 16u; ++h) {
        if (go_heading(s, h, now_us)) {
            s->heading = h;
            return true;
        }
    }
    return false;
}

/* fd-gradient: a probe to p + step along axis (0 = x, 1 = y), or p - step when that is
 * illegal or has no path. Returns the direction used (+1, -1) or 0 when neither works. */
static int8_t fd_probe(rfs_seek_t *s, int axis, int64_t now_us)
{
    for (int8_t sg = 1; sg >= -1; sg = (int8_t)(sg - 2)) {
        rfs_q16_t gx = s->fd_px, gy = s->fd_py;
        rfs_q16_t d = sg > 0 ? s->cfg.step : -s->cfg.step;
        if (axis == 0) {
            gx = rfs_q16_add(gx, d);
        } else {
            gy = rfs_q16_add(gy, d);
        }
        s->decision.goal_x = gx;
        s->decision.goal_y = gy;
        if (rfs_map_point_legal(s->map, gx, gy) && rfs_seek_go_to(s, gx, gy, now_us)) {
            return sg;
        }
    }
    return 0;
}

/* fd-gradient: the 1 s mean at p, at p + step x and at p + step y (each after standing
 * still for one averaging window: the table's `dwell`), then one step from p along the
 * estimated gradient ((m_x - m_0) / step, (m_y - m_0) / step). An axis whose probe point
 * is illegal in both directions contributes no component. */
bool rfs_seek_baseline_fd(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us)
{
    (void)model_ok;
    rfs_seek_decision_t *d = &s->decision;
    bool ok = false;
    s->dwell_done = false;
    if (!d->mean_valid) {
        /* Nothing heard for a whole window: no difference to take; move and try again. */
        s->fd_phase = 0;
        d->kind = RFS_SEEK_TUMBLE;
        return go_random_heading(s, false, rng, now_us);
    }
    rfs_q16_t my = 0;
    if (s->fd_phase == 0) {
        s->fd_px = s->pose.x;
        s->fd_py = s->pose.y;
        s->fd_m0 = d->mean;
    } else if (s->fd_phase == 1) {
        s->fd_mx = d->mean;
    } else {
        my = d->mean;
    }
    if (s->fd_phase == 0) {
        s->fd_sx = fd_probe(s, 0, now_us);
        s->fd_phase = 1;
        if (s->fd_sx != 0) {
            d->kind = RFS_SEEK_PROBE;
            ok = true;
        } else {
            s->fd_mx = s->fd_m0;
        }
    }
    if (!ok && s->fd_phase == 1) {
        s->fd_sy = fd_probe(s, 1, now_us);
        s->fd_phase = 2;
        if (s->fd_sy != 0) {
            d->kind = RFS_SEEK_PROBE;
            ok = true;
        } else {
            my = s->fd_m0;
        }
    }
    if (!ok && s->fd_phase == 2) {
        s->fd_phase = 0;
        /* The common 1 / step factor does not change the direction. */
        rfs_q16_t gx = rfs_q16_sub(s->fd_mx, s->fd_m0), gy = rfs_q16_sub(my, s->fd_m0);
        gx = s->fd_sx < 0 ? -gx : (s->fd_sx == 0 ? 0 : gx);
        gy = s->fd_sy < 0 ? -gy : (s->fd_sy == 0 ? 0 : gy);
        rfs_q16_t ux, uy;
        d->kind = RFS_SEEK_GRADIENT;
        if (rfs_seek_unit(gx, gy, &ux, &uy)) {
            ok = go_step(s, s->fd_px, s->fd_py, ux, uy, now_us);
        }
        if (!ok) {
            d->kind = RFS_SEEK_TUMBLE; /* flat or blocked: a random step */
            ok = go_random_heading(s, false, rng, now_us);
        }
    }
    return ok;
}

/* plane-gradient (the gradient view of paper section 4.1): the model (refit at every
 * step: the table's `refit`) is followed one step along its gradient, taken as central
 * differences one step either side (exact for the ridge plane). No epsilon, no check. */
bool rfs_seek_baseline_plane(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us)
{
    rfs_seek_decision_t *d = &s->decision;
    const rfs_model_t *m = &s->model;
    rfs_q16_t h = s->cfg.step, x = s->pose.x, y = s->pose.y;
    rfs_q16_t xp, xm, yp, ym, ux, uy;
    d->kind = RFS_SEEK_GRADIENT;
    if (model_ok && m->ops->predict(m->self, rfs_q16_add(x, h), y, &xp) &&
        m->ops->predict(m->self, rfs_q16_sub(x, h), y, &xm) &&
        m->ops->predict(m->self, x, rfs_q16_add(y, h), &yp) &&
        m->ops->predict(m->self, x, rfs_q16_sub(y, h), &ym) &&
        rfs_seek_unit(rfs_q16_sub(xp, xm), rfs_q16_sub(yp, ym), &ux, &uy) &&
        go_step(s, x, y, ux, uy, now_us)) {
        return true;
    }
    d->kind = RFS_SEEK_TUMBLE; /* no model, a flat one, or blocked: a random step */
    return go_random_heading(s, false, rng, now_us);
}

/* chemotaxis: run-and-tumble on the change of the 1 s mean since the last decision.
 * After a rise it runs on in its heading (tumbling with tumble_better), after a fall it
 * tumbles with tumble_worse. Its decisions use no position; the position only checks
 * that a step is legal and plans it. */
bool rfs_seek_baseline_chemo(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us)
{
    (void)model_ok;
    rfs_seek_decision_t *d = &s->decision;
    bool tumble = true;
    if (d->mean_valid && s->have_prev_mean && d->iteration > 0u) {
        rfs_q16_t p = d->mean > s->prev_mean ? s->cfg.tumble_better : s->cfg.tumble_worse;
        tumble = rfs_rng_q16(rng) < p;
    }
    if (d->mean_valid) {
        s->prev_mean = d->mean;
        s->have_prev_mean = true;
    }
    bool ok = false;
    if (!tumble) {
        d->kind = RFS_SEEK_RUN;
        ok = go_heading(s, s->heading, now_us);
    }
    if (!ok) {
        d->kind = RFS_SEEK_TUMBLE;
        ok = go_random_heading(s, d->iteration > 0u, rng, now_us);
    }
    return ok;
}
