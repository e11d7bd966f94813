/* hs_ctrl.c - the in-process controller: the core's rfs_seek behind hs_ctrl.h. */
#include "hs_ctrl.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <math.h>

#include "rfs_cellsum.h"
#include "rfs_knn.h"
#include "rfs_knn_index.h"
#include "rfs_models.h"
#include "rfs_pathloss.h"
#include "rfs_pdr.h"
#include "rfs_ridge.h"

/* Candidates per origin of the path-loss model's wall-count cache on the host: a run's
 * coarse, refinement and hold candidates (at most 1,024 coarse; the Intel lab's runs use
 * under 900 in all), 1 MB (docs/PATHLOSS.md, "Work, the wall-count cache and slicing"). */
#define HS_CTRL_PATHLOSS_CACHE_COLS 2048u

typedef struct inproc {
    rfs_seek_t seek;
    void *model_state; // rfs_models_max_state_bytes(), aligned to RFS_MODELS_STATE_ALIGN
    void *wall_cache;  // the path-loss model's attached wall-count cache, or NULL
    rfs_knn_index_t *knn_index; // knn and radius: the attached finer index, or NULL
    rfs_fields_t *fields; // one fit per source (rfs_models_per_source()), else NULL
    rfs_fields_mem_t fmem;
    rfs_rng_t rng;
    rfs_seek_mem_t mem;
    rfs_cellsum_t cellsum;           // the ridge's cell sums (open_cellsum), or unused
    rfs_store_index_t cellsum_index; // the store's view of them
    rfs_cellsum_cell_t *cells;
    uint16_t *cell_links;
    uint32_t fit_slices; // rfs_seek_background() calls after each period
} inproc_t;

hs_ctrl_inproc_cfg_t hs_ctrl_inproc_cfg_default(void)
{
    hs_ctrl_inproc_cfg_t c;
    c.seek = rfs_seek_cfg_default();
    c.model = "ridge";
    c.target = "rssi";
    c.seed = 1;
    c.period_us = 50000;
    c.p0_min_dbm = NAN;
    c.coarse_footprint_m = NAN;
    c.p0_max_wall_db = NAN;
    c.coarse_snap = -1;
    c.pathloss_log2 = NULL;
    c.pathloss_builtin_cache = false;
    c.fit_slices = 0u;
    return c;
}

bool hs_ctrl_model_known(const char *name)
{
    return name && rfs_models_lookup(name) != NULL;
}

static void ip_on_pose(void *self, const rfs_pose_t *pose)
{
    inproc_t *p = self;
    rfs_seek_on_pose(&p->seek, pose, &p->rng);
}

static void ip_on_rssi(void *self, uint8_t src, int64_t t_us, int8_t dbm)
{
    inproc_t *p = self;
    rfs_seek_on_rssi(&p->seek, src, t_us, dbm, &p->rng);
}

static void ip_on_receiver(void *self, int64_t t_us)
{
    inproc_t *p = self;
    rfs_seek_on_receiver(&p->seek, t_us);
}

static void ip_step(void *self, int64_t now_us, hs_ctrl_out_t *out)
{
    inproc_t *p = self;
    rfs_seek_step(&p->seek, now_us, &p->rng, out);
    (void)rfs_seek_background_n(&p->seek, &p->rng, p->fit_slices);
}

static bool ip_predict(void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *v)
{
    inproc_t *p = self;
    const rfs_model_t *m = &p->seek.model;
    return m->ops->predict(m->self, x, y, v);
}

static const rfs_pathloss_t *ip_pathloss(void *self)
{
    inproc_t *p = self;
    return p->seek.model.ops == &rfs_pathloss_ops ? (const rfs_pathloss_t *)p->seek.model.self
                                                  : NULL;
}

static const rfs_fields_t *ip_fields(void *self)
{
    inproc_t *p = self;
    return p->fields;
}

static void ip_close(void *self)
{
    inproc_t *p = self;
    if (!p) {
        return;
    }
    free(p->mem.src);
    for (unsigned k = 0; k < RFS_TARGET_MAX_SOURCES; k++) {
        free(p->mem.src_samples[k]);
        free(p->mem.src_pending[k]);
        free(p->fmem.walls[k]);
        free(p->fmem.rsum[k]);
        free(p->fmem.rcount[k]);
    }
    free(p->fmem.f);
    free(p->fields);
    free(p->mem.samples);
    free(p->mem.pending);
    free(p->mem.plan_work);
    free(p->mem.plan_queue);
    free(p->mem.visited);
    free(p->mem.reach);
    free(p->model_state);
    free(p->wall_cache);
    free(p->knn_index);
    free(p->cells);
    free(p->cell_links);
    free(p);
}

