/* rfs_fields.c - one path-loss fit per source and the target on the predicted fields
 * (see rfs_fields.h; docs/PATHLOSS.md, "One fit per source").
 *
 * A fit runs in parts: each source's path-loss fit on its own samples, each source's
 * residuals binned into cells, then one pass over the lattice that predicts the target
 * at every legal point and keeps the best. Lattice point (i, j) is index j * lw + i (as
 * the reach bits), in residual cell (i / cs, j / cs).
 */
#include "rfs_fields.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_reach.h"

/* walls[] of a lattice point not counted yet. */
#define NO_WALLS 0xFFu
/* Samples or lattice points per work unit. */
#define PER_UNIT 32u
/* A residual is clipped to +-64 dB (Q8): a cell's sum of up to 65,535 stays below 2^30. */
#define RES_CLIP (64 * 256)
/* Most lattice points: draw weights (Q0.8, <= 256) then sum below 2^32. */
#define MAX_POINTS (1u << 24)

rfs_fields_cfg_t rfs_fields_cfg_default(void)
{
    rfs_fields_cfg_t c;
    c.pathloss = rfs_pathloss_cfg_default();
    c.pathloss.p0_max = INT32_MAX; /* a node's f, not a source: no ceiling */
    /* Tuned on seeds 1..30 of scenarios/bridge.yaml (docs/STRATEGIES.md, "Bridging"): the
     * true f changes by a wall's 5 dB across the edge of a doorway's line of sight, so a
     * cell and kernel much larger than the lattice blur the best point away. */
    c.cell = RFS_Q16_FRAC(1, 4);
    c.radius = RFS_Q16_HALF;
    c.prior_n = 3u; /* about 12 cm of travel at 4 cm between samples */
    c.draw_t = RFS_Q16_INT(3);
    c.coarse = RFS_Q16_ONE;
    c.refit_min = 100u; /* about 4 m of new travel */
    /* The settle tour (docs/STRATEGIES.md, "Bridging"), tuned on seeds 1..40 of
     * scenarios/bridge.yaml: 6 candidates half a metre apart, each measured 64 times
     * (a 0.25 m cell crossed about 6 times a 0.25 m orbit). */
    c.settle_k = 6u;
    c.settle_n = 8u;
    c.settle_conf = 64u;
    c.settle_sep = 2u;
    c.lcb = 0; /* 1: held-out seeds 1001..1200 141 -> 136 and 150 -> 143 of 200 within 3 m
                * (office, corridor; docs/PATHLOSS.md) */
    return c;
}

/* Residual cell side in lattice steps: cell / grid, rounded, 1..255. */
static uint16_t cell_steps(const rfs_fields_cfg_t *c, const rfs_map_t *m)
{
    int64_t cs = rfs_sdiv64_round(c->cell, m->cfg.grid);
    return (uint16_t)(cs < 1 ? 1 : cs > 255 ? 255 : cs);
}

void rfs_fields_mem_size(const rfs_map_t *m, const rfs_fields_cfg_t *cfg, uint32_t *points,
                         uint32_t *cells)
{
    RFS_ASSERT(m != 0 && cfg != 0 && points != 0 && cells != 0);
    uint32_t cs = cell_steps(cfg, m);
    *points = (uint32_t)m->lw * m->lh;
    *cells = ((m->lw + cs - 1u) / cs) * ((m->lh + cs - 1u) / cs);
}

int rfs_fields_init(rfs_fields_t *f, const rfs_fields_cfg_t *cfg, const rfs_target_ops_t *t,
                    const rfs_fields_mem_t *mem)
{
    if (f == 0 || cfg == 0 || t == 0 || mem == 0 || t->combine == 0 || t->nsources == 0u ||
        t->nsources > RFS_MODEL_MAX_SOURCES || cfg->cell <= 0 || cfg->cell > RFS_Q16_INT(8) ||
        cfg->radius < 0 || (int64_t)cfg->radius > (int64_t)cfg->cell * RFS_FIELDS_KERNEL_MAX ||
        cfg->prior_n == 0u || cfg->draw_t <= 0 || cfg->coarse <= 0 || cfg->refit_min == 0u ||
        cfg->lcb < 0 || cfg->lcb > RFS_Q16_INT(8) || cfg->settle_k > RFS_FIELDS_CAND ||
        cfg->settle_n == 0u || cfg->settle_sep == 0u || mem->f == 0) {
        return -1;
    }
    for (uint8_t k = 0u; k < t->nsources; ++k) {
        if (mem->walls[k] == 0 || mem->rsum[k] == 0 || mem->rcount[k] == 0) {
            return -1;
        }
    }
    memset(f, 0, sizeof(*f));
    f->cfg = *cfg;
    f->target = t;
    f->mem = *mem;
    for (uint8_t k = 0u; k < t->nsources; ++k) {
        if (rfs_pathloss_init(&f->src[k], &cfg->pathloss) != 0) {
            return -1;
        }
    }
    f->best_v = RFS_FIELDS_NONE;
    return 0;
}

