/* rfs_seek_meta.c - the paper's choices of an iteration's goal (section 2): the initial
 * random move, the greedy step towards the model's maximum and the novelty-driven epsilon
 * step, with their meta-path variants (docs/STRATEGIES.md, "meta-path's
 * presets"). rfs_seek.c decides which one an iteration takes. */
#include "rfs_seek_internal.h"

#include "rfs_gridmax.h"
#include "rfs_reach.h"

/* Line-search candidates and epsilon redraws tried before giving up on an iteration. */
#define GOAL_TRIES 6

/* Length of a lattice offset (di, dj) with q = di^2 + dj^2, metres Q16.16: grid * sqrt(q).
 * Scaling: grid Q16 * isqrt(q << 32) Q16 -> Q32 >> 16 = Q16 metres, saturated. */
static rfs_q16_t offset_dist(const rfs_map_t *m, uint32_t q)
{
    uint32_t root_q16 = rfs_isqrt64((uint64_t)q << 32);
    return rfs_sat32(((int64_t)m->cfg.grid * root_q16) >> 16);
}

/* The lattice points at most r (>= 0) points from (ci, cj) in i and in j, clipped to the
 * map: i in [i0, i1], j in [j0, j1]. Scaling: the sums in int64, the bounds in the map. */
typedef struct lattice_window {
    int32_t i0, i1, j0, j1;
} lattice_window_t;

static int32_t clip(int64_t v, int32_t n)
{
    return v < 0 ? 0 : v >= n ? n - 1 : (int32_t)v;
}

static lattice_window_t lattice_window(const rfs_map_t *m, uint16_t ci, uint16_t cj, int32_t r)
{
    lattice_window_t w = { clip((int64_t)ci - r, m->lw), clip((int64_t)ci + r, m->lw),
                           clip((int64_t)cj - r, m->lh), clip((int64_t)cj + r, m->lh) };
    return w;
}

void rfs_seek_meta_init(rfs_seek_t *s)
{
    /* Epsilon weights e^(-d), d = grid * sqrt(q) for q = di^2 + dj^2 (section 2:
     * P(x) proportional to e^(-|x - x0|)), tabulated once so a draw costs a lookup per
     * candidate (offset_dist). */
    for (uint32_t q = 0; q < RFS_SEEK_EPS_TABLE; ++q) {
        rfs_q16_t w = rfs_q16_exp_neg(offset_dist(s->map, q));
        s->eps_w[q] = (uint16_t)(w >= RFS_Q16_ONE ? 0xFFFFu : (uint32_t)w);
    }
}

rfs_q16_t rfs_seek_epsilon(const rfs_seek_cfg_t *cfg, uint32_t n)
{
    /* Scaling: rate (Q16) * n saturates at Q16 max, where e^-x is 0 anyway. */
    int64_t x = (int64_t)cfg->eps_rate * (int64_t)(n > 65535u ? 65535u : n);
    rfs_q16_t e = rfs_q16_exp_neg(rfs_sat32(x));
    return rfs_q16_add(rfs_q16_mul(cfg->eps_amp, e), cfg->eps_floor);
}

/* Epsilon's n: the iteration (paper), or with eps_by_travel the larger of it and the
 * whole steps travelled. Scaling: travel (Q16, >= 0) / step (Q16, > 0) is whole steps,
 * floor, by rfs_udiv64 (no libgcc division on 32-bit targets). */
static uint32_t epsilon_index(const rfs_seek_t *s)
{
    uint32_t n = s->decision.iteration;
    if (s->cfg.eps_by_travel) {
        int64_t steps = (int64_t)rfs_udiv64((uint64_t)s->travel, (uint64_t)s->cfg.step);
        uint32_t t = steps > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)steps;
        n = t > n ? t : n;
    }
    return n;
}

/* Novelty (paper section 2): the lattice points within the novelty radius of a position
 * the robot reported, which epsilon goals avoid. Scaling: offsets Q16 squared in int64
 * (Q32) against the radius squared. */
void rfs_seek_meta_visit(rfs_seek_t *s, rfs_q16_t x, rfs_q16_t y)
{
    const rfs_map_t *m = s->map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, x, y, &ci, &cj);
    if (s->have_last_l && s->last_li == ci && s->last_lj == cj) {
        return;
    }
    s->have_last_l = true;
    s->last_li = ci;
    s->last_lj = cj;
    const lattice_window_t w = lattice_window(m, ci, cj, s->cfg.novelty_radius / m->cfg.grid + 1);
    int64_t r2 = (int64_t)s->cfg.novelty_radius * s->cfg.novelty_radius;
    for (int32_t j = w.j0; j <= w.j1; ++j) {
        for (int32_t i = w.i0; i <= w.i1; ++i) {
            rfs_q16_t px, py;
            rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
            int64_t dx = (int64_t)px - x, dy = (int64_t)py - y;
            /* Q16 squared = Q32; compare with the radius squared (Q32). */
            if (dx * dx + dy * dy <= r2) {
                rfs_reach_bit_set(s->visited, (uint32_t)j * m->lw + (uint32_t)i);
            }
        }
    }
}

