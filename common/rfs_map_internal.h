/* rfs_map_internal.h - the exact traversal's integer helpers, shared by rfs_map.c (legality,
 * step patterns) and rfs_map_walls.c (walls crossed); not part of the API (docs/MAPS.md). */
#ifndef RFS_MAP_INTERNAL_H
#define RFS_MAP_INTERNAL_H

#include <stdint.h>

/* floor(a / r) and the smallest i with (i + 1) * r >= a, for |a| < 2^31, r > 0.
 * Scaling and overflow: plain integers; |a| < 2^31 keeps the 32-bit division exact. */
static inline int32_t rfs_map_fdiv(int64_t a, int32_t r)
{
    if (a >= 0) {
        return (int32_t)((uint32_t)a / (uint32_t)r);
    }
    return -(int32_t)(((uint32_t)(-a) + (uint32_t)r - 1u) / (uint32_t)r);
}

/* ceil(a / r) - 1: the last cell of width r ending before coordinate a. Scaling and
 * overflow: rfs_map_fdiv()'s. */
static inline int32_t rfs_map_low_cell(int64_t a, int32_t r)
{
    return -rfs_map_fdiv(-a, r) - 1;
}

#endif
