/* rfs_pathloss_warm.c - the path-loss model's warming (rfs_model_ops_t.warm;
 * docs/PATHLOSS.md, "Work, the wall-count cache and slicing"): while the robot drives a
 * leg, the wall counts the next relearn will need are made in the leg's spare periods.
 *
 * A relearn counts walls for the bins whose wall origin (the core cell of the centroid)
 * has no cache row: bins the robot made or changed since the last fit (and, with a full
 * store, bins whose centroid moved as its samples were replaced). A pass bins the samples
 * as a fit does (rfs_pathloss_bin_add, in the fit's bin arrays, which no operation reads
 * between fits), and counts each such bin but the robot's own (its samples are not
 * complete) against the columns the last fit evaluated: its coarse candidates first, then
 * its refinement points, then its source. The counts go into the cache, where a fit reads
 * them as its own (cached = fresh): its results do not change, only its work. A pass
 * begins when the robot is in another bin than at the last pass's start.
 *
 * Rows: one never used, else (the cache full) one no bin of the last fit holds, after the
 * one tidy a fit itself would make; warming stops when every row holds a bin of the last
 * fit or one warming counted. Columns are never made, only found.
 */
#include "rfs_pathloss.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_pathloss_internal.h"
#include "rfs_reach.h"

/// Warming's phases (rfs_pathloss_warm_t.phase).
enum { WARM_START = 0, WARM_BIN, WARM_SCAN, WARM_COUNT, WARM_HOLD, WARM_REFINE };
/// Bins or columns looked at per work unit (as a fit gathers bins).
#define PER_UNIT RFS_PATHLOSS_BINS_PER_UNIT
/// Samples binned per work unit (as a fit bins them).
#define SAMPLES_PER_UNIT RFS_PATHLOSS_SAMPLES_PER_UNIT
/// Work units of tidying the rows (as a fit's, rfs_pathloss.c TIDY_UNITS).
#define TIDY_UNITS 40u

/* Metres Q16.16 to centimetres, rounded. Scaling: |v| < 2^31 times 100 in int64. */
static int32_t q16_to_cm(rfs_q16_t v)
{
    return (int32_t)rfs_sdiv64_round((int64_t)v * 100, 65536);
}

/* The wall origin of core cell (cx, cy): its centre, as rfs_pathloss.c bin_means() puts
 * it. Scaling: cell corner + half a cell is inside the map's Q16 extent. */
static void origin(const rfs_map_t *m, uint16_t cx, uint16_t cy, rfs_q16_t *x, rfs_q16_t *y)
{
    *x = rfs_sat32((int64_t)m->origin_x + (int64_t)cx * m->res + m->res / 2);
    *y = rfs_sat32((int64_t)m->origin_y + (int64_t)cy * m->res + m->res / 2);
}

/* The budget has no room for `need` more units (at least one piece a call). */
static bool full(uint32_t budget, uint32_t used, uint32_t need)
{
    return budget != 0u && used != 0u && used + need > budget;
}

/* A look at one more bin or column: a work unit every PER_UNIT. */
static uint32_t look(rfs_pathloss_warm_t *w)
{
    w->seen++;
    return w->seen % PER_UNIT == 0u ? 1u : 0u;
}

/* Bin the samples as a fit would (doubling the bin until they fit); false when the budget
 * ran out first. */
static bool warm_bin(rfs_pathloss_t *p, const rfs_model_fit_in_t *in, uint32_t budget,
                     uint32_t *used)
{
    const uint32_t n = p->bin_n < in->n ? p->bin_n : in->n;
    while (p->pos < n) {
        if (full(budget, *used, 1u)) {
            return false;
        }
        const uint32_t end = n - p->pos > SAMPLES_PER_UNIT ? p->pos + SAMPLES_PER_UNIT : n;
        (*used)++;
        if (!rfs_pathloss_bin_add(p, in->samples, end)) {
            rfs_pathloss_bin_reset(p, p->bin_cm * 2);
        }
    }
    return true;
}

