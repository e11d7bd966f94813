/* rfs_seek.c - the meta-algorithm (paper section 2) over the core's modules. */
#include "rfs_seek.h"

#include <string.h>

#include "rfs_assert.h"

/* ln(9/4) / 5 in Q16.16: epsilon(5) = 0.9 e^(-5a) + 0.1 = 0.5 (paper section 2). */
#define EPS_RATE_PAPER ((rfs_q16_t)10629)
/* Line-search candidates and epsilon redraws tried before giving up on an iteration. */
#define GOAL_TRIES 6
/* Lattice points predicted per predict_row call in the grid search (stack buffer). */
#define RFS_SEEK_ROW_CHUNK 16
/* How far (lattice steps) an off-lattice or illegal start looks for a legal lattice point. */
#define SNAP_RADIUS 6
/* Wait before deciding again after no goal could be found, microseconds (one window). */
#define NO_GOAL_RETRY_US 1000000

rfs_seek_cfg_t rfs_seek_cfg_default(void)
{
    rfs_seek_cfg_t c;
    memset(&c, 0, sizeof c);
    c.step = RFS_Q16_ONE;                   /* paper section 2: 1 m */
    c.initial_step_max = RFS_Q16_INT(2);    /* "restricted to twice the regular step width" */
    c.error_threshold = RFS_Q16_INT(3);     /* 3 dB */
    c.eps_floor = RFS_Q16_FRAC(1, 10);      /* epsilon = 0.9 e^(-a n) + 0.1 */
    c.eps_amp = RFS_Q16_FRAC(9, 10);
    c.eps_rate = EPS_RATE_PAPER;
    c.novelty_radius = RFS_Q16_HALF;        /* "about the size of the robot": 0.5 m */
    c.pose_timeout_us = 150000;             /* + one 50 ms period: stopped within 200 ms */
    c.rssi_timeout_us = 150000;
    c.fit_budget = 0;
    c.rssi = rfs_rssi_cfg_default();
    c.store = rfs_store_cfg_default();      /* 10,000 samples (section 5.2) */
    c.drive = rfs_drive_cfg_default();
    c.strategy = RFS_SEEK_META;
    c.tumble_better = RFS_Q16_FRAC(1, 5);   /* E. coli runs on while things improve */
    c.tumble_worse = RFS_Q16_ONE;           /* and tumbles when they do not */
    c.recheck_dist = 0;                     /* the paper checks when a step ends */
    c.eps_by_travel = false;                /* and counts epsilon's n in iterations */
    c.recheck_adapt = false;                /* one fixed threshold */
    c.eps_geodesic = false;                 /* epsilon weights by straight distance */
    c.eps_sample = false;                   /* and epsilon goals at random, not drawn */
    return c;
}

void rfs_seek_cfg_use_strategy(rfs_seek_cfg_t *cfg, rfs_seek_strategy_t strategy)
{
    RFS_ASSERT(cfg != 0);
    bool path = strategy == RFS_SEEK_META_PATH;
    cfg->strategy = strategy;
    /* A meta-path greedy leg walks the whole planned path: check the model every step of
     * it, as the paper does after each 1 m step, and anneal epsilon by the steps' worth
     * of travel, not by the few long iterations. */
    cfg->recheck_dist = path ? cfg->step : 0;
    cfg->eps_by_travel = path;
    cfg->recheck_adapt = path;
    cfg->eps_geodesic = path;
    cfg->eps_sample = path;
}

uint32_t rfs_seek_lattice_bits_bytes(const rfs_map_t *map)
{
    return ((uint32_t)map->lw * map->lh + 7u) / 8u;
}

static bool bit_get(const uint8_t *bits, uint32_t i)
{
    return (bits[i >> 3] >> (i & 7u)) & 1u;
}

static void bit_set(uint8_t *bits, uint32_t i)
{
    bits[i >> 3] = (uint8_t)(bits[i >> 3] | (1u << (i & 7u)));
}

/* Length of a lattice offset (di, dj) with q = di^2 + dj^2, metres Q16.16: grid * sqrt(q).
 * Scaling: grid Q16 * isqrt(q << 32) Q16 -> Q32 >> 16 = Q16 metres, saturated. */
static rfs_q16_t offset_dist(const rfs_map_t *m, uint32_t q)
{
    uint32_t root_q16 = rfs_isqrt64((uint64_t)q << 32);
    return rfs_sat32(((int64_t)m->cfg.grid * root_q16) >> 16);
}

int rfs_seek_init(rfs_seek_t *s, const rfs_seek_cfg_t *cfg, const rfs_map_t *map,
                  rfs_model_t model, const rfs_target_ops_t *target, const rfs_seek_mem_t *mem)
{
    RFS_ASSERT(s != 0 && cfg != 0 && map != 0 && mem != 0);
    if (cfg->step <= 0 || cfg->initial_step_max <= 0 || cfg->error_threshold <= 0 ||
        cfg->eps_floor < 0 || cfg->eps_amp < 0 ||
        (int64_t)cfg->eps_floor + cfg->eps_amp > RFS_Q16_ONE || cfg->eps_rate < 0 ||
        cfg->novelty_radius < 0 || cfg->pose_timeout_us <= 0 || cfg->rssi_timeout_us <= 0 ||
        (uint32_t)cfg->strategy >= (uint32_t)RFS_SEEK_STRATEGY_COUNT ||
        cfg->tumble_better < 0 || cfg->tumble_better > RFS_Q16_ONE || cfg->tumble_worse < 0 ||
        cfg->tumble_worse > RFS_Q16_ONE || cfg->recheck_dist < 0) {
        return -1;
    }
    if (model.ops == 0 || model.ops->fit == 0 || model.ops->predict == 0 ||
        model.ops->reset == 0 || target == 0 || target->nsources == 0 ||
        target->nsources > RFS_SEEK_MAX_SOURCES) {
        return -1;
    }
    uint32_t lbytes = rfs_seek_lattice_bits_bytes(map);
    if (mem->visited == 0 || mem->visited_bytes < lbytes || mem->reach == 0 ||
        mem->reach_bytes < lbytes) {
        return -1;
    }
    memset(s, 0, sizeof *s);
    s->cfg = *cfg;
    s->map = map;
    s->model = model;
    s->target = target;
    for (uint8_t i = 0; i < target->nsources; ++i) {
        if (rfs_rssi_init(&s->win[i], &cfg->rssi) != 0) {
            return -1;
        }
    }
    if (rfs_store_init(&s->store, &cfg->store, mem->samples, mem->pending, mem->pending_cap) != 0 ||
        rfs_plan_init(&s->plan, map, mem->plan_work, mem->plan_work_bytes, mem->plan_queue,
                      mem->plan_queue_cap) != 0 ||
        rfs_drive_init(&s->drive, &cfg->drive) != 0) {
        return -1;
    }
    s->visited = mem->visited;
    s->reach = mem->reach;
    s->queue = mem->plan_queue;
    s->queue_cap = mem->plan_queue_cap;
    memset(s->visited, 0, lbytes);
    memset(s->reach, 0, lbytes);
    /* The reach bits are the robot's component (or every legal point, or none): a plan to
     * a goal outside it fails without flooding the goal's side (line searches and epsilon
     * draws next to a closed room, docs/PERFORMANCE.md). */
    rfs_plan_set_component(&s->plan, s->reach);
    /* Epsilon weights e^(-d), d = grid * sqrt(q) for q = di^2 + dj^2 (section 2:
     * P(x) proportional to e^(-|x - x0|)), tabulated once so a draw costs a lookup per
     * candidate (offset_dist). */
    for (uint32_t q = 0; q < RFS_SEEK_EPS_TABLE; ++q) {
        rfs_q16_t w = rfs_q16_exp_neg(offset_dist(map, q));
        s->eps_w[q] = (uint16_t)(w >= RFS_Q16_ONE ? 0xFFFFu : (uint32_t)w);
    }
    s->state = RFS_SEEK_WAITING;
    s->prev_status = RFS_DRIVE_IDLE;
    return 0;
}

rfs_q16_t rfs_seek_epsilon(const rfs_seek_cfg_t *cfg, uint32_t n)
{
    /* Scaling: rate (Q16) * n saturates at Q16 max, where e^-x is 0 anyway. */
    int64_t x = (int64_t)cfg->eps_rate * (int64_t)(n > 65535u ? 65535u : n);
    rfs_q16_t e = rfs_q16_exp_neg(rfs_sat32(x));
    return rfs_q16_add(rfs_q16_mul(cfg->eps_amp, e), cfg->eps_floor);
}