// The local ridge's cell sums over the map's box at 32 cm cells (docs/MODELS.md, "Cell
// sums"): the same fits, without visiting every sample. A map over 655 m a side, or no
// memory, runs without them.
static void open_cellsum(inproc_t *p, const rfs_map_t *map, uint16_t capacity)
{
    const int32_t x0 = (int32_t)floor(map->origin_x / 65536.0 * 100.0);
    const int32_t y0 = (int32_t)floor(map->origin_y / 65536.0 * 100.0);
    const int32_t w = (int32_t)ceil((map->origin_x + (double)map->w * map->res) / 65536.0 * 100.0) - x0;
    const int32_t h = (int32_t)ceil((map->origin_y + (double)map->h * map->res) / 65536.0 * 100.0) - y0;
    const uint8_t shift = 5;
    uint32_t n = rfs_cellsum_cells(w, h, shift);
    if (n == 0u || capacity == 0u) {
        return;
    }
    p->cells = malloc((size_t)n * sizeof *p->cells);
    p->cell_links = malloc(2u * capacity * sizeof *p->cell_links);
    if (p->cells && p->cell_links &&
        rfs_cellsum_init(&p->cellsum, x0, y0, w, h, shift, p->cells, n, p->cell_links,
                         capacity) == 0) {
        p->cellsum_index = rfs_cellsum_index(&p->cellsum);
        p->mem.index = &p->cellsum_index;
    }
}

/* The scenario's path-loss settings into pc: P0 bounded by the node's transmit power when
 * known, the ceiling's charge per wall (docs/PATHLOSS.md, "The P0 floor") and the coarse
 * pass's footprint ("A bin's walls") and its snap ("Fit"). */
static void pathloss_options(const hs_ctrl_inproc_cfg_t *cfg, rfs_pathloss_cfg_t *pc)
{
    if (!isnan(cfg->p0_min_dbm)) {
        pc->p0_min = (rfs_q16_t)lround(fmax(-200.0, fmin(100.0, cfg->p0_min_dbm)) * 65536.0);
    }
    if (!isnan(cfg->p0_max_wall_db)) {
        pc->p0_max_wall = (rfs_q16_t)lround(fmax(0.0, fmin(60.0, cfg->p0_max_wall_db)) * 65536.0);
    }
    if (!isnan(cfg->coarse_footprint_m)) {
        pc->coarse_footprint =
            (rfs_q16_t)lround(fmax(0.0, fmin(0.5, cfg->coarse_footprint_m)) * 65536.0);
    }
    if (cfg->coarse_snap >= 0) {
        pc->coarse_snap = cfg->coarse_snap != 0;
    }
}

/* The path-loss model's options (pathloss_options) and the simulator's large wall-count
 * cache. 0, or -1 with the reason in err. */
static int open_pathloss(inproc_t *p, const hs_ctrl_inproc_cfg_t *cfg, char *err, size_t errlen)
{
    if (!isnan(cfg->p0_min_dbm) || !isnan(cfg->p0_max_wall_db) || !isnan(cfg->coarse_footprint_m) ||
        cfg->coarse_snap >= 0) {
        rfs_pathloss_cfg_t pc = rfs_pathloss_cfg_default();
        pathloss_options(cfg, &pc);
        if (rfs_pathloss_init(p->model_state, &pc) != 0) {
            snprintf(err, errlen,
                     "model: pathloss: p0_min_dbm %g, p0_max_wall_db %g or coarse_footprint_m %g rejected",
                     cfg->p0_min_dbm, cfg->p0_max_wall_db, cfg->coarse_footprint_m);
            return -1;
        }
    }
    /* The host's cache holds every candidate of a run; the built-in one (the Cortex-M4's)
     * 120 origins by 256 candidates: the same fits, more counts. */
    const uint32_t cb = rfs_pathloss_cache_bytes(HS_CTRL_PATHLOSS_CACHE_COLS);
    p->wall_cache = cfg->pathloss_builtin_cache ? NULL : malloc(cb);
    if (!cfg->pathloss_builtin_cache &&
        (!p->wall_cache || rfs_pathloss_cache_attach(p->model_state, p->wall_cache, cb,
                                                     HS_CTRL_PATHLOSS_CACHE_COLS) != 0)) {
        snprintf(err, errlen, "model: pathloss: out of memory");
        return -1;
    }
    if (cfg->pathloss_log2 != NULL) {
        (void)rfs_pathloss_log2_attach(p->model_state, cfg->pathloss_log2);
    }
    return 0;
}

