/* rfs_seek.c - the meta-algorithm (paper section 2, Algorithm 1): configuration, inputs,
 * and the control loop that decides an iteration when the previous goal ends (relearn
 * check, learning, the strategy's choice) and drives it. The choices are in
 * rfs_seek_meta.c (the paper's) and rfs_seek_baseline.c, picked through k_strategies. */
#include "rfs_seek.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_reach.h"
#include "rfs_seek_internal.h"

/* ln(9/4) / 5 in Q16.16: epsilon(5) = 0.9 e^(-5a) + 0.1 = 0.5 (paper section 2). */
#define EPS_RATE_PAPER ((rfs_q16_t)10629)
_Static_assert(RFS_MODEL_MAX_SOURCES == RFS_TARGET_MAX_SOURCES,
               "a fit sees every source a target combines");
/* Wait before deciding again after no goal could be found, microseconds (one window). */
#define NO_GOAL_RETRY_US 1000000

/* |a - b| > limit, without signed overflow at extreme timestamps. */
static bool apart(int64_t a, int64_t b, int64_t limit)
{
    uint64_t d = a >= b ? (uint64_t)a - (uint64_t)b : (uint64_t)b - (uint64_t)a;
    return d > (uint64_t)limit;
}

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
    c.fit_early = false;
    c.plan_budget = RFS_SEEK_PLAN_BUDGET;   /* how the paths are computed, not which */
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
    c.refute_r = 0;                         /* and nothing is ruled out */
    c.local_r = 0;                          /* stand at the estimate */
    c.local_gap = 0;
    c.local_refute = false;
    c.at_tol = 0;                           /* the drive's goal tolerance for every goal */
    c.leg_max = 0;                          /* and walk the whole leg to it */
    c.floor_gap = 0;                        /* whatever the fit's power */
    c.floor_max = 0;                        /* and however often */
    c.mean_t = 0;                           /* greedy goes to the argmax */
    c.reach_min = 0;                        /* the robot's component, however small */
    c.silence_floor = INT32_MIN;            /* silence adds no sample */
    c.recheck_silent = false;               /* and a silent check passes */
    c.settle_dist = 0;                      /* epsilon anneals to eps_floor, never 0 */
    c.settle_orbit = 0;
    c.settle_end = 0;
    c.src_spacing = 0;
    c.src_floor = INT32_MIN;
    return c;
}

/* The strategies (docs/STRATEGIES.md), in rfs_seek_strategy_t order: everything the loop
 * below does differently for one of them is a field of its row. */
static const rfs_seek_strategy_ops_t k_strategies[RFS_SEEK_STRATEGY_COUNT] = {
    [RFS_SEEK_META] = { .name = "meta", .choose = rfs_seek_meta_choose,
                        .to_max = rfs_seek_meta_step, .learns = true },
    /* The same rule; the caller gives the model a map-wide radius. */
    [RFS_SEEK_META_GLOBAL] = { .name = "meta-global", .choose = rfs_seek_meta_choose,
                               .to_max = rfs_seek_meta_step, .learns = true },
    [RFS_SEEK_FD_GRADIENT] = { .name = "fd-gradient", .choose = rfs_seek_baseline_fd,
                               .dwell = true },
    [RFS_SEEK_PLANE_GRADIENT] = { .name = "plane-gradient", .learns = true, .refit = true,
                                  .choose = rfs_seek_baseline_plane },
    [RFS_SEEK_CHEMOTAXIS] = { .name = "chemotaxis", .choose = rfs_seek_baseline_chemo },
    [RFS_SEEK_META_PATH] = { .name = "meta-path", .choose = rfs_seek_meta_choose,
                             .to_max = rfs_seek_meta_path_step, .learns = true,
                             .improvements = true },
};

const rfs_seek_strategy_ops_t *rfs_seek_ops(const rfs_seek_t *s)
{
    return &k_strategies[s->cfg.strategy];
}

void rfs_seek_cfg_per_source(rfs_seek_cfg_t *cfg)
{
    RFS_ASSERT(cfg != 0);
    cfg->src_spacing = RFS_Q16_FRAC(1, 25); /* 4 cm: a third of the 12.5 cm wavelength */
    cfg->src_floor = RFS_Q16_INT(-100);     /* radiotap receivers report down to -100 dBm */
    /* Two thirds of the bridging scenarios' 150 m (docs/STRATEGIES.md, "Bridging"). */
    cfg->settle_dist = RFS_Q16_INT(100);
    /* The settle tour (docs/STRATEGIES.md, "Bridging"): a lattice step round each
     * candidate, 25 m of the 50 left. */
    cfg->settle_orbit = RFS_Q16_FRAC(1, 4);
    cfg->settle_end = RFS_Q16_INT(125);
    cfg->refute_r = 0; /* the argmax is the target's best point, not a source */
    cfg->local_r = 0;  /* and the settle tour measures round it */
    cfg->at_tol = 0;   /* with the drive's own tolerance (bridging as measured) */
    cfg->silence_floor = INT32_MIN; /* each node's store has src_floor */
}