/* Rule out sources within refute_r of (mx, my) for later fits (the latest
 * RFS_MODEL_MAX_EXCL places), in centimetres as the store's samples (the
 * microcontroller's RAM budget). Scaling: x * 100 < 2^39 in int64, rounded, saturated to
 * +-327.67 m. */
static void exclude(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my)
{
    s->excl_x_cm[s->excl_next] = rfs_sat16(((int64_t)mx * 100 + 32768) >> 16);
    s->excl_y_cm[s->excl_next] = rfs_sat16(((int64_t)my * 100 + 32768) >> 16);
    s->excl_next = (uint8_t)((s->excl_next + 1u) % RFS_MODEL_MAX_EXCL);
    s->nexcl = (uint8_t)(s->nexcl < RFS_MODEL_MAX_EXCL ? s->nexcl + 1u : RFS_MODEL_MAX_EXCL);
}

bool rfs_seek_meta_refute_near(const rfs_seek_t *s, rfs_q16_t margin, rfs_q16_t *mx,
                               rfs_q16_t *my)
{
    if (s->cfg.refute_r <= 0 || s->model.ops->argmax == 0 ||
        !s->model.ops->argmax(s->model.self, mx, my)) {
        return false;
    }
    /* At the maximum, or, when it is unreachable, at the reachable point driven to instead
     * (greedy_along_path): as close as the robot can come. */
    const bool sub = s->have_sub && s->sub_mx == *mx && s->sub_my == *my;
    const rfs_q16_t ax = sub ? s->sub_x : *mx, ay = sub ? s->sub_y : *my;
    return (int64_t)rfs_q16_dist(s->pose.x, s->pose.y, ax, ay) <=
           (int64_t)(s->cfg.step / 2) + margin;
}

bool rfs_seek_meta_refute(rfs_seek_t *s, int64_t now_us)
{
    rfs_seek_decision_t *d = &s->decision;
    d->refuted = rfs_seek_meta_refute_with(s, now_us, 0, d->model_valid, d->prediction,
                                           d->mean_valid, d->mean);
    return d->refuted;
}

bool rfs_seek_meta_refute_with(rfs_seek_t *s, int64_t now_us, rfs_q16_t margin, bool have_pred,
                               rfs_q16_t pred, bool mean_valid, rfs_q16_t mean)
{
    rfs_q16_t mx, my;
    if (!have_pred || !rfs_seek_meta_refute_near(s, margin, &mx, &my)) {
        return false;
    }
    /* Weaker than the model says by twice the relearn threshold (a robot standing still
     * sees one fade: 3 dB is within its spread near the source), or silent: a whole
     * window without a packet from a source heard before while the receiver reports
     * itself up (a dead zone, where no source within a metre could be). Scaling: the
     * doubled threshold (<= 2^31 - 1 in Q16 for any sane threshold) in int64; |now - last
     * report| as in rfs_seek_on_receiver's freshness (clock microseconds). */
    bool weak = mean_valid && (int64_t)rfs_q16_sub(pred, mean) > 2 * (int64_t)s->cfg.error_threshold;
    bool silent = !mean_valid && s->have_meas && s->have_rx && now_us >= s->last_rx_us &&
                  now_us - s->last_rx_us <= s->cfg.rssi_timeout_us;
    if (!weak && !silent && !(s->cfg.refute_reached && s->parked)) {
        return false;
    }
    exclude(s, mx, my);
    return true;
}

/* Initial random move: a uniformly chosen reachable lattice point within
 * initial_step_max of the robot (paper: "restricted to twice the regular step width"). */