/* The sources' fits are kept: a relearn refits only those whose samples changed. */
static void fields_reset(void *self)
{
    rfs_fields_t *f = (rfs_fields_t *)self;
    RFS_ASSERT(f != 0);
    f->valid = false;
    f->phase = RFS_FIELDS_IDLE;
}

/* The residual cells and the kernel for map m: weight 1 - d / radius, d between cell
 * centres (cs * grid * sqrt(q) for squared offset q). Scaling: cs * grid < 2^24 (Q16),
 * times isqrt(q << 32) (Q16, q <= 32) >> 16 stays Q16; the weight is Q0.16, below 1. */
static void setup_cells(rfs_fields_t *f, const rfs_map_t *m)
{
    f->cs = cell_steps(&f->cfg, m);
    int64_t cst = rfs_sdiv64_round(f->cfg.coarse, m->cfg.grid);
    f->cstep = (uint16_t)(cst < 1 ? 1 : cst > 64 ? 64 : cst);
    f->cw = (uint16_t)((m->lw + f->cs - 1u) / f->cs);
    f->ch = (uint16_t)((m->lh + f->cs - 1u) / f->cs);
    const int64_t side = (int64_t)f->cs * m->cfg.grid;
    int64_t kr = f->cfg.radius > 0 ? rfs_sdiv64_round(f->cfg.radius, side) : 0;
    f->kr = (uint8_t)(kr > RFS_FIELDS_KERNEL_MAX ? RFS_FIELDS_KERNEL_MAX : kr);
    for (uint32_t q = 0u; q < RFS_FIELDS_KERNEL_TABLE; ++q) {
        int64_t d = (side * rfs_isqrt64((uint64_t)q << 32)) >> 16;
        int64_t w = q == 0u ? RFS_Q16_ONE
                    : f->cfg.radius > 0 ? RFS_Q16_ONE - rfs_sdiv64_round(d << 16, f->cfg.radius)
                                        : 0;
        f->kw[q] = (uint16_t)(w <= 0 ? 0 : w >= RFS_Q16_ONE ? 0xFFFF : w);
    }
}

/* Start a fit: false (no model) without a map, without every source's samples, or on a
 * map larger than the arrays. */
static bool fit_begin(rfs_fields_t *f, const rfs_model_fit_in_t *in)
{
    const rfs_map_t *m = in->map;
    if (m == 0 || in->nsources < f->target->nsources) {
        return false;
    }
    uint32_t points, cells;
    rfs_fields_mem_size(m, &f->cfg, &points, &cells);
    if (points > f->mem.points || cells > f->mem.cells || points > MAX_POINTS) {
        return false;
    }
    setup_cells(f, m);
    if (m != f->wmap) {
        memset(f->wvalid, 0, sizeof(f->wvalid));
        memset(f->fitted, 0, sizeof(f->fitted));
        f->wmap = m;
    }
    for (uint8_t k = 0u; k < f->target->nsources; ++k) {
        /* Samples since source k's path-loss fit: refit at refit_min, else only its
         * residuals are binned again. */
        const uint32_t fresh = in->src_seen[k] - f->fit_seen[k];
        f->changed[k] = !f->fitted[k] || f->fit_n[k] != in->src_n[k] || fresh != 0u;
        f->refit[k] = !f->fitted[k] || fresh >= f->cfg.refit_min;
    }
    if (in->settle != f->settle) {
        f->lattice_done = false; /* ranked otherwise now */
        if (f->settle == RFS_MODEL_EXPLORE || in->settle == RFS_MODEL_EXPLORE) {
            f->ncand = 0u;
            f->frozen = false;
        }
        f->settle = in->settle;
    }
    f->map = m;
    f->valid = false;
    f->phase = RFS_FIELDS_SOURCE;
    f->k = 0u;
    f->pos = 0u;
    f->walls_counted = 0u;
    return true;
}

