/* hs_bridge.h - the bridging figures of a run (target bridge, paper section 6;
 * docs/STRATEGIES.md, "Bridging"): where the true f = -|R1 - R2| - |R1 + R2| is best, f
 * where the robot settled, and when it settled.
 *
 * The true f is the mean field's (path loss, walls and the seed's shadowing; no fading,
 * no noise) of both sources, on a 0.1 m grid from the map's corner (the radio's wall-count
 * cache points) of the points the robot can stand on: legal on the core map and in the
 * lattice component of the start (rfs_reach.h). Settling: the
 * travel after which the robot never again left a circle of HS_BRIDGE_SETTLE_M round its
 * final position.
 */
#ifndef HS_BRIDGE_H
#define HS_BRIDGE_H

#include <stdbool.h>
#include <stddef.h>

#include "hs_radio.h"
#include "rfs_map.h"

/// Radius of the circle a settled robot stays in, metres.
#define HS_BRIDGE_SETTLE_M 1.0
/// A run ending within this of the best point is "within 3 m" (scripts/bench_bridge.py);
/// the runner-up is the best point further away, metres.
#define HS_BRIDGE_FAR_M 3.0

/// The robot's positions along its travel, one every few centimetres.
typedef struct hs_bridge_track {
    double *x;     ///< positions, metres
    double *y;
    double *d;     ///< distance travelled there, metres
    size_t n;      ///< points held
    size_t cap;    ///< room for
} hs_bridge_track_t;

/// Add the position (x, y) after `travelled` metres when it is 5 cm or more past the last
/// point kept (always the first). false when out of memory.
bool hs_bridge_track_add(hs_bridge_track_t *t, double x, double y, double travelled);

/// Free the track (safe on a zeroed one).
void hs_bridge_track_free(hs_bridge_track_t *t);

/// Travel to settle for a run that ended at (fx, fy): the distance travelled at the last
/// point further than HS_BRIDGE_SETTLE_M from it (0 when there is none).
double hs_bridge_settle_travel(const hs_bridge_track_t *t, double fx, double fy);

/// The true f at (x, y) from the radio's mean field of sources 0 and 1, dB.
double hs_bridge_f(hs_radio_t *radio, double x, double y);

/// The best point of the true f over the points the robot can stand on, reachable from
/// (sx, sy) on core map m, on a 0.1 m grid from (x0, y0) to (x1, y1): its position and f,
/// and in *far_f the runner-up, the highest f of those points more than HS_BRIDGE_FAR_M
/// from it, by 1 nm so that a grid point at that distance stays near (NaN when there is
/// none). false when there is no such point (or out of memory).
bool hs_bridge_best(hs_radio_t *radio, const rfs_map_t *m, double sx, double sy, double x0,
                    double y0, double x1, double y1, double *bx, double *by, double *bf,
                    double *far_f);

#endif /* HS_BRIDGE_H */