/* The next bin whose wall origin has no row (but the robot's), given a row: true and
 * p->warm set to count it; false at the end of the bins, when the budget ran out (*more)
 * or when no row is left (w->stopped: nothing more until the next fit). */
static bool warm_scan(rfs_pathloss_t *p, const rfs_model_fit_in_t *in, uint32_t budget,
                      uint32_t *used, bool *more)
{
    rfs_pathloss_warm_t *w = &p->warm;
    const rfs_map_t *m = p->map;
    const int16_t rkx = (int16_t)rfs_pathloss_floor_div(q16_to_cm(in->qx), p->bin_cm);
    const int16_t rky = (int16_t)rfs_pathloss_floor_div(q16_to_cm(in->qy), p->bin_cm);
    while (w->b < p->nbins) {
        if (full(budget, *used, 1u)) {
            *more = true;
            return false;
        }
        const rfs_pathloss_bin_t *bb = &p->bins[w->b];
        /* The centroid and its core cell as rfs_pathloss.c bin_means() finds them. */
        const int32_t xcm = (int32_t)rfs_sdiv64_round(bb->sx_cm, bb->count);
        const int32_t ycm = (int32_t)rfs_sdiv64_round(bb->sy_cm, bb->count);
        uint16_t cx, cy;
        if ((bb->kx == rkx && bb->ky == rky) ||
            !rfs_map_cell(m, rfs_pathloss_cm_to_q16(xcm), rfs_pathloss_cm_to_q16(ycm), &cx, &cy) ||
            rfs_pathloss_walls_row_find(p, cx, cy) != RFS_PATHLOSS_NO_ROW) {
            w->b++;
            *used += look(w);
            continue;
        }
        if (p->nrows == (p->x.cells != 0 ? RFS_PATHLOSS_CACHE_ROWS : RFS_PATHLOSS_BUILTIN_ROWS) &&
            !w->tidied && full(budget, *used, TIDY_UNITS)) {
            *more = true;
            return false;
        }
        bool tidied = false;
        const uint16_t r = rfs_pathloss_walls_row_warm(p, cx, cy, &tidied);
        *used += tidied ? TIDY_UNITS : 0u;
        if (r == RFS_PATHLOSS_NO_ROW) {
            w->stopped = true; /* every row holds a bin: nothing more until the next fit */
            return false;
        }
        w->b++;
        w->row = r;
        rfs_reach_bit_set(w->warmed, r);
        origin(m, cx, cy, &w->wx, &w->wy);
        w->col = 0u;
        return true;
    }
    return false;
}

/* Count the row in p->warm against the last fit's columns from w->col up to `end`: the
 * coarse points it evaluated (0 .. ncx ncy - 1), its refinement points, its source (the
 * last). false when the budget ran out first. */
static bool warm_count(rfs_pathloss_t *p, uint32_t end, uint32_t budget, uint32_t *used)
{
    rfs_pathloss_warm_t *w = &p->warm;
    const uint32_t nc = (uint32_t)p->lat.ncx * p->lat.ncy;
    const bool ranks = p->cfg.coarse_footprint != p->cfg.footprint;
    while (w->col < end) {
        if (full(budget, *used, 1u)) {
            return false; /* a look is work too */
        }
        int32_t i = p->best.li, j = p->best.lj;
        const bool coarse = w->col < nc;
        if (coarse) {
            if (p->surface[w->col] == RFS_PATHLOSS_NO_LOSS ||
                !rfs_pathloss_coarse_ij(p, w->col, &i, &j)) {
                w->col++;
                *used += look(w);
                continue;
            }
        } else if (w->col < nc + p->nvis) {
            i = p->vis_i[w->col - nc];
            j = p->vis_j[w->col - nc];
        }
        const int32_t k = rfs_pathloss_walls_col_find(p, (uint16_t)i, (uint16_t)j, coarse);
        if (k >= 0) {
            if (full(budget, *used, RFS_PATHLOSS_FOOTPRINT_RAYS)) {
                return false;
            }
            const rfs_q16_t fp = coarse && ranks ? p->cfg.coarse_footprint : p->cfg.footprint;
            const uint32_t lines =
                rfs_pathloss_walls_warm(p, w->row, w->wx, w->wy, k, (uint16_t)i, (uint16_t)j, fp);
            *used += lines;
            w->lines += lines;
            w->footprints += lines != 0u ? 1u : 0u;
        }
        w->col++;
        *used += look(w);
    }
    return true;
}