void rfs_seek_cfg_use_strategy(rfs_seek_cfg_t *cfg, rfs_seek_strategy_t strategy)
{
    RFS_ASSERT(cfg != 0);
    bool on = (uint32_t)strategy < (uint32_t)RFS_SEEK_STRATEGY_COUNT &&
              k_strategies[strategy].improvements;
    cfg->strategy = strategy;
    /* A meta-path greedy leg walks the whole planned path: check the model every step of
     * it, as the paper does after each 1 m step, and anneal epsilon by the steps' worth
     * of travel, not by the few long iterations. */
    cfg->recheck_dist = on ? cfg->step : 0;
    cfg->eps_by_travel = on;
    cfg->recheck_adapt = on;
    cfg->eps_geodesic = on;
    cfg->eps_sample = on;
    /* The source within a step of a refuted argmax would be within 1.5 steps of the robot
     * (docs/STRATEGIES.md, "Stalls"). */
    cfg->refute_r = on ? cfg->step : 0;
    /* Radiotap receivers report down to -100 dBm (docs/STRATEGIES.md, "Stalls"). */
    cfg->silence_floor = on ? RFS_Q16_INT(-100) : INT32_MIN;
    cfg->recheck_silent = on; /* docs/STRATEGIES.md, "Stalls" */
    /* Sweep round an estimate already stood at (docs/STRATEGIES.md, "Stalls"). */
    cfg->local_r = on ? 4 * cfg->step : 0;
    /* Its sweeps 1 m apart: a source within local_r passes within the 1.5 m "at source"
     * radius; and the robot stands on the estimate, not 5 cm short (docs/STRATEGIES.md,
     * "Stalls"). */
    cfg->local_gap = on ? cfg->step / 2 : 0;
    cfg->at_tol = on ? RFS_Q16_FRAC(3, 100) : 0;
    cfg->local_refute = on; /* no parking at a swept estimate (docs/STRATEGIES.md, "Stalls") */
    /* 1 m^2 at the 0.25 m lattice, no room for a step; larger sealed components can hold
     * the source (docs/STRATEGIES.md, "Stalls"). */
    cfg->reach_min = on ? 16u : 0u;
    /* floor_gap stays off: 3 dB shortens the real floors' tails but loses weak nodes,
     * whose true P0 sits at the floor (docs/STRATEGIES.md, "Stalls"). */
}

const char *rfs_seek_strategy_name(rfs_seek_strategy_t st)
{
    return (uint32_t)st < (uint32_t)RFS_SEEK_STRATEGY_COUNT ? k_strategies[st].name : "?";
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
        if (same_str(name, k_strategies[i].name)) {
            *st = (rfs_seek_strategy_t)i;
            return true;
        }
    }
    return false;
}

const char *rfs_seek_kind_name(rfs_seek_kind_t k)
{
    static const char *const names[] = { "none", "initial", "greedy", "epsilon", "probe",
                                          "gradient", "run", "tumble" };
    return (uint32_t)k < sizeof names / sizeof names[0] ? names[k] : "none";
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
        cfg->tumble_worse > RFS_Q16_ONE || cfg->recheck_dist < 0 || cfg->settle_dist < 0 ||
        cfg->settle_orbit < 0 || cfg->settle_end < 0 || cfg->refute_r < 0 ||
        cfg->src_spacing < 0 || cfg->local_r < 0 || cfg->leg_max < 0 ||
        cfg->floor_gap < 0 || cfg->mean_t < 0 || cfg->mean_t > RFS_Q16_INT(64) ||
        cfg->local_gap < 0 || cfg->at_tol < 0) {
        return -1;
    }
    if (model.ops == 0 || model.ops->fit == 0 || model.ops->predict == 0 ||
        model.ops->reset == 0 || target == 0 || target->nsources == 0 ||
        target->nsources > RFS_SEEK_MAX_SOURCES) {
        return -1;
    }
    uint32_t lbytes = rfs_reach_bytes(map);
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
    if (!rfs_seek_src_init(s, mem) ||
        rfs_store_init(&s->store, &cfg->store, mem->samples, mem->pending, mem->pending_cap) != 0 ||
        rfs_plan_init(&s->plan, map, mem->plan_work, mem->plan_work_bytes, mem->plan_queue,
                      mem->plan_queue_cap) != 0 ||
        rfs_drive_init(&s->drive, &cfg->drive) != 0 ||
        (mem->index != 0 && mem->index->cap < cfg->store.capacity)) {
        return -1;
    }
    rfs_store_set_index(&s->store, mem->index);
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
    rfs_seek_meta_init(s);
    s->state = RFS_SEEK_WAITING;
    s->prev_status = RFS_DRIVE_IDLE;
    return 0;
}

