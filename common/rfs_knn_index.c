/* rfs_knn_index.c - the finer index of a nearest-neighbour model (see rfs_knn_index.h). */
#include "rfs_knn_index.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_knn_internal.h"

/* Sub-cell of a sample along one axis, from its offset to the grid origin (cm):
 * floor(rel F / c), so that sub-cell f lies in grid cell floor(f / F). */
static uint32_t sub_axis_cm(int32_t rel_cm, uint16_t cell_cm)
{
    return (uint32_t)rel_cm * RFS_KNN_FINE / cell_cm;
}

static uint32_t sub_of(const rfs_knn_t *s, const rfs_sample_t *p)
{
    return sub_axis_cm(p->y_cm - s->min_y_cm, s->cell_cm) * ((uint32_t)s->gw * RFS_KNN_FINE) +
           sub_axis_cm(p->x_cm - s->min_x_cm, s->cell_cm);
}

/* Sort key of a position inside a sub-cell: x, then y. */
static uint32_t pos_key(const rfs_sample_t *p)
{
    return (uint32_t)(uint16_t)p->x_cm << 16 | (uint16_t)p->y_cm;
}

/* Stable bottom-up merge sort of entries [a, a + n) by pos_key() (so rank ascending
 * among equal positions), through the scratch arrays. */
static void index_sort(rfs_knn_index_t *ix, uint32_t a, uint32_t n)
{
    for (uint32_t w = 1u; w < n; w *= 2u) {
        for (uint32_t lo = 0u; lo < n; lo += 2u * w) {
            uint32_t mid = lo + w < n ? lo + w : n, hi = lo + 2u * w < n ? lo + 2u * w : n;
            uint32_t i = lo, j = mid, o = lo;
            while (i < mid || j < hi) {
                uint32_t from = (j >= hi || (i < mid && pos_key(&ix->pts[a + i]) <=
                                                            pos_key(&ix->pts[a + j])))
                                    ? i++
                                    : j++;
                ix->tmp_pts[a + o] = ix->pts[a + from];
                ix->tmp_rank[a + o] = ix->rank[a + from];
                o++;
            }
        }
        memcpy(&ix->pts[a], &ix->tmp_pts[a], n * sizeof(ix->pts[0]));
        memcpy(&ix->rank[a], &ix->tmp_rank[a], n * sizeof(ix->rank[0]));
    }
}

/* The attached index of a complete grid: a counting sort of the samples by sub-cell
 * (ascending place in pts within a sub-cell), each sub-cell sorted by position, the
 * position runs and the prefix sums of the targets.
 * Scaling and overflow: sums of <= 10,000 Q9.6 targets fit int32. */
static void index_build(rfs_knn_t *s)
{
    rfs_knn_index_t *ix = s->index;
    uint32_t cells = (uint32_t)s->gw * s->gh * RFS_KNN_FINE * RFS_KNN_FINE;
    memset(ix->start, 0, (cells + 1u) * sizeof(ix->start[0]));
    for (uint32_t p = 0u; p < s->n; ++p) {
        ix->start[sub_of(s, &s->pts[p])]++;
    }
    uint32_t run = 0u;
    for (uint32_t c = 0u; c <= cells; ++c) {
        run += ix->start[c];
        ix->start[c] = (uint16_t)run; /* end of sub-cell c for now */
    }
    for (uint32_t p = s->n; p-- > 0u;) {
        uint32_t at = --ix->start[sub_of(s, &s->pts[p])];
        ix->pts[at] = s->pts[p];
        ix->rank[at] = (uint16_t)p;
    }
    for (uint32_t c = 0u; c < cells; ++c) {
        index_sort(ix, ix->start[c], (uint32_t)ix->start[c + 1u] - ix->start[c]);
    }
    for (uint32_t c = 0u; c < cells; ++c) {
        for (uint32_t k = ix->start[c + 1u]; k-- > ix->start[c];) {
            bool more = k + 1u < ix->start[c + 1u] && pos_key(&ix->pts[k]) == pos_key(&ix->pts[k + 1u]);
            ix->same[k] = (uint16_t)(more ? ix->same[k + 1u] + 1u : 1u);
        }
    }
    ix->psum_q6[0] = 0;
    for (uint32_t k = 0u; k < s->n; ++k) {
        ix->psum_q6[k + 1u] = ix->psum_q6[k] + ix->pts[k].v_q6;
    }
}

