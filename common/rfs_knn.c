/* rfs_knn.c - k-neighbours and radius-neighbours regression (see rfs_knn.h). */
#include "rfs_knn.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_knn_index.h"
#include "rfs_knn_internal.h"

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
                    if (s->index != NULL) {
                        s->index->build(s);
                    }
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




typedef struct knn_best {
    int64_t d2[RFS_KNN_MAX_K]; /* ascending, (cm Q8)^2 */
    int16_t v[RFS_KNN_MAX_K];  /* target, Q9.6 */
    uint32_t m;                /* entries held */
    uint32_t k;                /* entries wanted */
} knn_best_t;


/* A cell none of whose samples can enter the k best is skipped: each would be rejected
 * (d2 >= the k-th), so the result, ties included, is the full ring scan's. */
static void scan_cell_k(const rfs_knn_t *s, uint32_t cell, int32_t qx, int32_t qy, knn_best_t *b)
{
    if (b->m == b->k && s->start[cell] != s->start[cell + 1u]) {
        int64_t near2 = rfs_knn_cell_near2(s, (int32_t)(cell % s->gw), (int32_t)(cell / s->gw), qx, qy);
        // NOLINTNEXTLINE(clang-analyzer-core.UndefinedBinaryOperatorResult): valid needs n >= 1, so k >= 1
        if (near2 >= b->d2[b->m - 1u]) {
            return;
        }
    }
    for (uint32_t i = s->start[cell]; i < s->start[cell + 1u]; ++i) {
        int64_t d2 = rfs_knn_dist2(&s->pts[i], qx, qy);
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

/* A walk over the rings of grid cells around a centre cell, nearest first: ring r is the
 * square of cells r away in x or y (ring 0 the centre), visited row by row, left to right,
 * cells outside the grid skipped. Rings run from 0 to max(gw, gh), by which every cell has
 * been visited; the caller stops earlier once no farther cell can matter. */
typedef struct knn_ring {
    int32_t cx, cy; /* centre cell */
    int32_t r;      /* current ring */
    int32_t i, j;   /* next cell of the ring to consider (column, row) */
} knn_ring_t;

/* Start ring r; false once r is past the last ring. */
static bool ring_start(const rfs_knn_t *s, knn_ring_t *it, int32_t r)
{
    it->r = r;
    it->i = it->cx - r;
    it->j = it->cy - r;
    return r <= (s->gw > s->gh ? s->gw : s->gh);
}

/* The next cell of the current ring inside the grid: (*i, *j); false when the ring is done.
 * Inner rows of a ring hold only their two end cells (step 2 r). */
static bool ring_next(const rfs_knn_t *s, knn_ring_t *it, int32_t *i, int32_t *j)
{
    for (; it->j <= it->cy + it->r; ++it->j, it->i = it->cx - it->r) {
        if (it->j < 0 || it->j >= s->gh) {
            continue;
        }
        bool edge_row = (it->j == it->cy - it->r) || (it->j == it->cy + it->r);
        int32_t step = edge_row || it->r == 0 ? 1 : 2 * it->r;
        while (it->i <= it->cx + it->r) {
            int32_t at = it->i;
            it->i += step;
            if (at >= 0 && at < s->gw) {
                *i = at;
                *j = it->j;
                return true;
            }
        }
    }
    return false;
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
    knn_ring_t ring;
    ring.cx = rfs_knn_axis_cell(qx - (int32_t)s->min_x_cm * 256, c8, s->gw);
    ring.cy = rfs_knn_axis_cell(qy - (int32_t)s->min_y_cm * 256, c8, s->gh);
    for (int32_t r = 0; ring_start(s, &ring, r); ++r) {
        int32_t i, j;
        while (ring_next(s, &ring, &i, &j)) {
            scan_cell_k(s, (uint32_t)(j * s->gw + i), qx, qy, &b);
        }
        // NOLINTNEXTLINE(clang-analyzer-core.UndefinedBinaryOperatorResult): valid needs n >= 1, so k >= 1
        if (b.m != 0u && rfs_knn_ring_done(b.m, b.k, b.d2[b.m - 1u], r, c8)) {
            break;
        }
    }
    *value = rfs_knn_mean_of(b.v, b.m);
    return true;
}

static bool predict_radius(const rfs_knn_t *s, int32_t qx, int32_t qy, rfs_q16_t *value)
{
    rfs_knn_rq_t q;
    if (!rfs_knn_radius_query(s, qx, qy, &q)) {
        return false;
    }
    const int32_t r8 = q.r8, c8 = q.c8, rx = q.rx, ry = q.ry;
    const int64_t r2 = q.r2;
    int32_t i0 = rfs_knn_axis_cell(rx - r8, c8, s->gw), i1 = rfs_knn_axis_cell(rx + r8, c8, s->gw);
    int32_t j0 = rfs_knn_axis_cell(ry - r8, c8, s->gh), j1 = rfs_knn_axis_cell(ry + r8, c8, s->gh);
    int32_t sum = 0;
    uint32_t count = 0u;
    for (int32_t j = j0; j <= j1; ++j) {
        for (int32_t i = i0; i <= i1; ++i) {
            uint32_t cell = (uint32_t)(j * s->gw + i);
            for (uint32_t k = s->start[cell]; k < s->start[cell + 1u]; ++k) {
                if (rfs_knn_dist2(&s->pts[k], qx, qy) <= r2) {
                    sum += s->pts[k].v_q6;
                    count++;
                }
            }
        }
    }
    if (count == 0u) {
        return false;
    }
    *value = rfs_knn_mean_q16(sum, count);
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
    if (s->index != NULL) {
        return s->index->predict(s, qx, qy, value);
    }
    return s->cfg.mode == RFS_KNN_RADIUS ? predict_radius(s, qx, qy, value)
                                         : predict_k(s, qx, qy, value);
}

/* --- Upper bound over a box (the grid search's branch and bound, rfs_gridmax.h) --- */

/* A query box in cm Q24.8: query_q8() is non-decreasing, so every query in the metre box
 * maps into the box of the rounded corners. */
typedef struct knn_box {
    int32_t x0, y0, x1, y1; /* cm Q8, x0 <= x1, y0 <= y1 */
} knn_box_t;

/* Squared distances from a sample to the nearest and to the farthest point of the box,
 * (cm Q8)^2. Scaling and overflow: coordinates below 2^26 + 2^23, differences below 2^28,
 * each sum of squares below 2^57. */
static void box_d2(const rfs_sample_t *p, const knn_box_t *b, int64_t *near2, int64_t *far2)
{
    int64_t px = (int64_t)p->x_cm * 256, py = (int64_t)p->y_cm * 256;
    int64_t nx = px < b->x0 ? b->x0 - px : (px > b->x1 ? px - b->x1 : 0);
    int64_t ny = py < b->y0 ? b->y0 - py : (py > b->y1 ? py - b->y1 : 0);
    int64_t fx = px - b->x0 > b->x1 - px ? px - b->x0 : b->x1 - px;
    int64_t fy = py - b->y0 > b->y1 - py ? py - b->y0 : b->y1 - py;
    *near2 = nx * nx + ny * ny;
    *far2 = fx * fx + fy * fy;
}

/* Grid cells along one axis holding samples within `d` (cm Q8) of [lo, hi] (cm Q8
 * relative to the grid origin): [*a, *b]; false when there is none. */
static bool axis_span(int64_t lo, int64_t hi, int64_t d, int32_t c8, uint8_t cells, int32_t *a,
                      int32_t *b)
{
    lo -= d;
    hi += d;
    if (hi < 0 || lo >= (int64_t)cells * c8) {
        return false;
    }
    /* In range, both are below cells * c8 < 2^29: 32-bit division (no libgcc on -m32). */
    *a = lo < 0 ? 0 : (int32_t)lo / c8;
    *b = hi >= (int64_t)cells * c8 ? cells - 1 : (int32_t)hi / c8;
    return true;
}

/* Over the samples a cell (i, j) can hold (whole centimetres in [i c, (i+1) c - 1] from
 * the origin): the smallest squared near distance to the box (far == false), or the
 * smallest squared far distance (far == true; along x the far distance
 * max(px - x0, x1 - px) is smallest at the point nearest the box's middle), (cm Q8)^2.
 * Scaling and overflow: as box_d2(). */
static int64_t cell_box_d2(const rfs_knn_t *s, int32_t i, int32_t j, const knn_box_t *b, bool far)
{
    int64_t c8 = (int64_t)s->cell_cm * 256;
    int64_t lo[2] = {(int64_t)s->min_x_cm * 256 + i * c8, (int64_t)s->min_y_cm * 256 + j * c8};
    int64_t b0[2] = {b->x0, b->y0}, b1[2] = {b->x1, b->y1};
    int64_t d2 = 0;
    for (int a = 0; a < 2; ++a) {
        int64_t hi = lo[a] + c8 - 256, d;
        if (far) {
            int64_t mid = b0[a] + (b1[a] - b0[a]) / 2;
            int64_t p = mid < lo[a] ? lo[a] : (mid > hi ? hi : mid);
            d = p - b0[a] > b1[a] - p ? p - b0[a] : b1[a] - p;
        } else {
            d = hi < b0[a] ? b0[a] - hi : (lo[a] > b1[a] ? lo[a] - b1[a] : 0);
        }
        d2 += d * d;
    }
    return d2;
}

/* The kk-th smallest far distance: rings of cells around the cell of the box's centre
 * m (rounded down to c), nearest first. The far distance of a sample p along x is
 * |px - mx| + (x1 - x0) / 2; a sample in a cell outside ring r has |px - mx| > r c8 - 1
 * along x or y (cells are [i c8, (i+1) c8) from the origin), so its squared far distance
 * exceeds (r c8 - 1)^2 + hx^2 + hy^2 (hx, hy: half the box sides, rounded down).
 * Scaling and overflow: r c8 < 2^30, half sides below 2^27: the sum is below 2^62. */
static int64_t kth_far2(const rfs_knn_t *s, const knn_box_t *b, uint32_t kk)
{
    RFS_ASSERT(kk >= 1u && kk <= RFS_KNN_MAX_K && kk <= s->n);
    int64_t far[RFS_KNN_MAX_K] = {0};
    uint32_t m = 0u;
    int32_t c8 = (int32_t)s->cell_cm * 256;
    int32_t ox = (int32_t)s->min_x_cm * 256, oy = (int32_t)s->min_y_cm * 256;
    int64_t hx = ((int64_t)b->x1 - b->x0) / 2, hy = ((int64_t)b->y1 - b->y0) / 2;
    knn_ring_t ring;
    ring.cx = rfs_knn_axis_cell((int32_t)(b->x0 + hx) - ox, c8, s->gw);
    ring.cy = rfs_knn_axis_cell((int32_t)(b->y0 + hy) - oy, c8, s->gh);
    for (int32_t r = 0; ring_start(s, &ring, r); ++r) {
        int32_t i, j;
        while (ring_next(s, &ring, &i, &j)) {
            uint32_t cell = (uint32_t)(j * s->gw + i);
            if (m == kk && s->start[cell] != s->start[cell + 1u] &&
                cell_box_d2(s, i, j, b, true) >= far[kk - 1u]) {
                continue;
            }
            for (uint32_t k = s->start[cell]; k < s->start[cell + 1u]; ++k) {
                int64_t n2, f2;
                box_d2(&s->pts[k], b, &n2, &f2);
                if (m == kk && f2 >= far[kk - 1u]) {
                    continue;
                }
                uint32_t at = m < kk ? m++ : m - 1u;
                while (at > 0u && far[at - 1u] > f2) {
                    far[at] = far[at - 1u];
                    --at;
                }
                far[at] = f2;
            }
        }
        int64_t reach = r > 0 ? (int64_t)r * c8 - 1 : 0;
        if (m == kk && reach * reach + hx * hx + hy * hy >= far[kk - 1u]) {
            break;
        }
    }
    return far[kk - 1u];
}

/* Insert target v into top[0, *m), kept descending; once *m == cap the smallest held
 * makes room (the caller has checked that v is larger). */
static void top_insert(int16_t *top, uint32_t *m, uint32_t cap, int16_t v)
{
    uint32_t at = *m < cap ? (*m)++ : *m - 1u;
    while (at > 0u && top[at - 1u] < v) {
        top[at] = top[at - 1u];
        --at;
    }
    top[at] = v;
}

/* k-neighbours: a query q of the box has its kk nearest samples within kth(q) of it, and
 * kth(q) <= U, the kk-th smallest far distance (those kk samples are all within U of q);
 * so each of them has its near distance <= U. Their mean is at most the mean of the kk
 * largest targets among the samples with near distance <= U; rfs_knn_mean_q16() is monotone in
 * the sum, so the bound holds after rounding, bit for bit. */
static bool bound_k(const rfs_knn_t *s, const knn_box_t *b, rfs_q16_t *ub)
{
    uint32_t kk = s->cfg.k < s->n ? s->cfg.k : s->n;
    int64_t u2 = kth_far2(s, b, kk);
    int32_t c8 = (int32_t)s->cell_cm * 256;
    int64_t d = rfs_isqrt64((uint64_t)u2); /* ceil(sqrt(u2)), cm Q8, below 2^29 */
    d += d * d < u2 ? 1 : 0;
    int32_t ox = (int32_t)s->min_x_cm * 256, oy = (int32_t)s->min_y_cm * 256;
    int32_t i0 = 0, i1 = -1, j0 = 0, j1 = -1; /* the kk samples within d: never empty */
    (void)axis_span((int64_t)b->x0 - ox, (int64_t)b->x1 - ox, d, c8, s->gw, &i0, &i1);
    (void)axis_span((int64_t)b->y0 - oy, (int64_t)b->y1 - oy, d, c8, s->gh, &j0, &j1);
    int16_t top[RFS_KNN_MAX_K]; /* descending, Q9.6 */
    uint32_t m = 0u;
    for (int32_t j = j0; j <= j1; ++j) {
        for (int32_t i = i0; i <= i1; ++i) {
            uint32_t cell = (uint32_t)(j * s->gw + i);
            if (s->start[cell] == s->start[cell + 1u] || cell_box_d2(s, i, j, b, false) > u2) {
                continue;
            }
            for (uint32_t k = s->start[cell]; k < s->start[cell + 1u]; ++k) {
                int16_t v = s->pts[k].v_q6;
                // NOLINTNEXTLINE(clang-analyzer-core.UndefinedBinaryOperatorResult): valid needs n >= 1, so kk >= 1
                if (m == kk && v <= top[m - 1u]) {
                    continue;
                }
                int64_t n2, f2;
                box_d2(&s->pts[k], b, &n2, &f2);
                if (n2 > u2) {
                    continue;
                }
                top_insert(top, &m, kk, v);
            }
        }
    }
    /* m == kk: the kk samples that define u2 have near <= far <= u2. */
    int32_t sum = 0;
    for (uint32_t i = 0u; i < m; ++i) {
        sum += top[i];
    }
    *ub = rfs_knn_mean_q16(sum, m);
    return true;
}

/* Radius: a sample whose far distance is <= r is in every query's neighbourhood (the
 * "core"; none: some query may have no prediction, so no promise); the others that can
 * be are those with near distance <= r. A query's mean is over the core plus a subset
 * T of the others, at most max_j mean(core + the j largest others); with only the
 * RFS_KNN_MAX_K largest others held, any dropped one is <= the smallest held, which then
 * bounds the rest (a mean of two parts is at most the larger part's mean). Means are
 * compared exactly (cross products: sums below 2^29, counts below 2^14) and rounded once
 * by rfs_knn_mean_q16(), which is monotone. */
static bool bound_radius(const rfs_knn_t *s, const knn_box_t *b, rfs_q16_t *ub)
{
    int32_t r8 = (int32_t)(((int64_t)s->cfg.radius * 100 + 128) >> 8);
    int64_t r2 = (int64_t)r8 * r8;
    int32_t c8 = (int32_t)s->cell_cm * 256;
    int32_t ox = (int32_t)s->min_x_cm * 256, oy = (int32_t)s->min_y_cm * 256;
    int32_t i0, i1, j0, j1;
    if (!axis_span((int64_t)b->x0 - ox, (int64_t)b->x1 - ox, r8, c8, s->gw, &i0, &i1) ||
        !axis_span((int64_t)b->y0 - oy, (int64_t)b->y1 - oy, r8, c8, s->gh, &j0, &j1)) {
        return false;
    }
    int32_t core_sum = 0;
    uint32_t core_n = 0u;
    int16_t top[RFS_KNN_MAX_K]; /* the largest others, descending, Q9.6 */
    uint32_t m = 0u;
    bool dropped = false;
    for (int32_t j = j0; j <= j1; ++j) {
        for (int32_t i = i0; i <= i1; ++i) {
            uint32_t cell = (uint32_t)(j * s->gw + i);
            if (s->start[cell] == s->start[cell + 1u] || cell_box_d2(s, i, j, b, false) > r2) {
                continue;
            }
            for (uint32_t k = s->start[cell]; k < s->start[cell + 1u]; ++k) {
                int64_t n2, f2;
                box_d2(&s->pts[k], b, &n2, &f2);
                int16_t v = s->pts[k].v_q6;
                if (f2 <= r2) {
                    core_sum += v;
                    core_n++;
                    continue;
                }
                if (n2 > r2) {
                    continue;
                }
                if (m == RFS_KNN_MAX_K) {
                    dropped = true;
                    if (v <= top[m - 1u]) {
                        continue;
                    }
                }
                top_insert(top, &m, RFS_KNN_MAX_K, v);
            }
        }
    }
    if (core_n == 0u) {
        return false;
    }
    int32_t best_sum = core_sum, sum = core_sum;
    uint32_t best_n = core_n, n = core_n;
    for (uint32_t i = 0u; i < m; ++i) {
        sum += top[i];
        n++;
        if ((int64_t)sum * best_n > (int64_t)best_sum * n) {
            best_sum = sum;
            best_n = n;
        }
    }
    if (dropped && (int64_t)top[m - 1u] * best_n > (int64_t)best_sum) {
        best_sum = top[m - 1u];
        best_n = 1u;
    }
    *ub = rfs_knn_mean_q16(best_sum, best_n);
    return true;
}

static bool knn_bound(const void *self, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1,
                      rfs_q16_t *ub)
{
    const rfs_knn_t *s = self;
    RFS_ASSERT(s != NULL && ub != NULL && x0 <= x1 && y0 <= y1);
    if (!s->valid) {
        return false;
    }
    knn_box_t b = {query_q8(x0), query_q8(y0), query_q8(x1), query_q8(y1)};
    return s->cfg.mode == RFS_KNN_RADIUS ? bound_radius(s, &b, ub) : bound_k(s, &b, ub);
}

const rfs_model_ops_t rfs_knn_ops = {
    .name = "knn",
    .reset = knn_reset,
    .fit = knn_fit,
    .predict = knn_predict,
    .argmax = NULL,
    .bound = knn_bound,
};

const rfs_model_ops_t rfs_radius_ops = {
    .name = "radius",
    .reset = knn_reset,
    .fit = knn_fit,
    .predict = knn_predict,
    .argmax = NULL,
    .bound = knn_bound,
};

rfs_model_t rfs_knn_model(rfs_knn_t *s)
{
    rfs_model_t m = {
        .ops = s->cfg.mode == RFS_KNN_RADIUS ? &rfs_radius_ops : &rfs_knn_ops,
        .self = s,
    };
    return m;
}
