/* rfs_plan.h - shortest paths on the map lattice (the paper's robot used the ROS
 * navigation stack; the controller plans for itself).
 *
 * Dijkstra over the legal lattice points (8-connected, an edge exists when the straight
 * segment between the two points is legal), from the goal's lattice point outward until
 * the start's is closed, with integer costs 2 for a straight and 3 for a diagonal step
 * (octile, diagonal 1.5 instead of 1.414) so the priority queue is Dial's: four ring
 * buffers, one per cost mod 4. Edges are tested by rfs_map_lattice_step_legal (the
 * traversal's cells recorded once per direction; same answers, a few byte loads), or
 * read from the map's edge table (rfs_map_edges_attach, rfs_plan_use_edges). The
 * start and the goal join the lattice through the closest legal lattice point of their
 * 3 x 3 neighbourhood that a legal segment reaches (a start inside the clearance zone:
 * the closest legal one of its 5 x 5, unchecked, so the robot can get out). The lattice
 * path is then shortened by string pulling, linear in its length: from each kept
 * waypoint, a later point of the path reachable by a legal straight segment, found by
 * galloping tests (2, 4, 8 ... points on) and three halvings. A goal in line of sight
 * gives a one-waypoint path without search. Work memory is caller-owned: one byte
 * per lattice point and the queue (docs/MAPS.md).
 */
#ifndef RFS_PLAN_H
#define RFS_PLAN_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"
#include "rfs_map.h"

/// Most waypoints a plan returns.
#define RFS_PLAN_MAX_WAYPOINTS 64u

/// The bucket queue of one Dijkstra (rfs_plan_path's, or a search tree's between calls).
typedef struct rfs_plan_dial {
    uint32_t head[4];   ///< oldest entry of each ring (index within its quarter of the queue)
    uint32_t count[4];  ///< entries in each ring (stale ones included)
    uint32_t cost;      ///< cost of the bucket being drained: half lattice steps
                        ///< (straight 2, diagonal 3; below 3 * lw * lh)
    uint32_t pending;   ///< a closed point whose neighbours are not yet relaxed (the
                        ///< point the last call stopped at), or UINT32_MAX
    uint32_t peak;      ///< most entries one ring has held
    bool overflow;      ///< a push found its ring full: the search is void
} rfs_plan_dial_t;

/// Planner state: caller-owned work arrays sized for the map's lattice.
typedef struct rfs_plan {
    const rfs_map_t *map;   ///< the map planned on
    uint8_t *work;          ///< lw * lh bytes: visit marks and back-pointers
    uint32_t *queue;        ///< wavefront queue of lattice indices
    uint32_t queue_cap;     ///< its capacity, split in four quarters (2 * (lw + lh) ample: docs/MAPS.md)
    uint32_t expanded;      ///< lattice points expanded by the last call (for benchmarks)
    uint32_t pulled;        ///< path points the last search path's string pulling tested
                            ///< segments across, summed: at most 10 per point of the path
    uint32_t queue_peak;    ///< most entries one of the four queue quarters held in the
                            ///< last search (a tree: since it was seeded)
    bool exact_edges;       ///< false (init): lattice points and edges from the map's
                            ///< step patterns where it has them; true: positions and
                            ///< rfs_map_segment_legal always (the tests' reference)
    const uint8_t *component; ///< optional (NULL at init): one bit per lattice point
                            ///< (idx = j * lw + i: bit idx & 7 of byte idx >> 3), a union
                            ///< of whole connected components of the lattice graph
                            ///< (rfs_plan_set_component)
    rfs_plan_dial_t dial;   ///< the search's queue state
    rfs_q16_t tree_x;       ///< search tree's root (rfs_plan_tree_begin), metres Q16.16
    rfs_q16_t tree_y;       ///< metres Q16.16
    uint32_t tree_root;     ///< its lattice point (idx = j * lw + i) once seeded
    uint8_t tree;           ///< tree state: 0 none (init, rfs_plan_path), 1 begun,
                            ///< 2 seeded (work holds it), 3 root joins no lattice point
    bool tree_done;         ///< the tree's search has closed every point it reaches
    bool tree_sliced;       ///< grown by rfs_plan_tree_grow: plans do not search
    bool tree_more;         ///< set (never cleared here) when a plan on a sliced tree asked
                            ///< for a point it has not closed yet: grow it, ask again
    uint32_t tree_from;     ///< the lattice point paths leave tree_x, tree_y by: the root,
                            ///< or the join point of a start moved (rfs_plan_tree_move)
    bool tree_defer;        ///< false (init); true (rfs_plan_tree_defer): grows only owe
    uint32_t tree_owed;     ///< points the tree's grows granted and no search closed yet
    uint8_t (*search)(struct rfs_plan *p, uint32_t target, uint32_t budget);
                            ///< the search loop: NULL (init) the lattice tests',
                            ///< rfs_plan_use_edges the edge table's
} rfs_plan_t;

/// A planned path: waypoints in order, the last one the goal itself.
typedef struct rfs_path {
    rfs_q16_t x[RFS_PLAN_MAX_WAYPOINTS]; ///< metres, Q16.16
    rfs_q16_t y[RFS_PLAN_MAX_WAYPOINTS]; ///< metres, Q16.16
    uint16_t n;                           ///< waypoints
    rfs_q16_t length;                     ///< metres, Q16.16 (saturates at 32 km)
    rfs_q16_t x0;                         ///< where it was planned from, metres Q16.16
    rfs_q16_t y0;                         ///< metres Q16.16
    bool has_start;                       ///< x0, y0 set: the first leg starts there
} rfs_path_t;