/* The whole centimetres of sub-cell f along one axis, as cm Q8 from the origin o (cm):
 * [*lo, *hi], those rel with floor(rel F / c) == f. */
static void sub_span(int16_t o, uint16_t cell_cm, int32_t f, int64_t *lo, int64_t *hi)
{
    /* f <= 256 and cell_cm < 2^15: 32-bit arithmetic (no libgcc on -m32) */
    int64_t a = ((uint32_t)f * cell_cm + RFS_KNN_FINE - 1u) / RFS_KNN_FINE;
    int64_t b = (int64_t)((((uint32_t)f + 1u) * cell_cm + RFS_KNN_FINE - 1u) / RFS_KNN_FINE) - 1;
    *lo = ((int64_t)o + a) * 256;
    *hi = ((int64_t)o + b) * 256;
}

/* Distance from q to [lo, hi] (near) and to its farther end (far), cm Q8. */
static void span_d(int64_t q, int64_t lo, int64_t hi, int64_t *near, int64_t *far)
{
    *near = q < lo ? lo - q : (q > hi ? q - hi : 0);
    *far = q - lo > hi - q ? q - lo : hi - q;
}

/* The k best by (squared distance, key), key = ring << 16 | place in pts: the order in
 * which the plain ring scan meets the samples, so ties at the k-th distance go the same
 * way. Keys are unique. */
typedef struct knn_kbest {
    int64_t d2[RFS_KNN_MAX_K]; /* ascending with key, (cm Q8)^2 */
    uint32_t key[RFS_KNN_MAX_K];
    int16_t v[RFS_KNN_MAX_K]; /* target, Q9.6 */
    uint32_t m;               /* entries held */
    uint32_t k;               /* entries wanted */
} knn_kbest_t;

static bool kbest_before(int64_t d2a, uint32_t ka, int64_t d2b, uint32_t kb)
{
    return d2a < d2b || (d2a == d2b && ka < kb);
}

/* false: refused (not before the k-th held). */
static bool kbest_offer(knn_kbest_t *b, int64_t d2, uint32_t key, int16_t v)
{
    if (b->m == b->k && !kbest_before(d2, key, b->d2[b->m - 1u], b->key[b->m - 1u])) {
        return false;
    }
    uint32_t at = b->m < b->k ? b->m++ : b->m - 1u;
    while (at > 0u && kbest_before(d2, key, b->d2[at - 1u], b->key[at - 1u])) {
        b->d2[at] = b->d2[at - 1u];
        b->key[at] = b->key[at - 1u];
        b->v[at] = b->v[at - 1u];
        --at;
    }
    b->d2[at] = d2;
    b->key[at] = key;
    b->v[at] = v;
    return true;
}

/* Squared distance from the query (cm Q8) to sub-cell (fi, fj)'s whole centimetres. */
static int64_t sub_near2(const rfs_knn_t *s, int32_t fi, int32_t fj, int32_t qx, int32_t qy)
{
    int64_t lo, hi, nx, ny, far;
    sub_span(s->min_x_cm, s->cell_cm, fi, &lo, &hi);
    span_d(qx, lo, hi, &nx, &far);
    sub_span(s->min_y_cm, s->cell_cm, fj, &lo, &hi);
    span_d(qy, lo, hi, &ny, &far);
    return nx * nx + ny * ny;
}

/* Cells (or sub-cells) to visit, nearest first. */
typedef struct knn_visit {
    int64_t near2;
    uint32_t cell;
} knn_visit_t;

/* Insert into v[0, *n), ascending near2. */
static void visit_push(knn_visit_t *v, uint32_t *n, int64_t near2, uint32_t cell)
{
    uint32_t at = (*n)++;
    while (at > 0u && v[at - 1u].near2 > near2) {
        v[at] = v[at - 1u];
        --at;
    }
    v[at].near2 = near2;
    v[at].cell = cell;
}