/* Keep source k's walls while its estimate stays where they were counted to. */
static void keep_walls(rfs_fields_t *f, uint8_t k)
{
    const rfs_pathloss_t *p = &f->src[k];
    if (!f->wvalid[k] || f->wsx[k] != p->best.sx || f->wsy[k] != p->best.sy) {
        memset(f->mem.walls[k], NO_WALLS, (uint32_t)f->map->lw * f->map->lh);
        f->wvalid[k] = true;
        f->wsx[k] = p->best.sx;
        f->wsy[k] = p->best.sy;
    }
}

/* Walls from lattice point (i, j) to source k, counted once. *used: work units. */
static uint32_t walls_at(rfs_fields_t *f, uint8_t k, uint16_t i, uint16_t j, uint32_t *used)
{
    uint8_t *w = &f->mem.walls[k][(uint32_t)j * f->map->lw + i];
    if (*w == NO_WALLS) {
        rfs_q16_t x, y;
        rfs_map_lattice_point(f->map, i, j, &x, &y);
        *w = (uint8_t)rfs_pathloss_walls_to_source(&f->src[k], x, y); /* <= 15 */
        f->walls_counted++;
        (*used)++;
    }
    return *w;
}

/* Source k's kernel-smoothed residual at lattice point (i, j), dB Q16.16, and its
 * kernel-weighted sample count (Q16) in *nw when nw is not NULL. Scaling and overflow:
 * weights Q0.16 times cell sums below 2^30 (Q8), over at most 81 cells, stay below 2^53;
 * times 2^8 (to Q16 after the division by the Q16 count) below 2^61. */
static rfs_q16_t residual(const rfs_fields_t *f, uint8_t k, uint16_t i, uint16_t j, int64_t *nw)
{
    const int32_t ci = (int32_t)(i / f->cs), cj = (int32_t)(j / f->cs), kr = f->kr;
    int64_t num = 0, den = 0;
    for (int32_t dj = -kr; dj <= kr; ++dj) {
        const int32_t y = cj + dj;
        if (y < 0 || y >= (int32_t)f->ch) {
            continue;
        }
        for (int32_t di = -kr; di <= kr; ++di) {
            const int32_t x = ci + di;
            const uint32_t w = f->kw[di * di + dj * dj];
            if (x < 0 || x >= (int32_t)f->cw || w == 0u) {
                continue;
            }
            const uint32_t c = (uint32_t)y * f->cw + (uint32_t)x;
            num += (int64_t)w * f->mem.rsum[k][c];
            den += (int64_t)w * f->mem.rcount[k][c];
        }
    }
    if (nw != 0) {
        *nw = den;
    }
    return rfs_sat32(rfs_sdiv64_round(num * 256, den + ((int64_t)f->cfg.prior_n << 16)));
}

/* Metres Q16.16 of centimetres. |cm| < 2^15: exact in int64. */
static rfs_q16_t cm_q16(int16_t cm)
{
    return rfs_sat32(rfs_sdiv64_round((int64_t)cm * 65536, 100));
}

/* Bin source k's residuals, from sample pos on. true when done; false when the budget
 * ran out (resumed at the next call). */
static bool residual_run(rfs_fields_t *f, const rfs_model_fit_in_t *in, uint32_t budget,
                         uint32_t *used)
{
    const uint8_t k = f->k;
    const rfs_sample_t *smp = in->src_samples[k];
    const uint16_t n = in->src_n[k];
    if (f->pos == 0u) {
        keep_walls(f, k);
        memset(f->mem.rsum[k], 0, (uint32_t)f->cw * f->ch * sizeof(int32_t));
        memset(f->mem.rcount[k], 0, (uint32_t)f->cw * f->ch * sizeof(uint16_t));
    }
    for (; f->pos < n; ++f->pos) {
        if (budget != 0u && *used >= budget) {
            return false;
        }
        if (f->pos % PER_UNIT == 0u) {
            (*used)++;
        }
        const rfs_sample_t *s = &smp[f->pos];
        rfs_q16_t x = cm_q16(s->x_cm), y = cm_q16(s->y_cm), pl;
        uint16_t i, j;
        rfs_map_lattice_nearest(f->map, x, y, &i, &j);
        uint32_t w = walls_at(f, k, i, j, used);
        if (!rfs_pathloss_predict_walls(&f->src[k], x, y, w, &pl)) {
            continue;
        }
        /* Scaling: Q9.6 << 10 is Q16; the difference of two Q16 values in int64, to Q8. */
        int64_t r = (((int64_t)s->v_q6 * 1024 - pl) + 128) >> 8;
        r = r > RES_CLIP ? RES_CLIP : r < -RES_CLIP ? -RES_CLIP : r;
        const uint32_t c = (uint32_t)(j / f->cs) * f->cw + (uint32_t)(i / f->cs);
        if (f->mem.rcount[k][c] < UINT16_MAX) {
            f->mem.rsum[k][c] += (int32_t)r;
            f->mem.rcount[k][c]++;
        }
    }
    return true;
}

