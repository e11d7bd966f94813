/* rfs_app.c - the application loop shared by every port (see rfs_app.h). */
#include "rfs_app.h"

#include <stddef.h>
#include <string.h>

#include "rfs_target.h"

rfs_app_cfg_t rfs_app_cfg_default(void)
{
    rfs_app_cfg_t c;
    memset(&c, 0, sizeof c);
    c.seek = rfs_seek_cfg_default();
    c.ridge = rfs_ridge_cfg_default();
    c.pathloss = rfs_pathloss_cfg_default();
    c.map = rfs_map_cfg_default();
    c.target = RFS_APP_TARGET_RSSI;
    c.seed = 1u;
    c.input_timeout_us = 150000;
    c.node_id = 1u;
    return c;
}

rfs_app_cfg_t rfs_app_cfg_mcu(void)
{
    rfs_app_cfg_t c = rfs_app_cfg_default();
    c.seek.fit_budget = RFS_APP_MCU_FIT_BUDGET;
    c.seek.reach_budget = RFS_SEEK_REACH_BUDGET; /* the boot's flood fill in slices */
    c.seek.fit_early = true; /* docs/FIRMWARE.md, "Learning between periods" */
    c.fit_budget_by_model = true;
    c.follow_epoch = true; /* its clock counts from boot: docs/CAN.md, "Time on the bus" */
    return c;
}

uint32_t rfs_app_fit_budget(const rfs_app_cfg_t *cfg)
{
    if (!cfg->fit_budget_by_model) {
        return cfg->seek.fit_budget;
    }
    /* A work unit is each model's own (a sample, a sample-update, a path-loss work unit), so the
     * slice that keeps the deadline is measured per model (docs/PERFORMANCE.md, "Models
     * on the Cortex-M4"). Only the entry's field is read: no registry code is linked. */
    return cfg->model != NULL ? cfg->model->mcu_fit_budget : RFS_APP_MCU_FIT_BUDGET;
}

uint32_t rfs_app_model_capacity(const rfs_app_cfg_t *cfg)
{
    return cfg->model_state != NULL ? cfg->model_state_bytes : RFS_APP_MODEL_BYTES;
}

bool rfs_app_model_fits(const rfs_app_cfg_t *cfg)
{
    return cfg->model == NULL || cfg->model->state_bytes <= rfs_app_model_capacity(cfg);
}

/* The configured model on its state: the ridge with cfg->ridge (the paper's numbers by
 * default, so a NULL model and the "ridge" entry decide alike), the path-loss model with
 * cfg->pathloss (its registry defaults but for a CONFIG's p0_min), any other with its
 * registry defaults. */
static int app_model_init(rfs_app_t *a, const rfs_app_cfg_t *cfg, rfs_model_t *model)
{
    void *state = cfg->model_state != NULL ? cfg->model_state : (void *)&a->ridge;
    if (!rfs_app_model_fits(cfg) ||
        (cfg->model_state != NULL &&
         ((uintptr_t)cfg->model_state & (uintptr_t)(RFS_MODELS_STATE_ALIGN - 1u)) != 0u)) {
        return -1;
    }
    if (cfg->model == NULL || cfg->model->ops == &rfs_ridge_ops) {
        *model = rfs_ridge_model((rfs_ridge_t *)state);
        return rfs_ridge_init((rfs_ridge_t *)state, &cfg->ridge);
    }
    if (cfg->model->ops == &rfs_pathloss_ops) {
        *model = rfs_pathloss_model((rfs_pathloss_t *)state);
        return rfs_pathloss_init((rfs_pathloss_t *)state, &cfg->pathloss);
    }
    model->ops = cfg->model->ops;
    model->self = state;
    return cfg->model->init_default(state);
}

_Static_assert(RFS_TARGET_MAX_SOURCES == 2u, "the seeker memory lists two sources' stores");

static const rfs_target_ops_t *app_target(rfs_app_target_t t)
{
    return t == RFS_APP_TARGET_BRIDGE ? &rfs_target_bridge : &rfs_target_rssi;
}

int rfs_app_cfg_choose(rfs_app_cfg_t *cfg, rfs_app_target_t target, rfs_seek_strategy_t strategy,
                       const rfs_models_entry_t *model, rfs_q16_t p0_min)
{
    /* meta-global needs a map-wide model radius; the baselines' decision kinds (probe,
     * gradient, run, tumble) do not fit the replay's DECISION kind (none .. epsilon). */
    if ((uint32_t)target > (uint32_t)RFS_APP_TARGET_BRIDGE ||
        (strategy != RFS_SEEK_META && strategy != RFS_SEEK_META_PATH) || cfg->built.ops != NULL) {
        return -1;
    }
    /* One fit per source needs a state and a store per source (rfs_fields.h): only a port
     * with the memory builds it (docs/FIRMWARE.md, "What the STM32 image holds"). */
    if (model != NULL && model->per_source && app_target(target)->nsources > 1u) {
        return -1;
    }
    /* Checked before cfg changes, without a copy of it (its 480 bytes are on the stack
     * of a CONFIG frame's deepest path, docs/FIRMWARE.md "Build"). */
    if (model != NULL && model->state_bytes > rfs_app_model_capacity(cfg)) {
        return -1;
    }
    cfg->model = model;
    cfg->target = target;
    rfs_seek_cfg_use_strategy(&cfg->seek, strategy);
    cfg->pathloss.p0_min = p0_min;
    return 0;
}