/* The columns of the points the next fit's hold search evaluates first (docs/PATHLOSS.md,
 * "Fit", step 6: when it moves from the last fit's source, the 3 x 3 round it at half the
 * coarse spacing), made when missing and free columns are left (rfs_pathloss_walls_col). */
static void hold_columns(rfs_pathloss_t *p)
{
    rfs_pathloss_warm_t *w = &p->warm;
    const int32_t step = p->lat.cs / 2u < 1u ? 1 : (int32_t)(p->lat.cs / 2u);
    for (uint32_t q = 0u; q < 8u; ++q) {
        const uint32_t rem = q < 4u ? q : q + 1u; /* the 3 x 3 but its centre */
        const int32_t i = p->best.li + ((int32_t)(rem % 3u) - 1) * step;
        const int32_t j = p->best.lj + ((int32_t)(rem / 3u) - 1) * step;
        w->hold_col[q] = -1;
        if (p->cfg.hold_k > 0 && p->cfg.hold_search && rfs_pathloss_cand_legal(p, i, j)) {
            w->hold_col[q] = (int16_t)rfs_pathloss_walls_col(p, (uint16_t)i, (uint16_t)j, false);
        }
    }
}

/* Every bin with a row but the robot's against the hold search's first points (p->warm
 * hold_col). false when the budget ran out first. */
static bool warm_hold(rfs_pathloss_t *p, const rfs_model_fit_in_t *in, uint32_t budget,
                      uint32_t *used)
{
    rfs_pathloss_warm_t *w = &p->warm;
    const rfs_map_t *m = p->map;
    const int16_t rkx = (int16_t)rfs_pathloss_floor_div(q16_to_cm(in->qx), p->bin_cm);
    const int16_t rky = (int16_t)rfs_pathloss_floor_div(q16_to_cm(in->qy), p->bin_cm);
    const int32_t step = p->lat.cs / 2u < 1u ? 1 : (int32_t)(p->lat.cs / 2u);
    for (; w->b < p->nbins; w->b++, w->col = 0u) {
        if (w->col == 0u && full(budget, *used, 1u)) {
            return false; /* a look is work too */
        }
        const rfs_pathloss_bin_t *bb = &p->bins[w->b];
        const int32_t xcm = (int32_t)rfs_sdiv64_round(bb->sx_cm, bb->count);
        const int32_t ycm = (int32_t)rfs_sdiv64_round(bb->sy_cm, bb->count);
        uint16_t cx, cy, row;
        if ((bb->kx == rkx && bb->ky == rky) ||
            !rfs_map_cell(m, rfs_pathloss_cm_to_q16(xcm), rfs_pathloss_cm_to_q16(ycm), &cx, &cy) ||
            (row = rfs_pathloss_walls_row_find(p, cx, cy)) == RFS_PATHLOSS_NO_ROW) {
            *used += look(w);
            continue;
        }
        rfs_q16_t wx, wy;
        origin(m, cx, cy, &wx, &wy);
        for (; w->col < 8u; w->col++) {
            if (w->hold_col[w->col] < 0) {
                continue;
            }
            if (full(budget, *used, RFS_PATHLOSS_FOOTPRINT_RAYS)) {
                return false;
            }
            const uint32_t rem = w->col < 4u ? w->col : w->col + 1u;
            const int32_t i = p->best.li + ((int32_t)(rem % 3u) - 1) * step;
            const int32_t j = p->best.lj + ((int32_t)(rem / 3u) - 1) * step;
            const uint32_t lines = rfs_pathloss_walls_warm(p, row, wx, wy, w->hold_col[w->col],
                                                           (uint16_t)i, (uint16_t)j,
                                                           p->cfg.footprint);
            *used += lines + look(w);
            w->lines += lines;
            w->footprints += lines != 0u ? 1u : 0u;
        }
        *used += look(w); /* a bin with a row is a look too */
    }
    return true;
}

