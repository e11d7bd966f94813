/* hs_paths.h - shortest paths on the core's legal grid, for the figures every run reports
 * (shortest_path_m, shortest_to_stop_m) and for drawing placements (hs_place.h).
 *
 * Distances run over legal cells of the core map (its clearance), 16-connected: straight,
 * diagonal and knight moves at their Euclidean length, a move allowed when the cells it
 * passes through are legal; this overestimates any-angle lengths by at most 2.7 %. The
 * controller itself plans on the 0.25 m lattice (rfs_plan.h), whose edges need a legal
 * straight segment between lattice points: hs_paths_lattice_reaches() asks it whether a
 * goal is reachable at all, so a door one cell wide counts as shut, as it is for the robot.
 */
#ifndef HS_PATHS_H
#define HS_PATHS_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_map.h"

/// The core cell a point (metres) lies in, from the map's origin (x0, y0) in metres;
/// false when off the grid.
bool hs_paths_cell(const rfs_map_t *m, double x0, double y0, double x, double y, long *cx,
                   long *cy);

/// Fill dist (w * h doubles, metres, INFINITY = unreachable) with the shortest distances
/// from core cell (sx, sy) over legal cells. 0, or -1 when out of memory.
int hs_paths_dist(const rfs_map_t *m, long sx, long sy, double *dist);

/// Paths towards a goal (gx, gy), from a dist field of hs_paths_dist.
typedef struct hs_paths_goal {
    double near_m;  ///< distance from the goal of the nearest reachable cell's centre, metres
    double path_m;  ///< the path to that cell (the nearest: the shortest one), metres
    double stop_m;  ///< the shortest path to a cell within the stop radius (INFINITY: none)
} hs_paths_goal_t;

/// The goal paths over the cells whose centres lie in the box [gx - reach, gx + reach] x
/// [gy - reach, gy + reach] (reach < 0: every cell); the same answer as the whole grid
/// when some reachable cell lies within min(reach, stop_radius) of the goal. (x0, y0): the
/// map's origin, metres.
void hs_paths_goal(const rfs_map_t *m, double x0, double y0, const double *dist, double gx,
                   double gy, double stop_radius, double reach, hs_paths_goal_t *out);

/// 1 when the controller's planner (0.25 m lattice) finds a path from (sx, sy) to some
/// legal lattice point within radius of (gx, gy) (metres), 0 when none, -1 out of memory.
int hs_paths_lattice_reaches(const rfs_map_t *m, double sx, double sy, double gx, double gy,
                             double radius);

#endif /* HS_PATHS_H */