/* silence_floor: a source heard before, silent for a window at t_us, the receiver up. */
static bool silent(const rfs_seek_t *s, int64_t t_us)
{
    return s->cfg.silence_floor != INT32_MIN && s->target == &rfs_target_rssi && s->have_meas &&
           s->have_rx && !apart(t_us, s->last_rx_us, s->cfg.rssi_timeout_us) &&
           t_us > s->last_meas_us &&
           apart(t_us, s->last_meas_us, (int64_t)s->cfg.rssi.window_us);
}

bool rfs_seek_on_pose(rfs_seek_t *s, const rfs_pose_t *pose, rfs_rng_t *rng)
{
    if (s->have_pose && pose->t_us <= s->pose.t_us) {
        (void)rfs_store_add_pose(&s->store, pose, rng); /* counts the rejection */
        return false;
    }
    (void)rfs_store_add_pose(&s->store, pose, rng);
    if (s->src != 0) {
        rfs_seek_src_on_pose(s, pose, rng);
    }
    if (silent(s, pose->t_us)) {
        rfs_store_add_value(&s->store, pose->t_us, s->cfg.silence_floor, rng);
    }
    s->pose = *pose;
    s->have_pose = true;
    rfs_seek_meta_visit(s, pose->x, pose->y);
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
    if (s->src != 0) {
        rfs_seek_src_on_rssi(s, src, t_us, dbm, rng);
    }
    return true;
}

/* A receiver report is a measurement without a value (docs/FAULTS.md, "The receiver
 * heartbeat"): it keeps the stream fresh, not the 1 s windows or the store. Ordering as
 * for measurements (rfs_rssi_push): older than the newest is rejected, equal accepted. */
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

bool rfs_seek_plan_start(const rfs_seek_t *s, rfs_q16_t *sx, rfs_q16_t *sy)
{
    rfs_pose_t est;
    if (!rfs_drive_estimate(&s->drive, &est)) {
        est = s->pose;
    }
    *sx = est.x;
    *sy = est.y;
    if (!rfs_map_point_legal(s->map, *sx, *sy)) {
        uint16_t i, j;
        if (!rfs_reach_snap(s->map, 0, *sx, *sy, &i, &j)) {
            return false;
        }
        rfs_map_lattice_point(s->map, i, j, sx, sy);
    }
    return true;
}

bool rfs_seek_plan_to(rfs_seek_t *s, rfs_q16_t gx, rfs_q16_t gy, bool tree)
{
    rfs_q16_t sx, sy;
    if (!tree && !rfs_seek_plan_start(s, &sx, &sy)) {
        return false;
    }
    /* Plan straight into the drive's own path: a 532-byte rfs_path_t on the stack would
     * overflow the microcontroller's 2.5 KB stack during a decision. */
    if (s->plan_ready && s->plan.tree_more) {
        return false; /* the decision is made again when the tree has grown */
    }
    tree = tree || s->plan_ready; /* plan_budget: the decision's tree serves */
    if (tree ? !rfs_plan_tree_path(&s->plan, gx, gy, &s->drive.path)
             : !rfs_plan_path(&s->plan, sx, sy, gx, gy, &s->drive.path)) {
        return false;
    }
    s->decision.path_len = s->drive.path.length;
    return true;
}

bool rfs_seek_go_to(rfs_seek_t *s, rfs_q16_t gx, rfs_q16_t gy, int64_t now_us)
{
    if (!rfs_seek_plan_to(s, gx, gy, false)) {
        return false;
    }
    rfs_drive_set_path(&s->drive, &s->drive.path, now_us);
    return true;
}

static void stop_wheels(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    rfs_drive_stop(&s->drive, now_us);
    out->left_mm_s = 0;
    out->right_mm_s = 0;
}

/* at_tol: a goal driven with the tighter tolerance that stalls (blocked) within the
 * drive's own goal_tol of its end counts as reached: under 20 cm pose noise the filtered
 * pose cannot settle within 3 cm (docs/STRATEGIES.md, "Stalls"). Other statuses, and
 * every goal at the drive's own tolerance, pass unchanged. */
