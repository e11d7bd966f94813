/* rfs_pathloss_lattice.c - the path-loss model's candidate lattice and its coarse points
 * (docs/PATHLOSS.md, "Fit", step 4): the map's lattice or a virtual one, the coarse grid,
 * and each coarse point's stand-in when its grid point is not legal (coarse_snap). */
#include "rfs_pathloss_internal.h"

#include <string.h>

/* Lattice spacing without a map, metres Q16.16 (the map default). */
#define NOMAP_GRID RFS_Q16_FRAC(1, 4)

void rfs_pathloss_lattice_setup(rfs_pathloss_t *p, const rfs_map_t *m)
{
    rfs_pathloss_lat_t *l = &p->lat;
    if (m != 0) {
        rfs_map_lattice_point(m, 0, 0, &l->ox, &l->oy);
        l->grid = m->cfg.grid;
        l->lw = m->lw;
        l->lh = m->lh;
    } else {
        int32_t x0 = INT32_MAX, y0 = INT32_MAX, x1 = INT32_MIN, y1 = INT32_MIN;
        for (uint32_t b = 0u; b < p->nbins; ++b) {
            const rfs_pathloss_bin_t *bb = &p->bins[b];
            x0 = bb->x < x0 ? bb->x : x0;
            y0 = bb->y < y0 ? bb->y : y0;
            x1 = bb->x > x1 ? bb->x : x1;
            y1 = bb->y > y1 ? bb->y : y1;
        }
        /* Scaling: centroids are within +-328 m, the margin <= 100 m: Q16 spans < 2^27. */
        l->grid = NOMAP_GRID;
        l->ox = x0 - p->cfg.margin;
        l->oy = y0 - p->cfg.margin;
        l->lw = (uint16_t)((x1 + p->cfg.margin - l->ox) / l->grid + 1);
        l->lh = (uint16_t)((y1 + p->cfg.margin - l->oy) / l->grid + 1);
    }
    int32_t cs = (int32_t)rfs_sdiv64_round(p->cfg.coarse, l->grid);
    cs = cs < 1 ? 1 : cs;
    for (;;) {
        l->ncx = (uint16_t)((l->lw - 1u) / (uint32_t)cs + 1u);
        l->ncy = (uint16_t)((l->lh - 1u) / (uint32_t)cs + 1u);
        if ((uint32_t)l->ncx * l->ncy <= RFS_PATHLOSS_MAX_COARSE) {
            break;
        }
        cs++;
    }
    l->cs = (uint16_t)cs;
    l->c0i = (uint16_t)(((uint32_t)l->lw - 1u - (uint32_t)(l->ncx - 1u) * (uint32_t)cs) / 2u);
    l->c0j = (uint16_t)(((uint32_t)l->lh - 1u - (uint32_t)(l->ncy - 1u) * (uint32_t)cs) / 2u);
    if (m == 0 || p->snap_map != m || !rfs_pathloss_same_lattice(&p->snap_lat, l)) {
        memset(p->snap, (int)RFS_PATHLOSS_SNAP_UNKNOWN, sizeof(p->snap));
        p->snap_map = m;
        p->snap_lat = *l;
    }
}

/* How far the snap search looks from a coarse point, lattice steps (the offsets' 4 bits). */
#define SNAP_REACH 7

/* Lattice point (i, j) is on the lattice and legal on the map (places ruled out aside). */
static bool lattice_legal(const rfs_pathloss_t *p, int32_t i, int32_t j)
{
    return i >= 0 && j >= 0 && i < (int32_t)p->lat.lw && j < (int32_t)p->lat.lh &&
           (p->map == 0 || rfs_map_lattice_legal(p->map, (uint16_t)i, (uint16_t)j));
}

static uint8_t snap_pack(int32_t di, int32_t dj)
{
    return (uint8_t)((uint32_t)(di + SNAP_REACH) | (uint32_t)(dj + SNAP_REACH) << 4);
}

/* The lowest and highest offset of a coarse point's cell, lattice steps: the cells tile the
 * lattice (lo + hi + 1 = cs), within SNAP_REACH. */
static void snap_span(const rfs_pathloss_lat_t *l, int32_t *lo, int32_t *hi)
{
    *lo = ((int32_t)l->cs - 1) / 2;
    *hi = (int32_t)l->cs / 2;
    *lo = *lo > SNAP_REACH ? SNAP_REACH : *lo;
    *hi = *hi > SNAP_REACH ? SNAP_REACH : *hi;
}

/* Coarse point c's grid point, lattice indices. */
static void coarse_grid(const rfs_pathloss_lat_t *l, uint32_t c, int32_t *i, int32_t *j)
{
    *i = (int32_t)l->c0i + (int32_t)(c % l->ncx) * (int32_t)l->cs;
    *j = (int32_t)l->c0j + (int32_t)(c / l->ncx) * (int32_t)l->cs;
}

uint8_t rfs_pathloss_snap_find(const rfs_pathloss_t *p, uint32_t c, bool *searched)
{
    int32_t i0, j0;
    coarse_grid(&p->lat, c, &i0, &j0);
    *searched = false;
    if (lattice_legal(p, i0, j0)) {
        return snap_pack(0, 0);
    }
    if (!p->cfg.coarse_snap) {
        return RFS_PATHLOSS_SNAP_NONE;
    }
    *searched = true;
    int32_t lo, hi;
    snap_span(&p->lat, &lo, &hi);
    int32_t best = INT32_MAX;
    uint8_t found = RFS_PATHLOSS_SNAP_NONE;
    for (int32_t dj = -lo; dj <= hi; ++dj) {
        for (int32_t di = -lo; di <= hi; ++di) {
            const int32_t d2 = di * di + dj * dj;
            if (d2 < best && lattice_legal(p, i0 + di, j0 + dj)) {
                best = d2;
                found = snap_pack(di, dj);
            }
        }
    }
    return found;
}

bool rfs_pathloss_coarse_ij(const rfs_pathloss_t *p, uint32_t c, int32_t *i, int32_t *j)
{
    const uint8_t s = p->snap[c];
    if (s == RFS_PATHLOSS_SNAP_NONE || s == RFS_PATHLOSS_SNAP_UNKNOWN) {
        return false;
    }
    coarse_grid(&p->lat, c, i, j);
    *i += (int32_t)(s & 15u) - SNAP_REACH;
    *j += (int32_t)(s >> 4) - SNAP_REACH;
    return true;
}

bool rfs_pathloss_is_coarse(const rfs_pathloss_t *p, int32_t i, int32_t j)
{
    const rfs_pathloss_lat_t *l = &p->lat;
    const int32_t ki = i - (int32_t)l->c0i + ((int32_t)l->cs - 1) / 2;
    const int32_t kj = j - (int32_t)l->c0j + ((int32_t)l->cs - 1) / 2;
    if (ki < 0 || kj < 0 || ki / l->cs >= l->ncx || kj / l->cs >= l->ncy) {
        return false;
    }
    const uint32_t c = (uint32_t)(kj / l->cs) * l->ncx + (uint32_t)(ki / l->cs);
    int32_t ci, cj;
    return rfs_pathloss_coarse_ij(p, c, &ci, &cj) && ci == i && cj == j;
}
