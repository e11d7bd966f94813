/* rfs_knn.c - k-neighbours and radius-neighbours regression (see rfs_knn.h). */
#include "rfs_knn.h"

#include <string.h>

#include "rfs_assert.h"

/* Fit phases, in order. */
enum {
    KNN_COPY = 0, /* copy the samples, find the bounding box */
    KNN_CLEAR,    /* zero the cell counts */
    KNN_COUNT,    /* count the samples of each cell */
    KNN_PREFIX,   /* counts -> first index of each cell */
    KNN_SORT,     /* in-place bucket sort (American flag sort) */
};

/* Queries farther than this from the origin are clamped (cm Q8: +-2^26 = +-2.6 km),
 * so squared distances stay below 2^55. */
#define KNN_QUERY_LIMIT_Q8 ((int64_t)1 << 26)

rfs_knn_cfg_t rfs_knn_cfg_default(void)
{
    rfs_knn_cfg_t c = {
        .mode = RFS_KNN_KNEIGHBORS,
        .k = 5u,
        .radius = RFS_Q16_ONE,
        .cell = RFS_Q16_ONE,
        .max_samples = RFS_KNN_MAX_SAMPLES,
    };
    return c;
}

rfs_knn_cfg_t rfs_knn_cfg_radius_default(void)
{
    rfs_knn_cfg_t c = rfs_knn_cfg_default();
    c.mode = RFS_KNN_RADIUS;
    return c;
}

int rfs_knn_init(rfs_knn_t *s, const rfs_knn_cfg_t *cfg)
{
    RFS_ASSERT(s != NULL && cfg != NULL);
    if ((cfg->mode != RFS_KNN_KNEIGHBORS && cfg->mode != RFS_KNN_RADIUS) || cfg->k == 0u ||
        cfg->k > RFS_KNN_MAX_K || cfg->radius <= 0 || cfg->radius > RFS_Q16_INT(300) ||
        cfg->cell < RFS_Q16_FRAC(5, 100) || cfg->cell > RFS_Q16_INT(300) ||
        cfg->max_samples == 0u || cfg->max_samples > RFS_KNN_MAX_SAMPLES) {
        return -1;
    }
    memset(s, 0, sizeof(*s));
    s->cfg = *cfg;
    return 0;
}

static uint32_t cell_of(const rfs_knn_t *s, const rfs_sample_t *p)
{
    uint32_t cx = (uint32_t)(p->x_cm - s->min_x_cm) / s->cell_cm;
    uint32_t cy = (uint32_t)(p->y_cm - s->min_y_cm) / s->cell_cm;
    return cy * s->gw + cx;
}

/* Cell side and grid size from the bounding box: at least cfg.cell, and at most
 * RFS_KNN_GRID cells per side (floor(extent / side) < RFS_KNN_GRID). */
static void size_grid(rfs_knn_t *s)
{
    uint32_t ex = (uint32_t)(s->max_x_cm - s->min_x_cm);
    uint32_t ey = (uint32_t)(s->max_y_cm - s->min_y_cm);
    uint32_t cell = (uint32_t)(((int64_t)s->cfg.cell * 100 + 32768) >> 16);
    uint32_t need_x = ex / RFS_KNN_GRID + 1u;
    uint32_t need_y = ey / RFS_KNN_GRID + 1u;
    cell = cell > need_x ? cell : need_x;
    cell = cell > need_y ? cell : need_y;
    s->cell_cm = (uint16_t)cell;
    s->gw = (uint8_t)(ex / cell + 1u);
    s->gh = (uint8_t)(ey / cell + 1u);
}

static void knn_reset(void *self)
{
    rfs_knn_t *s = self;
    s->valid = false;
    s->fitting = false;
}

