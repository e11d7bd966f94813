/* rfs_knn_internal.h - private to rfs_knn*.c: the geometry the plain scan (rfs_knn.c)
 * and the attached index (rfs_knn_index.c) share. Not part of the core's API.
 */
#ifndef RFS_KNN_INTERNAL_H
#define RFS_KNN_INTERNAL_H

#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_knn.h"

/* Cell index along one axis of a query coordinate relative to the grid origin (cm Q8),
 * clamped to the grid. */
static inline int32_t rfs_knn_axis_cell(int32_t rel_q8, int32_t cell_q8, uint8_t cells)
{
    if (rel_q8 < 0) {
        return 0;
    }
    int32_t c = rel_q8 / cell_q8;
    return c >= cells ? cells - 1 : c;
}

/* Mean of target values (Q9.6 sum over count) in Q16.16, rounded.
 * Scaling and overflow: the sum of <= 10,000 int16 fits int32; << 10 in int64. */
static inline rfs_q16_t rfs_knn_mean_q16(int32_t sum_q6, uint32_t count)
{
    return rfs_sat32(rfs_sdiv64_round((int64_t)sum_q6 * 1024, (int64_t)count));
}

/* A radius query in grid terms: the radius r8 (cm Q8) and its square, the cell side c8
 * (cm Q8), the query relative to the grid's origin (rx, ry, cm Q8). */
typedef struct rfs_knn_rq {
    int32_t r8;
    int64_t r2;
    int32_t c8;
    int32_t rx;
    int32_t ry;
} rfs_knn_rq_t;

/* Fill *q for the query (qx, qy) (cm Q8); false when the radius's box misses the grid.
 * Scaling and overflow: the radius (Q16 m, <= 2^31) in cm Q8 below 2^31, its square in
 * int64; the grid (at most RFS_KNN_GRID cells of cell_cm a side) in cm Q8 below 2^31. */
static inline bool rfs_knn_radius_query(const rfs_knn_t *s, int32_t qx, int32_t qy, rfs_knn_rq_t *q)
{
    q->r8 = (int32_t)(((int64_t)s->cfg.radius * 100 + 128) >> 8);
    q->r2 = (int64_t)q->r8 * q->r8;
    q->c8 = (int32_t)s->cell_cm * 256;
    q->rx = qx - (int32_t)s->min_x_cm * 256;
    q->ry = qy - (int32_t)s->min_y_cm * 256;
    return !(q->rx + q->r8 < 0 || q->ry + q->r8 < 0 || q->rx - q->r8 >= (int32_t)s->gw * q->c8 ||
             q->ry - q->r8 >= (int32_t)s->gh * q->c8);
}

/* The k values found (Q9.6), their mean in Q16.16 (rfs_knn_mean_q16). */
static inline rfs_q16_t rfs_knn_mean_of(const int16_t *v, uint32_t m)
{
    int32_t sum = 0;
    for (uint32_t i = 0u; i < m; ++i) {
        sum += v[i];
    }
    return rfs_knn_mean_q16(sum, m);
}

/* A ring search may stop after ring r: k found (m == k >= 1) and every cell of ring r + 1
 * lies at least r cells of c8 (cm Q8) away, beyond the k-th distance d2_k.
 * Scaling and overflow: r * c8 below 2^31, its square below 2^62. */
static inline bool rfs_knn_ring_done(uint32_t m, uint32_t k, int64_t d2_k, int32_t r, int32_t c8)
{
    const int64_t reach = (int64_t)r * c8;
    return m == k && reach * reach >= d2_k;
}

/* Squared distance from the query (cm Q8) to a sample, (cm Q8)^2: each difference is
 * below 2^27, the sum of squares below 2^55. */
static inline int64_t rfs_knn_dist2(const rfs_sample_t *p, int32_t qx, int32_t qy)
{
    int64_t dx = (int64_t)p->x_cm * 256 - qx;
    int64_t dy = (int64_t)p->y_cm * 256 - qy;
    return dx * dx + dy * dy;
}

/* Squared distance from the query (cm Q8) to the smallest rectangle holding every sample
 * of cell (i, j): samples are whole centimetres in [i c, (i+1) c - 1] from the origin.
 * Scaling and overflow: as dist2(). */
static inline int64_t rfs_knn_cell_near2(const rfs_knn_t *s, int32_t i, int32_t j, int32_t qx, int32_t qy)
{
    int64_t c8 = (int64_t)s->cell_cm * 256;
    int64_t x0 = (int64_t)s->min_x_cm * 256 + i * c8, y0 = (int64_t)s->min_y_cm * 256 + j * c8;
    int64_t x1 = x0 + c8 - 256, y1 = y0 + c8 - 256;
    int64_t dx = qx < x0 ? x0 - qx : (qx > x1 ? qx - x1 : 0);
    int64_t dy = qy < y0 ? y0 - qy : (qy > y1 ? qy - y1 : 0);
    return dx * dx + dy * dy;
}

#endif /* RFS_KNN_INTERNAL_H */
