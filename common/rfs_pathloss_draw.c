/* rfs_pathloss_draw.c - where the path-loss model sends the robot besides its estimate
 * (docs/PATHLOSS.md, "Uncertainty"; docs/STRATEGIES.md, "Stalls"): epsilon goals drawn
 * among the last fit's coarse candidates with their tempered likelihood-ratio weights, and
 * the nearer plausible source (rfs_model_ops_t.sample and .near). */
#include "rfs_pathloss.h"

#include "rfs_assert.h"
#include "rfs_pathloss_internal.h"

/* The per-fit constants of the draw's weights. x = (m - m0) bins / (2 T bm): chi2 / 2T
 * against the chosen source (bm), less the same for the best coarse point (m0 <= m),
 * which so weighs 1; the draw's probabilities are those of e^(-chi2 / 2T). */
typedef struct draw_k {
    uint64_t m0;  /* best coarse point's mean loss, dB^2 Q16 */
    uint64_t den; /* 2 T bm, dB^2 Q16, >= 1 */
} draw_k_t;

static draw_k_t draw_consts(const rfs_pathloss_t *p, rfs_q16_t temp)
{
    uint64_t bm = rfs_pathloss_mean_loss(p, p->best.loss);
    bm = bm > 0u ? bm : 1u;
    uint64_t den = (bm * 2u * (uint64_t)temp) >> 16;
    draw_k_t k = {rfs_pathloss_mean_loss(p, p->top[0].loss), den > 0u ? den : 1u};
    return k;
}

/* Weight of coarse surface point c (rfs_pathloss_draw_weight), for a valid model. */
static uint32_t draw_weight(const rfs_pathloss_t *p, const draw_k_t *k, uint32_t c)
{
    uint32_t m = p->surface[c];
    if (m == RFS_PATHLOSS_NO_LOSS) {
        return 0u;
    }
    uint64_t num = m > k->m0 ? ((uint64_t)m - k->m0) * p->used_bins : 0u;
    if (num >= 16u * k->den) {
        return 0u;
    }
    return (uint32_t)rfs_q16_exp_neg((rfs_q16_t)rfs_udiv64(num << 16, k->den));
}

uint32_t rfs_pathloss_draw_weight(const rfs_pathloss_t *p, uint16_t ci, uint16_t cj)
{
    RFS_ASSERT(p != 0);
    if (!p->valid || ci >= p->lat.ncx || cj >= p->lat.ncy) {
        return 0u;
    }
    draw_k_t k = draw_consts(p, p->cfg.sample_t);
    return draw_weight(p, &k, (uint32_t)cj * p->lat.ncx + ci);
}

/* A plausible source: a coarse candidate of the last fit drawn with its weight (the
 * tempered likelihood ratio against the chosen source). Two passes over the surface,
 * no table. Scaling: at most RFS_PATHLOSS_MAX_COARSE weights <= 2^16 sum below 2^26. */
bool rfs_pathloss_sample_op(const void *self, rfs_rng_t *rng, rfs_q16_t *x, rfs_q16_t *y)
{
    const rfs_pathloss_t *p = (const rfs_pathloss_t *)self;
    RFS_ASSERT(p != 0 && rng != 0 && x != 0 && y != 0);
    if (!p->valid) {
        return false;
    }
    const rfs_pathloss_lat_t *l = &p->lat;
    const uint32_t nc = (uint32_t)l->ncx * l->ncy;
    const draw_k_t k = draw_consts(p, p->cfg.sample_t);
    uint32_t total = 0u;
    for (uint32_t c = 0u; c < nc; ++c) {
        total += draw_weight(p, &k, c);
    }
    RFS_ASSERT(total > 0u); /* the best coarse point weighs 1 */
    uint32_t pick = rfs_rng_below(rng, total), acc = 0u;
    for (uint32_t c = 0u; c < nc; ++c) {
        acc += draw_weight(p, &k, c);
        if (acc > pick) {
            int32_t i, j;
            /* A point with weight was a candidate, unless a fit on another lattice has
             * begun since (its snaps not looked for yet): then no draw. */
            if (!rfs_pathloss_coarse_ij(p, c, &i, &j)) {
                return false;
            }
            rfs_pathloss_lattice_xy(l, (uint16_t)i, (uint16_t)j, x, y);
            return true;
        }
    }
    RFS_ASSERT(false); /* acc reaches total > pick */
    return false;
}