static rfs_drive_status_t goal_end(const rfs_seek_t *s, rfs_drive_status_t st)
{
    const rfs_path_t *p = &s->drive.path;
    rfs_pose_t est;
    if (st != RFS_DRIVE_BLOCKED || s->drive.cfg.goal_tol >= s->cfg.drive.goal_tol ||
        p->n == 0u || !rfs_drive_estimate(&s->drive, &est)) {
        return st;
    }
    return rfs_q16_dist(est.x, est.y, p->x[p->n - 1u], p->y[p->n - 1u]) <= s->cfg.drive.goal_tol
               ? RFS_DRIVE_REACHED
               : st;
}

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
    rfs_q16_t mean, pred;
    const bool have_mean = rfs_seek_src_mean(s, now_us, &mean);
    if (!s->model.ops->predict(s->model.self, s->pose.x, s->pose.y, &pred)) {
        return false;
    }
    if (have_mean) {
        return rfs_seek_recheck_miss(&s->cfg, &s->miss_ms, rfs_q16_abs(rfs_q16_sub(mean, pred)));
    }
    /* recheck_silent: silence says the signal is below the floor, not how far below. */
    if (!s->cfg.recheck_silent || !silent(s, now_us)) {
        return false;
    }
    rfs_q16_t above = rfs_q16_sub(pred, s->cfg.silence_floor);
    return rfs_seek_recheck_miss(&s->cfg, &s->miss_ms, above > 0 ? above : 0);
}

/* plan_budget: begin the search tree of the next decision where it will be made, to be
 * grown while the leg is driven (drive_on, hold_still): the leg's end, or on a leg
 * checked every recheck_dist (a greedy or sampled leg with recheck_dist) the next check
 * point, recheck_dist further along the path from the robot, where a failed check
 * decides anew (drive_on begins it again after each check that passes). Scaling: as
 * rfs_seek_meta.c's greedy_along_path, offsets (< 2^32, Q16) times a length (< 2^16 m)
 * in int64. */
static void begin_next_tree(rfs_seek_t *s)
{
    const rfs_path_t *p = &s->drive.path;
    if (s->cfg.plan_budget == 0u || p->n == 0u) {
        return;
    }
    rfs_q16_t x = p->x[p->n - 1u], y = p->y[p->n - 1u];
    if (s->cfg.recheck_dist > 0 &&
        (s->decision.kind == RFS_SEEK_GREEDY || s->decision.sampled)) {
        int64_t left = s->cfg.recheck_dist;
        rfs_q16_t px = s->pose.x, py = s->pose.y;
        for (uint16_t k = s->drive.next; k < p->n; ++k) {
            const int64_t len = rfs_q16_dist(px, py, p->x[k], p->y[k]);
            if (len >= left && len > 0) {
                x = rfs_sat32(px + rfs_sdiv64_round(((int64_t)p->x[k] - px) * left, len));
                y = rfs_sat32(py + rfs_sdiv64_round(((int64_t)p->y[k] - py) * left, len));
                break;
            }
            left -= len;
            px = p->x[k];
            py = p->y[k];
        }
    }
    /* A short leg (a line search's few centimetres) ends within half a step of the tree
     * the robot decided on: that tree, further grown, serves the next decision. */
    if (!rfs_plan_tree_move(&s->plan, x, y, s->cfg.step / 2)) {
        rfs_plan_tree_begin(&s->plan, x, y);
    }
}

/* Count the decision, report it, and start driving (or flag that there is no goal). */
static void end_decision(rfs_seek_t *s, bool ok, int64_t now_us, rfs_seek_out_t *out)
{
    rfs_seek_decision_t *d = &s->decision;
    s->iteration++;
    out->decided = true;
    s->parked = false;
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
    begin_next_tree(s);
    rfs_drive_status_t st = goal_end(s, rfs_drive_update(&s->drive, &s->pose, now_us,
                                                         &out->left_mm_s, &out->right_mm_s));
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
        s->parked = d->kind == RFS_SEEK_GREEDY;
    }
}

/* plan_budget (docs/PERFORMANCE.md, "Planning in slices"): every plan of a decision
 * walks one search tree from the robot, grown plan_budget points a period, never
 * searched within the decision. The tree grown on the leg from its goal serves when the
 * robot stopped there (rfs_plan_tree_move); otherwise (a leg cut short, the first
 * decision) one is begun at the robot. Start the decision's use of it; false when the
 * robot has no legal start (every plan then fails at once, as without a tree). */
static bool plan_begin(rfs_seek_t *s)
{
    rfs_q16_t sx, sy;
    if (!rfs_seek_plan_start(s, &sx, &sy)) {
        return false;
    }
    if (!rfs_plan_tree_move(&s->plan, sx, sy, s->cfg.step)) {
        rfs_plan_tree_begin(&s->plan, sx, sy);
    }
    return true;
}