/* A sub-cell's samples: a position's samples come in rank order, so once one is refused,
 * so are the rest (same distance, later keys). */
static void offer_sub(const rfs_knn_index_t *ix, uint32_t sc, uint32_t ring, int32_t qx,
                      int32_t qy, knn_kbest_t *b)
{
    for (uint32_t k = ix->start[sc]; k < ix->start[sc + 1u];) {
        uint32_t end = k + ix->same[k];
        int64_t d2 = rfs_knn_dist2(&ix->pts[k], qx, qy);
        while (k < end && kbest_offer(b, d2, ring << 16 | ix->rank[k], ix->pts[k].v_q6)) {
            ++k;
        }
        k = end;
    }
}

/* predict_k()'s rings of grid cells and its stop rule, but each ring's cells, and each
 * cell's sub-cells, nearest first, and any whose nearest point is beyond the k-th
 * distance skipped. The k best are by (distance, key), so the order of the visits does
 * not change them. */
static bool predict_k_index(const rfs_knn_t *s, int32_t qx, int32_t qy, rfs_q16_t *value)
{
    const rfs_knn_index_t *ix = s->index;
    knn_kbest_t b;
    b.m = 0u;
    b.k = s->cfg.k < s->n ? s->cfg.k : s->n;
    int32_t c8 = (int32_t)s->cell_cm * 256;
    uint32_t fw = (uint32_t)s->gw * RFS_KNN_FINE;
    knn_visit_t cells[8u * RFS_KNN_GRID], subs[RFS_KNN_FINE * RFS_KNN_FINE];
    int32_t cx = rfs_knn_axis_cell(qx - (int32_t)s->min_x_cm * 256, c8, s->gw);
    int32_t cy = rfs_knn_axis_cell(qy - (int32_t)s->min_y_cm * 256, c8, s->gh);
    int32_t rmax = s->gw > s->gh ? s->gw : s->gh;
    for (int32_t r = 0; r <= rmax; ++r) {
        int32_t i, j;
        uint32_t nc = 0u;
        int32_t j0 = cy - r < 0 ? 0 : cy - r, j1 = cy + r >= s->gh ? s->gh - 1 : cy + r;
        for (j = j0; j <= j1; ++j) {
            bool edge = j == cy - r || j == cy + r;
            int32_t step = edge || r == 0 ? 1 : 2 * r;
            for (i = cx - r; i <= cx + r; i += step) {
                if (i < 0 || i >= s->gw) {
                    continue;
                }
                uint32_t cell = (uint32_t)(j * s->gw + i);
                if (s->start[cell] == s->start[cell + 1u]) {
                    continue;
                }
                int64_t near2 = rfs_knn_cell_near2(s, i, j, qx, qy);
                // NOLINTNEXTLINE(clang-analyzer-core.UndefinedBinaryOperatorResult): valid needs n >= 1, so k >= 1
                if (b.m < b.k || near2 <= b.d2[b.m - 1u]) {
                    visit_push(cells, &nc, near2, cell);
                }
            }
        }
        for (uint32_t c = 0u; c < nc; ++c) {
            if (b.m == b.k && cells[c].near2 > b.d2[b.m - 1u]) {
                break;
            }
            i = (int32_t)(cells[c].cell % s->gw);
            j = (int32_t)(cells[c].cell / s->gw);
            uint32_t ns = 0u;
            for (int32_t fj = j * (int32_t)RFS_KNN_FINE; fj < (j + 1) * (int32_t)RFS_KNN_FINE; ++fj) {
                for (int32_t fi = i * (int32_t)RFS_KNN_FINE; fi < (i + 1) * (int32_t)RFS_KNN_FINE; ++fi) {
                    uint32_t sc = (uint32_t)fj * fw + (uint32_t)fi;
                    if (ix->start[sc] != ix->start[sc + 1u]) {
                        visit_push(subs, &ns, sub_near2(s, fi, fj, qx, qy), sc);
                    }
                }
            }
            for (uint32_t k = 0u; k < ns; ++k) {
                if (b.m == b.k && subs[k].near2 > b.d2[b.m - 1u]) {
                    break;
                }
                offer_sub(ix, subs[k].cell, (uint32_t)r, qx, qy, &b);
            }
        }
        // NOLINTNEXTLINE(clang-analyzer-core.UndefinedBinaryOperatorResult): valid needs n >= 1, so k >= 1
        if (b.m != 0u && rfs_knn_ring_done(b.m, b.k, b.d2[b.m - 1u], r, c8)) {
            break;
        }
    }
    *value = rfs_knn_mean_of(b.v, b.m);
    return true;
}