/* rfs_model_ops_t.near over the coarse candidates of the last fit: w = e^(-chi2 / 2T),
 * chi2 = (m / m_best - 1) x bins against the chosen source, as the draws' weights
 * (draw_consts) at temperature q->temp. One pass; refuse() only for a point that would
 * lead. Scaling: w (Q16, <= 2^16) times a distance plus d0 (Q16, < 2^32) < 2^48; the
 * exponent as draw_weight's (cut at 16, where w < 2^-23). */
bool rfs_pathloss_near_op(const void *self, const rfs_model_near_t *q, rfs_q16_t *x,
                          rfs_q16_t *y)
{
    const rfs_pathloss_t *p = (const rfs_pathloss_t *)self;
    RFS_ASSERT(p != 0 && q != 0 && x != 0 && y != 0);
    if (!p->valid || q->temp <= 0) {
        return false;
    }
    const rfs_pathloss_lat_t *l = &p->lat;
    const uint32_t nc = (uint32_t)l->ncx * l->ncy;
    const uint64_t bm = rfs_pathloss_mean_loss(p, p->best.loss);
    const uint64_t den2 = ((bm > 0u ? bm : 1u) * 2u * (uint64_t)q->temp) >> 16;
    const uint64_t den = den2 > 0u ? den2 : 1u;
    int64_t wb = RFS_Q16_ONE; /* the leader: weight wb at distance db (+ d0) */
    int64_t db = (int64_t)rfs_q16_dist(q->x, q->y, q->ax, q->ay) + q->d0;
    bool found = false;
    for (uint32_t c = 0u; c < nc; ++c) {
        const uint32_t m = p->surface[c];
        const uint64_t num = m != RFS_PATHLOSS_NO_LOSS && m > bm ? ((uint64_t)m - bm) * p->used_bins
                                                                 : 0u;
        if (m == RFS_PATHLOSS_NO_LOSS || num >= 16u * den) {
            continue;
        }
        const int64_t w = rfs_q16_exp_neg((rfs_q16_t)rfs_udiv64(num << 16, den));
        rfs_q16_t cx, cy;
        int32_t i, j;
        if (!rfs_pathloss_coarse_ij(p, c, &i, &j)) {
            continue;
        }
        rfs_pathloss_lattice_xy(l, (uint16_t)i, (uint16_t)j, &cx, &cy);
        const int64_t d = (int64_t)rfs_q16_dist(q->x, q->y, cx, cy) + q->d0;
        if (w * db > wb * d && !(q->refuse != 0 && q->refuse(q->ctx, cx, cy))) {
            wb = w;
            db = d;
            *x = cx;
            *y = cy;
            found = true;
        }
    }
    return found;
}

/* rfs_model_ops_t.mean: the coarse candidates' mean position, each weighted as the draws
 * (draw_weight) at temperature temp. One pass, no table. Scaling: weights <=
 * 2^16 times coordinates (Q16, |.| < 2^31) < 2^47, summed over at most
 * RFS_PATHLOSS_MAX_COARSE (2^10) points < 2^57; the weights sum below 2^26. */
bool rfs_pathloss_mean_op(const void *self, rfs_q16_t temp, rfs_q16_t *x, rfs_q16_t *y)
{
    const rfs_pathloss_t *p = (const rfs_pathloss_t *)self;
    RFS_ASSERT(p != 0 && temp > 0 && x != 0 && y != 0);
    if (!p->valid) {
        return false;
    }
    const rfs_pathloss_lat_t *l = &p->lat;
    const uint32_t nc = (uint32_t)l->ncx * l->ncy;
    const draw_k_t k = draw_consts(p, temp);
    int64_t sw = 0, sx = 0, sy = 0;
    for (uint32_t c = 0u; c < nc; ++c) {
        const uint32_t w = draw_weight(p, &k, c);
        int32_t i, j;
        if (w == 0u || !rfs_pathloss_coarse_ij(p, c, &i, &j)) {
            continue;
        }
        rfs_q16_t cx, cy;
        rfs_pathloss_lattice_xy(l, (uint16_t)i, (uint16_t)j, &cx, &cy);
        sw += w;
        sx += (int64_t)w * cx;
        sy += (int64_t)w * cy;
    }
    if (sw == 0) {
        return false; /* a fit on another lattice has begun since (as the draws) */
    }
    *x = (rfs_q16_t)rfs_sdiv64_round(sx, sw);
    *y = (rfs_q16_t)rfs_sdiv64_round(sy, sw);
    return true;
}