/* plan_budget: the decision is not made in this period; the wheels stay stopped. */
static void plan_wait(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    s->plan_wait = s->plan_wait < UINT16_MAX ? (uint16_t)(s->plan_wait + 1u) : UINT16_MAX;
    s->state = RFS_SEEK_LEARNING;
    stop_wheels(s, now_us, out);
}

/* Finish the decision after a (possibly sliced) fit: the initial move (Algorithm 1's
 * first line), then the strategy's choice. With plan_budget a period either chooses or
 * grows the tree, not both at full cost: `whole_fit` (this period relearnt in one go)
 * leaves the choice to the next period; when a plan asked for a point the tree had not
 * closed yet (plan.tree_more), the choice is dropped, the tree grows by one slice, and
 * the choice is made again in the next period, the wheels stopped meanwhile: the
 * bounded wait of a leg cut short (docs/PERFORMANCE.md, "Planning in slices"). */
static void finish_decision(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out,
                            bool whole_fit)
{
    rfs_seek_decision_t *d = &s->decision;
    const bool replan = s->replan; /* the choice clears it */
    bool ok = false;
    if (s->cfg.plan_budget != 0u) {
        if (!s->planning) {
            s->planning = true;
            s->plan_wait = 0;
            s->plan_ready = plan_begin(s);
        }
        if (whole_fit && s->plan_ready) {
            plan_wait(s, now_us, out);
            return;
        }
        (void)rfs_plan_tree_grow(&s->plan, 0u); /* seeded, marked sliced */
        s->plan.tree_more = false;
        d->line_search = false; /* flags a dropped choice may have set */
        d->sampled = false;
        d->near = false;
        d->pinned = false;
        d->hedged = false;
    }
    if (!rfs_seek_ops(s)->learns) {
        ok = rfs_seek_ops(s)->choose(s, false, rng, now_us);
    } else if (d->iteration == 0u) {
        d->kind = RFS_SEEK_INITIAL;
        ok = rfs_seek_meta_initial(s, rng, now_us);
    } else {
        /* decide() asked the same model at this pose unless it relearnt (predict is pure). */
        rfs_q16_t v;
        bool model_ok = d->model_valid;
        if (d->relearned) {
            model_ok = s->model.ops->predict(s->model.self, s->pose.x, s->pose.y, &v);
        }
        ok = rfs_seek_ops(s)->choose(s, model_ok, rng, now_us);
    }
    if (s->planning && s->plan_ready && s->plan.tree_more) {
        s->replan = replan;
        (void)rfs_plan_tree_grow(&s->plan, s->cfg.plan_budget);
        plan_wait(s, now_us, out);
        return;
    }
    s->planning = false;
    s->plan_ready = false;
    d->plan_wait = s->plan_wait;
    end_decision(s, ok, now_us, out);
}

/* One slice of learning (all of it when fit_budget is 0). false while the fit needs more
 * periods: the wheels stay stopped meanwhile. The query point is where the decision began,
 * not the latest pose: a pose that moves by its noise between slices would restart a local
 * fit (ridge) every period, and a fit longer than two periods would never end. */
static bool fit_slice(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
    if (!s->fit_ended) { /* else it ended between periods (rfs_seek_background) */
        rfs_model_fit_in_t fin;
        rfs_seek_fit_input(s, s->fit_qx, s->fit_qy, &fin);
        if (s->model.ops->fit(s->model.self, &fin, s->cfg.fit_budget, rng) == RFS_FIT_MORE) {
            s->state = RFS_SEEK_LEARNING;
            stop_wheels(s, now_us, out);
            return false;
        }
    }
    s->fitting = false;
    s->fit_ended = false;
    return true;
}

