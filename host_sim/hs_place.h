/* hs_place.h - random start and source placements on a scenario's floor, for judging a
 * seeker where nobody tuned it (rfseek-sim --placements, docs/SIMULATOR.md "Placements").
 *
 * Placement k of seed S is drawn from its own random stream (S, k), so it is the same in
 * every batch that includes it. A draw takes a start uniformly among the legal cells of
 * the core grid (the scenario's clearance; a uniform heading) and then a source uniformly
 * among the free cells of the map image (anywhere a node could stand: rooms, corridors,
 * against walls), and keeps the pair when the shortest path from the start to the legal
 * cell nearest the source (hs_paths.h: the figure every run reports as shortest_path_m)
 * is HS_PLACE_MIN_M to HS_PLACE_MAX_M long, some legal cell lies within the stop radius
 * of the source, and the controller's planner reaches that radius (hs_sim_env_open's
 * checks). A start gets HS_PLACE_SOURCE_TRIES sources before the next start is drawn, so
 * starts with few sources in range are drawn a little less often than the rest. Positions
 * are cell centres rounded to the millimetre and headings to 1e-4 rad, so the numbers
 * printed with 3 and 4 decimals are exact.
 */
#ifndef HS_PLACE_H
#define HS_PLACE_H

#include <stddef.h>
#include <stdint.h>

#include "hs_sim.h"

/// Shortest path of a placement, metres: at least this ...
#define HS_PLACE_MIN_M 10.0
/// ... and at most this.
#define HS_PLACE_MAX_M 40.0
/// Sources tried for one start.
#define HS_PLACE_SOURCE_TRIES 64u
/// Starts tried before a draw gives up (the floor has no pair in range, or very few).
#define HS_PLACE_START_TRIES 400u
/// Largest placement number.
#define HS_PLACE_MAX_INDEX 1000000000u

/// One placement.
typedef struct hs_place {
    uint64_t index;             ///< placement number, 1..HS_PLACE_MAX_INDEX
    uint64_t seed;              ///< the placement seed it was drawn from
    double start_x, start_y;    ///< metres
    double start_theta;         ///< radians, [-pi, pi)
    double source_x, source_y;  ///< metres
    double shortest_path_m;     ///< start to the legal cell nearest the source, metres
    double shortest_to_stop_m;  ///< start into the stop radius, metres
} hs_place_t;

/// The candidate cells of a floor and the work memory of the draws.
typedef struct hs_placer {
    const hs_sim_env_t *env;    ///< the floor (the scenario's map, clearance, stop radius)
    uint32_t *starts;           ///< legal core cells (index y * w + x)
    uint32_t nstarts;
    uint32_t *sources;          ///< free map image cells (index y * w + x)
    uint32_t nsources;
    double *dist;               ///< core cells: distances from the start being tried
} hs_placer_t;

/// Collect the candidates of e's floor. 0, or -1 with err (no legal cell, no memory, a
/// scenario with two sources or a goal of its own).
int hs_placer_open(hs_placer_t *p, const hs_sim_env_t *e, char *err, size_t errlen);

/// Draw placement `index` (1..HS_PLACE_MAX_INDEX) of `seed`. 0, or -1 with err (no pair
/// found in HS_PLACE_START_TRIES starts, out of memory).
int hs_placer_draw(hs_placer_t *p, uint64_t seed, uint64_t index, hs_place_t *out, char *err,
                   size_t errlen);

/// Release (safe on a zeroed placer).
void hs_placer_close(hs_placer_t *p);

#endif /* HS_PLACE_H */
