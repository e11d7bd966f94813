/* hs_place.c - random start and source placements (see hs_place.h). */
#include "hs_place.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "hs_paths.h"
#include "rfs_fix.h"

/* Millimetres (positions) and 1e-4 rad (headings): a decimal printed with 3 or 4
 * places parses back to this very double (one correctly rounded division each way). */
static double round_to(double v, double per_unit)
{
    return (double)llround(v * per_unit) / per_unit;
}

int hs_placer_open(hs_placer_t *p, const hs_sim_env_t *e, char *err, size_t errlen)
{
    const hs_scenario_t *sc = &e->sc;
    const rfs_map_t *cm = &e->core.map;
    *p = (hs_placer_t){.env = e};
    if (sc->nsources != 1 || sc->has_goal || !(sc->stop_radius_m > 0.0)) {
        snprintf(err, errlen, "%s: placements need a scenario with one source, no stop.goal "
                 "and a stop radius", sc->path);
        return -1;
    }
    const size_t ncore = (size_t)cm->w * cm->h, nmap = (size_t)e->map.w * e->map.h;
    p->starts = malloc(sizeof *p->starts * (ncore ? ncore : 1));
    p->sources = malloc(sizeof *p->sources * (nmap ? nmap : 1));
    p->dist = malloc(sizeof *p->dist * (ncore ? ncore : 1));
    if (!p->starts || !p->sources || !p->dist || ncore > UINT32_MAX || nmap > UINT32_MAX) {
        hs_placer_close(p);
        snprintf(err, errlen, "%s: placements: out of memory", sc->path);
        return -1;
    }
    for (uint32_t i = 0; i < (uint32_t)ncore; i++) {
        if (rfs_map_bit(cm->legal, cm->stride, (uint16_t)(i % cm->w), (uint16_t)(i / cm->w))) {
            p->starts[p->nstarts++] = i;
        }
    }
    for (uint32_t i = 0; i < (uint32_t)nmap; i++) {
        if (e->map.cell[i] == LX_CELL_FREE) {
            p->sources[p->nsources++] = i;
        }
    }
    if (p->nstarts == 0) {
        hs_placer_close(p);
        snprintf(err, errlen, "%s: placements: no legal cell on the map (clearance %.2f m)",
                 sc->path, sc->clearance_m);
        return -1;
    }
    return 0;
}

/* Start candidate i as a legal point (cell centre to the millimetre): true, or false when
 * the rounding left its cell or its legality (never on a sane grid; then redrawn). */
static bool start_at(const hs_placer_t *p, uint32_t i, double *x, double *y, long *cx, long *cy)
{
    const hs_sim_env_t *e = p->env;
    const rfs_map_t *cm = &e->core.map;
    const double res = cm->res / 65536.0;
    const long ix = (long)(p->starts[i] % cm->w), iy = (long)(p->starts[i] / cm->w);
    *x = round_to(e->x0 + (ix + 0.5) * res, 1000.0);
    *y = round_to(e->y0 + (iy + 0.5) * res, 1000.0);
    uint32_t mx, my;
    return hs_paths_cell(cm, e->x0, e->y0, *x, *y, cx, cy) && *cx == ix && *cy == iy &&
           lx_map_cell_at(&e->map, *x, *y, &mx, &my) &&
           e->map.cell[(size_t)my * e->map.w + mx] == LX_CELL_FREE &&
           rfs_map_point_legal(cm, (rfs_q16_t)lround(*x * 65536.0), (rfs_q16_t)lround(*y * 65536.0));
}

/* Source candidate i as a point on a free cell (its centre to the millimetre): true, or
 * false when the rounding left the cell. */
static bool source_at(const hs_placer_t *p, uint32_t i, double *x, double *y)
{
    const lx_map_t *m = &p->env->map;
    const uint32_t ix = p->sources[i] % m->w, iy = p->sources[i] / m->w;
    *x = round_to(m->origin_x + (ix + 0.5) * m->res, 1000.0);
    *y = round_to(m->origin_y + (iy + 0.5) * m->res, 1000.0);
    uint32_t cx, cy;
    return lx_map_cell_at(m, *x, *y, &cx, &cy) && cx == ix && cy == iy;
}