/* One path-loss fit per source (rfs_fields.h) and each source's own sample store. */
static int open_fields(inproc_t *p, const hs_ctrl_inproc_cfg_t *cfg, const rfs_map_t *map,
                       const rfs_target_ops_t *target)
{
    rfs_fields_cfg_t fc = rfs_fields_cfg_default();
    pathloss_options(cfg, &fc.pathloss);
    uint32_t points, cells;
    rfs_fields_mem_size(map, &fc, &points, &cells);
    p->fmem.points = points;
    p->fmem.cells = cells;
    p->fmem.f = calloc(points, sizeof(int16_t));
    p->mem.src = calloc(target->nsources, sizeof(rfs_seek_src_t));
    bool ok = p->fmem.f != NULL && p->mem.src != NULL;
    for (unsigned k = 0; k < target->nsources && k < RFS_TARGET_MAX_SOURCES; k++) {
        p->fmem.walls[k] = calloc(points, 1);
        p->fmem.rsum[k] = calloc(cells, sizeof(int32_t));
        p->fmem.rcount[k] = calloc(cells, sizeof(uint16_t));
        p->mem.src_samples[k] = calloc(cfg->seek.store.capacity ? cfg->seek.store.capacity : 1,
                                       sizeof(rfs_sample_t));
        p->mem.src_pending[k] = calloc(p->mem.pending_cap, sizeof(rfs_pending_t));
        ok = ok && p->fmem.walls[k] && p->fmem.rsum[k] && p->fmem.rcount[k] &&
             p->mem.src_samples[k] && p->mem.src_pending[k];
    }
    p->fields = aligned_alloc(RFS_MODELS_STATE_ALIGN,
                              (sizeof(rfs_fields_t) + RFS_MODELS_STATE_ALIGN - 1u) /
                                  RFS_MODELS_STATE_ALIGN * RFS_MODELS_STATE_ALIGN);
    if (!ok || !p->fields) {
        return -1;
    }
    return rfs_fields_init(p->fields, &fc, target, &p->fmem);
}

/* The target named `name`, or NULL. pdr: the caller feeds rfs_pdr_value() percentages as
 * the measurements (rfs_pdr.h). */
static const rfs_target_ops_t *target_named(const char *name)
{
    if (name && strcmp(name, "rssi") == 0) {
        return &rfs_target_rssi;
    }
    if (name && strcmp(name, "bridge") == 0) {
        return &rfs_target_bridge;
    }
    return name && strcmp(name, "pdr") == 0 ? &rfs_target_pdr : NULL;
}