bool rfs_seek_meta_initial(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
{
    const rfs_map_t *m = s->map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, s->pose.x, s->pose.y, &ci, &cj);
    int32_t r = s->cfg.initial_step_max / m->cfg.grid;
    int64_t r2 = (int64_t)s->cfg.initial_step_max * s->cfg.initial_step_max;
    for (int attempt = 0; attempt < GOAL_TRIES; ++attempt) {
        /* Count candidates, then pick the k-th: uniform without a candidate list. */
        uint32_t n = 0;
        for (int pass = 0; pass < 2; ++pass) {
            uint32_t pick = pass ? rfs_rng_below(rng, n) : 0u, seen = 0;
            for (int32_t dj = -r; dj <= r; ++dj) {
                for (int32_t di = -r; di <= r; ++di) {
                    int32_t i = (int32_t)ci + di, j = (int32_t)cj + dj;
                    if ((di == 0 && dj == 0) || i < 0 || j < 0 || i >= (int32_t)m->lw ||
                        j >= (int32_t)m->lh || !rfs_reach_at(m, s->reach, (uint16_t)i, (uint16_t)j)) {
                        continue;
                    }
                    rfs_q16_t px, py;
                    rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
                    int64_t dx = (int64_t)px - s->pose.x, dy = (int64_t)py - s->pose.y;
                    if (dx * dx + dy * dy > r2) {
                        continue;
                    }
                    if (pass == 0) {
                        n++;
                    } else if (seen++ == pick) {
                        s->decision.goal_x = px;
                        s->decision.goal_y = py;
                        if (rfs_seek_go_to(s, px, py, now_us)) {
                            return true;
                        }
                        goto next_attempt;
                    }
                }
            }
            if (n == 0) {
                return false;
            }
        }
    next_attempt:;
    }
    return false;
}

/* Rejection step of a geodesic epsilon draw: a candidate proposed with weight
 * e^(-straight distance) is kept with probability e^(-(path length - straight distance)),
 * so the kept goals have weight e^(-path length) (the last try is always kept). The
 * length is the lattice path's before string pulling (rfs_plan_tree_length: a walk on
 * the search tree; only the kept draw's path is pulled).
 * Scaling: the straight distance from the weight table's q (grid * sqrt(q), Q16) and
 * the path length (Q16, <= 32 km) differ by less than 2^31; e^(-d) is Q16. */
static bool accept_detour(const rfs_seek_t *s, rfs_rng_t *rng, uint32_t q, rfs_q16_t len)
{
    int64_t detour = (int64_t)len - offset_dist(s->map, q);
    if (detour <= 0) {
        return true;
    }
    rfs_q16_t keep = rfs_q16_exp_neg(rfs_sat32(detour));
    return rfs_rng_below(rng, RFS_Q16_ONE) < (uint32_t)keep;
}

/* meta-path (an improvement beside the paper): plan to the maximum and keep the first
 * `step` metres of the path, so a greedy step goes round walls the way the planner does
 * instead of straight at the maximum with a line search; with a model that knows where
 * its maximum is (argmax: the pathloss model's estimated source) the goal is that point
 * itself, reached through the planner (leg > 0: the first leg metres of the way; 0: all
 * of it). The cut point lies on a legal segment
 * of the path. Scaling: waypoint offsets (Q16, < 2^32) times the remaining length
 * (Q16, < 2^16 m) < 2^63; segment lengths by rfs_q16_dist(). */
static bool greedy_along_path(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, rfs_q16_t leg,
                              int64_t now_us)
{
    if (!rfs_seek_go_to(s, mx, my, now_us)) {
        /* The maximum is where the robot cannot go (a room whose door the clearance does
         * not pass, a spot off the free space): head for the reachable point nearest to
         * it rather than giving the iteration to a random epsilon move. */
        rfs_q16_t nx, ny;
        if (!rfs_reach_nearest(s->map, s->reach, mx, my, &nx, &ny) ||
            !rfs_seek_go_to(s, nx, ny, now_us)) {
            return false;
        }
        s->have_sub = true;
        s->sub_mx = mx;
        s->sub_my = my;
        s->sub_x = nx;
        s->sub_y = ny;
    }
    rfs_path_t *p = &s->drive.path;
    int64_t px = s->pose.x, py = s->pose.y;
    int64_t left = leg > 0 ? leg : INT32_MAX;
    for (uint16_t k = 0; k < p->n; ++k) {
        int64_t dx = (int64_t)p->x[k] - px, dy = (int64_t)p->y[k] - py;
        int64_t len = rfs_q16_dist((rfs_q16_t)px, (rfs_q16_t)py, p->x[k], p->y[k]);
        if (len >= left) {
            if (len > 0) {
                p->x[k] = rfs_sat32(px + rfs_sdiv64_round(dx * left, len));
                p->y[k] = rfs_sat32(py + rfs_sdiv64_round(dy * left, len));
            }
            p->n = (uint16_t)(k + 1u);
            p->length = leg;
            break;
        }
        left -= len;
        px = p->x[k];
        py = p->y[k];
    }
    s->decision.goal_x = p->x[p->n - 1u];
    s->decision.goal_y = p->y[p->n - 1u];
    s->decision.path_len = p->length;
    rfs_drive_set_path(&s->drive, p, now_us);
    return true;
}