/* Start an iteration: the relearn check, then (after learning) the step choice. */
static void decide(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
    const rfs_seek_strategy_ops_t *ops = rfs_seek_ops(s);
    rfs_seek_decision_t *d = &s->decision;
    memset(d, 0, sizeof *d);
    d->iteration = s->iteration;
    d->t_us = now_us;
    d->prev = s->prev_status;
    d->x = s->pose.x;
    d->y = s->pose.y;
    d->samples = s->store.count;
    count_travel(s);
    d->mean_valid = rfs_seek_src_mean(s, now_us, &d->mean);
    if (!ops->learns) {
        finish_decision(s, now_us, rng, out, false);
        return;
    }
    /* "if |mean RSSI over last second - model prediction| > threshold: discard current
     * model; learn new model on all available data" (Algorithm 1). */
    d->model_valid = s->model.ops->predict(s->model.self, s->pose.x, s->pose.y, &d->prediction);
    bool relearn = !d->model_valid;
    if (d->model_valid && d->mean_valid) {
        relearn = rfs_q16_abs(rfs_q16_sub(d->mean, d->prediction)) > s->cfg.error_threshold;
    }
    /* A leg abandoned by a failed recheck relearns (the check failed on this model), even
     * when the mean has moved back within the threshold while the base braked. */
    if (s->early) {
        d->refuted = s->early_refuted; /* made as the early relearn began */
        relearn = relearn || s->early_refuted;
    } else {
        relearn = rfs_seek_meta_refute(s, now_us) || relearn;
    }
    relearn = relearn || ops->refit || s->replan;
    /* settle_orbit: every decision ranks the candidates with the samples of the last
     * orbit, and sees the tour end (docs/STRATEGIES.md, "Bridging"). */
    relearn = relearn || (s->cfg.settle_orbit > 0 && rfs_seek_src_settled(s));

    if (s->early && !rfs_seek_fit_early_holds(s)) {
        s->early = false; /* a place ruled out or a phase changed since: begin again */
        s->fitting = false;
        s->fit_ended = false;
        relearn = true;
    }
    if ((relearn && s->store.count > 0u) || s->early) {
        d->relearned = true;
        if (!s->early) {
            s->model.ops->reset(s->model.self);
            s->fitting = true;
            s->fit_qx = d->x;
            s->fit_qy = d->y;
        }
        s->early = false;
    }
    const bool whole_fit = s->fitting && s->cfg.fit_budget == 0u;
    if (s->fitting && !fit_slice(s, now_us, rng, out)) {
        return;
    }
    finish_decision(s, now_us, rng, out, whole_fit);
}

/* b - a > limit: stamp b further ahead of now a than limit (a clock jump, docs/FAULTS.md). */
static bool ahead(int64_t a, int64_t b, int64_t limit)
{
    return b > a && apart(a, b, limit);
}

/* The measurement stream is stale when neither a measurement nor a receiver report lies
 * within rssi_timeout_us of now, or either newest stamp lies further ahead than that (the
 * feed's clock jumped: while it is the newest every real input is rejected as out of
 * order). Without reports this is the measurement-only rule. */
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

/* The wheels stop this period: a goal being driven is kept, to be resumed when they may
 * turn again (its legs driven so far and its driving time kept). */
static void hold(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    if (s->state == RFS_SEEK_DRIVING && s->drive.status == RFS_DRIVE_RUNNING) {
        s->resume = true;
        s->resume_path = s->drive.path;
        s->resume_next = s->drive.next; /* the legs already driven are not driven again */
        s->resume_start_us = elapsed(now_us, s->drive.start_us); /* driven so far */
    }
    if (s->state != RFS_SEEK_WAITING) {
        s->state = RFS_SEEK_STALE;
    }
    stop_wheels(s, now_us, out);
}

void rfs_seek_hold(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    hold(s, now_us, out);
    out->state = s->state;
}

/* This period's fault flags. true when an input is stale: the wheels are stopped and a
 * goal being driven is kept, to be resumed when the inputs return. */
static bool inputs_stale(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    /* A newest stamp further ahead of now than the timeout is stale too (a clock jump,
     * docs/FAULTS.md): while it is the newest, every real input is rejected as out of
     * order and the pose would freeze with the wheels still driving. */
    bool pose_stale = !s->have_pose || apart(now_us, s->pose.t_us, s->cfg.pose_timeout_us);
    bool rssi_stale = meas_stale(s, now_us);
    out->faults |= pose_stale ? RFS_SEEK_FAULT_POSE_STALE : 0u;
    out->faults |= rssi_stale ? RFS_SEEK_FAULT_RSSI_STALE : 0u;
    uint16_t ci, cj;
    if (s->have_pose && !rfs_map_cell(s->map, s->pose.x, s->pose.y, &ci, &cj)) {
        out->faults |= RFS_SEEK_FAULT_OFF_MAP;
    }
    if (!pose_stale && !rssi_stale) {
        return false;
    }
    hold(s, now_us, out);
    return true;
}

/* reach_min, at the end of a flood: a component of fewer than reach_min points is a pocket
 * (a clutter pocket the snap joined at a tie: the robot would be sealed in it). Flood once
 * from the nearest legal lattice point outside it; keep that component when larger, else
 * flood the pocket again. true when a flood began. */