int hs_ctrl_inproc_open(hs_ctrl_t *c, const hs_ctrl_inproc_cfg_t *cfg, const rfs_map_t *map,
                        char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    const rfs_target_ops_t *target = target_named(cfg->target);
    if (!target) {
        snprintf(err, errlen, "target: unknown '%s' (rssi, bridge, pdr)", cfg->target ? cfg->target : "");
        return -1;
    }
    if (!hs_ctrl_model_known(cfg->model)) {
        snprintf(err, errlen, "model: unknown '%s' (ridge, mlp, knn, radius, pathloss)",
                 cfg->model ? cfg->model : "");
        return -1;
    }
    if ((unsigned)cfg->seek.strategy >= (unsigned)RFS_SEEK_STRATEGY_COUNT) {
        snprintf(err, errlen, "strategy: out of range");
        return -1;
    }
    if (cfg->period_us <= 0) {
        snprintf(err, errlen, "controller: period must be positive");
        return -1;
    }
    inproc_t *p = calloc(1, sizeof *p);
    if (!p) {
        snprintf(err, errlen, "controller: out of memory");
        return -1;
    }
    uint32_t lat = (uint32_t)map->lw * map->lh;
    p->mem.samples = calloc(cfg->seek.store.capacity ? cfg->seek.store.capacity : 1,
                            sizeof(rfs_sample_t));
    p->mem.pending_cap = 1024; // two 200 pkt/s sources across a 0.5 s pose gap, with margin
    p->mem.pending = calloc(p->mem.pending_cap, sizeof(rfs_pending_t));
    p->mem.plan_work_bytes = lat;
    p->mem.plan_work = calloc(lat, 1);
    p->mem.plan_queue_cap = lat; // never overflows: each lattice point is queued once
    p->mem.plan_queue = calloc(lat, sizeof(uint32_t));
    p->mem.visited_bytes = rfs_reach_bytes(map);
    p->mem.visited = calloc(p->mem.visited_bytes, 1);
    p->mem.reach_bytes = rfs_reach_bytes(map);
    p->mem.reach = calloc(p->mem.reach_bytes, 1);
    if (!p->mem.samples || !p->mem.pending || !p->mem.plan_work || !p->mem.plan_queue ||
        !p->mem.visited || !p->mem.reach) {
        ip_close(p);
        snprintf(err, errlen, "controller: out of memory");
        return -1;
    }
    const rfs_models_entry_t *me = rfs_models_lookup(cfg->model);
    if (me->ops == &rfs_ridge_ops) {
        open_cellsum(p, map, cfg->seek.store.capacity);
    }
    size_t sbytes = (rfs_models_max_state_bytes() + RFS_MODELS_STATE_ALIGN - 1u) /
                    RFS_MODELS_STATE_ALIGN * RFS_MODELS_STATE_ALIGN;
    p->model_state = aligned_alloc(RFS_MODELS_STATE_ALIGN, sbytes);
    if (!p->model_state || me->init_default(p->model_state) != 0) {
        ip_close(p);
        snprintf(err, errlen, "model: %s: initialisation failed", cfg->model);
        return -1;
    }
    if (cfg->seek.strategy == RFS_SEEK_META_GLOBAL && me->ops == &rfs_ridge_ops) {
        // the local ridge with a radius covering the whole map (ridge limit 300 m).
        double diag = hypot((double)map->w, (double)map->h) * map->res / 65536.0 + 1.0;
        rfs_ridge_cfg_t rc = rfs_ridge_cfg_default();
        rc.radius = (rfs_q16_t)lround(fmin(diag, 300.0) * 65536.0);
        if (rfs_ridge_init(p->model_state, &rc) != 0) {
            ip_close(p);
            snprintf(err, errlen, "model: ridge: map-wide radius rejected");
            return -1;
        }
    }
    if (me->ops == &rfs_knn_ops || me->ops == &rfs_radius_ops) {
        // predictions read fewer samples through it, the same answers (rfs_knn_index.h)
        p->knn_index = malloc(sizeof *p->knn_index);
        if (!p->knn_index) {
            ip_close(p);
            snprintf(err, errlen, "controller: out of memory");
            return -1;
        }
        rfs_knn_index_attach(p->model_state, p->knn_index);
    }
    if (me->ops == &rfs_pathloss_ops && open_pathloss(p, cfg, err, errlen) != 0) {
        ip_close(p);
        return -1;
    }
    rfs_model_t model = {me->ops, p->model_state};
    if (rfs_models_per_source(me, target)) {
        if (open_fields(p, cfg, map, target) != 0) {
            ip_close(p);
            snprintf(err, errlen, "model: %s per source: out of memory or rejected", cfg->model);
            return -1;
        }
        model = rfs_fields_model(p->fields);
    }
    rfs_seek_cfg_t scfg = cfg->seek;
    if (p->fields) {
        rfs_seek_cfg_per_source(&scfg);
    }
    if (rfs_seek_init(&p->seek, &scfg, map, model, target, &p->mem) != 0) {
        ip_close(p);
        snprintf(err, errlen, "controller: the core rejected the seeker configuration");
        return -1;
    }
    /* No period budget to keep here: the tree's search runs when a plan needs it. */
    rfs_plan_tree_defer(&p->seek.plan, true);
    rfs_plan_use_edges(&p->seek.plan); /* the edge table hs_sim_env_open attached */
    rfs_rng_seed(&p->rng, cfg->seed);
    p->fit_slices = cfg->fit_slices;
    c->name = rfs_seek_strategy_name(cfg->seek.strategy);
    c->self = p;
    c->period_us = cfg->period_us;
    c->on_pose = ip_on_pose;
    c->on_rssi = ip_on_rssi;
    c->on_receiver = ip_on_receiver;
    c->step = ip_step;
    c->predict = ip_predict;
    c->close = ip_close;
    c->pathloss = ip_pathloss;
    c->fields = ip_fields;
    return 0;
}

void hs_ctrl_close(hs_ctrl_t *c)
{
    if (c && c->close) {
        c->close(c->self);
    }
    if (c) {
        memset(c, 0, sizeof *c);
    }
}