/* Every source's residual at lattice point (i, j) into res[], its kernel-weighted count
 * (Q16) into nw[]; true when a sample lies within the kernel of any of them. */
static bool residuals(const rfs_fields_t *f, uint16_t i, uint16_t j, rfs_q16_t *res,
                      int64_t *nw)
{
    bool near = false;
    for (uint8_t k = 0u; k < f->target->nsources; ++k) {
        res[k] = residual(f, k, i, j, &nw[k]);
        near = near || nw[k] > 0;
    }
    return near;
}

/* The target's uncertainty at a point with kernel-weighted counts nw[] (Q16): sqrt(2 sum_k
 * rms_k^2 prior_n / (prior_n + nw_k)), target units Q16.16 (rfs_fields_est_t.sigma).
 * Scaling and overflow: rms^2 in Q16 dB^2 (< 2^32) times the shrinkage factor (Q16,
 * <= 1) < 2^48; the sum of two, doubled, saturated to Q16.16 for the root. */
static rfs_q16_t point_sigma(const rfs_fields_t *f, const int64_t *nw)
{
    const int64_t prior = (int64_t)f->cfg.prior_n << 16;
    int64_t s2 = 0;
    for (uint8_t k = 0u; k < f->target->nsources; ++k) {
        const int64_t shrink = rfs_sdiv64_round(prior << 16, prior + nw[k]); /* Q16, <= 1 */
        s2 += (f->rms2[k] * shrink) >> 16;
    }
    return rfs_q16_sqrt(rfs_sat32(2 * s2));
}

/* The corrected fields' target at lattice point (i, j) given its residuals res[],
 * target units Q16.16; false without a path-loss model. *used: work units.
 * Scaling and overflow: each field and residual Q16.16, added saturating; combine()
 * saturates (rfs_target.h). */
static bool target_at(rfs_fields_t *f, uint16_t i, uint16_t j, const rfs_q16_t *res,
                      uint32_t *used, rfs_q16_t *v)
{
    rfs_q16_t x, y, r[RFS_MODEL_MAX_SOURCES];
    rfs_map_lattice_point(f->map, i, j, &x, &y);
    for (uint8_t k = 0u; k < f->target->nsources; ++k) {
        rfs_q16_t pl;
        if (!rfs_pathloss_predict_walls(&f->src[k], x, y, walls_at(f, k, i, j, used), &pl)) {
            return false;
        }
        r[k] = rfs_q16_add(pl, res[k]);
    }
    *v = f->target->combine(r);
    return true;
}

/* settle_n: every source's mean residual in the cell of lattice point (i, j) into res[],
 * dB Q16.16, without the kernel and the prior: once settled the robot ranks the places
 * it measured by what it measured there, the fine wall pattern of each fit's lattice
 * point added (target_at). false when a source has fewer than settle_n samples there.
 * Scaling: a cell's sum (Q8, < 2^30) times 2^8 over its count, in int64. */
static bool measured(const rfs_fields_t *f, uint16_t i, uint16_t j, uint16_t min,
                     rfs_q16_t *res)
{
    const uint32_t c = (uint32_t)(j / f->cs) * f->cw + (uint32_t)(i / f->cs);
    for (uint8_t k = 0u; k < f->target->nsources; ++k) {
        const uint16_t n = f->mem.rcount[k][c];
        if (n < min || n == 0u) {
            return false;
        }
        res[k] = rfs_sat32(rfs_sdiv64_round((int64_t)f->mem.rsum[k][c] * 256, n));
    }
    return true;
}

/* Keep lattice point idx, measured v, among the settle_k best candidates at least
 * settle_sep lattice steps apart, best first: a better point within settle_sep replaces
 * those it is near; a worse one is dropped. Scaling: lattice offsets below 2^16, their
 * squares summed in int64. */