/* Sub-cell along one axis of a query offset (cm Q8) to the grid origin, clamped. */
static int32_t sub_axis_q8(int64_t rel_q8, int32_t c8, uint8_t cells)
{
    if (rel_q8 < 0) {
        return 0;
    }
    if (rel_q8 >= (int64_t)cells * c8) {
        return (int32_t)(cells * RFS_KNN_FINE - 1u);
    }
    /* below cells * c8 < 2^29, times RFS_KNN_FINE below 2^31: 32-bit division */
    return (int32_t)((uint32_t)rel_q8 * RFS_KNN_FINE / (uint32_t)c8);
}

/* predict_radius() over sub-cells: none of a sub-cell's samples can be within r (skipped),
 * all are (its prefix sums), or each is tested. Sums are exact, so the order is free. */
static bool predict_radius_index(const rfs_knn_t *s, int32_t qx, int32_t qy, rfs_q16_t *value)
{
    const rfs_knn_index_t *ix = s->index;
    rfs_knn_rq_t q;
    if (!rfs_knn_radius_query(s, qx, qy, &q)) {
        return false;
    }
    const int32_t r8 = q.r8, c8 = q.c8, rx = q.rx, ry = q.ry;
    const int64_t r2 = q.r2;
    int32_t i0 = sub_axis_q8((int64_t)rx - r8, c8, s->gw), i1 = sub_axis_q8((int64_t)rx + r8, c8, s->gw);
    int32_t j0 = sub_axis_q8((int64_t)ry - r8, c8, s->gh), j1 = sub_axis_q8((int64_t)ry + r8, c8, s->gh);
    uint32_t fw = (uint32_t)s->gw * RFS_KNN_FINE;
    int32_t sum = 0;
    uint32_t count = 0u;
    for (int32_t fj = j0; fj <= j1; ++fj) {
        int64_t ylo, yhi, ny, fy;
        sub_span(s->min_y_cm, s->cell_cm, fj, &ylo, &yhi);
        span_d(qy, ylo, yhi, &ny, &fy);
        if (ny * ny > r2) {
            continue;
        }
        for (int32_t fi = i0; fi <= i1; ++fi) {
            uint32_t sc = (uint32_t)fj * fw + (uint32_t)fi;
            if (ix->start[sc] == ix->start[sc + 1u]) {
                continue;
            }
            int64_t xlo, xhi, nx, fx;
            sub_span(s->min_x_cm, s->cell_cm, fi, &xlo, &xhi);
            span_d(qx, xlo, xhi, &nx, &fx);
            if (nx * nx + ny * ny > r2) {
                continue;
            }
            uint32_t a = ix->start[sc], e = ix->start[sc + 1u];
            if (fx * fx + fy * fy <= r2) {
                sum += ix->psum_q6[e] - ix->psum_q6[a];
                count += e - a;
                continue;
            }
            for (uint32_t k = a; k < e; k += ix->same[k]) {
                if (rfs_knn_dist2(&ix->pts[k], qx, qy) <= r2) {
                    sum += ix->psum_q6[k + ix->same[k]] - ix->psum_q6[k];
                    count += ix->same[k];
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

static bool index_predict(const rfs_knn_t *s, int32_t qx, int32_t qy, rfs_q16_t *value)
{
    return s->cfg.mode == RFS_KNN_RADIUS ? predict_radius_index(s, qx, qy, value)
                                         : predict_k_index(s, qx, qy, value);
}

void rfs_knn_index_attach(rfs_knn_t *s, rfs_knn_index_t *ix)
{
    RFS_ASSERT(s != NULL);
    s->index = ix;
    if (ix != NULL) {
        ix->build = index_build;
        ix->predict = index_predict;
        if (s->valid) {
            index_build(s);
        }
    }
}