/// Bind work arrays to a map. Returns 0, or -1 when an array is null or too small
/// (work must hold lw * lh bytes, the queue at least 8 entries).
int rfs_plan_init(rfs_plan_t *p, const rfs_map_t *map, uint8_t *work, uint32_t work_bytes,
                  uint32_t *queue, uint32_t queue_cap);

/// Plan from (x0, y0) to the legal point (x1, y1). Returns false when the goal is not
/// legal or not reachable, or the queue overflowed or the path needs more than
/// RFS_PLAN_MAX_WAYPOINTS waypoints (both counted as unreachable; out->n is then 0).
bool rfs_plan_path(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1,
                   rfs_path_t *out);

/// Begin a search tree rooted at (x0, y0), usually the robot, for several goals planned
/// from the same start (one geodesic epsilon decision). O(1): the root joins the lattice
/// (as rfs_plan_path joins its start) and the Dijkstra is seeded at the first goal that
/// needs a search. Any rfs_plan_path call ends the tree (it reuses the work memory).
void rfs_plan_tree_begin(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0);

/// Plan from the tree's root to the legal point (x1, y1): rfs_plan_path's contract and
/// result cases, but the tree's Dijkstra (from the root) is continued only until the
/// goal's lattice point is closed, and a goal closed by an earlier call needs no search.
/// A tree grown by rfs_plan_tree_grow is never searched here: a goal it has not closed
/// fails, and sets tree_more unless the tree is done (then it is unreachable). The
/// lattice path may differ from rfs_plan_path's among equal-cost ones (ties); the
/// waypoints are string pulled from the root forwards, as rfs_plan_path does. A path depends only on the root and the goal, not on the goals asked before
/// nor on how the search was sliced. false, out->n 0, also when no tree was begun or an
/// rfs_plan_path call ended it.
bool rfs_plan_tree_path(rfs_plan_t *p, rfs_q16_t x1, rfs_q16_t y1, rfs_path_t *out);

/// The length of the path from the tree's start to the legal point (x1, y1) before string
/// pulling, metres Q16.16 (saturated): the start's position to its lattice point, the
/// lattice path (straight steps grid, diagonal ones grid sqrt 2), the goal's lattice
/// point to the goal; the straight distance in line of sight. From a moved start
/// (rfs_plan_tree_move) the lattice part runs by the root: at most twice the start's
/// tree path over rfs_plan_tree_path's. At least the pulled path's length; from the
/// root its lattice part at most 6.1 % above the shortest lattice path (octile costs 1.5
/// for sqrt 2); a walk, no pull.
/// rfs_plan_tree_path's result cases (false, *len 0, when it would fail).
bool rfs_plan_tree_length(rfs_plan_t *p, rfs_q16_t x1, rfs_q16_t y1, rfs_q16_t *len);

/// Continue the begun tree's search by at most `budget` closed lattice points (a
/// control period's slice, or owed: rfs_plan_tree_defer; the first call also clears the
/// work, lw * lh bytes). true
/// when it is done: every point the root reaches is closed (then each rfs_plan_tree_path
/// is a walk along the back-pointers and a pull), or the root joins no lattice point, or
/// the queue overflowed (plans to points not closed fail); false while more is left, or
/// when no tree was begun.
bool rfs_plan_tree_grow(rfs_plan_t *p, uint32_t budget);

/// The tree's search has no work left for a grow: it is done, or its root joins no lattice
/// point, or none is begun (a begun tree not seeded yet has). A deferred tree's debt is
/// paid first (rfs_plan_tree_defer: the search its grows would have run), so the answer is
/// the undeferred one's.
bool rfs_plan_tree_grown(rfs_plan_t *p);

/// Let a seeded tree serve plans from (x0, y0), e.g. a robot stopped near the point the
/// tree was begun at, braked past it or cut short before it: true, and later paths start
/// at (x0, y0), when the lattice point it joins (as rfs_plan_path joins a start) is
/// closed and the hop to it plus its tree path to the root (straight steps grid,
/// diagonal ones grid sqrt 2) is at most max_hop (metres, Q16.16). Paths then go from
/// that point up its branch to the goal's and along it: at most 2 max_hop longer than
/// from a tree rooted at (x0, y0), before string pulling. false (the tree unchanged)
/// otherwise.
bool rfs_plan_tree_move(rfs_plan_t *p, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t max_hop);

/// Search with the map's edge table when it has one (rfs_map_edges_attach; a host
/// option: the code for it is linked only into programs that call this). The same
/// plans and trees, point for point.
void rfs_plan_use_edges(rfs_plan_t *p);

/// Defer the searches of rfs_plan_tree_grow (a host option: the simulator has no period
/// budget to keep). Each grow then only adds its budget to the points owed; a plan or a
/// move asking for a point not closed yet first continues the search until that point
/// is closed, the debt is paid or the tree is done. The tree closes points in one order
/// however its search is sliced, so every answer is the undeferred one; only `expanded`
/// counts the points where they are closed, and a grow's result is true only once a
/// plan found the tree done.
void rfs_plan_tree_defer(rfs_plan_t *p, bool on);

/// Tell the planner which lattice points are known to be connected: `bits` (NULL: none)
/// holds one bit per lattice point and must be a union of whole components of the lattice
/// graph (8 neighbours, an edge where the segment between the points is legal: the graph
/// the search walks), e.g. a flood fill from the robot, or every legal point. A plan whose
/// start and goal join the lattice at points of which exactly one is marked then fails at
/// once: they lie in different components, and the search would flood the goal's whole
/// component and fail (a closed room can cost a million instructions on a Cortex-M4).
/// Results are unchanged; the caller keeps the array valid while set.
void rfs_plan_set_component(rfs_plan_t *p, const uint8_t *bits);

#endif /* RFS_PLAN_H */