int rfs_app_init(rfs_app_t *a, const rfs_app_cfg_t *cfg, const rfs_app_map_t *map)
{
    if (a == NULL || cfg == NULL || map == NULL || map->free == NULL || cfg->samples == NULL) {
        return -1;
    }
    if (cfg->target > RFS_APP_TARGET_BRIDGE || cfg->input_timeout_us <= 0) {
        return -1;
    }
    if (rfs_map_bytes(map->w, map->h) > RFS_APP_MAX_MAP_BYTES) {
        return -1;
    }
    /* Only the state before the large arrays is cleared: each module initialises what it
     * reads of its array (the store counts what it holds, rfs_map_init derives the legal
     * grid, the seeker clears its bit arrays), and 60 KB of memset would be 15,000
     * stores at every boot. */
    memset(a, 0, offsetof(rfs_app_t, pending));
    a->cfg = *cfg;
    a->map_in = *map;
    a->cfg.seek.fit_budget = rfs_app_fit_budget(cfg);
    if (rfs_map_init(&a->map, &cfg->map, map->w, map->h, map->res, map->origin_x,
                     map->origin_y, map->free, map->wall, a->legal) != 0) {
        return -1;
    }
    const uint32_t lattice = (uint32_t)a->map.lw * a->map.lh;
    if (lattice > RFS_APP_MAX_LATTICE || cfg->seek.store.capacity > RFS_APP_MAX_SAMPLES) {
        return -1;
    }
    rfs_model_t model = cfg->built;
    if (model.ops == NULL && app_model_init(a, cfg, &model) != 0) {
        return -1;
    }
    rfs_rng_seed(&a->rng, cfg->seed);
    const rfs_seek_mem_t mem = {
        .samples = cfg->samples,
        .pending = a->pending,
        .pending_cap = RFS_APP_PENDING,
        .plan_work = a->plan_work,
        .plan_work_bytes = RFS_APP_MAX_LATTICE,
        .plan_queue = a->plan_queue,
        .plan_queue_cap = RFS_APP_PLAN_QUEUE,
        .visited = a->visited,
        .visited_bytes = (uint32_t)sizeof a->visited,
        .reach = a->reach,
        .reach_bytes = (uint32_t)sizeof a->reach,
        .src = cfg->src,
        .src_samples = {cfg->src_samples[0], cfg->src_samples[1]},
        .src_pending = {cfg->src_pending[0], cfg->src_pending[1]},
    };
    if (rfs_seek_init(&a->seek, &a->cfg.seek, &a->map, model, app_target(cfg->target), &mem) != 0) {
        return -1;
    }
    rfs_can_rx_cfg_t rx_cfg = rfs_can_rx_cfg_default();
    rx_cfg.follow_epoch = cfg->follow_epoch;
    if (rfs_can_rx_init(&a->can_rx, &rx_cfg) != 0) {
        return -1;
    }
    rfs_can_tx_init(&a->can_tx);
    a->after_reset = true;
    return 0;
}

bool rfs_app_on_pose(rfs_app_t *a, const rfs_pose_t *pose, int64_t rx_us)
{
    a->pose_rx_us = rx_us;
    a->have_pose_rx = true;
    const bool ok = rfs_seek_on_pose(&a->seek, pose, &a->rng);
    if (ok) {
        a->stats.poses++;
    } else {
        a->stats.rejected++;
    }
    return ok;
}

bool rfs_app_on_rssi(rfs_app_t *a, uint8_t src, int64_t t_us, int8_t dbm, int64_t rx_us)
{
    a->rssi_rx_us = rx_us;
    a->have_rssi_rx = true;
    const bool ok = rfs_seek_on_rssi(&a->seek, src, t_us, dbm, &a->rng);
    if (ok) {
        a->stats.rssi++;
    } else {
        a->stats.rejected++;
    }
    return ok;
}

bool rfs_app_on_receiver(rfs_app_t *a, int64_t t_us, int64_t rx_us)
{
    /* The heartbeat comes from the radio module like its packets: in a dead zone it is
     * the only proof that module is alive, so it feeds the same receive-time watchdog. */
    a->rssi_rx_us = rx_us;
    a->have_rssi_rx = true;
    const bool ok = rfs_seek_on_receiver(&a->seek, t_us);
    if (ok) {
        a->stats.receiver++;
    } else {
        a->stats.rejected++;
    }
    return ok;
}