bool rfs_pathloss_warm_op(void *self, const rfs_model_fit_in_t *in, uint32_t budget)
{
    rfs_pathloss_t *p = (rfs_pathloss_t *)self;
    RFS_ASSERT(p != 0 && in != 0);
    /* Only after a finished fit on this map, its cache that of its lattice. */
    if (!p->valid || p->phase != RFS_PATHLOSS_IDLE || p->map == 0 || in->map != p->map ||
        in->n == 0u || in->samples == 0 || p->cache_map != p->map ||
        !rfs_pathloss_same_lattice(&p->cache_lat, &p->lat)) {
        return false;
    }
    rfs_pathloss_warm_t *w = &p->warm;
    uint32_t used = 0u;
    for (;;) {
        if (w->phase == WARM_START) {
            const int32_t bin_cm = (int32_t)(((int64_t)p->cfg.bin * 100 + 32768) >> 16);
            const int16_t kx = (int16_t)rfs_pathloss_floor_div(q16_to_cm(in->qx), bin_cm);
            const int16_t ky = (int16_t)rfs_pathloss_floor_div(q16_to_cm(in->qy), bin_cm);
            if (w->stopped || (w->passed && kx == w->rkx && ky == w->rky)) {
                return false; /* no row left, or the robot is in the last pass's first bin */
            }
            w->rkx = kx;
            w->rky = ky;
            rfs_pathloss_bin_reset(p, bin_cm);
            p->bin_n = in->n;
            w->phase = WARM_BIN;
        }
        if (w->phase == WARM_BIN) {
            if (!warm_bin(p, in, budget, &used)) {
                return true;
            }
            w->b = 0u;
            w->phase = WARM_SCAN;
        }
        if (w->phase == WARM_SCAN) {
            bool more = false;
            if (!warm_scan(p, in, budget, &used, &more)) {
                if (more) {
                    return true;
                }
                hold_columns(p);
                w->b = 0u;
                w->col = 0u;
                w->phase = WARM_HOLD;
            } else {
                w->phase = WARM_COUNT;
            }
        }
        const uint32_t nc = (uint32_t)p->lat.ncx * p->lat.ncy;
        if (w->phase == WARM_COUNT) {
            if (!warm_count(p, nc, budget, &used)) {
                return true;
            }
            w->phase = WARM_SCAN;
        } else if (w->phase == WARM_HOLD) {
            if (!warm_hold(p, in, budget, &used)) {
                return true;
            }
            w->b = 0u; /* rows now */
            w->col = nc;
            w->phase = WARM_REFINE;
        } else {
            /* the rows this pass counted against the last fit's refinement points */
            for (; w->b < p->nrows; w->b++, w->col = nc) {
                if (w->col == nc && full(budget, used, 1u)) {
                    return true;
                }
                if (!rfs_reach_bit(w->warmed, w->b)) {
                    used += look(w);
                    continue;
                }
                w->row = w->b;
                origin(p->map, p->rows[w->b].cx, p->rows[w->b].cy, &w->wx, &w->wy);
                if (!warm_count(p, nc + p->nvis + 1u, budget, &used)) {
                    return true;
                }
            }
            memset(w->warmed, 0, sizeof(w->warmed));
            w->passed = true;
            w->phase = WARM_START;
            return false;
        }
    }
}