/* Mark the lattice points within the novelty radius of (x, y) as visited. */
static void mark_visited(rfs_seek_t *s, rfs_q16_t x, rfs_q16_t y)
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
    int32_t r = s->cfg.novelty_radius / m->cfg.grid + 1;
    int64_t r2 = (int64_t)s->cfg.novelty_radius * s->cfg.novelty_radius;
    for (int32_t dj = -r; dj <= r; ++dj) {
        int32_t j = (int32_t)cj + dj;
        if (j < 0 || j >= (int32_t)m->lh) {
            continue;
        }
        for (int32_t di = -r; di <= r; ++di) {
            int32_t i = (int32_t)ci + di;
            if (i < 0 || i >= (int32_t)m->lw) {
                continue;
            }
            rfs_q16_t px, py;
            rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
            int64_t dx = (int64_t)px - x, dy = (int64_t)py - y;
            /* Q16 squared = Q32; compare with the radius squared (Q32). */
            if (dx * dx + dy * dy <= r2) {
                bit_set(s->visited, (uint32_t)j * m->lw + (uint32_t)i);
            }
        }
    }
}

bool rfs_seek_on_pose(rfs_seek_t *s, const rfs_pose_t *pose, rfs_rng_t *rng)
{
    if (s->have_pose && pose->t_us <= s->pose.t_us) {
        (void)rfs_store_add_pose(&s->store, pose, rng); /* counts the rejection */
        return false;
    }
    (void)rfs_store_add_pose(&s->store, pose, rng);
    s->pose = *pose;
    s->have_pose = true;
    mark_visited(s, pose->x, pose->y);
    return true;
}

bool rfs_seek_on_rssi(rfs_seek_t *s, uint8_t src, int64_t t_us, int8_t dbm, rfs_rng_t *rng)
{
    if (src >= s->target->nsources) {
        s->meas_rejected++;
        return false;
    }
    if (!rfs_rssi_push(&s->win[src], t_us, dbm)) {
        return false;
    }
    if (!s->have_meas || t_us > s->last_meas_us) {
        s->last_meas_us = t_us;
    }
    s->have_meas = true;
    rfs_target_in_t in = { s->win, s->target->nsources, t_us };
    rfs_q16_t v;
    if (s->target->sample(&in, src, dbm, &v)) {
        rfs_store_add_value(&s->store, t_us, v, rng);
    }
    return true;
}

/* A receiver report is a measurement without a value (issue 10): it keeps the stream
 * fresh and touches neither the 1 s windows nor the store. Ordering as for measurements
 * (rfs_rssi_push): older than the newest report is rejected, equal is accepted. */
bool rfs_seek_on_receiver(rfs_seek_t *s, int64_t t_us)
{
    if (s->have_rx && t_us < s->last_rx_us) {
        s->rx_rejected = s->rx_rejected < UINT32_MAX ? s->rx_rejected + 1u : UINT32_MAX;
        return false;
    }
    s->last_rx_us = t_us;
    s->have_rx = true;
    return true;
}

/* Nearest legal lattice point to (x, y), searching rings up to SNAP_RADIUS; when
 * need_reach, it must also be marked reachable. */
static bool snap_legal(const rfs_seek_t *s, rfs_q16_t x, rfs_q16_t y, bool need_reach,
                       uint16_t *oi, uint16_t *oj)
{
    const rfs_map_t *m = s->map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, x, y, &ci, &cj);
    for (int32_t r = 0; r <= SNAP_RADIUS; ++r) {
        int64_t best = INT64_MAX;
        for (int32_t dj = -r; dj <= r; ++dj) {
            for (int32_t di = -r; di <= r; ++di) {
                if (di != -r && di != r && dj != -r && dj != r) {
                    continue; /* ring only */
                }
                int32_t i = (int32_t)ci + di, j = (int32_t)cj + dj;
                if (i < 0 || j < 0 || i >= (int32_t)m->lw || j >= (int32_t)m->lh) {
                    continue;
                }
                if (!rfs_map_lattice_legal(m, (uint16_t)i, (uint16_t)j)) {
                    continue;
                }
                if (need_reach && !bit_get(s->reach, (uint32_t)j * m->lw + (uint32_t)i)) {
                    continue;
                }
                int64_t d = (int64_t)di * di + (int64_t)dj * dj;
                if (d < best) {
                    best = d;
                    *oi = (uint16_t)i;
                    *oj = (uint16_t)j;
                }
            }
        }
        if (best != INT64_MAX) {
            return true;
        }
    }
    return false;
}

/* Flood-fill the lattice points reachable from the robot (8-connected, an edge where the
 * straight segment is legal: rfs_map_lattice_step_legal), so that greedy maxima and
 * epsilon goals never lie in a pocket of the map the robot cannot reach (SLAM maps have
 * many). */
static void compute_reach(rfs_seek_t *s)
{
    const rfs_map_t *m = s->map;
    uint32_t lbytes = rfs_seek_lattice_bits_bytes(m);
    memset(s->reach, 0, lbytes);
    uint16_t si, sj;
    if (!snap_legal(s, s->pose.x, s->pose.y, false, &si, &sj)) {
        s->reach_valid = false;
        return;
    }
    static const int8_t k_di[8] = { 1, -1, 0, 0, 1, 1, -1, -1 };
    static const int8_t k_dj[8] = { 0, 0, 1, -1, 1, -1, 1, -1 };
    uint32_t head = 0, count = 0;
    uint32_t start = (uint32_t)sj * m->lw + si;
    bit_set(s->reach, start);
    s->queue[0] = start;
    count = 1;
    bool overflow = false;
    while (count > 0) {
        uint32_t idx = s->queue[head];
        head = (head + 1u) % s->queue_cap;
        count--;
        uint16_t i = (uint16_t)(idx % m->lw), j = (uint16_t)(idx / m->lw);
        for (int k = 0; k < 8; ++k) {
            int32_t ni = (int32_t)i + k_di[k], nj = (int32_t)j + k_dj[k];
            if (ni < 0 || nj < 0 || ni >= (int32_t)m->lw || nj >= (int32_t)m->lh) {
                continue;
            }
            uint32_t nidx = (uint32_t)nj * m->lw + (uint32_t)ni;
            if (bit_get(s->reach, nidx) || !rfs_map_lattice_legal(m, (uint16_t)ni, (uint16_t)nj)) {
                continue;
            }
            /* The recorded step cells when the map has them, else the traversal: the
             * same answer as rfs_map_segment_legal between the two lattice points. */
            if (!rfs_map_lattice_step_legal(m, i, j, k_di[k], k_dj[k])) {
                continue;
            }
            bit_set(s->reach, nidx);
            if (count == s->queue_cap) {
                overflow = true; /* marked but not expanded: handled below */
                continue;
            }
            s->queue[(head + count) % s->queue_cap] = nidx;
            count++;
        }
    }
    if (overflow) {
        /* A queue too small for this map's frontier: fall back to "every legal point is
         * reachable" rather than a wrong partial set; the planner still checks goals. */
        for (uint16_t j = 0; j < m->lh; ++j) {
            for (uint16_t i = 0; i < m->lw; ++i) {
                if (rfs_map_lattice_legal(m, i, j)) {
                    bit_set(s->reach, (uint32_t)j * m->lw + i);
                }
            }
        }
    }
    s->reach_valid = true;
}

static bool reachable_point(const rfs_seek_t *s, uint16_t i, uint16_t j)
{
    return bit_get(s->reach, (uint32_t)j * s->map->lw + i);
}

/* Where plans start: the robot, or the closest legal lattice point when it stands in the
 * clearance zone. false when there is none. */
static bool plan_start(const rfs_seek_t *s, rfs_q16_t *sx, rfs_q16_t *sy)
{
    *sx = s->pose.x;
    *sy = s->pose.y;
    if (!rfs_map_point_legal(s->map, *sx, *sy)) {
        uint16_t i, j;
        if (!snap_legal(s, *sx, *sy, false, &i, &j)) {
            return false;
        }
        rfs_map_lattice_point(s->map, i, j, sx, sy);
    }
    return true;
}

/* Plan from the robot to (gx, gy) into the drive's path (not yet driven). false when
 * there is no path. With `tree`, from the search tree choose_epsilon began at
 * plan_start (rfs_plan_tree_path: same contract). */
static bool plan_to_from(rfs_seek_t *s, rfs_q16_t gx, rfs_q16_t gy, bool tree)
{
    rfs_q16_t sx, sy;
    if (!tree && !plan_start(s, &sx, &sy)) {
        return false;
    }
    /* Plan straight into the drive's own path: a 520-byte rfs_path_t on the stack would
     * overflow the microcontroller's 2.5 KB stack during a decision. */
    if (tree ? !rfs_plan_tree_path(&s->plan, gx, gy, &s->drive.path)
             : !rfs_plan_path(&s->plan, sx, sy, gx, gy, &s->drive.path)) {
        return false;
    }
    s->decision.path_len = s->drive.path.length;
    return true;
}