/* What a CONFIG's re-initialisation keeps: the counters, the CAN receiver and sender
 * (rolling counters run on) and the input and transport state the safety rules read. */
typedef struct app_kept {
    rfs_app_stats_t stats;
    rfs_can_rx_t can_rx;
    rfs_can_tx_t can_tx;
    int64_t pose_rx_us, rssi_rx_us;
    bool have_pose_rx, have_rssi_rx, bus_off, after_reset, bad_frame;
} app_kept_t;

static void app_keep(const rfs_app_t *a, app_kept_t *k)
{
    k->stats = a->stats;
    k->can_rx = a->can_rx;
    k->can_tx = a->can_tx;
    k->pose_rx_us = a->pose_rx_us;
    k->rssi_rx_us = a->rssi_rx_us;
    k->have_pose_rx = a->have_pose_rx;
    k->have_rssi_rx = a->have_rssi_rx;
    k->bus_off = a->bus_off;
    k->after_reset = a->after_reset;
    k->bad_frame = a->bad_frame;
}

static void app_restore(rfs_app_t *a, const app_kept_t *k)
{
    a->stats = k->stats;
    a->can_rx = k->can_rx;
    a->can_tx = k->can_tx;
    a->pose_rx_us = k->pose_rx_us;
    a->rssi_rx_us = k->rssi_rx_us;
    a->have_pose_rx = k->have_pose_rx;
    a->have_rssi_rx = k->have_rssi_rx;
    a->bus_off = k->bus_off;
    a->after_reset = k->after_reset;
    a->bad_frame = k->bad_frame;
}

bool rfs_app_on_config(rfs_app_t *a, const rfs_can_config_t *c)
{
    /* Idle: before the mission's first decision (the initial move), so a mission never
     * changes its rule or model half-way. */
    rfs_app_cfg_t n = a->cfg;
    const rfs_models_entry_t *model = c->model < (uint8_t)RFS_CAN_NMODELS ? n.models[c->model] : NULL;
    const bool offered = c->model == (uint8_t)RFS_CAN_MODEL_RIDGE || model != NULL;
    n.seed = c->seed;
    if (a->seek.iteration != 0u || !offered ||
        rfs_app_cfg_choose(&n, (rfs_app_target_t)c->target, (rfs_seek_strategy_t)c->strategy, model,
                           rfs_can_p0_to_q16(c->p0_min)) != 0) {
        a->stats.configs_rejected++;
        return false;
    }
    if (c->fit_early != (uint8_t)RFS_CAN_FIT_EARLY_KEEP) {
        n.seek.fit_early = c->fit_early == (uint8_t)RFS_CAN_FIT_EARLY_ON;
    }
    app_kept_t k;
    app_keep(a, &k);
    const rfs_app_cfg_t old = a->cfg;
    const rfs_app_map_t map = a->map_in;
    const bool ok = rfs_app_init(a, &n, &map) == 0;
    if (!ok) {
        (void)rfs_app_init(a, &old, &map); /* it ran with these before */
    }
    app_restore(a, &k);
    if (ok) {
        a->stats.configs++;
    } else {
        a->stats.configs_rejected++;
    }
    return ok;
}

void rfs_app_set_bus_off(rfs_app_t *a, bool off)
{
    a->bus_off = off;
}

bool rfs_app_background(rfs_app_t *a)
{
    return rfs_seek_background(&a->seek, &a->rng);
}

void rfs_app_background_all(rfs_app_t *a)
{
    (void)rfs_seek_background_n(&a->seek, &a->rng, RFS_APP_BACKGROUND_SLICES);
}