static void keep_cand(rfs_fields_t *f, uint32_t idx, rfs_q16_t v)
{
    const uint32_t lw = f->map->lw;
    const int64_t sep = f->cfg.settle_sep;
    uint8_t n = 0u;
    for (uint8_t c = 0u; c < f->ncand; ++c) {
        const int64_t di = (int64_t)(f->cand[c] % lw) - (int64_t)(idx % lw);
        const int64_t dj = (int64_t)(f->cand[c] / lw) - (int64_t)(idx / lw);
        if (di * di + dj * dj < sep * sep) {
            if (f->cand_s[c] >= v) {
                return;
            }
            continue; /* replaced */
        }
        f->cand[n] = f->cand[c];
        f->cand_s[n++] = f->cand_s[c];
    }
    uint8_t at = n;
    while (at > 0u && f->cand_s[at - 1u] < v) {
        at--;
    }
    if (at >= f->cfg.settle_k) {
        f->ncand = n;
        return;
    }
    for (uint8_t c = (uint8_t)(n < f->cfg.settle_k ? n : f->cfg.settle_k - 1u); c > at; --c) {
        f->cand[c] = f->cand[c - 1u];
        f->cand_s[c] = f->cand_s[c - 1u];
    }
    f->cand[at] = idx;
    f->cand_s[at] = v;
    f->ncand = (uint8_t)(n < f->cfg.settle_k ? n + 1u : f->cfg.settle_k);
}

/* Settle phase: the best point is the first candidate, best measured first, not yet
 * measured enough (settle_conf), so that the robot measures each; once all are, the one
 * measured best. Candidates are chosen once, in the first fit after settling: later
 * fits would rank the places the robot passes between them, each on one pass. */
static void settle_best(rfs_fields_t *f)
{
    if (f->settle == RFS_MODEL_EXPLORE || f->cfg.settle_k == 0u || f->ncand == 0u) {
        return;
    }
    f->frozen = true;
    const uint16_t lw = f->map->lw;
    bool any = false;
    rfs_q16_t best = 0;
    uint32_t used = 0u;
    for (uint8_t c = 0u; c < f->ncand; ++c) {
        const uint16_t i = (uint16_t)(f->cand[c] % lw), j = (uint16_t)(f->cand[c] / lw);
        rfs_q16_t res[RFS_MODEL_MAX_SOURCES], v;
        if (f->settle == RFS_MODEL_TOUR && !measured(f, i, j, f->cfg.settle_conf, res)) {
            f->best = f->cand[c];
            return;
        }
        if (!measured(f, i, j, 1u, res)) {
            continue;
        }
        if (target_at(f, i, j, res, &used, &v) && (!any || v > best)) {
            any = true;
            best = v;
            f->best = f->cand[c];
        }
    }
}

/* Q16.16 to Q9.6, rounded, saturated, never one of the markers.
 * Scaling and overflow: (v + 2^9) >> 10 of an int32 fits int32; clamped to int16. */
static int16_t q16_to_q6(rfs_q16_t v)
{
    int32_t q = (int32_t)(((int64_t)v + 512) >> 10);
    return (int16_t)(q > INT16_MAX ? INT16_MAX : q <= RFS_FIELDS_SKIPPED ? RFS_FIELDS_SKIPPED + 1 : q);
}

/* Predict candidate idx = (i, j) into f[] (residuals res[], counts nw[]), keeping the
 * highest prediction and the best point: the highest prediction less lcb sigmas.
 * false without a model. Scaling and overflow: lcb (Q16, <= 8) times sigma (Q16.16,
 * < 2^31) in int64, the score saturated to Q16.16. */
static bool predict_point(rfs_fields_t *f, uint32_t idx, const rfs_q16_t *res,
                          const int64_t *nw, uint32_t *used)
{
    const uint16_t i = (uint16_t)(idx % f->map->lw), j = (uint16_t)(idx / f->map->lw);
    rfs_q16_t v;
    if (!target_at(f, i, j, res, used, &v)) {
        return false;
    }
    int16_t q = q16_to_q6(v);
    f->mem.f[idx] = q;
    f->best_v = q > f->best_v ? q : f->best_v;
    /* lcb 0 ranks by the kept Q9.6 value: the first of equal predictions is the best. */
    int64_t score = (int64_t)q * 1024;
    if (f->cfg.lcb > 0) {
        score = (int64_t)v - (((int64_t)f->cfg.lcb * point_sigma(f, nw)) >> 16);
    }
    rfs_q16_t mres[RFS_MODEL_MAX_SOURCES], mv;
    if (f->settle != RFS_MODEL_EXPLORE && f->cfg.settle_k > 0u && !f->frozen &&
        measured(f, i, j, f->cfg.settle_n, mres) && target_at(f, i, j, mres, used, &mv)) {
        keep_cand(f, idx, mv);
    }
    if (!f->scored || score > f->best_s) {
        f->scored = true;
        f->best_s = score;
        f->best = idx;
    }
    return true;
}

