/* rfs_plan.h - shortest paths on the map lattice (the paper's robot used the ROS
 * navigation stack; the controller plans for itself).
 *
 * Breadth-first wavefront over the legal lattice points (8-connected, an edge exists
 * when the straight segment between the two points is legal), from the goal's lattice
 * point outward until the start's is reached, with diagonal steps costing 3/2 of
 * straight ones (octile approximation). The path is then shortened by string pulling:
 * from each kept waypoint, the farthest later waypoint reachable by a legal straight
 * segment. Work memory is caller-owned: one byte per lattice point and a queue.
 */
#ifndef RFS_PLAN_H
#define RFS_PLAN_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_map.h"

/// Most waypoints a plan returns.
#define RFS_PLAN_MAX_WAYPOINTS 64u

/// Planner state: caller-owned work arrays sized for the map's lattice.
typedef struct rfs_plan {
    const rfs_map_t *map;   ///< the map planned on
    uint8_t *work;          ///< lw * lh bytes: visit marks and back-pointers
    uint32_t *queue;        ///< wavefront queue of lattice indices
    uint32_t queue_cap;     ///< its capacity (>= lw + lh is enough for most maps; 2*(lw+lh) safe)
    uint32_t expanded;      ///< lattice points expanded by the last search (for benchmarks)
} rfs_plan_t;

/// A planned path: waypoints in order, the last one the goal itself.
typedef struct rfs_path {
    rfs_q16_t x[RFS_PLAN_MAX_WAYPOINTS]; ///< metres, Q16.16
    rfs_q16_t y[RFS_PLAN_MAX_WAYPOINTS]; ///< metres, Q16.16
    uint16_t n;                           ///< waypoints
    rfs_q16_t length;                     ///< metres, Q16.16 (saturates at 32 km)
} rfs_path_t;

/// Bind work arrays to a map. Returns 0, or -1 when an array is null or too small
/// (work must hold lw * lh bytes).
int rfs_plan_init(rfs_plan_t *p, const rfs_map_t *map, uint8_t *work, uint32_t work_bytes,
                  uint32_t *queue, uint32_t queue_cap);

/// Plan from (x0, y0) to the legal point (x1, y1). Returns false when the goal is not
/// legal or not reachable (or the queue overflowed, counted as unreachable).
bool rfs_plan_path(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1,
                   rfs_path_t *out);

#endif /* RFS_PLAN_H */
