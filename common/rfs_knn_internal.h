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