/* Keep coarse point idx among the RFS_FIELDS_TOP best, best first. */
static void keep_top(rfs_fields_t *f, uint32_t idx)
{
    const int16_t v = f->mem.f[idx];
    uint8_t at = f->ntop;
    while (at > 0u && f->top_v[at - 1u] < v) {
        at--;
    }
    if (at >= RFS_FIELDS_TOP) {
        return;
    }
    for (uint8_t k = (uint8_t)(f->ntop < RFS_FIELDS_TOP ? f->ntop : RFS_FIELDS_TOP - 1u); k > at; --k) {
        f->top[k] = f->top[k - 1u];
        f->top_v[k] = f->top_v[k - 1u];
    }
    f->top[at] = idx;
    f->top_v[at] = v;
    f->ntop = (uint8_t)(f->ntop < RFS_FIELDS_TOP ? f->ntop + 1u : RFS_FIELDS_TOP);
}

/* The lattice from pos on: every candidate within the kernel of a sample and every
 * `coarse` one is predicted, the others are marked skipped. true when done; false when
 * the budget ran out. */
static bool lattice_run(rfs_fields_t *f, const rfs_model_fit_in_t *in, uint32_t budget,
                        uint32_t *used)
{
    const rfs_map_t *m = f->map;
    const uint32_t n = (uint32_t)m->lw * m->lh;
    if (f->pos == 0u) {
        f->best_v = RFS_FIELDS_NONE;
        f->best = 0u;
        f->scored = false;
        f->ntop = 0u;
        f->lattice_done = false;
        for (uint8_t k = 0u; k < f->target->nsources; ++k) {
            rfs_pathloss_est_t e;
            (void)rfs_pathloss_estimate(&f->src[k], &e);
            f->rms2[k] = ((int64_t)e.rms * e.rms) >> 16;
        }
    }
    for (; f->pos < n; ++f->pos) {
        if (budget != 0u && *used >= budget) {
            return false;
        }
        if (f->pos % PER_UNIT == 0u) {
            (*used)++;
        }
        const uint16_t i = (uint16_t)(f->pos % m->lw), j = (uint16_t)(f->pos / m->lw);
        int16_t *out = &f->mem.f[f->pos];
        rfs_q16_t res[RFS_MODEL_MAX_SOURCES];
        int64_t nw[RFS_MODEL_MAX_SOURCES];
        *out = RFS_FIELDS_NONE;
        if (!rfs_map_lattice_legal(m, i, j) ||
            (in->reach != 0 && !rfs_reach_bit(in->reach, f->pos))) {
            continue;
        }
        *out = RFS_FIELDS_SKIPPED;
        const bool coarse = i % f->cstep == 0u && j % f->cstep == 0u;
        if ((residuals(f, i, j, res, nw) || coarse) && predict_point(f, f->pos, res, nw, used) &&
            coarse) {
            keep_top(f, f->pos);
        }
    }
    return true;
}

/* Round the best coarse points, from pos on: the skipped candidates within cstep - 1
 * lattice steps. true when done; false when the budget ran out. */
static bool refine_run(rfs_fields_t *f, uint32_t budget, uint32_t *used)
{
    const rfs_map_t *m = f->map;
    const int32_t r = (int32_t)f->cstep - 1, side = 2 * r + 1;
    for (; f->pos < (uint32_t)f->ntop * (uint32_t)(side * side); ++f->pos) {
        if (budget != 0u && *used >= budget) {
            return false;
        }
        const uint32_t t = f->top[f->pos / (uint32_t)(side * side)];
        const int32_t o = (int32_t)(f->pos % (uint32_t)(side * side));
        const int32_t i = (int32_t)(t % m->lw) + o % side - r, j = (int32_t)(t / m->lw) + o / side - r;
        if (i < 0 || j < 0 || i >= (int32_t)m->lw || j >= (int32_t)m->lh) {
            continue;
        }
        const uint32_t idx = (uint32_t)j * m->lw + (uint32_t)i;
        rfs_q16_t res[RFS_MODEL_MAX_SOURCES];
        int64_t nw[RFS_MODEL_MAX_SOURCES];
        if (f->mem.f[idx] == RFS_FIELDS_SKIPPED) {
            (void)residuals(f, (uint16_t)i, (uint16_t)j, res, nw);
            (void)predict_point(f, idx, res, nw, used);
        }
    }
    return true;
}

/* The estimate at the best point: its exact prediction, sigma and the area within it
 * (rfs_fields_est_t). Scaling and overflow: the area is the count times grid^2 (Q16,
 * < 2^20) below 2^52. */