static bool flood_pocket(rfs_seek_t *s)
{
    uint16_t i, j;
    rfs_q16_t x = s->pose.x, y = s->pose.y;
    if (s->cfg.reach_min == 0u || s->reach_pocket == RFS_SEEK_POCKET_AGAIN ||
        (s->reach_pocket == RFS_SEEK_POCKET_OWN && s->flood.marked >= s->cfg.reach_min) ||
        (s->reach_pocket == RFS_SEEK_POCKET_BESIDE && s->flood.marked > s->reach_own)) {
        return false;
    }
    if (s->reach_pocket == RFS_SEEK_POCKET_OWN) {
        if (!rfs_reach_snap_outside(s->map, s->reach, x, y, &i, &j)) {
            return false;
        }
        s->reach_own = s->flood.marked;
        rfs_map_lattice_point(s->map, i, j, &x, &y);
    }
    s->reach_pocket = s->reach_pocket == RFS_SEEK_POCKET_OWN ? RFS_SEEK_POCKET_BESIDE
                                                             : RFS_SEEK_POCKET_AGAIN;
    s->reach_valid = false;
    return rfs_reach_flood_begin(&s->flood, s->map, x, y, s->reach, s->queue);
}

/* Keep the reach bits the robot's component: computed at the first fresh period, and
 * again when the robot is somewhere the flood fill did not reach (pushed, relocalised);
 * with reach_budget in slices. true while a sliced flood goes on: the period ends with
 * the wheels stopped. */
static bool keep_reach(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    uint16_t si, sj;
    bool filled = false;
    if (!s->flooding &&
        (!s->reach_valid || !rfs_reach_snap(s->map, s->reach, s->pose.x, s->pose.y, &si, &sj))) {
        s->reach_valid = false;
        s->reach_pocket = RFS_SEEK_POCKET_OWN;
        s->flooding = rfs_reach_flood_begin(&s->flood, s->map, s->pose.x, s->pose.y, s->reach,
                                            s->queue);
        filled = !s->flooding; /* no legal point near: no flood */
    }
    while (s->flooding) {
        if (!rfs_reach_flood_run(&s->flood, s->map, s->reach, s->queue, s->queue_cap,
                                 s->cfg.reach_budget)) {
            stop_wheels(s, now_us, out);
            return true;
        }
        s->flooding = false;
        s->reach_valid = true;
        filled = true;
        s->flooding = flood_pocket(s);
        if (s->flooding && s->cfg.reach_budget != 0u) {
            stop_wheels(s, now_us, out); /* sliced: the next flood from the next period */
            return true;
        }
    }
    if (filled && s->plan.tree != 0u) {
        /* The fill used the planner's queue: a tree being grown starts again. */
        rfs_plan_tree_begin(&s->plan, s->plan.tree_x, s->plan.tree_y);
    }
    if (filled && s->cfg.reach_budget != 0u) {
        stop_wheels(s, now_us, out); /* sliced: the flood's last slice ends its period */
        return true;
    }
    return false;
}

/* Drive on the goal that stale inputs interrupted. Its timeout counts driving time only:
 * before the interruption (a goal interrupted again and again must still end), not the
 * stale time (after a 30 s silence it would time out as it resumes, docs/FAULTS.md). */
static void resume_goal(rfs_seek_t *s, int64_t now_us)
{
    s->resume = false;
    rfs_drive_set_path(&s->drive, &s->resume_path, now_us);
    s->drive.next = s->resume_next < s->drive.path.n ? s->resume_next : 0;
    s->drive.start_us = now_us >= INT64_MIN + s->resume_start_us ? now_us - s->resume_start_us
                                                                 : INT64_MIN;
    s->state = RFS_SEEK_DRIVING;
}

/* The model warms between fits (rfs_model_ops_t.warm): it has the operation and its fits
 * are sliced (a whole fit does the work in one period anyway). */
static bool warms(const rfs_seek_t *s)
{
    return s->cfg.fit_budget != 0u && s->model.ops != 0 && s->model.ops->warm != 0 &&
           rfs_seek_ops(s)->learns;
}

/* plan_budget: one slice of the next decision's search tree (begun by end_decision). A
 * period that drives or stands without choosing has the room of the choice: its slice
 * is 5/4 plan_budget (docs/PERFORMANCE.md, "Planning in slices"). true when the tree had
 * no work left for it (none is grown, or it is done: asked only of a model that warms). */
static bool grow_next(rfs_seek_t *s)
{
    if (s->cfg.plan_budget == 0u) {
        return true;
    }
    const bool grown = warms(s) && rfs_plan_tree_grown(&s->plan);
    (void)rfs_plan_tree_grow(&s->plan, RFS_SEEK_DRIVE_SLICE(s->cfg.plan_budget));
    return grown;
}

/* A driving period the tree left free: the model warms for the next relearn, at most
 * RFS_SEEK_WARM_SLICE of its fit budget beside the drive's work (docs/PERFORMANCE.md,
 * "Decision latency"). The model and its next fit's results are unchanged. */