void rfs_app_step(rfs_app_t *a, int64_t now_us, rfs_app_out_t *out)
{
    rfs_seek_out_t so;
    rfs_seek_step(&a->seek, now_us, &a->rng, &so);

    uint16_t faults = so.faults;
    /* Received-time watchdogs on the inputs (docs/FIRMWARE.md, safety): independent of the sender
     * time stamps the seeker judges, so a sender whose clock runs on while its frames
     * stop arriving still stops the wheels. */
    /* Differences in uint64 only when now > rx (exact there): recorded times are outside
     * input, and now - rx overflowed int64 for extreme ones (tests/fuzz/fuzz_replay.c). */
    if (!a->have_pose_rx || (now_us > a->pose_rx_us &&
                             (uint64_t)now_us - (uint64_t)a->pose_rx_us > (uint64_t)a->cfg.input_timeout_us)) {
        faults |= RFS_APP_FAULT_POSE_LOST;
    }
    if (!a->have_rssi_rx || (now_us > a->rssi_rx_us &&
                             (uint64_t)now_us - (uint64_t)a->rssi_rx_us > (uint64_t)a->cfg.input_timeout_us)) {
        faults |= RFS_APP_FAULT_RSSI_LOST;
    }
    if (a->bus_off) {
        faults |= RFS_APP_FAULT_BUS_OFF;
    }
    if (a->after_reset) {
        faults |= RFS_APP_FAULT_RESET;
    }
    if (a->bad_frame) {
        faults |= RFS_APP_FAULT_BAD_FRAME;
    }
    const bool stop = (faults & (RFS_APP_FAULT_POSE_LOST | RFS_APP_FAULT_RSSI_LOST |
                                 RFS_APP_FAULT_BUS_OFF | RFS_APP_FAULT_RESET)) != 0u;
    if (stop) {
        /* The drive must know (else, the stop over, its speed of before is commanded at
         * once, without the acceleration ramp), and the period's output says it. */
        rfs_seek_hold(&a->seek, now_us, &so);
    }

    memset(out, 0, sizeof *out);
    out->t_us = now_us;
    out->left_mm_s = so.left_mm_s;
    out->right_mm_s = so.right_mm_s;
    out->state = so.state;
    out->faults = faults;
    out->decided = so.decided;
    out->decision = so.decision;

    a->after_reset = false;
    a->bad_frame = false;
    a->stats.steps++;
    a->last = *out;
}

rfs_can_err_t rfs_app_on_can(rfs_app_t *a, const rfs_can_frame_t *f, int64_t rx_us)
{
    rfs_can_msg_t msg;
    const rfs_can_err_t e = rfs_can_rx_frame(&a->can_rx, f, rx_us, &msg);
    if (e == RFS_CAN_E_ID) {
        a->stats.unknown_frames++;
        return e;
    }
    if (e != RFS_CAN_OK) {
        a->stats.bad_frames++;
        a->bad_frame = true;
        return e;
    }
    if (msg.kind == RFS_CAN_MSG_POSE) {
        (void)rfs_app_on_pose(a, &msg.pose, rx_us);
    } else if (msg.kind == RFS_CAN_MSG_RSSI) {
        (void)rfs_app_on_rssi(a, msg.rssi_src, msg.rssi_t_us, msg.rssi_dbm, rx_us);
    } else if (msg.kind == RFS_CAN_MSG_RECEIVER) {
        (void)rfs_app_on_receiver(a, msg.receiver_t_us, rx_us);
    } else if (msg.kind == RFS_CAN_MSG_CONFIG) {
        (void)rfs_app_on_config(a, &msg.config);
    }
    return e;
}

rfs_can_wheel_t rfs_app_wheel(const rfs_app_out_t *out)
{
    rfs_can_wheel_t wheel;
    wheel.left_mm_s = out->left_mm_s;
    wheel.right_mm_s = out->right_mm_s;
    /* STOP whenever the controller is not following a goal or a safety stop holds:
     * the motor controller may brake instead of ramping. */
    const bool moving = out->state == RFS_SEEK_DRIVING &&
                        (out->faults & 0xFF00u & ~(uint32_t)RFS_APP_FAULT_BAD_FRAME) == 0u;
    wheel.flags = moving ? 0u : RFS_CAN_WHEEL_STOP;
    return wheel;
}

uint8_t rfs_app_frames(rfs_app_t *a, const rfs_app_out_t *out, rfs_can_frame_t frames[2])
{
    const rfs_can_wheel_t wheel = rfs_app_wheel(out);

    rfs_can_status_t st;
    memset(&st, 0, sizeof st);
    st.state = (uint8_t)out->state;
    st.kind = rfs_can_status_kind(out->decision.kind);
    st.prev = (uint8_t)out->decision.prev;
    st.relearned = out->decision.relearned;
    st.line_search = out->decision.line_search;
    /* The frame carries the seeker's fault bits; lost inputs show as stale ones. */
    uint8_t faults = (uint8_t)(out->faults & 0xFFu);
    if ((out->faults & RFS_APP_FAULT_POSE_LOST) != 0u) {
        faults |= RFS_SEEK_FAULT_POSE_STALE;
    }
    if ((out->faults & RFS_APP_FAULT_RSSI_LOST) != 0u) {
        faults |= RFS_SEEK_FAULT_RSSI_STALE;
    }
    st.faults = faults;
    st.iteration = out->decision.iteration;
    /* An operator who sent a CONFIG and reads false sends it again (a reset forgets it). */
    st.configured = a->stats.configs != 0u;

    rfs_can_tx_wheel(&a->can_tx, &wheel, &frames[0]);
    rfs_can_tx_status(&a->can_tx, &st, &frames[1]);
    return 2u;
}