/* eps_sample: the epsilon goal is a draw from the model's belief (a plausible source),
 * driven the whole planned way and rechecked like a greedy leg. false (the novelty draw
 * follows) when the model draws nothing, a point within 1.5 steps of the robot (or whose
 * reachable stand-in is), or one
 * the robot has been to (within the novelty radius of a past position), and whenever the
 * robot stands within 1.5 steps of the model's own maximum: at a wrong estimate the
 * draws lie in the rooms round it, a leg there fails its recheck within a metre and the
 * relearnt fit holds the estimate (hold_k), so the robot shuttles; only the novelty
 * move's new places shift the fit. */
static bool epsilon_sample(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
{
    rfs_q16_t x, y;
    if (!s->cfg.eps_sample || s->model.ops->sample == 0 ||
        !s->model.ops->sample(s->model.self, rng, &x, &y)) {
        return false;
    }
    rfs_q16_t near = rfs_q16_add(s->cfg.step, s->cfg.step / 2);
    if (rfs_q16_dist(s->pose.x, s->pose.y, x, y) < near) {
        return false;
    }
    rfs_q16_t mx, my;
    if (s->model.ops->argmax != 0 && s->model.ops->argmax(s->model.self, &mx, &my) &&
        rfs_q16_dist(s->pose.x, s->pose.y, mx, my) < near) {
        return false;
    }
    uint16_t li, lj;
    rfs_map_lattice_nearest(s->map, x, y, &li, &lj);
    if (rfs_reach_bit(s->visited, (uint32_t)lj * s->map->lw + li)) {
        return false;
    }
    /* An unreachable draw's stand-in (the reachable point nearest to it) where the robot
     * stands is a null move: the robot would learn nothing new there, again and again. */
    if (!greedy_along_path(s, x, y, 0, now_us) ||
        rfs_q16_dist(s->pose.x, s->pose.y, s->decision.goal_x, s->decision.goal_y) < near) {
        return false;
    }
    s->decision.sampled = true;
    s->decision.max_x = x;
    s->decision.max_y = y;
    return true;
}

/* Lattice point (i, j)'s epsilon weight seen from (ci, cj), Q0.16: e^(-distance) for a
 * reachable point not visited inside the table's radius, else 0. */
static uint32_t eps_weight(const rfs_seek_t *s, uint16_t ci, uint16_t cj, int32_t i, int32_t j)
{
    const int32_t di = i - (int32_t)ci, dj = j - (int32_t)cj;
    const uint32_t q = (uint32_t)(di * di + dj * dj);
    if (q >= RFS_SEEK_EPS_TABLE) {
        return 0u;
    }
    const uint32_t idx = (uint32_t)j * s->map->lw + (uint32_t)i;
    if (rfs_reach_bit(s->visited, idx) || !rfs_reach_bit(s->reach, idx)) {
        return 0u;
    }
    return s->eps_w[q];
}

/* Epsilon step (paper section 2): a random reachable point at least the novelty radius
 * from every past position, drawn with probability proportional to e^(-distance); with
 * eps_sample, the model's draw first (above). */
static bool choose_epsilon(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
{
    if (epsilon_sample(s, rng, now_us)) {
        return true;
    }
    const rfs_map_t *m = s->map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, s->pose.x, s->pose.y, &ci, &cj);
    const lattice_window_t w = lattice_window(m, ci, cj, RFS_SEEK_EPS_RADIUS);
    /* Geodesic: every try plans from the robot, so one search tree rooted there serves
     * them all (resumed out to each goal; a goal it already reached costs no search).
     * No tree when the robot has no legal start: every plan then fails, as a
     * plan from the robot does. */
    const bool tree = s->cfg.eps_geodesic;
    rfs_q16_t sx, sy;
    const bool tree_ok = tree && rfs_seek_plan_start(s, &sx, &sy);
    if (tree_ok && !s->plan_ready) { /* plan_ready: the decision's grown tree (rfs_seek.c) */
        rfs_plan_tree_begin(&s->plan, sx, sy);
    }
    /* Row totals once, so a draw finds its row by 2 r + 1 additions and scans only that
     * row; a try changes them only by marking its draw visited.
     * Scaling: weights Q0.16 <= 65535, at most 65^2 candidates: sum < 2^28. */
    uint32_t row_total[2 * RFS_SEEK_EPS_RADIUS + 1];
    uint32_t total = 0;
    for (int32_t j = w.j0; j <= w.j1; ++j) {
        uint32_t t = 0;
        for (int32_t i = w.i0; i <= w.i1; ++i) {
            t += eps_weight(s, ci, cj, i, j);
        }
        row_total[j - w.j0] = t;
        total += t;
    }
    for (int attempt = 0; attempt < GOAL_TRIES && !s->plan.tree_more; ++attempt) {
        if (total == 0) {
            return false;
        }
        uint32_t pick = rfs_rng_below(rng, total), acc = 0;
        int32_t j = w.j0;
        while (acc + row_total[j - w.j0] <= pick) {
            acc += row_total[j - w.j0];
            j++;
        }
        for (int32_t i = w.i0; i <= w.i1; ++i) {
            const uint32_t wt = eps_weight(s, ci, cj, i, j);
            acc += wt;
            if (wt == 0u || acc <= pick) {
                continue;
            }
            const int32_t di = i - (int32_t)ci, dj = j - (int32_t)cj;
            const uint32_t q = (uint32_t)(di * di + dj * dj);
            const uint32_t idx = (uint32_t)j * m->lw + (uint32_t)i;
            rfs_q16_t px, py;
            rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
            s->decision.goal_x = px;
            s->decision.goal_y = py;
            bool ok = !tree || tree_ok;
            rfs_q16_t len = 0;
            if (ok && tree && attempt != GOAL_TRIES - 1) {
                ok = rfs_plan_tree_length(&s->plan, px, py, &len);
                if (ok && !accept_detour(s, rng, q, len)) {
                    goto next_attempt; /* a rejected draw is not pulled */
                }
            }
            if (ok && rfs_seek_plan_to(s, px, py, tree)) {
                rfs_drive_set_path(&s->drive, &s->drive.path, now_us);
                return true;
            }
            if (!s->plan.tree_more) { /* else decided again later (rfs_seek.c) */
                rfs_reach_bit_set(s->visited, idx); /* unreachable in practice: do not redraw it */
                row_total[j - w.j0] -= wt;
                total -= wt;
            }
            goto next_attempt;
        }
    next_attempt:;
    }
    return false;
}

/* mean_t: the greedy goal is the belief's mean, where the way from
 * the robot and on to the argmax is open (docs/STRATEGIES.md, "Stalls"): a mirror image
 * across the line of the first samples, or a weaker source nearer the robot, fits the
 * early data as well as the argmax, which flips between them; heading for their mean
 * loses little whichever holds. With a wall between any two of robot, mean and argmax
 * the mean is no way to either (a corridor ring's two ways round): the argmax.
 * Nor where the robot has been: between two modes the mean stays put, and the robot
 * shuttled between it and a wrong argmax. The whole planned leg, rechecked as any (no
 * local search: the mean is no estimate). */
static bool hedge(rfs_seek_t *s, rfs_q16_t ax, rfs_q16_t ay, int64_t now_us)
{
    rfs_q16_t x, y;
    uint16_t li, lj;
    if (s->cfg.mean_t <= 0 || s->model.ops->mean == 0 ||
        !s->model.ops->mean(s->model.self, s->cfg.mean_t, &x, &y) ||
        rfs_q16_dist(s->pose.x, s->pose.y, x, y) < rfs_q16_add(s->cfg.step, s->cfg.step / 2) ||
        (rfs_map_lattice_nearest(s->map, x, y, &li, &lj),
         rfs_reach_bit(s->visited, (uint32_t)lj * s->map->lw + li)) ||
        rfs_map_walls_crossed(s->map, s->pose.x, s->pose.y, ax, ay) != 0u ||
        rfs_map_walls_crossed(s->map, s->pose.x, s->pose.y, x, y) != 0u ||
        rfs_map_walls_crossed(s->map, x, y, ax, ay) != 0u ||
        !greedy_along_path(s, x, y, s->cfg.leg_max, now_us)) {
        return false;
    }
    s->decision.max_x = x;
    s->decision.max_y = y;
    s->decision.hedged = true;
    return true;
}

/* Greedy step (paper section 2): the model's maximum, from the model itself when it
 * knows where it is (argmax: the pathloss model's estimated source, docs/PATHLOSS.md,
 * "Model"), else by the grid search over every reachable legal lattice point; then
 * the strategy's step towards it. */
static bool choose_greedy(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
{
    rfs_q16_t mx = 0, my = 0;
    bool found = false;
    bool known = false;
    if (s->model.ops->argmax != 0 && s->model.ops->argmax(s->model.self, &mx, &my)) {
        if (hedge(s, mx, my, now_us)) {
            return true;
        }
        found = true;
        known = true;
    } else {
        found = rfs_gridmax_find(s->map, &s->model, s->reach, &mx, &my);
    }
    if (!found) {
        return false;
    }
    s->decision.max_x = mx;
    s->decision.max_y = my;
    return rfs_seek_ops(s)->to_max(s, mx, my, known, rng, now_us);
}

/* local_gap: a visited lattice point within local_gap of lattice point (i, j) (a window
 * of (2 local_gap / grid + 1)^2 points). Scaling: lattice offsets squared times grid^2
 * (Q16 squared: Q32) in int64 against local_gap^2 (Q32). */
static bool near_visited(const rfs_seek_t *s, int32_t i, int32_t j)
{
    const rfs_map_t *m = s->map;
    const lattice_window_t w = lattice_window(m, (uint16_t)i, (uint16_t)j,
                                              s->cfg.local_gap / m->cfg.grid);
    const int64_t r2 = (int64_t)s->cfg.local_gap * s->cfg.local_gap;
    const int64_t g2 = (int64_t)m->cfg.grid * m->cfg.grid;
    for (int32_t b = w.j0; b <= w.j1; ++b) {
        for (int32_t a = w.i0; a <= w.i1; ++a) {
            const int64_t q = (int64_t)(a - i) * (a - i) + (int64_t)(b - j) * (b - j);
            if (q * g2 <= r2 && rfs_reach_bit(s->visited, (uint32_t)b * m->lw + (uint32_t)a)) {
                return true;
            }
        }
    }
    return false;
}

/* local_r: the goal of a local search round an estimate (mx, my) the robot has stood
 * at, or round its reachable stand-in when it is unreachable (the centre: its lattice
 * point is visited), the unvisited reachable lattice point within local_r of the centre
 * (and, with local_gap, no visited point within local_gap of it)
 * with the least sum of its squared straight distances to the robot and to the centre
 * (the nearest to their midpoint; ties: the first in row order): when the robot is at
 * the centre the nearest ring round it first, then on round the ring; false when the
 * centre is not yet visited (-1) or no point is left (0; 1: a goal). No square root: a window of up to
 * (2 local_r / grid + 3)^2 points stays within a control period on the microcontroller;
 * the local_gap test runs only for a point that would be the best so far.
 * Scaling: offsets Q16 (< 2^31 each, map coordinates) in int64, squared Q32 < 2^62;
 * a sum of two squared distances to the robot and centre saturates at INT64_MAX. */
static int local_goal(const rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, rfs_q16_t *gx,
                      rfs_q16_t *gy)
{
    const rfs_map_t *m = s->map;
    uint16_t ci, cj;
    rfs_q16_t cx = mx, cy = my;
    rfs_map_lattice_nearest(m, mx, my, &ci, &cj);
    if (!rfs_reach_bit(s->reach, (uint32_t)cj * m->lw + ci)) {
        if (!rfs_reach_nearest(m, s->reach, mx, my, &cx, &cy)) {
            return -1;
        }
        rfs_map_lattice_nearest(m, cx, cy, &ci, &cj);
    }
    if (!rfs_reach_bit(s->visited, (uint32_t)cj * m->lw + ci)) {
        return -1;
    }
    const lattice_window_t w = lattice_window(m, ci, cj, s->cfg.local_r / m->cfg.grid + 1);
    const int64_t r2 = (int64_t)s->cfg.local_r * s->cfg.local_r;
    int64_t best = INT64_MAX;
    for (int32_t j = w.j0; j <= w.j1; ++j) {
        for (int32_t i = w.i0; i <= w.i1; ++i) {
            const uint32_t idx = (uint32_t)j * m->lw + (uint32_t)i;
            if (rfs_reach_bit(s->visited, idx) || !rfs_reach_bit(s->reach, idx)) {
                continue;
            }
            rfs_q16_t px, py;
            rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
            const int64_t dx = (int64_t)px - cx, dy = (int64_t)py - cy;
            if (dx * dx + dy * dy > r2) {
                continue;
            }
            const int64_t rx = (int64_t)px - s->pose.x, ry = (int64_t)py - s->pose.y;
            const uint64_t rr = (uint64_t)(rx * rx) + (uint64_t)(ry * ry);
            const uint64_t sum = rr + (uint64_t)(dx * dx + dy * dy);
            const int64_t cost = sum > (uint64_t)INT64_MAX - 1u ? INT64_MAX - 1 : (int64_t)sum;
            if (cost < best && (s->cfg.local_gap <= 0 || !near_visited(s, i, j))) {
                best = cost;
                *gx = px;
                *gy = py;
            }
        }
    }
    return best != INT64_MAX ? 1 : 0;
}

/* near_t (rfs_seek_cfg_t): a place is the argmax's own within NEAR_OWN steps of it (the
 * local search's), distances count NEAR_D0 steps more, and a path longer than
 * NEAR_DETOUR x straight + NEAR_SLACK steps (round walls) sends the robot to the argmax. */
#define NEAR_OWN 4
#define NEAR_D0 5
#define NEAR_DETOUR RFS_Q16_FRAC(13, 10)
#define NEAR_SLACK 2

/* near: refuse a place visited, unreachable or the argmax's own. */
static bool near_refuse(const void *ctx, rfs_q16_t x, rfs_q16_t y)
{
    const rfs_seek_t *s = (const rfs_seek_t *)ctx;
    if (rfs_q16_dist(x, y, s->decision.max_x, s->decision.max_y) <= NEAR_OWN * s->cfg.step) {
        return true;
    }
    uint16_t i, j;
    rfs_map_lattice_nearest(s->map, x, y, &i, &j);
    const uint32_t idx = (uint32_t)j * s->map->lw + i;
    return rfs_reach_bit(s->visited, idx) || !rfs_reach_bit(s->reach, idx);
}

/* near_t: the whole way to a nearer plausible source than the argmax (mx, my), when the
 * model names one and its path is not much longer than the straight line; false (the
 * argmax's leg follows, or a plan waits: s->plan.tree_more) otherwise.
 * Scaling: straight (Q16, < 2^31) x NEAR_DETOUR (Q16) in int64. */
static bool near_first(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, int64_t now_us)
{
    rfs_q16_t gx, gy;
    rfs_model_near_t q = { s->pose.x, s->pose.y, mx, my, s->cfg.near_t,
                           NEAR_D0 * s->cfg.step, near_refuse, s };
    if (s->cfg.near_t <= 0 || s->model.ops->near == 0 ||
        rfs_q16_dist(s->pose.x, s->pose.y, mx, my) < s->cfg.near_min ||
        !s->model.ops->near(s->model.self, &q, &gx, &gy) ||
        !greedy_along_path(s, gx, gy, 0, now_us)) {
        return false;
    }
    const int64_t straight = rfs_q16_dist(s->pose.x, s->pose.y, gx, gy);
    if ((int64_t)s->drive.path.length >
        ((straight * NEAR_DETOUR) >> 16) + (int64_t)NEAR_SLACK * s->cfg.step) {
        return false;
    }
    s->decision.near = true;
    return true;
}

bool rfs_seek_meta_path_step(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, bool known,
                             rfs_rng_t *rng, int64_t now_us)
{
    (void)rng;
    rfs_q16_t gx, gy;
    if (known && near_first(s, mx, my, now_us)) {
        return true;
    }
    if (known && s->cfg.near_t > 0 && s->plan.tree_more) {
        return false; /* near_first's plan waits for the search tree */
    }
    if (known && s->cfg.at_tol > 0) {
        /* Read at every drive update: this goal's, until the next decision resets it
         * (rfs_seek_meta_choose). */
        s->drive.cfg.goal_tol = s->cfg.at_tol;
    }
    const int local = known && s->cfg.local_r > 0 ? local_goal(s, mx, my, &gx, &gy) : -1;
    if (local == 1) {
        /* One scan a decision (the period budget); a point that cannot be planned to
         * (unreachable in practice) is marked visited and this decision goes to the
         * estimate; a plan waiting for the search tree decides again later. */
        if (rfs_seek_go_to(s, gx, gy, now_us)) {
            s->decision.goal_x = gx;
            s->decision.goal_y = gy;
            return true;
        }
        if (s->plan.tree_more) {
            return false;
        }
        uint16_t li, lj;
        rfs_map_lattice_nearest(s->map, gx, gy, &li, &lj);
        rfs_reach_bit_set(s->visited, (uint32_t)lj * s->map->lw + li);
    }
    if (!greedy_along_path(s, mx, my, known ? s->cfg.leg_max : s->cfg.step, now_us)) {
        return false;
    }
    if (local == 0 && s->cfg.local_refute && s->cfg.refute_r > 0) {
        /* local_refute: the disc round the estimate swept to within the novelty radius
         * plus local_gap of every reachable point, and no source met: rule the estimate
         * out and relearn at the next decision (docs/STRATEGIES.md, "Stalls"). */
        exclude(s, mx, my);
        s->replan = true;
    }
    return true;
}

/* The paper's greedy step: move min(distance, step) towards the maximum; when that point
 * is not legal, search the line to the maximum for the first legal point, before or after
 * the obstacle. */
bool rfs_seek_meta_step(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, bool known,
                        rfs_rng_t *rng, int64_t now_us)
{
    (void)known;
    const rfs_map_t *m = s->map;
    int64_t dx = (int64_t)mx - s->pose.x, dy = (int64_t)my - s->pose.y;
    rfs_q16_t dist = rfs_q16_dist(s->pose.x, s->pose.y, mx, my);
    if (dist <= s->cfg.step) {
        s->decision.goal_x = mx;
        s->decision.goal_y = my;
        return rfs_seek_go_to(s, mx, my, now_us);
    }
    /* Point at fraction t (Q16) of the way to the maximum. */
    rfs_q16_t t_step = rfs_q16_div(s->cfg.step, dist);
    rfs_q16_t gx = rfs_sat32(s->pose.x + ((dx * t_step) >> 16));
    rfs_q16_t gy = rfs_sat32(s->pose.y + ((dy * t_step) >> 16));
    if (rfs_map_point_legal(m, gx, gy) && rfs_seek_go_to(s, gx, gy, now_us)) {
        s->decision.goal_x = gx;
        s->decision.goal_y = gy;
        return true;
    }
    /* Line search at the map resolution, alternating at random between in front of the
     * step point (towards the robot) and beyond it (towards the maximum). */
    s->decision.line_search = true;
    rfs_q16_t dt = rfs_q16_div(m->res, dist);
    if (dt <= 0) {
        dt = 1;
    }
    for (int32_t k = 1; k < 65536; ++k) {
        bool any = false;
        bool beyond_first = (rfs_rng_u32(rng) & 1u) != 0u;
        for (int side = 0; side < 2; ++side) {
            bool beyond = (side == 0) == beyond_first;
            int64_t t = (int64_t)t_step + (beyond ? (int64_t)k * dt : -(int64_t)k * dt);
            if (t <= 0 || t > RFS_Q16_ONE) {
                continue;
            }
            any = true;
            gx = rfs_sat32(s->pose.x + ((dx * t) >> 16));
            gy = rfs_sat32(s->pose.y + ((dy * t) >> 16));
            if (rfs_map_point_legal(m, gx, gy) && rfs_seek_go_to(s, gx, gy, now_us)) {
                s->decision.goal_x = gx;
                s->decision.goal_y = gy;
                return true;
            }
        }
        if (!any) {
            break;
        }
    }
    s->decision.goal_x = mx;
    s->decision.goal_y = my;
    return rfs_seek_go_to(s, mx, my, now_us);
}

/* floor_gap: the fit's source power within cfg.floor_gap of the model's floor (its
 * penalty about to bind): distance traded against power, a weak source placed near the
 * robot, the real one farther. floor_max: a fit still pinned after that many rule-outs
 * is a weak node the data keep pointing at (docs/STRATEGIES.md, "Stalls"). */
static bool floor_pinned(const rfs_seek_t *s)
{
    rfs_q16_t gap;
    return s->cfg.floor_gap > 0 && s->model.ops->floor_gap != 0 &&
           (s->cfg.floor_max == 0u || s->nfloor < s->cfg.floor_max) &&
           s->model.ops->argmax != 0 &&
           s->model.ops->floor_gap(s->model.self, &gap) && gap < s->cfg.floor_gap;
}

/* "if random() > epsilon: greedy, else epsilon" (Algorithm 1), for every meta strategy.
 * A leg abandoned by a failed recheck continues greedily on the relearnt model: the draw
 * was made when the leg began. When the chosen move finds no goal the other is tried. */
bool rfs_seek_meta_choose(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us)
{
    rfs_seek_decision_t *d = &s->decision;
    s->drive.cfg.goal_tol = s->cfg.drive.goal_tol; /* at_tol: only a goal at the estimate */
    d->epsilon = rfs_seek_epsilon(&s->cfg, epsilon_index(s));
    /* settle_dist: exploration is over, the robot holds the model's best point. No draw is
     * taken then, so the paper's configuration (0: never) draws as it always did. */
    bool settled = rfs_seek_src_settled(s);
    bool greedy = model_ok && (s->replan || settled || rfs_rng_q16(rng) >= d->epsilon);
    s->replan = false;
    rfs_q16_t ax, ay;
    d->pinned = greedy && !settled && floor_pinned(s) &&
                s->model.ops->argmax(s->model.self, &ax, &ay);
    if (d->pinned) {
        s->nfloor = (uint8_t)(s->nfloor < UINT8_MAX ? s->nfloor + 1u : UINT8_MAX);
        exclude(s, ax, ay); /* for the relearn the next decision makes */
        s->replan = true;
        greedy = false;
    }
    d->kind = greedy ? RFS_SEEK_GREEDY : RFS_SEEK_EPSILON;
    if (greedy && rfs_seek_src_orbit(s, rng, now_us)) {
        return true; /* settle_orbit: round the best point, rfs_seek_src.c */
    }
    bool ok = greedy ? choose_greedy(s, rng, now_us) : choose_epsilon(s, rng, now_us);
    if (s->plan.tree_more) {
        return false; /* a plan waits for the search tree: decided again (rfs_seek.c) */
    }
    if (!ok && greedy) {
        d->kind = RFS_SEEK_EPSILON; /* no reachable maximum: explore instead */
        ok = choose_epsilon(s, rng, now_us);
    }
    if (!ok && !greedy && model_ok) {
        d->kind = RFS_SEEK_GREEDY; /* nothing novel left within reach */
        ok = choose_greedy(s, rng, now_us);
    }
    return ok;
}