static rfs_fit_result_t knn_fit(void *self, const rfs_model_fit_in_t *in, uint32_t budget,
                                rfs_rng_t *rng)
{
    rfs_knn_t *s = self;
    RFS_ASSERT(s != NULL && in != NULL);
    (void)rng;
    s->updates = 0u;
    uint16_t n = in->n < s->cfg.max_samples ? in->n : s->cfg.max_samples;
    if (!s->fitting) {
        s->valid = false;
        if (n == 0u || in->samples == NULL) {
            return RFS_FIT_FAILED;
        }
        s->n = n;
        s->phase = KNN_COPY;
        s->pos = 0u;
        s->min_x_cm = s->max_x_cm = in->samples[0].x_cm;
        s->min_y_cm = s->max_y_cm = in->samples[0].y_cm;
        s->fitting = true;
    }
    /* Later slices read only the copy, so a store that changes between calls cannot
     * break the index; the copy itself takes the first n samples as they are then. */
    uint32_t cells = (uint32_t)s->gw * s->gh;
    for (;;) {
        if (budget != 0u && s->updates >= budget) {
            return RFS_FIT_MORE;
        }
        s->updates++;
        switch (s->phase) {
        case KNN_COPY: {
            rfs_sample_t p = in->samples[s->pos];
            s->pts[s->pos] = p;
            s->min_x_cm = p.x_cm < s->min_x_cm ? p.x_cm : s->min_x_cm;
            s->max_x_cm = p.x_cm > s->max_x_cm ? p.x_cm : s->max_x_cm;
            s->min_y_cm = p.y_cm < s->min_y_cm ? p.y_cm : s->min_y_cm;
            s->max_y_cm = p.y_cm > s->max_y_cm ? p.y_cm : s->max_y_cm;
            if (++s->pos == s->n) {
                size_grid(s);
                cells = (uint32_t)s->gw * s->gh;
                s->phase = KNN_CLEAR;
                s->pos = 0u;
            }
            break;
        }
        case KNN_CLEAR:
            s->start[s->pos] = 0u;
            if (++s->pos == cells + 1u) {
                s->phase = KNN_COUNT;
                s->pos = 0u;
            }
            break;
        case KNN_COUNT:
            s->start[cell_of(s, &s->pts[s->pos]) + 1u]++;
            if (++s->pos == s->n) {
                s->phase = KNN_PREFIX;
                s->pos = 0u;
            }
            break;
        case KNN_PREFIX:
            s->start[s->pos + 1u] = (uint16_t)(s->start[s->pos + 1u] + s->start[s->pos]);
            s->cursor[s->pos] = s->start[s->pos];
            if (++s->pos == cells) {
                s->phase = KNN_SORT;
                s->pos = 0u;
            }
            break;
        default: { /* KNN_SORT: pos is the bucket being filled */
            uint32_t b = s->pos;
            if (s->cursor[b] == s->start[b + 1u]) {
                if (++s->pos == cells) {
                    s->fitting = false;
                    s->valid = true;
                    return RFS_FIT_DONE;
                }
                break;
            }
            uint32_t c = cell_of(s, &s->pts[s->cursor[b]]);
            if (c == b) {
                s->cursor[b]++;
            } else {
                /* Each swap puts one sample into its own bucket for good. */
                rfs_sample_t t = s->pts[s->cursor[c]];
                s->pts[s->cursor[c]] = s->pts[s->cursor[b]];
                s->pts[s->cursor[b]] = t;
                s->cursor[c]++;
            }
            break;
        }
        }
    }
}

/* Query in centimetres Q24.8, clamped. Scaling: metres Q16.16 x 100 >> 8. */
static int32_t query_q8(rfs_q16_t v)
{
    int64_t q = ((int64_t)v * 100 + 128) >> 8;
    q = q > KNN_QUERY_LIMIT_Q8 ? KNN_QUERY_LIMIT_Q8 : (q < -KNN_QUERY_LIMIT_Q8 ? -KNN_QUERY_LIMIT_Q8 : q);
    return (int32_t)q;
}

/* Cell index along one axis of a query coordinate relative to the grid origin (cm Q8),
 * clamped to the grid. */
static int32_t axis_cell(int32_t rel_q8, int32_t cell_q8, uint8_t cells)
{
    if (rel_q8 < 0) {
        return 0;
    }
    int32_t c = rel_q8 / cell_q8;
    return c >= cells ? cells - 1 : c;
}

/* Mean of target values (Q9.6 sum over count) in Q16.16, rounded.
 * Scaling and overflow: the sum of <= 10,000 int16 fits int32; << 10 in int64. */
static rfs_q16_t mean_q16(int32_t sum_q6, uint32_t count)
{
    return rfs_sat32(rfs_sdiv64_round((int64_t)sum_q6 * 1024, (int64_t)count));
}

/* Squared distance from the query (cm Q8) to a sample, (cm Q8)^2: each difference is
 * below 2^27, the sum of squares below 2^55. */
static int64_t dist2(const rfs_sample_t *p, int32_t qx, int32_t qy)
{
    int64_t dx = (int64_t)p->x_cm * 256 - qx;
    int64_t dy = (int64_t)p->y_cm * 256 - qy;
    return dx * dx + dy * dy;
}

typedef struct knn_best {
    int64_t d2[RFS_KNN_MAX_K]; /* ascending, (cm Q8)^2 */
    int16_t v[RFS_KNN_MAX_K];  /* target, Q9.6 */
    uint32_t m;                /* entries held */
    uint32_t k;                /* entries wanted */
} knn_best_t;

static void scan_cell_k(const rfs_knn_t *s, uint32_t cell, int32_t qx, int32_t qy, knn_best_t *b)
{
    for (uint32_t i = s->start[cell]; i < s->start[cell + 1u]; ++i) {
        int64_t d2 = dist2(&s->pts[i], qx, qy);
        // NOLINTNEXTLINE(clang-analyzer-core.UndefinedBinaryOperatorResult): valid needs n >= 1, so k >= 1
        if (b->m == b->k && d2 >= b->d2[b->m - 1u]) {
            continue;
        }
        uint32_t at = b->m < b->k ? b->m++ : b->m - 1u;
        while (at > 0u && b->d2[at - 1u] > d2) {
            b->d2[at] = b->d2[at - 1u];
            b->v[at] = b->v[at - 1u];
            --at;
        }
        b->d2[at] = d2;
        b->v[at] = s->pts[i].v_q6;
    }
}

