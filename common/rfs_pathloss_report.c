/* rfs_pathloss_report.c - what a path-loss fit reports (docs/PATHLOSS.md): its estimate
 * for logs and the status message, and its residual surface over the coarse candidates
 * ("Uncertainty"). Read-only views of the fit in rfs_pathloss.c. */
#include "rfs_pathloss.h"

#include "rfs_assert.h"
#include "rfs_pathloss_internal.h"

bool rfs_pathloss_estimate(const rfs_pathloss_t *p, rfs_pathloss_est_t *est)
{
    RFS_ASSERT(p != 0 && est != 0);
    if (!p->valid) {
        return false;
    }
    est->sx = p->best.sx;
    est->sy = p->best.sy;
    est->p0 = p->best.p0;
    est->n = p->best.n;
    est->w = p->best.w;
    uint32_t m2 = rfs_pathloss_mean_loss(p, p->best.loss);
    est->rms = rfs_q16_sqrt(m2 > (uint32_t)INT32_MAX / 2u ? INT32_MAX : (rfs_q16_t)(2u * m2));
    est->spread_m2 = p->spread_m2;
    est->bins = p->used_bins;
    est->bin = rfs_pathloss_cm_to_q16(p->used_bin_cm);
    est->candidates = p->candidates;
    est->walls_counted = p->walls_counted;
    est->footprints = p->footprints;
    est->footprints_cached = p->footprints_cached;
    est->walls_warmed = p->walls_warmed;
    return true;
}

void rfs_pathloss_surface_size(const rfs_pathloss_t *p, uint16_t *ncx, uint16_t *ncy)
{
    RFS_ASSERT(p != 0 && ncx != 0 && ncy != 0);
    *ncx = p->valid ? p->lat.ncx : 0u;
    *ncy = p->valid ? p->lat.ncy : 0u;
}

bool rfs_pathloss_residual_at(const rfs_pathloss_t *p, uint16_t ci, uint16_t cj, rfs_q16_t *x,
                              rfs_q16_t *y, rfs_q16_t *rms)
{
    RFS_ASSERT(p != 0 && x != 0 && y != 0 && rms != 0);
    const rfs_pathloss_lat_t *l = &p->lat;
    if (!p->valid || ci >= l->ncx || cj >= l->ncy) {
        return false;
    }
    const uint32_t c = (uint32_t)cj * l->ncx + ci;
    const uint32_t m = p->surface[c];
    int32_t i, j;
    if (m == RFS_PATHLOSS_NO_LOSS || !rfs_pathloss_coarse_ij(p, c, &i, &j)) {
        rfs_pathloss_lattice_xy(l, (uint16_t)(l->c0i + ci * l->cs), (uint16_t)(l->c0j + cj * l->cs),
                                x, y);
        return false;
    }
    rfs_pathloss_lattice_xy(l, (uint16_t)i, (uint16_t)j, x, y);
    /* sqrt(2 m): 2 m saturated to the Q16 range (181 dB). */
    *rms = rfs_q16_sqrt(m > (uint32_t)INT32_MAX / 2u ? INT32_MAX : (rfs_q16_t)(2u * m));
    return true;
}
