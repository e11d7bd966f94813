/* rfs_reach.h - reachability on the map's lattice: which lattice points the robot can
 * drive to (paper section 2: "movements are restricted to legal movements").
 *
 * A lattice bit array holds one bit per lattice point (idx = j * lw + i: bit idx & 7 of
 * byte idx >> 3). rfs_reach_fill() marks the robot's component of the lattice graph
 * (8 neighbours, an edge where the straight segment between the points is legal), so that
 * greedy maxima and epsilon goals never lie in a pocket of the map the robot cannot reach
 * (SLAM maps have many), and the planner refuses a goal outside it without a search
 * (rfs_plan_set_component).
 */
#ifndef RFS_REACH_H
#define RFS_REACH_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_map.h"

/// How far (lattice steps) rfs_reach_snap() looks for a legal lattice point.
#define RFS_REACH_SNAP_RADIUS 6

/// Bytes of one lattice bit array for a map: (lw * lh + 7) / 8.
uint32_t rfs_reach_bytes(const rfs_map_t *map);

/// Bit idx of a lattice bit array.
static inline bool rfs_reach_bit(const uint8_t *bits, uint32_t idx)
{
    return (bits[idx >> 3] >> (idx & 7u)) & 1u;
}

/// Set bit idx of a lattice bit array.
static inline void rfs_reach_bit_set(uint8_t *bits, uint32_t idx)
{
    bits[idx >> 3] = (uint8_t)(bits[idx >> 3] | (1u << (idx & 7u)));
}

/// Lattice point (i, j) is set in `reach`.
static inline bool rfs_reach_at(const rfs_map_t *map, const uint8_t *reach, uint16_t i,
                                uint16_t j)
{
    return rfs_reach_bit(reach, (uint32_t)j * map->lw + i);
}

/// The legal lattice point nearest to (x, y) (metres Q16.16), searched in square rings
/// round the nearest lattice point up to RFS_REACH_SNAP_RADIUS, the smallest squared
/// lattice offset first, row-major within a ring at a tie. With `reach` (NULL: any legal
/// point) it must also be set there. false when there is none.
bool rfs_reach_snap(const rfs_map_t *map, const uint8_t *reach, rfs_q16_t x, rfs_q16_t y,
                    uint16_t *oi, uint16_t *oj);

/// rfs_reach_snap(), but the point must be clear in `reach` (outside that component).
bool rfs_reach_snap_outside(const rfs_map_t *map, const uint8_t *reach, rfs_q16_t x,
                            rfs_q16_t y, uint16_t *oi, uint16_t *oj);

/// Fill `reach` (rfs_reach_bytes(map) bytes) with the component of the lattice graph
/// that holds the legal lattice point nearest to (x, y) (rfs_reach_snap). `queue` (cap
/// entries, >= 1) is the flood's work memory; when it is too small for the frontier every
/// legal point is marked instead (still a union of whole components). false, and no bit
/// set, when no legal lattice point lies within RFS_REACH_SNAP_RADIUS of (x, y).
bool rfs_reach_fill(const rfs_map_t *map, rfs_q16_t x, rfs_q16_t y, uint8_t *reach,
                    uint32_t *queue, uint32_t cap);

/// A flood fill in progress (rfs_reach_flood_begin(), rfs_reach_flood_run()): its queue
/// window and whether the queue overflowed.
typedef struct rfs_reach_flood {
    uint32_t head;  ///< queue index of the next point to expand
    uint32_t count; ///< points queued, 0 when the flood is over
    bool overflow;  ///< a point was marked but not queued (queue too small)
    uint32_t marked; ///< points marked so far (UINT32_MAX once every legal point is)
} rfs_reach_flood_t;
/// rfs_reach_fill() in slices: clear `reach` and queue the legal lattice point nearest to
/// (x, y) (rfs_reach_snap). false, and no bit set, when there is none within
/// RFS_REACH_SNAP_RADIUS.
bool rfs_reach_flood_begin(rfs_reach_flood_t *f, const rfs_map_t *map, rfs_q16_t x,
                           rfs_q16_t y, uint8_t *reach, uint32_t *queue);
/// Expand up to `budget` queued points (0: all) of flood f, with the same `reach`,
/// `queue` and `cap` as before. true when the flood is over: `reach` then equals
/// rfs_reach_fill()'s.
bool rfs_reach_flood_run(rfs_reach_flood_t *f, const rfs_map_t *map, uint8_t *reach,
                         uint32_t *queue, uint32_t cap, uint32_t budget);
/// The point set in `reach` nearest to (x, y) by squared lattice offset from (x, y)'s
/// nearest lattice point, first in row-major order at a tie, as metres Q16.16, by a scan
/// of all lw x lh points (squared offsets < 2^32 in int64). false when none is set.
bool rfs_reach_nearest(const rfs_map_t *map, const uint8_t *reach, rfs_q16_t x, rfs_q16_t y,
                       rfs_q16_t *ox, rfs_q16_t *oy);

#endif /* RFS_REACH_H */