/* Rings of cells around the query's cell, nearest first; after ring r every cell not
 * yet visited is at least r cells away in x or y, so the search stops once the k-th
 * distance is within r cell sides. */
static bool predict_k(const rfs_knn_t *s, int32_t qx, int32_t qy, rfs_q16_t *value)
{
    knn_best_t b;
    b.m = 0u;
    b.k = s->cfg.k < s->n ? s->cfg.k : s->n;
    int32_t c8 = (int32_t)s->cell_cm * 256;
    int32_t cx = axis_cell(qx - (int32_t)s->min_x_cm * 256, c8, s->gw);
    int32_t cy = axis_cell(qy - (int32_t)s->min_y_cm * 256, c8, s->gh);
    int32_t rmax = s->gw > s->gh ? s->gw : s->gh;
    for (int32_t r = 0; r <= rmax; ++r) {
        for (int32_t j = cy - r; j <= cy + r; ++j) {
            if (j < 0 || j >= s->gh) {
                continue;
            }
            bool edge_row = (j == cy - r) || (j == cy + r);
            int32_t step = edge_row || r == 0 ? 1 : 2 * r;
            for (int32_t i = cx - r; i <= cx + r; i += step) {
                if (i >= 0 && i < s->gw) {
                    scan_cell_k(s, (uint32_t)(j * s->gw + i), qx, qy, &b);
                }
            }
        }
        int64_t reach = (int64_t)r * c8;
        // NOLINTNEXTLINE(clang-analyzer-core.UndefinedBinaryOperatorResult): valid needs n >= 1, so k >= 1
        if (b.m == b.k && reach * reach >= b.d2[b.m - 1u]) {
            break;
        }
    }
    int32_t sum = 0;
    for (uint32_t i = 0u; i < b.m; ++i) {
        sum += b.v[i];
    }
    *value = mean_q16(sum, b.m);
    return true;
}

static bool predict_radius(const rfs_knn_t *s, int32_t qx, int32_t qy, rfs_q16_t *value)
{
    int32_t r8 = (int32_t)(((int64_t)s->cfg.radius * 100 + 128) >> 8);
    int64_t r2 = (int64_t)r8 * r8;
    int32_t c8 = (int32_t)s->cell_cm * 256;
    int32_t rx = qx - (int32_t)s->min_x_cm * 256;
    int32_t ry = qy - (int32_t)s->min_y_cm * 256;
    if (rx + r8 < 0 || ry + r8 < 0 || rx - r8 >= (int32_t)s->gw * c8 ||
        ry - r8 >= (int32_t)s->gh * c8) {
        return false;
    }
    int32_t i0 = axis_cell(rx - r8, c8, s->gw), i1 = axis_cell(rx + r8, c8, s->gw);
    int32_t j0 = axis_cell(ry - r8, c8, s->gh), j1 = axis_cell(ry + r8, c8, s->gh);
    int32_t sum = 0;
    uint32_t count = 0u;
    for (int32_t j = j0; j <= j1; ++j) {
        for (int32_t i = i0; i <= i1; ++i) {
            uint32_t cell = (uint32_t)(j * s->gw + i);
            for (uint32_t k = s->start[cell]; k < s->start[cell + 1u]; ++k) {
                if (dist2(&s->pts[k], qx, qy) <= r2) {
                    sum += s->pts[k].v_q6;
                    count++;
                }
            }
        }
    }
    if (count == 0u) {
        return false;
    }
    *value = mean_q16(sum, count);
    return true;
}

static bool knn_predict(const void *self, rfs_q16_t x, rfs_q16_t y, rfs_q16_t *value)
{
    const rfs_knn_t *s = self;
    RFS_ASSERT(s != NULL && value != NULL);
    if (!s->valid) {
        return false;
    }
    int32_t qx = query_q8(x), qy = query_q8(y);
    return s->cfg.mode == RFS_KNN_RADIUS ? predict_radius(s, qx, qy, value)
                                         : predict_k(s, qx, qy, value);
}

const rfs_model_ops_t rfs_knn_ops = {
    .name = "knn",
    .reset = knn_reset,
    .fit = knn_fit,
    .predict = knn_predict,
    .argmax = NULL,
};

const rfs_model_ops_t rfs_radius_ops = {
    .name = "radius",
    .reset = knn_reset,
    .fit = knn_fit,
    .predict = knn_predict,
    .argmax = NULL,
};

rfs_model_t rfs_knn_model(rfs_knn_t *s)
{
    rfs_model_t m = {
        .ops = s->cfg.mode == RFS_KNN_RADIUS ? &rfs_radius_ops : &rfs_knn_ops,
        .self = s,
    };
    return m;
}
