/* hs_bridge.c - the bridging figures of a run (see hs_bridge.h). */
#include "hs_bridge.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "rfs_reach.h"

/* Track points are kept this far apart, metres. */
#define TRACK_STEP_M 0.05
/* The true f's grid, metres: from the map's corner, so that its points are the radio's
 * wall-count cache points (radio.walls.cache_m 0.1 m), each with its own count; a point
 * between two (a cell centre) would take either's by rounding. */
#define GRID_M 0.1

bool hs_bridge_track_add(hs_bridge_track_t *t, double x, double y, double travelled)
{
    if (t->n > 0 && travelled - t->d[t->n - 1] < TRACK_STEP_M) {
        return true;
    }
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 1024;
        double *nx = realloc(t->x, cap * sizeof *nx);
        if (nx) {
            t->x = nx;
        }
        double *ny = realloc(t->y, cap * sizeof *ny);
        if (ny) {
            t->y = ny;
        }
        double *nd = realloc(t->d, cap * sizeof *nd);
        if (nd) {
            t->d = nd;
        }
        if (!nx || !ny || !nd) {
            return false;
        }
        t->cap = cap;
    }
    t->x[t->n] = x;
    t->y[t->n] = y;
    t->d[t->n] = travelled;
    t->n++;
    return true;
}

void hs_bridge_track_free(hs_bridge_track_t *t)
{
    free(t->x);
    free(t->y);
    free(t->d);
    t->x = t->y = t->d = NULL;
    t->n = t->cap = 0;
}

double hs_bridge_settle_travel(const hs_bridge_track_t *t, double fx, double fy)
{
    for (size_t k = t->n; k > 0; k--) {
        if (hypot(t->x[k - 1] - fx, t->y[k - 1] - fy) > HS_BRIDGE_SETTLE_M) {
            return t->d[k - 1];
        }
    }
    return 0.0;
}

double hs_bridge_f(hs_radio_t *radio, double x, double y)
{
    double a = hs_radio_mean_dbm(radio, 0, x, y), b = hs_radio_mean_dbm(radio, 1, x, y);
    return -fabs(a - b) - fabs(a + b);
}

static rfs_q16_t q16(double v)
{
    return (rfs_q16_t)lround(v * 65536.0);
}

bool hs_bridge_best(hs_radio_t *radio, const rfs_map_t *m, double sx, double sy, double x0,
                    double y0, double x1, double y1, double *bx, double *by, double *bf,
                    double *far_f)
{
    long nx = lround(floor((x1 - x0) / GRID_M)), ny = lround(floor((y1 - y0) / GRID_M));
    size_t npts = (size_t)(nx + 1) * (size_t)(ny + 1);
    uint32_t nbytes = rfs_reach_bytes(m), cap = (uint32_t)m->lw * m->lh;
    uint8_t *reach = calloc(nbytes ? nbytes : 1, 1);
    uint32_t *queue = calloc(cap ? cap : 1, sizeof *queue);
    double *fv = malloc(npts * sizeof *fv); /* f at every standing point, NaN elsewhere */
    bool found = false;
    if (reach && queue && fv && rfs_reach_fill(m, q16(sx), q16(sy), reach, queue, cap)) {
        for (long j = 0; j <= ny; j++) {
            for (long i = 0; i <= nx; i++) {
                double x = x0 + i * GRID_M, y = y0 + j * GRID_M;
                uint16_t li, lj;
                double *v = &fv[(size_t)j * (size_t)(nx + 1) + (size_t)i];
                *v = NAN;
                rfs_map_lattice_nearest(m, q16(x), q16(y), &li, &lj);
                if (!rfs_map_point_legal(m, q16(x), q16(y)) || !rfs_reach_at(m, reach, li, lj)) {
                    continue;
                }
                *v = hs_bridge_f(radio, x, y);
                if (!found || *v > *bf) {
                    *bx = x;
                    *by = y;
                    *bf = *v;
                    found = true;
                }
            }
        }
    }
    *far_f = NAN;
    for (long j = 0; found && j <= ny; j++) {
        for (long i = 0; i <= nx; i++) {
            double v = fv[(size_t)j * (size_t)(nx + 1) + (size_t)i];
            if (!isnan(v) && hypot(x0 + i * GRID_M - *bx, y0 + j * GRID_M - *by) >
                                 HS_BRIDGE_FAR_M + 1e-9 &&
                (isnan(*far_f) || v > *far_f)) {
                *far_f = v;
            }
        }
    }
    free(reach);
    free(queue);
    free(fv);
    return found;
}