static void warm_next(rfs_seek_t *s)
{
    if (!warms(s)) {
        return;
    }
    rfs_model_fit_in_t fin;
    rfs_seek_fit_input(s, s->pose.x, s->pose.y, &fin);
    (void)s->model.ops->warm(s->model.self, &fin, RFS_SEEK_WARM_SLICE(s->cfg.fit_budget));
}

/* Drive the current goal. true while it is still being driven; when it ends (reached,
 * timed out, blocked, or abandoned by a failed recheck) the period goes on to decide. */
static bool drive_on(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    const rfs_q16_t chk_x = s->chk_x, chk_y = s->chk_y;
    if (s->drive.status == RFS_DRIVE_RUNNING && recheck_fails(s, now_us)) {
        rfs_drive_stop(&s->drive, now_us);
        s->prev_status = RFS_DRIVE_RUNNING; /* abandoned while running: the model failed */
        s->replan = true;
        rfs_seek_fit_early_begin(s, now_us);
    }
    if (s->drive.status != RFS_DRIVE_RUNNING) {
        return false;
    }
    rfs_drive_status_t st = goal_end(s, rfs_drive_update(&s->drive, &s->pose, now_us,
                                                         &out->left_mm_s, &out->right_mm_s));
    if (st == RFS_DRIVE_RUNNING) {
        s->state = RFS_SEEK_DRIVING;
        if (s->chk_x != chk_x || s->chk_y != chk_y) {
            begin_next_tree(s); /* a check passed: the next one is further on */
        }
        if (s->cfg.fit_early && !s->fitting &&
            rfs_q16_dist(s->pose.x, s->pose.y, s->decision.goal_x, s->decision.goal_y) <=
                RFS_SEEK_EARLY_GOAL &&
            rfs_seek_fit_early_asks(s, now_us)) {
            rfs_seek_fit_early_begin(s, now_us); /* the decision at the goal will relearn */
        }
        if (grow_next(s)) { /* the next decision's search tree */
            warm_next(s);
        }
        return true;
    }
    s->prev_status = st;
    return false;
}

/* true while the robot stands before deciding: until the base has stopped (a goal ended
 * while moving: the next path is planned from where the robot stands, not from a point
 * it brakes past; docs/MAPS.md, "Drive control"), after no goal or a null move
 * (end_decision), and for a dwelling strategy one averaging window at each point. */
static bool hold_still(rfs_seek_t *s, int64_t now_us, rfs_seek_out_t *out)
{
    if (!rfs_drive_at_rest(&s->drive)) {
        stop_wheels(s, now_us, out);
        s->state = RFS_SEEK_DRIVING;
        if (grow_next(s)) {
            warm_next(s);
        }
        return true;
    }
    if (now_us < s->retry_after_us) {
        out->faults |= s->retry_no_goal ? RFS_SEEK_FAULT_NO_GOAL : 0u;
        stop_wheels(s, now_us, out);
        if (grow_next(s)) {
            warm_next(s);
        }
        return true;
    }
    if (!rfs_seek_ops(s)->dwell) {
        return false;
    }
    if (!s->dwell_done) {
        s->dwell_done = true;
        s->dwell_until_us = now_us + (int64_t)s->cfg.rssi.window_us;
    }
    if (now_us < s->dwell_until_us) {
        stop_wheels(s, now_us, out);
        s->state = RFS_SEEK_DRIVING;
        return true;
    }
    return false;
}

/* One period: stop on stale inputs, go on learning or driving, else decide. */
static void control(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
    if (inputs_stale(s, now_us, out)) {
        return;
    }
    if (keep_reach(s, now_us, out)) {
        return;
    }
    if (s->resume) {
        resume_goal(s, now_us);
    }
    if (s->fitting && !s->early) {
        /* A sliced fit continues (or ended between periods); the decision finishes when it
         * is done. */
        if (fit_slice(s, now_us, rng, out)) {
            finish_decision(s, now_us, rng, out, false);
        }
        return;
    }
    if (s->planning) {
        /* The decision waits for its search tree: the choice is made again. */
        finish_decision(s, now_us, rng, out, false);
        return;
    }
    if (drive_on(s, now_us, out) || hold_still(s, now_us, out)) {
        return;
    }
    decide(s, now_us, rng, out);
}

void rfs_seek_step(rfs_seek_t *s, int64_t now_us, rfs_rng_t *rng, rfs_seek_out_t *out)
{
    out->left_mm_s = 0;
    out->right_mm_s = 0;
    out->faults = 0;
    out->decided = false;
    if (s->have_pose) {
        /* The drive's pose filter runs every period, driving or not: plans start from
         * its estimate (rfs_seek_plan_start). */
        rfs_drive_observe(&s->drive, &s->pose, now_us);
    }
    control(s, now_us, rng, out);
    out->state = s->state;
    out->decision = s->decision;
}