static void finish(rfs_fields_t *f)
{
    const rfs_map_t *m = f->map;
    settle_best(f);
    const uint16_t i = (uint16_t)(f->best % m->lw), j = (uint16_t)(f->best / m->lw);
    uint32_t used = 0u;
    rfs_map_lattice_point(m, i, j, &f->bx, &f->by);
    rfs_q16_t res[RFS_MODEL_MAX_SOURCES];
    int64_t nw[RFS_MODEL_MAX_SOURCES];
    (void)residuals(f, i, j, res, nw);
    (void)target_at(f, i, j, res, &used, &f->bf);
    f->sigma = point_sigma(f, nw);
    const int32_t floor_q6 = q16_to_q6(rfs_q16_sub(f->bf, f->sigma));
    uint32_t within = 0u;
    for (uint32_t p = 0u; p < (uint32_t)m->lw * m->lh; ++p) {
        within += f->mem.f[p] > RFS_FIELDS_SKIPPED && f->mem.f[p] >= floor_q6 ? 1u : 0u;
    }
    const int64_t cell_m2 = ((int64_t)m->cfg.grid * m->cfg.grid) >> 16;
    f->area_m2 = rfs_sat32((int64_t)within * cell_m2);
}

static bool any_changed(const rfs_fields_t *f)
{
    bool any = false;
    for (uint8_t k = 0u; k < f->target->nsources; ++k) {
        any = any || f->changed[k];
    }
    return any;
}

static rfs_fit_result_t fields_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                   rfs_rng_t *rng)
{
    rfs_fields_t *f = (rfs_fields_t *)self;
    RFS_ASSERT(f != 0 && in != 0);
    if (f->phase == RFS_FIELDS_IDLE && !fit_begin(f, in)) {
        return RFS_FIT_FAILED;
    }
    uint32_t used = 0u;
    for (;;) {
        if (f->phase == RFS_FIELDS_SOURCE && !f->refit[f->k]) {
            /* The same samples as its last fit: that fit, its residuals and walls stand. */
            if (++f->k == f->target->nsources) {
                f->phase = RFS_FIELDS_RESIDUAL;
                f->k = 0u;
                f->pos = 0u;
            }
            continue;
        }
        if (f->phase == RFS_FIELDS_SOURCE) {
            f->fitted[f->k] = false;
            const rfs_model_fit_in_t sub = {.samples = in->src_samples[f->k],
                                            .n = in->src_n[f->k], .qx = in->qx, .qy = in->qy,
                                            .map = in->map, .reach = in->reach};
            rfs_fit_result_t r = rfs_pathloss_ops.fit(&f->src[f->k], &sub, budget, rng);
            if (r != RFS_FIT_DONE) {
                f->phase = r == RFS_FIT_FAILED ? RFS_FIELDS_IDLE : f->phase;
                return r;
            }
            f->fitted[f->k] = true;
            f->fit_n[f->k] = in->src_n[f->k];
            f->fit_seen[f->k] = in->src_seen[f->k];
            if (++f->k == f->target->nsources) {
                f->phase = RFS_FIELDS_RESIDUAL;
                f->k = 0u;
                f->pos = 0u;
            }
        } else if (f->phase == RFS_FIELDS_RESIDUAL) {
            if (f->changed[f->k] && !residual_run(f, in, budget, &used)) {
                return RFS_FIT_MORE;
            }
            f->pos = 0u;
            if (++f->k == f->target->nsources) {
                f->phase = RFS_FIELDS_LATTICE;
                if (!any_changed(f) && f->lattice_done) {
                    /* Nothing new: the last fit's lattice and estimate stand. */
                    f->phase = RFS_FIELDS_IDLE;
                    f->valid = f->best_v > RFS_FIELDS_SKIPPED;
                    return f->valid ? RFS_FIT_DONE : RFS_FIT_FAILED;
                }
            }
        } else if (f->phase == RFS_FIELDS_LATTICE) {
            if (!lattice_run(f, in, budget, &used)) {
                return RFS_FIT_MORE;
            }
            f->phase = RFS_FIELDS_REFINE;
            f->pos = 0u;
        } else {
            if (!refine_run(f, budget, &used)) {
                return RFS_FIT_MORE;
            }
            f->phase = RFS_FIELDS_IDLE;
            f->lattice_done = true;
            if (f->best_v == RFS_FIELDS_NONE) {
                return RFS_FIT_FAILED;
            }
            finish(f);
            f->valid = true;

            return RFS_FIT_DONE;
        }
        if (budget != 0u) {
            return RFS_FIT_MORE; /* one part per call */
        }
    }
}