static bool plan_to(rfs_seek_t *s, rfs_q16_t gx, rfs_q16_t gy)
{
    return plan_to_from(s, gx, gy, false);
}

/* Plan to (gx, gy) and drive the path. */
static bool go_to(rfs_seek_t *s, rfs_q16_t gx, rfs_q16_t gy, int64_t now_us)
{
    if (!plan_to(s, gx, gy)) {
        return false;
    }
    rfs_drive_set_path(&s->drive, &s->drive.path, now_us);
    return true;
}

/* Initial random move: a uniformly chosen reachable lattice point within
 * initial_step_max of the robot (paper: "restricted to twice the regular step width"). */
static bool choose_initial(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
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
                        j >= (int32_t)m->lh || !reachable_point(s, (uint16_t)i, (uint16_t)j)) {
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
                        if (go_to(s, px, py, now_us)) {
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
 * so the kept goals have weight e^(-path length) (the last try is always kept).
 * Scaling: the straight distance from the weight table's q (grid * sqrt(q), Q16) and
 * the path length (Q16, <= 32 km) differ by less than 2^31; e^(-d) is Q16. */
static bool accept_detour(const rfs_seek_t *s, rfs_rng_t *rng, uint32_t q)
{
    int64_t detour = (int64_t)s->drive.path.length - offset_dist(s->map, q);
    if (detour <= 0) {
        return true;
    }
    rfs_q16_t keep = rfs_q16_exp_neg(rfs_sat32(detour));
    return rfs_rng_below(rng, RFS_Q16_ONE) < (uint32_t)keep;
}

static bool greedy_along_path(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, bool whole,
                              int64_t now_us);

/* eps_sample: the epsilon goal is a draw from the model's belief (a plausible source),
 * driven the whole planned way and rechecked like a greedy leg. false (the novelty draw
 * follows) when the model draws nothing, a point within 1.5 steps of the robot, or one
 * the robot has been to (within the novelty radius of a past position), and whenever the
 * robot stands within 1.5 steps of the model's own maximum: at a wrong estimate the
 * draws lie in the rooms round it, a leg there fails its recheck within a metre and the
 * relearnt fit holds the estimate (hold_k), so the robot shuttles; only the novelty
 * move's new places shift the fit. */
static bool choose_epsilon_sample(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
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
    if (bit_get(s->visited, (uint32_t)lj * s->map->lw + li)) {
        return false;
    }
    if (!greedy_along_path(s, x, y, true, now_us)) {
        return false;
    }
    s->decision.sampled = true;
    s->decision.max_x = x;
    s->decision.max_y = y;
    return true;
}

/* Epsilon step (paper section 2): a random reachable point at least the novelty radius
 * from every past position, drawn with probability proportional to e^(-distance); with
 * eps_sample, the model's draw first (above). */
static bool choose_epsilon(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
{
    if (choose_epsilon_sample(s, rng, now_us)) {
        return true;
    }
    const rfs_map_t *m = s->map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, s->pose.x, s->pose.y, &ci, &cj);
    const int32_t r = RFS_SEEK_EPS_RADIUS;
    /* Geodesic: every try plans from the robot, so one search tree rooted there serves
     * them all (resumed out to each goal; a goal it already reached costs no search).
     * No tree when the robot has no legal start: every plan then fails, as plan_to's. */
    const bool tree = s->cfg.eps_geodesic;
    rfs_q16_t sx, sy;
    const bool tree_ok = tree && plan_start(s, &sx, &sy);
    if (tree_ok) {
        rfs_plan_tree_begin(&s->plan, sx, sy);
    }
    for (int attempt = 0; attempt < GOAL_TRIES; ++attempt) {
        /* Scaling: weights Q0.16 <= 65535, at most 65^2 candidates: sum < 2^28. */
        uint32_t total = 0;
        for (int pass = 0; pass < 2; ++pass) {
            uint32_t pick = pass ? rfs_rng_below(rng, total) : 0u, acc = 0;
            for (int32_t dj = -r; dj <= r; ++dj) {
                int32_t j = (int32_t)cj + dj;
                if (j < 0 || j >= (int32_t)m->lh) {
                    continue;
                }
                for (int32_t di = -r; di <= r; ++di) {
                    int32_t i = (int32_t)ci + di;
                    uint32_t q = (uint32_t)(di * di + dj * dj);
                    if (i < 0 || i >= (int32_t)m->lw || q >= RFS_SEEK_EPS_TABLE) {
                        continue;
                    }
                    uint32_t idx = (uint32_t)j * m->lw + (uint32_t)i;
                    if (bit_get(s->visited, idx) || !bit_get(s->reach, idx)) {
                        continue;
                    }
                    uint32_t w = s->eps_w[q];
                    if (pass == 0) {
                        total += w;
                        continue;
                    }
                    acc += w;
                    if (acc > pick) {
                        rfs_q16_t px, py;
                        rfs_map_lattice_point(m, (uint16_t)i, (uint16_t)j, &px, &py);
                        s->decision.goal_x = px;
                        s->decision.goal_y = py;
                        if (tree ? tree_ok && plan_to_from(s, px, py, true)
                                 : plan_to(s, px, py)) {
                            /* A rejected draw never reaches the drive. */
                            if (!s->cfg.eps_geodesic || attempt == GOAL_TRIES - 1 ||
                                accept_detour(s, rng, q)) {
                                rfs_drive_set_path(&s->drive, &s->drive.path, now_us);
                                return true;
                            }
                            goto next_attempt;
                        }
                        bit_set(s->visited, idx); /* unreachable in practice: do not redraw it */
                        goto next_attempt;
                    }
                }
            }
            if (total == 0) {
                return false;
            }
        }
    next_attempt:;
    }
    return false;
}

/* Full scan: row by row, in chunks, so that a model with predict_row costs one call per
 * chunk and the lattice coordinates advance by addition. The paper's greedy step takes
 * the argmax of the model over the reachable points (section 2); a point where the model
 * has no prediction (radius: no sample within the radius, scikit-learn's NaN) is skipped,
 * and the search fails only when no reachable point has one. predict_row returning false
 * means no point of its chunk has a prediction (rfs_model.h: no model). First strict
 * maximum in row-major order wins. Unreachable points are not predicted. */
static bool grid_max_scan(const rfs_seek_t *s, rfs_q16_t *mx, rfs_q16_t *my)
{
    const rfs_map_t *m = s->map;
    const rfs_model_ops_t *ops = s->model.ops;
    rfs_q16_t best = RFS_Q16_MIN;
    rfs_q16_t row[RFS_SEEK_ROW_CHUNK];
    bool found = false;
    for (uint16_t j = 0; j < m->lh; ++j) {
        rfs_q16_t x0, py;
        rfs_map_lattice_point(m, 0, j, &x0, &py);
        uint32_t base = (uint32_t)j * m->lw;
        for (uint16_t i0 = 0; i0 < m->lw; i0 = (uint16_t)(i0 + RFS_SEEK_ROW_CHUNK)) {
            uint16_t n = (uint16_t)(m->lw - i0 < RFS_SEEK_ROW_CHUNK ? m->lw - i0
                                                                    : RFS_SEEK_ROW_CHUNK);
            rfs_q16_t cx0 = x0 + (rfs_q16_t)i0 * m->cfg.grid;
            bool any = false;
            for (uint16_t k = 0; k < n && !any; ++k) {
                any = bit_get(s->reach, base + i0 + k);
            }
            if (!any) {
                continue;
            }
            bool have_row = ops->predict_row != 0 &&
                            ops->predict_row(s->model.self, cx0, py, m->cfg.grid, n, row);
            if (ops->predict_row != 0 && !have_row) {
                continue;
            }
            for (uint16_t k = 0; k < n; ++k) {
                rfs_q16_t v;
                if (!bit_get(s->reach, base + i0 + k)) {
                    continue;
                }
                if (have_row) {
                    v = row[k];
                } else if (!ops->predict(s->model.self, cx0 + (rfs_q16_t)k * m->cfg.grid, py,
                                         &v)) {
                    continue;
                }
                if (!found || v > best) {
                    best = v;
                    *mx = cx0 + (rfs_q16_t)k * m->cfg.grid;
                    *my = py;
                    found = true;
                }
            }
        }
    }
    return found;
}

/* First set bit in [from, to), or -1; whole zero bytes are skipped at once. */
static int32_t first_set(const uint8_t *b, uint32_t from, uint32_t to)
{
    uint32_t i = from;
    for (; i < to && (i & 7u) != 0u; ++i) {
        if (bit_get(b, i)) {
            return (int32_t)i;
        }
    }
    for (; i + 8u <= to; i += 8u) {
        uint32_t v = b[i >> 3];
        if (v != 0u) {
            return (int32_t)(i + (uint32_t)__builtin_ctz(v));
        }
    }
    for (; i < to; ++i) {
        if (bit_get(b, i)) {
            return (int32_t)i;
        }
    }
    return -1;
}

/* Last set bit in [from, to), or -1. */
static int32_t last_set(const uint8_t *b, uint32_t from, uint32_t to)
{
    uint32_t i = to;
    while (i > from && (i & 7u) != 0u) {
        --i;
        if (bit_get(b, i)) {
            return (int32_t)i;
        }
    }
    while (i >= from + 8u) {
        uint32_t v = b[(i >> 3) - 1u];
        if (v != 0u) {
            return (int32_t)(i - 8u + (uint32_t)(31 - __builtin_clz(v)));
        }
        i -= 8u;
    }
    while (i > from) {
        --i;
        if (bit_get(b, i)) {
            return (int32_t)i;
        }
    }
    return -1;
}

/* For a model monotone along rows (a plane), the maximum of a row's reachable points is
 * at one end; walking back from the high end over equal predictions gives the first of
 * the tied points, so the result is exactly grid_max_scan()'s. */
static bool grid_max_rows(const rfs_seek_t *s, int dir, rfs_q16_t *mx, rfs_q16_t *my)
{
    const rfs_map_t *m = s->map;
    const rfs_model_ops_t *ops = s->model.ops;
    rfs_q16_t best = RFS_Q16_MIN;
    bool found = false;
    for (uint16_t j = 0; j < m->lh; ++j) {
        rfs_q16_t x0, py;
        rfs_map_lattice_point(m, 0, j, &x0, &py);
        uint32_t base = (uint32_t)j * m->lw;
        int32_t first = first_set(s->reach, base, base + m->lw);
        int32_t last = first < 0 ? -1 : last_set(s->reach, base, base + m->lw);
        first = first < 0 ? -1 : first - (int32_t)base;
        last = last < 0 ? -1 : last - (int32_t)base;
        if (first < 0) {
            continue;
        }
        int32_t pick = dir > 0 ? last : first;
        rfs_q16_t v;
        if (!ops->predict(s->model.self, x0 + (rfs_q16_t)pick * m->cfg.grid, py, &v)) {
            return false;
        }
        if (dir > 0) {
            for (int32_t i = pick - 1; i >= first; --i) {
                rfs_q16_t w;
                if (!bit_get(s->reach, base + (uint32_t)i)) {
                    continue;
                }
                if (!ops->predict(s->model.self, x0 + (rfs_q16_t)i * m->cfg.grid, py, &w) ||
                    w != v) {
                    break;
                }
                pick = i;
            }
        }
        if (!found || v > best) {
            best = v;
            *mx = x0 + (rfs_q16_t)pick * m->cfg.grid;
            *my = py;
            found = true;
        }
    }
    return found;
}

/* Branch and bound over the lattice (issue 8), for a model with a bound over a box:
 * tiles of RFS_SEEK_ROW_CHUNK x RFS_SEEK_ROW_CHUNK points, aligned with the full scan's
 * chunks (a tile row is one chunk), split into quadrants (see bb_node()).
 * A node is skipped when its bound cannot beat the best so far in the scan's own order
 * (bound < best, or == best and the node's first point comes after the best's), so the
 * answer is exactly grid_max_scan()'s, ties included: the first reachable point of
 * greatest prediction in row-major order, points without a prediction skipped, false
 * only when no reachable point has one. A bound that returns false promises nothing
 * (some point may have no prediction): such a node is split and its reachable points
 * are predicted one by one. The GRID_BB_SEEDS tiles whose middle point predicts highest
 * go first, to find a high maximum early; then every other tile in row-major order. No
 * memory beyond the stack (about 250 bytes). */
/* Nodes without a bound are split down to this many points (4 x 4): down to 2 x 2 costs
 * more than it saves on robot-path samples, where most small boxes near the path get no
 * radius bound either (docs/PERFORMANCE.md, "Models"). */
#define GRID_BB_LEAF 16
/* Tiles searched first. */
#define GRID_BB_SEEDS 4
/* Split depths told apart when counting bounds (tile, 8 x 8, 4 x 4, smaller). */
#define GRID_BB_DEPTHS 4u
/* Bounds at a depth stop being asked for, for the rest of the search, once this many
 * have been asked and fewer than one in four pruned its node: a radius bound is refused
 * on every box wider than twice the radius and on most boxes along a robot's path, a
 * k-neighbours bound on robot-path samples rarely prunes, and each costs a read of the
 * samples around its box (docs/PERFORMANCE.md, "Models"). */
#define GRID_BB_ASK 8u

_Static_assert(RFS_SEEK_ROW_CHUNK <= 32, "one bit per tile row in a uint32_t");

typedef struct grid_bb {
    const rfs_seek_t *s;
    rfs_q16_t x0;      /* x of lattice column 0, metres Q16.16 */
    rfs_q16_t best;    /* best prediction so far, target units Q16.16 */
    uint32_t best_idx; /* its row-major lattice index */
    bool found;        /* best is valid */
    uint32_t asked[GRID_BB_DEPTHS];  /* bounds asked for at each split depth (0: tile) */
    uint32_t pruned[GRID_BB_DEPTHS]; /* nodes there skipped by their bound */
} grid_bb_t;

/* Lattice columns [i0, i0 + w), rows [j0, j0 + h), inside one tile whose row rj0 is bit 0
 * of the row mask (rows holding a reachable point). */
typedef struct grid_node {
    uint16_t i0, j0, w, h, rj0;
    uint16_t depth; /* splits below its tile */
} grid_node_t;

static bool bb_reach_any(const rfs_seek_t *s, const grid_node_t *nd)
{
    for (uint16_t j = nd->j0; j < nd->j0 + nd->h; ++j) {
        uint32_t base = (uint32_t)j * s->map->lw + nd->i0;
        if (first_set(s->reach, base, base + nd->w) >= 0) {
            return true;
        }
    }
    return false;
}

static uint32_t bb_rows(const grid_node_t *nd)
{
    uint32_t ones = nd->h >= 32u ? 0xFFFFFFFFu : (1u << nd->h) - 1u;
    return ones << (nd->j0 - nd->rj0);
}

/* The model's bound over the node, or false without asking when bounds at this depth have
 * rarely pruned in this search (GRID_BB_ASK). Not asking only costs pruning: a node
 * without a bound is searched point by point, so the answer is the same.
 * Scaling: lattice coordinates as grid_max_scan() forms them (x0 + i * grid < 2^31);
 * the counts are below the lattice's point count (< 2^32). */
static bool bb_bound(grid_bb_t *bb, const grid_node_t *nd, rfs_q16_t *ub)
{
    const rfs_map_t *m = bb->s->map;
    uint32_t d = nd->depth < GRID_BB_DEPTHS ? nd->depth : GRID_BB_DEPTHS - 1u;
    if (bb->asked[d] >= GRID_BB_ASK && bb->pruned[d] * 4u < bb->asked[d]) {
        return false;
    }
    bb->asked[d]++;
    rfs_q16_t xa, ya, xb, yb;
    rfs_map_lattice_point(m, 0, nd->j0, &xa, &ya);
    rfs_map_lattice_point(m, 0, (uint16_t)(nd->j0 + nd->h - 1u), &xb, &yb);
    xa = bb->x0 + (rfs_q16_t)nd->i0 * m->cfg.grid;
    xb = bb->x0 + (rfs_q16_t)(nd->i0 + nd->w - 1u) * m->cfg.grid;
    return bb->s->model.ops->bound(bb->s->model.self, xa, ya, xb, yb, ub);
}

static bool bb_prunable(grid_bb_t *bb, const grid_node_t *nd, rfs_q16_t ub)
{
    uint32_t first = (uint32_t)nd->j0 * bb->s->map->lw + nd->i0;
    bool skip = bb->found && (ub < bb->best || (ub == bb->best && first > bb->best_idx));
    bb->pruned[nd->depth < GRID_BB_DEPTHS ? nd->depth : GRID_BB_DEPTHS - 1u] += skip;
    return skip;
}

static void bb_consider(grid_bb_t *bb, rfs_q16_t v, uint32_t idx)
{
    if (!bb->found || v > bb->best || (v == bb->best && idx < bb->best_idx)) {
        bb->best = v;
        bb->best_idx = idx;
        bb->found = true;
    }
}

/* Predict the node's reachable points and take those with a prediction as candidates.
 * A model with predict_row gets the scan's very call (the whole chunk), so the values are
 * the scan's bit for bit; false from it skips the row as the scan skips the chunk. */
static void bb_leaf(grid_bb_t *bb, const grid_node_t *nd, uint32_t rmask)
{
    const rfs_seek_t *s = bb->s;
    const rfs_map_t *m = s->map;
    const rfs_model_ops_t *ops = s->model.ops;
    rfs_q16_t row[RFS_SEEK_ROW_CHUNK];
    uint16_t c0 = (uint16_t)(nd->i0 - nd->i0 % RFS_SEEK_ROW_CHUNK);
    uint16_t cn = (uint16_t)(m->lw - c0 < RFS_SEEK_ROW_CHUNK ? m->lw - c0 : RFS_SEEK_ROW_CHUNK);
    for (uint16_t j = nd->j0; j < nd->j0 + nd->h; ++j) {
        uint32_t base = (uint32_t)j * m->lw;
        if (((rmask >> (j - nd->rj0)) & 1u) == 0u ||
            first_set(s->reach, base + nd->i0, base + nd->i0 + nd->w) < 0) {
            continue;
        }
        rfs_q16_t x, py;
        rfs_map_lattice_point(m, 0, j, &x, &py);
        if (ops->predict_row != 0 &&
            !ops->predict_row(s->model.self, bb->x0 + (rfs_q16_t)c0 * m->cfg.grid, py,
                              m->cfg.grid, cn, row)) {
            continue;
        }
        for (uint16_t i = nd->i0; i < nd->i0 + nd->w; ++i) {
            rfs_q16_t v;
            if (!bit_get(s->reach, base + i)) {
                continue;
            }
            if (ops->predict_row != 0) {
                v = row[i - c0];
            } else if (!ops->predict(s->model.self, bb->x0 + (rfs_q16_t)i * m->cfg.grid, py,
                                     &v)) {
                continue;
            }
            bb_consider(bb, v, base + i);
        }
    }
}

/* Search a node holding reachable points; own: the node's own bound promised predictions
 * over it (and did not prune it). A node with its own bound is scanned whole: splitting it
 * costs four bounds, each several predictions' work, and on robot-path samples (dense,
 * noisy) the children's bounds rarely prune (docs/PERFORMANCE.md, "Models"). A node
 * without one (radius: a sample may not cover it) is split down to GRID_BB_LEAF points,
 * where smaller boxes can be covered. Children without a reachable point are dropped
 * before their bound is asked; children with a bound go highest first (the tie rule does
 * not depend on the order). */
static void bb_node(grid_bb_t *bb, const grid_node_t *nd, uint32_t rmask, bool own)
{
    if (own || (uint32_t)nd->w * nd->h <= GRID_BB_LEAF) {
        bb_leaf(bb, nd, rmask);
        return;
    }
    uint16_t hw = (uint16_t)((nd->w + 1u) / 2u), hh = (uint16_t)((nd->h + 1u) / 2u);
    grid_node_t ch[4];
    rfs_q16_t ub[4];
    bool ok[4];
    uint32_t order[4] = {0u, 0u, 0u, 0u}, n = 0; /* filled in insertion order below */
    for (uint32_t q = 0; q < 4u; ++q) {
        grid_node_t c = *nd;
        c.i0 = (uint16_t)(nd->i0 + ((q & 1u) ? hw : 0u));
        c.w = (uint16_t)((q & 1u) ? nd->w - hw : hw);
        c.j0 = (uint16_t)(nd->j0 + ((q & 2u) ? hh : 0u));
        c.h = (uint16_t)((q & 2u) ? nd->h - hh : hh);
        c.depth = (uint16_t)(nd->depth + 1u);
        if (c.w == 0u || c.h == 0u || (rmask & bb_rows(&c)) == 0u ||
            !bb_reach_any(bb->s, &c)) {
            continue;
        }
        ok[q] = bb_bound(bb, &c, &ub[q]);
        ch[q] = c;
        uint32_t at = n++;
        while (at > 0u && ok[q] &&
               (!ok[order[at - 1u]] || ub[order[at - 1u]] < ub[q])) {
            order[at] = order[at - 1u];
            --at;
        }
        order[at] = q;
    }
    for (uint32_t k = 0; k < n; ++k) {
        uint32_t q = order[k];
        if (ok[q] && bb_prunable(bb, &ch[q], ub[q])) {
            continue;
        }
        bb_node(bb, &ch[q], rmask, ok[q]);
    }
}

/* Tile (ti, tj) and its row mask: bit r set when chunk row r holds a reachable point. */
static uint32_t bb_tile(const rfs_seek_t *s, uint16_t ti, uint16_t tj, grid_node_t *nd)
{
    const rfs_map_t *m = s->map;
    nd->i0 = (uint16_t)(ti * RFS_SEEK_ROW_CHUNK);
    nd->j0 = (uint16_t)(tj * RFS_SEEK_ROW_CHUNK);
    nd->rj0 = nd->j0;
    nd->depth = 0u;
    nd->w = (uint16_t)(m->lw - nd->i0 < RFS_SEEK_ROW_CHUNK ? m->lw - nd->i0 : RFS_SEEK_ROW_CHUNK);
    nd->h = (uint16_t)(m->lh - nd->j0 < RFS_SEEK_ROW_CHUNK ? m->lh - nd->j0 : RFS_SEEK_ROW_CHUNK);
    uint32_t rmask = 0u;
    for (uint16_t r = 0; r < nd->h; ++r) {
        uint32_t base = (uint32_t)(nd->j0 + r) * m->lw + nd->i0;
        if (first_set(s->reach, base, base + nd->w) >= 0) {
            rmask |= 1u << r;
        }
    }
    return rmask;
}

static bool grid_max_bb(const rfs_seek_t *s, rfs_q16_t *mx, rfs_q16_t *my)
{
    const rfs_map_t *m = s->map;
    grid_bb_t bb = {.s = s, .best = RFS_Q16_MIN, .best_idx = 0u, .found = false};
    rfs_q16_t py;
    rfs_map_lattice_point(m, 0, 0, &bb.x0, &py);
    uint16_t tw = (uint16_t)((m->lw + RFS_SEEK_ROW_CHUNK - 1u) / RFS_SEEK_ROW_CHUNK);
    uint16_t th = (uint16_t)((m->lh + RFS_SEEK_ROW_CHUNK - 1u) / RFS_SEEK_ROW_CHUNK);
    uint32_t seed[GRID_BB_SEEDS]; /* tile numbers, highest bound first */
    rfs_q16_t seed_ub[GRID_BB_SEEDS];
    uint32_t ns = 0;
    grid_node_t nd;
    rfs_q16_t ub;
    for (uint32_t t = 0; t < (uint32_t)tw * th; ++t) {
        uint32_t rmask = bb_tile(s, (uint16_t)(t % tw), (uint16_t)(t / tw), &nd);
        if (rmask == 0u) {
            continue;
        }
        /* Seeds by the prediction at the tile's middle point (a bound costs more); a
         * middle point without one makes no seed (the tile is searched in order). */
        uint16_t mi = (uint16_t)(nd.i0 + nd.w / 2u), mj = (uint16_t)(nd.j0 + nd.h / 2u);
        rfs_q16_t cx, cy;
        rfs_map_lattice_point(m, 0, mj, &cx, &cy);
        cx = bb.x0 + (rfs_q16_t)mi * m->cfg.grid;
        if (!s->model.ops->predict(s->model.self, cx, cy, &ub)) {
            continue;
        }
        if (ns == GRID_BB_SEEDS && ub <= seed_ub[ns - 1u]) {
            continue;
        }
        uint32_t at = ns < GRID_BB_SEEDS ? ns++ : ns - 1u;
        while (at > 0u && seed_ub[at - 1u] < ub) {
            seed[at] = seed[at - 1u];
            seed_ub[at] = seed_ub[at - 1u];
            --at;
        }
        seed[at] = t;
        seed_ub[at] = ub;
    }
    for (uint32_t k = 0; k < ns; ++k) {
        uint32_t rmask = bb_tile(s, (uint16_t)(seed[k] % tw), (uint16_t)(seed[k] / tw), &nd);
        bool ok = bb_bound(&bb, &nd, &ub);
        if (!ok || !bb_prunable(&bb, &nd, ub)) {
            bb_node(&bb, &nd, rmask, ok);
        }
    }
    for (uint32_t t = 0; t < (uint32_t)tw * th; ++t) {
        bool seeded = false;
        for (uint32_t k = 0; k < ns; ++k) {
            seeded = seeded || seed[k] == t;
        }
        uint32_t rmask = bb_tile(s, (uint16_t)(t % tw), (uint16_t)(t / tw), &nd);
        if (seeded || rmask == 0u) {
            continue;
        }
        bool ok = bb_bound(&bb, &nd, &ub);
        if (ok && bb_prunable(&bb, &nd, ub)) {
            continue;
        }
        bb_node(&bb, &nd, rmask, ok);
    }
    if (bb.found) {
        uint16_t i = (uint16_t)(bb.best_idx % m->lw), j = (uint16_t)(bb.best_idx / m->lw);
        rfs_map_lattice_point(m, 0, j, mx, my);
        *mx = bb.x0 + (rfs_q16_t)i * m->cfg.grid;
    }
    return bb.found;
}

bool rfs_seek_grid_max(const rfs_seek_t *s, rfs_q16_t *mx, rfs_q16_t *my)
{
    const rfs_model_ops_t *ops = s->model.ops;
    if (ops->row_monotone != 0) {
        return grid_max_rows(s, ops->row_monotone(s->model.self), mx, my);
    }
    if (ops->bound != 0) {
        return grid_max_bb(s, mx, my);
    }
    return grid_max_scan(s, mx, my);
}

bool rfs_seek_grid_max_scan(const rfs_seek_t *s, rfs_q16_t *mx, rfs_q16_t *my)
{
    return grid_max_scan(s, mx, my);
}

/* meta-path (an improvement beside the paper): plan to the maximum and keep the first
 * `step` metres of the path, so a greedy step goes round walls the way the planner does
 * instead of straight at the maximum with a line search; with a model that knows where
 * its maximum is (argmax: the pathloss model's estimated source, issue 10) the goal is
 * that point itself, reached through the planner. The cut point lies on a legal segment
 * of the path. Scaling: waypoint offsets (Q16, < 2^32) times the remaining length
 * (Q16, < 2^16 m) < 2^63; segment lengths by rfs_q16_dist(). */
/* The reachable legal lattice point nearest to (x, y), by a scan of the reach bits
 * (lw x lh points; squared lattice offsets < 2^32 in int64). false when none. */
static bool nearest_reachable(const rfs_seek_t *s, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *ox,
                              rfs_q16_t *oy)
{
    const rfs_map_t *m = s->map;
    uint16_t ci, cj;
    rfs_map_lattice_nearest(m, x, y, &ci, &cj);
    int64_t best = INT64_MAX;
    uint16_t bi = 0, bj = 0;
    for (uint16_t j = 0; j < m->lh; ++j) {
        for (uint16_t i = 0; i < m->lw; ++i) {
            if (!reachable_point(s, i, j)) {
                continue;
            }
            int64_t di = (int64_t)i - ci, dj = (int64_t)j - cj;
            int64_t d = di * di + dj * dj;
            if (d < best) {
                best = d;
                bi = i;
                bj = j;
            }
        }
    }
    if (best == INT64_MAX) {
        return false;
    }
    rfs_map_lattice_point(m, bi, bj, ox, oy);
    return true;
}

static bool greedy_along_path(rfs_seek_t *s, rfs_q16_t mx, rfs_q16_t my, bool whole,
                              int64_t now_us)
{
    if (!go_to(s, mx, my, now_us)) {
        /* The maximum is where the robot cannot go (a room whose door the clearance does
         * not pass, a spot off the free space): head for the reachable point nearest to
         * it rather than giving the iteration to a random epsilon move. */
        rfs_q16_t nx, ny;
        if (!nearest_reachable(s, mx, my, &nx, &ny) || !go_to(s, nx, ny, now_us)) {
            return false;
        }
    }
    rfs_path_t *p = &s->drive.path;
    int64_t px = s->pose.x, py = s->pose.y;
    int64_t left = whole ? INT32_MAX : s->cfg.step;
    for (uint16_t k = 0; k < p->n; ++k) {
        int64_t dx = (int64_t)p->x[k] - px, dy = (int64_t)p->y[k] - py;
        int64_t len = rfs_q16_dist((rfs_q16_t)px, (rfs_q16_t)py, p->x[k], p->y[k]);
        if (len >= left) {
            if (len > 0) {
                p->x[k] = rfs_sat32(px + rfs_sdiv64_round(dx * left, len));
                p->y[k] = rfs_sat32(py + rfs_sdiv64_round(dy * left, len));
            }
            p->n = (uint16_t)(k + 1u);
            p->length = s->cfg.step;
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

/* Greedy step (paper section 2): grid search over every reachable legal lattice point
 * for the model's maximum; move min(distance, step) towards it; when that point is not
 * legal, search the line to the maximum for the first legal point, before or after the
 * obstacle. */
static bool choose_greedy(rfs_seek_t *s, rfs_rng_t *rng, int64_t now_us)
{
    const rfs_map_t *m = s->map;
    rfs_q16_t mx = 0, my = 0;
    bool found = false;
    bool known = false;
    if (s->model.ops->argmax != 0 && s->model.ops->argmax(s->model.self, &mx, &my)) {
        found = true;
        known = true;
    } else {
        found = rfs_seek_grid_max(s, &mx, &my);
    }
    if (!found) {
        return false;
    }
    s->decision.max_x = mx;
    s->decision.max_y = my;
    if (s->cfg.strategy == RFS_SEEK_META_PATH) {
        return greedy_along_path(s, mx, my, known, now_us);
    }
    int64_t dx = (int64_t)mx - s->pose.x, dy = (int64_t)my - s->pose.y;
    rfs_q16_t dist = rfs_q16_dist(s->pose.x, s->pose.y, mx, my);
    if (dist <= s->cfg.step) {
        s->decision.goal_x = mx;
        s->decision.goal_y = my;
        return go_to(s, mx, my, now_us);
    }
    /* Point at fraction t (Q16) of the way to the maximum. */
    rfs_q16_t t_step = rfs_q16_div(s->cfg.step, dist);
    rfs_q16_t gx = rfs_sat32(s->pose.x + ((dx * t_step) >> 16));
    rfs_q16_t gy = rfs_sat32(s->pose.y + ((dy * t_step) >> 16));
    if (rfs_map_point_legal(m, gx, gy) && go_to(s, gx, gy, now_us)) {
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
            if (rfs_map_point_legal(m, gx, gy) && go_to(s, gx, gy, now_us)) {
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
    return go_to(s, mx, my, now_us);
}

static void stop_wheels(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    rfs_drive_stop(&s->drive, now_us);
    out->left_mm_s = 0;
    out->right_mm_s = 0;
}

static void end_decision(rfs_seek_t *s, bool ok, int64_t now_us, rfs_seek_out_t *out);

/* ---- Baseline strategies (issue 7) ------------------------------------------------- */

/* cos(2 pi k / 16), Q16.16; sin(2 pi k / 16) = cos(2 pi (k - 4) / 16). */
static const rfs_q16_t k_cos16[16] = { 65536,  60547,  46341,  25080, 0, -25080, -46341, -60547,
                                      -65536, -60547, -46341, -25080, 0,  25080,  46341,  60547 };

static rfs_q16_t sin16(uint8_t h)
{
    return k_cos16[(h + 12u) & 15u];
}

static const char *const k_strategy_names[RFS_SEEK_STRATEGY_COUNT] = {
    "meta", "meta-global", "fd-gradient", "plane-gradient", "chemotaxis", "meta-path",
};

const char *rfs_seek_strategy_name(rfs_seek_strategy_t st)
{
    return (uint32_t)st < (uint32_t)RFS_SEEK_STRATEGY_COUNT ? k_strategy_names[st] : "?";
}

static bool same_str(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        ++a;
        ++b;
    }
    return *a == *b;
}

bool rfs_seek_strategy_parse(const char *name, rfs_seek_strategy_t *st)
{
    if (name == 0) {
        return false;
    }
    for (uint32_t i = 0; i < (uint32_t)RFS_SEEK_STRATEGY_COUNT; ++i) {
        if (same_str(name, k_strategy_names[i])) {
            *st = (rfs_seek_strategy_t)i;
            return true;
        }
    }
    return false;
}

const char *rfs_seek_kind_name(rfs_seek_kind_t k)
{
    switch (k) {
    case RFS_SEEK_INITIAL: return "initial";
    case RFS_SEEK_GREEDY: return "greedy";
    case RFS_SEEK_EPSILON: return "epsilon";
    case RFS_SEEK_PROBE: return "probe";
    case RFS_SEEK_GRADIENT: return "gradient";
    case RFS_SEEK_RUN: return "run";
    case RFS_SEEK_TUMBLE: return "tumble";
    default: return "none";
    }
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
    if (rfs_map_point_legal(s->map, gx, gy) && go_to(s, gx, gy, now_us)) {
        return true;
    }
    uint16_t i, j;
    if (!snap_legal(s, gx, gy, true, &i, &j)) {
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
    return go_to(s, gx, gy, now_us);
}

/* One step from the robot in heading h (sixteenths of a turn); the goal must be legal
 * and have a path (position is used for nothing else). */
static bool go_heading(rfs_seek_t *s, uint8_t h, int64_t now_us)
{
    rfs_q16_t gx, gy;
    step_point(s, s->pose.x, s->pose.y, k_cos16[h & 15u], sin16(h), &gx, &gy);
    s->decision.goal_x = gx;
    s->decision.goal_y = gy;
    return rfs_map_point_legal(s->map, gx, gy) && go_to(s, gx, gy, now_us);
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
        if (rfs_map_point_legal(s->map, gx, gy) && go_to(s, gx, gy, now_us)) {
            return sg;
        }
    }
    return 0;
}

/* fd-gradient (issue 7 a): the 1 s mean at p, at p + step x and at p + step y (each
 * after standing still for one averaging window, rfs_seek_step), then one step from p
 * along the estimated gradient ((m_x - m_0) / step, (m_y - m_0) / step). An axis whose
 * probe point is illegal in both directions contributes no component. */
static void decide_fd(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
    rfs_seek_decision_t *d = &s->decision;
    bool ok = false;
    s->dwell_done = false;
    if (!d->mean_valid) {
        /* Nothing heard for a whole window: no difference to take; move and try again. */
        s->fd_phase = 0;
        d->kind = RFS_SEEK_TUMBLE;
        ok = go_random_heading(s, false, rng, now_us);
        end_decision(s, ok, now_us, out);
        return;
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
    end_decision(s, ok, now_us, out);
}

/* plane-gradient (issue 7 b, the gradient view of paper section 4.1): the model (refit
 * at every step by decide()) is followed one step along its gradient, taken as central
 * differences one step either side (exact for the ridge plane). No epsilon, no check. */
static bool choose_plane(rfs_seek_t *s, bool model_ok, rfs_rng_t *rng, int64_t now_us)
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

/* chemotaxis (issue 7 c): run-and-tumble on the change of the 1 s mean since the last
 * decision. After a rise it runs on in its heading (tumbling with tumble_better), after
 * a fall it tumbles with tumble_worse. Its decisions use no position; the position only
 * checks that a step is legal and plans it. */
static void decide_chemo(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
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
    end_decision(s, ok, now_us, out);
}

/* Finish the decision after a (possibly sliced) fit: epsilon-greedy choice and goal. */
/* Add the straight distance from the last check point to the pose to the travel and
 * make the pose the check point. Scaling: each leg < 2^16 m in Q16.16 (rfs_q16_dist),
 * the sum saturates far beyond any mission (2^47 m). */
static void count_travel(rfs_seek_t *s)
{
    if (s->have_chk) {
        int64_t leg = rfs_q16_dist(s->chk_x, s->chk_y, s->pose.x, s->pose.y);
        s->travel = s->travel < ((int64_t)1 << 62) ? s->travel + leg : s->travel;
    }
    s->have_chk = true;
    s->chk_x = s->pose.x;
    s->chk_y = s->pose.y;
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

bool rfs_seek_recheck_miss(const rfs_seek_cfg_t *cfg, int64_t *miss_ms, rfs_q16_t miss)
{
    RFS_ASSERT(cfg != 0 && miss_ms != 0 && miss >= 0);
    rfs_q16_t thr = cfg->error_threshold;
    if (cfg->recheck_adapt) {
        /* The running mean of the squared misses moves 1/8 of the way at each check (about
         * the last eight metres); the check fails only beyond the larger of the threshold
         * and its square root. Scaling: a miss clamped to 128 dB (Q16 < 2^24) squared is
         * below 2^48 in Q32; >> 16 is dB^2 Q16 < 2^32; the mean stays in that range. */
        int64_t m = miss > RFS_Q16_INT(128) ? RFS_Q16_INT(128) : miss;
        int64_t sq = (m * m) >> 16;
        *miss_ms += (sq - *miss_ms) / 8;
        rfs_q16_t rms = rfs_q16_sqrt(rfs_sat32(*miss_ms));
        thr = rms > thr ? rms : thr;
    }
    return miss > thr;
}

/* recheck_dist: while a greedy leg is driven, every recheck_dist of travel, the relearn
 * check of Algorithm 1 (|1 s mean - prediction| > threshold; with recheck_adapt the
 * threshold is at least the RMS of the recent misses). true when it fails: the leg is
 * abandoned and the next iteration relearns. */
static bool recheck_fails(rfs_seek_t *s, int64_t now_us)
{
    if (s->cfg.recheck_dist <= 0 ||
        (s->decision.kind != RFS_SEEK_GREEDY && !s->decision.sampled) || !s->have_chk ||
        rfs_q16_dist(s->chk_x, s->chk_y, s->pose.x, s->pose.y) < s->cfg.recheck_dist) {
        return false;
    }
    count_travel(s);
    rfs_target_in_t in = { s->win, s->target->nsources, now_us };
    rfs_q16_t mean, pred;
    if (!s->target->mean(&in, &mean) ||
        !s->model.ops->predict(s->model.self, s->pose.x, s->pose.y, &pred)) {
        return false;
    }
    return rfs_seek_recheck_miss(&s->cfg, &s->miss_ms, rfs_q16_abs(rfs_q16_sub(mean, pred)));
}

static void finish_decision(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
    rfs_seek_decision_t *d = &s->decision;
    bool ok = false;
    rfs_q16_t dummy;
    bool model_ok = s->model.ops->predict(s->model.self, s->pose.x, s->pose.y, &dummy);
    if (d->iteration == 0u) {
        d->kind = RFS_SEEK_INITIAL;
        ok = choose_initial(s, rng, now_us);
    } else if (s->cfg.strategy == RFS_SEEK_PLANE_GRADIENT) {
        ok = choose_plane(s, model_ok, rng, now_us);
    } else {
        d->epsilon = rfs_seek_epsilon(&s->cfg, epsilon_index(s));
        /* "if random() > epsilon: greedy" (Algorithm 1). A leg abandoned by a failed
         * recheck continues greedily on the relearnt model: the draw was made when the
         * leg began. */
        bool greedy = model_ok && (s->replan || rfs_rng_q16(rng) >= d->epsilon);
        s->replan = false;
        d->kind = greedy ? RFS_SEEK_GREEDY : RFS_SEEK_EPSILON;
        ok = greedy ? choose_greedy(s, rng, now_us) : choose_epsilon(s, rng, now_us);
        if (!ok && greedy) {
            d->kind = RFS_SEEK_EPSILON; /* no reachable maximum: explore instead */
            ok = choose_epsilon(s, rng, now_us);
        }
        if (!ok && !greedy && model_ok) {
            d->kind = RFS_SEEK_GREEDY; /* nothing novel left within reach */
            ok = choose_greedy(s, rng, now_us);
        }
    }
    end_decision(s, ok, now_us, out);
}

/* Count the decision, report it, and start driving (or flag that there is no goal). */
static void end_decision(rfs_seek_t *s, bool ok, int64_t now_us, rfs_seek_out_t *out)
{
    rfs_seek_decision_t *d = &s->decision;
    s->iteration++;
    out->decided = true;
    if (!ok) {
        out->faults |= RFS_SEEK_FAULT_NO_GOAL;
        d->goal_x = s->pose.x;
        d->goal_y = s->pose.y;
        stop_wheels(s, now_us, out);
        s->state = RFS_SEEK_DRIVING;
        /* Decide again after NO_GOAL_RETRY_US, not at every period: a robot from where
         * nothing can be planned would otherwise relearn and search the whole lattice
         * (and plan every line-search point) 20 times a second while standing still. */
        s->retry_after_us = now_us + NO_GOAL_RETRY_US;
        s->retry_no_goal = true;
        return;
    }
    s->state = RFS_SEEK_DRIVING;
    rfs_drive_status_t st = rfs_drive_update(&s->drive, &s->pose, now_us, &out->left_mm_s,
                                             &out->right_mm_s);
    if (st != RFS_DRIVE_RUNNING) {
        s->prev_status = st;
    }
    if (st == RFS_DRIVE_REACHED && (d->kind == RFS_SEEK_GREEDY || d->kind == RFS_SEEK_EPSILON)) {
        /* A null move: the goal is where the robot stands (a greedy step or line search
         * blocked at a wall). An iteration of the paper takes a step's time; deciding
         * again at every 50 ms period instead repeats the relearn check, the grid search
         * and the line search's planning 20 times a second (one 3ne run: 111 s of CPU
         * for 900 simulated seconds). Decide again after one window, as after no goal. */
        s->retry_after_us = now_us + NO_GOAL_RETRY_US;
        s->retry_no_goal = false;
    }
}

/* Start an iteration: the relearn check, then (after learning) the step choice. */
static void decide(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
    rfs_seek_decision_t *d = &s->decision;
    memset(d, 0, sizeof *d);
    d->iteration = s->iteration;
    d->t_us = now_us;
    d->prev = s->prev_status;
    d->x = s->pose.x;
    d->y = s->pose.y;
    d->samples = s->store.count;
    count_travel(s);
    rfs_target_in_t in = { s->win, s->target->nsources, now_us };
    d->mean_valid = s->target->mean(&in, &d->mean);
    if (s->cfg.strategy == RFS_SEEK_FD_GRADIENT) {
        decide_fd(s, now_us, rng, out);
        return;
    }
    if (s->cfg.strategy == RFS_SEEK_CHEMOTAXIS) {
        decide_chemo(s, now_us, rng, out);
        return;
    }
    d->model_valid = s->model.ops->predict(s->model.self, s->pose.x, s->pose.y, &d->prediction);
    bool relearn = !d->model_valid;
    if (d->model_valid && d->mean_valid) {
        relearn = rfs_q16_abs(rfs_q16_sub(d->mean, d->prediction)) > s->cfg.error_threshold;
    }
    if (s->cfg.strategy == RFS_SEEK_PLANE_GRADIENT) {
        relearn = true; /* issue 7 b: the local fit is redone at every step */
    }
    if (relearn && s->store.count > 0u) {
        d->relearned = true;
        s->model.ops->reset(s->model.self);
        s->fitting = true;
    }
    if (s->fitting) {
        rfs_model_fit_in_t fin = { s->store.samples, s->store.count, s->pose.x, s->pose.y, s->map };
        rfs_fit_result_t r = s->model.ops->fit(s->model.self, &fin, s->cfg.fit_budget, rng);
        if (r == RFS_FIT_MORE) {
            s->state = RFS_SEEK_LEARNING;
            stop_wheels(s, now_us, out);
            return;
        }
        s->fitting = false;
    }
    finish_decision(s, now_us, rng, out);
}

/* |a - b| > limit, without signed overflow at extreme timestamps. */
static bool apart(int64_t a, int64_t b, int64_t limit)
{
    uint64_t d = a >= b ? (uint64_t)a - (uint64_t)b : (uint64_t)b - (uint64_t)a;
    return d > (uint64_t)limit;
}

/* b - a > limit: stamp b further ahead of now a than limit (a clock jump, issue 9). */
static bool ahead(int64_t a, int64_t b, int64_t limit)
{
    return b > a && apart(a, b, limit);
}

/* The measurement stream is stale when neither a measurement nor a receiver report
 * (issue 10) lies within rssi_timeout_us of now, or when either newest stamp lies further
 * ahead than that: the feed's clock jumped, and while it is the newest every real input
 * is rejected as out of order. Without reports (have_rx false) this is exactly the
 * measurement-only rule: stale when there is none or it is apart from now. */
static bool meas_stale(const rfs_seek_t *s, int64_t now_us)
{
    int64_t lim = s->cfg.rssi_timeout_us;
    bool meas_fresh = s->have_meas && !apart(now_us, s->last_meas_us, lim);
    bool rx_fresh = s->have_rx && !apart(now_us, s->last_rx_us, lim);
    bool jumped = (s->have_meas && ahead(now_us, s->last_meas_us, lim)) ||
                  (s->have_rx && ahead(now_us, s->last_rx_us, lim));
    return jumped || !(meas_fresh || rx_fresh);
}

/* a - b saturated to [0, INT64_MAX]. */
static int64_t elapsed(int64_t a, int64_t b)
{
    if (a <= b) {
        return 0;
    }
    uint64_t d = (uint64_t)a - (uint64_t)b;
    return d > (uint64_t)INT64_MAX ? INT64_MAX : (int64_t)d;
}

void rfs_seek_step(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
    out->left_mm_s = 0;
    out->right_mm_s = 0;
    out->faults = 0;
    out->decided = false;
    /* A newest stamp further ahead of now than the timeout is stale too (a clock jump,
     * issue 9): while it is the newest, every real input is rejected as out of order and
     * the pose would freeze with the wheels still driving. */
    bool pose_stale = !s->have_pose || apart(now_us, s->pose.t_us, s->cfg.pose_timeout_us);
    bool rssi_stale = meas_stale(s, now_us);
    if (pose_stale) {
        out->faults |= RFS_SEEK_FAULT_POSE_STALE;
    }
    if (rssi_stale) {
        out->faults |= RFS_SEEK_FAULT_RSSI_STALE;
    }
    if (s->have_pose && !rfs_map_point_legal(s->map, s->pose.x, s->pose.y)) {
        uint16_t ci, cj;
        if (!rfs_map_cell(s->map, s->pose.x, s->pose.y, &ci, &cj)) {
            out->faults |= RFS_SEEK_FAULT_OFF_MAP;
        }
    }
    if (pose_stale || rssi_stale) {
        if (s->state == RFS_SEEK_DRIVING && s->drive.status == RFS_DRIVE_RUNNING) {
            s->resume = true;
            s->resume_path = s->drive.path;
            s->resume_start_us = elapsed(now_us, s->drive.start_us); /* driven so far */
        }
        if (s->state != RFS_SEEK_WAITING) {
            s->state = RFS_SEEK_STALE;
        }
        stop_wheels(s, now_us, out);
        goto report;
    }
    if (!s->reach_valid) {
        compute_reach(s);
    } else {
        /* The robot is somewhere the flood fill did not reach (pushed, relocalised):
         * recompute its reachable component. */
        uint16_t si, sj;
        if (!snap_legal(s, s->pose.x, s->pose.y, true, &si, &sj)) {
            compute_reach(s);
        }
    }
    if (s->resume) {
        s->resume = false;
        rfs_drive_set_path(&s->drive, &s->resume_path, now_us);
        /* The goal's timeout counts driving time only: the time it was driven before
         * the interruption still counts (a goal interrupted again and again must still
         * end), the stale time does not (after a 30 s silence, issue 9, the goal would
         * otherwise time out the moment it resumes). */
        s->drive.start_us = now_us >= INT64_MIN + s->resume_start_us ? now_us - s->resume_start_us
                                                                     : INT64_MIN;
        s->state = RFS_SEEK_DRIVING;
    }
    if (s->fitting) {
        /* A sliced fit continues; the decision finishes when it is done. */
        rfs_model_fit_in_t fin = { s->store.samples, s->store.count, s->pose.x, s->pose.y,
                                   s->map };
        rfs_fit_result_t r = s->model.ops->fit(s->model.self, &fin, s->cfg.fit_budget, rng);
        if (r == RFS_FIT_MORE) {
            s->state = RFS_SEEK_LEARNING;
            stop_wheels(s, now_us, out);
            goto report;
        }
        s->fitting = false;
        finish_decision(s, now_us, rng, out);
        goto report;
    }
    if (s->drive.status == RFS_DRIVE_RUNNING && recheck_fails(s, now_us)) {
        rfs_drive_stop(&s->drive, now_us);
        s->prev_status = RFS_DRIVE_RUNNING; /* abandoned while running: the model failed */
        s->replan = true;
    }
    if (s->drive.status == RFS_DRIVE_RUNNING) {
        rfs_drive_status_t st = rfs_drive_update(&s->drive, &s->pose, now_us, &out->left_mm_s,
                                                 &out->right_mm_s);
        if (st == RFS_DRIVE_RUNNING) {
            s->state = RFS_SEEK_DRIVING;
            goto report;
        }
        s->prev_status = st;
    }
    if (now_us < s->retry_after_us) {
        out->faults |= s->retry_no_goal ? RFS_SEEK_FAULT_NO_GOAL : 0u;
        stop_wheels(s, now_us, out);
        goto report;
    }
    if (s->cfg.strategy == RFS_SEEK_FD_GRADIENT) {
        /* fd-gradient measures standing still: one whole window at each point. */
        if (!s->dwell_done) {
            s->dwell_done = true;
            s->dwell_until_us = now_us + (int64_t)s->cfg.rssi.window_us;
        }
        if (now_us < s->dwell_until_us) {
            stop_wheels(s, now_us, out);
            s->state = RFS_SEEK_DRIVING;
            goto report;
        }
    }
    decide(s, now_us, rng, out);
report:
    out->state = s->state;
    out->decision = s->decision;
}