/* The sources tried for one start (its distances in p->dist): 1 with *out filled, 0 when
 * none fits, -1 out of memory. */
static int try_sources(hs_placer_t *p, rfs_rng_t *rng, double sx, double sy, hs_place_t *out)
{
    const hs_sim_env_t *e = p->env;
    const double r = e->sc.stop_radius_m;
    for (unsigned k = 0; k < HS_PLACE_SOURCE_TRIES; k++) {
        double gx, gy;
        if (!source_at(p, rfs_rng_below(rng, p->nsources), &gx, &gy)) {
            continue;
        }
        // Any path into the stop radius is at least the straight line minus the radius
        // (the cells' centres are the points the distances join): no search needed.
        if (hypot(gx - sx, gy - sy) > HS_PLACE_MAX_M + r + 0.01) {
            continue;
        }
        hs_paths_goal_t gp;
        hs_paths_goal(&e->core.map, e->x0, e->y0, p->dist, gx, gy, r, r, &gp);
        if (!isfinite(gp.stop_m) || gp.path_m < HS_PLACE_MIN_M || gp.path_m > HS_PLACE_MAX_M) {
            continue;
        }
        int lr = hs_paths_lattice_reaches(&e->core.map, sx, sy, gx, gy, r);
        if (lr < 0) {
            return -1;
        }
        if (lr == 1) {
            out->source_x = gx;
            out->source_y = gy;
            out->shortest_path_m = gp.path_m;
            out->shortest_to_stop_m = gp.stop_m;
            return 1;
        }
    }
    return 0;
}

int hs_placer_draw(hs_placer_t *p, uint64_t seed, uint64_t index, hs_place_t *out, char *err,
                   size_t errlen)
{
    const hs_sim_env_t *e = p->env;
    rfs_rng_t rng;
    // Its own stream per (seed, index): rfs_rng_seed mixes the word with splitmix64.
    rfs_rng_seed(&rng, seed * 0x9E3779B97F4A7C15ull + index);
    *out = (hs_place_t){.index = index, .seed = seed};
    for (unsigned t = 0; t < HS_PLACE_START_TRIES; t++) {
        double sx, sy;
        long cx, cy;
        const uint32_t i = rfs_rng_below(&rng, p->nstarts);
        // The heading is drawn with the start, so each start try uses the same numbers.
        out->start_theta = (double)((int32_t)rfs_rng_below(&rng, 62832u) - 31416) / 10000.0;
        if (!start_at(p, i, &sx, &sy, &cx, &cy)) {
            continue;
        }
        if (hs_paths_dist(&e->core.map, cx, cy, p->dist) != 0) {
            snprintf(err, errlen, "%s: placements: out of memory", e->sc.path);
            return -1;
        }
        int found = try_sources(p, &rng, sx, sy, out);
        if (found < 0) {
            snprintf(err, errlen, "%s: placements: out of memory", e->sc.path);
            return -1;
        }
        if (found) {
            out->start_x = sx;
            out->start_y = sy;
            return 0;
        }
    }
    snprintf(err, errlen, "%s: placement %llu: no start and source %.0f to %.0f m apart by the "
             "shortest path in %u starts x %u sources (the floor is too small or too broken up "
             "at clearance %.2f m)", e->sc.path, (unsigned long long)index, HS_PLACE_MIN_M,
             HS_PLACE_MAX_M, HS_PLACE_START_TRIES, HS_PLACE_SOURCE_TRIES, e->sc.clearance_m);
    return -1;
}

void hs_placer_close(hs_placer_t *p)
{
    free(p->starts);
    free(p->sources);
    free(p->dist);
    p->starts = p->sources = NULL;
    p->dist = NULL;
}