/* The fields' target at (x, y): each source's prediction (walls counted) plus its
 * residual at the nearest lattice point. */
static bool fields_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    const rfs_fields_t *f = (const rfs_fields_t *)self;
    if (!f->valid) {
        return false;
    }
    uint16_t i, j;
    rfs_map_lattice_nearest(f->map, x, y, &i, &j);
    rfs_q16_t r[RFS_MODEL_MAX_SOURCES];
    for (uint8_t k = 0u; k < f->target->nsources; ++k) {
        rfs_q16_t pl;
        if (!rfs_pathloss_ops.predict(&f->src[k], x, y, &pl)) {
            return false;
        }
        r[k] = rfs_q16_add(pl, residual(f, k, i, j, 0));
    }
    *value = f->target->combine(r);
    return true;
}

static bool fields_argmax(const void *self, rfs_q16_t *x, rfs_q16_t *y)
{
    const rfs_fields_t *f = (const rfs_fields_t *)self;
    if (!f->valid) {
        return false;
    }
    *x = f->bx;
    *y = f->by;
    return true;
}

/* Draw weight of a kept prediction v (Q9.6), Q0.8: e^(-(best - v) / draw_t).
 * Scaling: the difference (Q6, < 2^17) to Q16 (< 2^27) over draw_t (Q16 > 0) in int64. */
static uint32_t draw_weight(const rfs_fields_t *f, int16_t v)
{
    if (v <= RFS_FIELDS_SKIPPED) {
        return 0u;
    }
    int64_t x = rfs_sdiv64_round((((int64_t)f->best_v - v) * 1024) << 16, f->cfg.draw_t);
    return x >= RFS_Q16_INT(16) ? 0u : (uint32_t)rfs_q16_exp_neg((rfs_q16_t)x) >> 8;
}

/* A point drawn with its weight over the kept predictions (two passes, no table). */
static bool fields_sample(const void *self, rfs_rng_t *rng, rfs_q16_t *x, rfs_q16_t *y)
{
    const rfs_fields_t *f = (const rfs_fields_t *)self;
    RFS_ASSERT(f != 0 && rng != 0 && x != 0 && y != 0);
    if (!f->valid) {
        return false;
    }
    const uint32_t n = (uint32_t)f->map->lw * f->map->lh;
    uint32_t total = 0u;
    for (uint32_t p = 0u; p < n; ++p) {
        total += draw_weight(f, f->mem.f[p]);
    }
    RFS_ASSERT(total > 0u); /* the best point weighs 256 */
    uint32_t pick = rfs_rng_below(rng, total), acc = 0u;
    for (uint32_t p = 0u; p < n; ++p) {
        acc += draw_weight(f, f->mem.f[p]);
        if (acc > pick) {
            rfs_map_lattice_point(f->map, (uint16_t)(p % f->map->lw), (uint16_t)(p / f->map->lw),
                                  x, y);
            return true;
        }
    }
    RFS_ASSERT(false); /* acc reaches total > pick */
    return false;
}

const rfs_model_ops_t rfs_fields_ops = {
    .name = "fields",
    .reset = fields_reset,
    .fit = fields_fit,
    .predict = fields_predict,
    .argmax = fields_argmax,
    .sample = fields_sample,
};

rfs_model_t rfs_fields_model(rfs_fields_t *f)
{
    rfs_model_t m;
    m.ops = &rfs_fields_ops;
    m.self = f;
    return m;
}

bool rfs_fields_estimate(const rfs_fields_t *f, rfs_fields_est_t *est)
{
    RFS_ASSERT(f != 0 && est != 0);
    if (!f->valid) {
        return false;
    }
    memset(est, 0, sizeof(*est));
    est->x = f->bx;
    est->y = f->by;
    est->value = f->bf;
    est->sigma = f->sigma;
    est->area_m2 = f->area_m2;
    est->nsources = f->target->nsources;
    for (uint8_t k = 0u; k < est->nsources; ++k) {
        (void)rfs_pathloss_estimate(&f->src[k], &est->src[k]);
    }
    return true;
}

bool rfs_fields_at(const rfs_fields_t *f, uint16_t i, uint16_t j, rfs_q16_t *value)
{
    RFS_ASSERT(f != 0 && value != 0);
    if (!f->valid || i >= f->map->lw || j >= f->map->lh) {
        return false;
    }
    int16_t v = f->mem.f[(uint32_t)j * f->map->lw + i];
    if (v <= RFS_FIELDS_SKIPPED) {
        return false;
    }
    *value = (rfs_q16_t)v * 1024;
    return true;
}
