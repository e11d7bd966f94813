/* rfs_pathloss_internal.h - private to rfs_pathloss*.c: the wall counts the fit and the
 * prediction share, and the conversions the fit and its report share. Not part of the
 * core's API.
 */
#ifndef RFS_PATHLOSS_INTERNAL_H
#define RFS_PATHLOSS_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_pathloss.h"

/* Centimetres to metres Q16.16, rounded. |cm| < 2^22: product < 2^38. */
static inline rfs_q16_t rfs_pathloss_cm_to_q16(int32_t cm)
{
    return rfs_sat32(rfs_sdiv64_round((int64_t)cm * 65536, 100));
}

/* The position of lattice point (i, j), metres Q16.16, saturated. */
static inline void rfs_pathloss_lattice_xy(const rfs_pathloss_lat_t *l, uint16_t i, uint16_t j,
                                           rfs_q16_t *x, rfs_q16_t *y)
{
    *x = rfs_sat32((int64_t)l->ox + (int64_t)i * l->grid);
    *y = rfs_sat32((int64_t)l->oy + (int64_t)j * l->grid);
}

/* Field by field: the core may call no memcmp (only memcpy/memset/memmove). */
static inline bool rfs_pathloss_same_lattice(const rfs_pathloss_lat_t *a,
                                             const rfs_pathloss_lat_t *b)
{
    return a->ox == b->ox && a->oy == b->oy && a->grid == b->grid && a->lw == b->lw &&
           a->lh == b->lh && a->cs == b->cs && a->c0i == b->c0i && a->c0j == b->c0j &&
           a->ncx == b->ncx && a->ncy == b->ncy;
}

/* The candidate lattice of a fit on map m (NULL: the bins' extent plus the margin, at
 * 0.25 m), its coarse grid (cfg coarse, wider beyond RFS_PATHLOSS_MAX_COARSE points), and
 * the snap table emptied when the map or lattice changed (rfs_pathloss_lattice.c). */
void rfs_pathloss_lattice_setup(rfs_pathloss_t *p, const rfs_map_t *m);

/* Coarse point c's lattice point, packed (rfs_pathloss_t.snap): its grid point when
 * legal on the map; else, with coarse_snap, the legal point of its cell nearest it (least
 * di^2 + dj^2, the first in row order on a tie); else RFS_PATHLOSS_SNAP_NONE. *searched:
 * the cell was searched (at most 225 legality tests). */
uint8_t rfs_pathloss_snap_find(const rfs_pathloss_t *p, uint32_t c, bool *searched);

/* Lattice point (i, j) is a coarse point's (its cell's, once looked for). */
bool rfs_pathloss_is_coarse(const rfs_pathloss_t *p, int32_t i, int32_t j);

/* Coarse point c's lattice point (i, j) on the last fit's lattice (its grid point, or its
 * cell's stand-in with coarse_snap: docs/PATHLOSS.md, "Fit", step 4); false when none, or
 * when not looked for yet (a fit on another lattice in progress). */
bool rfs_pathloss_coarse_ij(const rfs_pathloss_t *p, uint32_t c, int32_t *i, int32_t *j);

/* floor(a / b) for b > 0. */
static inline int32_t rfs_pathloss_floor_div(int32_t a, int32_t b)
{
    int32_t q = a / b;
    return (a % b != 0 && a < 0) ? q - 1 : q;
}

/* Binning (re)starts with bins of bin_cm and none used. */
void rfs_pathloss_bin_reset(rfs_pathloss_t *p, int32_t bin_cm);

/* Bin samples p->pos..end - 1 into bins of p->bin_cm (sums of position and value, and
 * counts); false (binning must restart with bins twice as wide) when they need more than
 * RFS_PATHLOSS_MAX_BINS. */
bool rfs_pathloss_bin_add(rfs_pathloss_t *p, const rfs_sample_t *smp, uint32_t end);

/* Lattice point (i, j) is a candidate of the fit: on the lattice, legal on the map and
 * not within excl_r of a place ruled out. */
bool rfs_pathloss_cand_legal(const rfs_pathloss_t *p, int32_t i, int32_t j);

/* Mean Huber loss per unit weight, dB^2 Q16, saturated below NO_LOSS. */
static inline uint32_t rfs_pathloss_mean_loss(const rfs_pathloss_t *p, int64_t loss)
{
    uint64_t m = rfs_udiv64((uint64_t)loss, p->total);
    return m >= RFS_PATHLOSS_NO_LOSS ? RFS_PATHLOSS_NO_LOSS - 1u : (uint32_t)m;
}

/* Wall counts saturate here (15 walls are 75 dB at 5 dB each; four of them, in quarter
 * walls, fit a byte of the cache). */
#define RFS_PATHLOSS_WALLS_MAX 15u
/* Wall counts per bin footprint. */
#define RFS_PATHLOSS_FOOTPRINT_RAYS 4u

/* Give every bin on the map its wall-count cache row (found by its origin's core cell, or
 * new), after clearing the cache when it belongs to another map or lattice; find the
 * map's wall-free blocks when the map is new. */
void rfs_pathloss_walls_assign(rfs_pathloss_t *p);

/* One line's walls on p->map from (x, y) to (sx, sy) (metres Q16.16), saturated at
 * RFS_PATHLOSS_WALLS_MAX (rfs_map_walls_crossed, over the map's wall-free blocks when
 * rfs_pathloss_walls_assign() has found them). */
uint32_t rfs_pathloss_walls_line(const rfs_pathloss_t *p, rfs_q16_t x, rfs_q16_t y, rfs_q16_t sx,
                                 rfs_q16_t sy);

/* The cache column of lattice point (li, lj) counted with footprint `coarse` ? the
 * coarse candidates' : cfg footprint (one column when both are equal): found, or the next
 * free one; -1 when the cache is full (its counts are then not kept), lj >= 2^15 with two
 * footprints, or there is no map. */
int32_t rfs_pathloss_walls_col(rfs_pathloss_t *p, uint16_t li, uint16_t lj, bool coarse);

/* Bin bb's walls to the candidate in p->ev, in quarter walls (0..4 x WALLS_MAX): from
 * the cache when counted before, else counted (and cached when the bin has a row and the
 * candidate a column). *lines: the wall counts computed (left alone when cached). */
uint32_t rfs_pathloss_walls_bin(rfs_pathloss_t *p, const rfs_pathloss_bin_t *bb, uint32_t *lines);

/* rfs_model_ops_t.sample of the path-loss model (rfs_pathloss_draw.c): a coarse candidate
 * of the last fit drawn with its tempered likelihood-ratio weight. */
bool rfs_pathloss_sample_op(const void *self, rfs_rng_t *rng, rfs_q16_t *x, rfs_q16_t *y);

/* rfs_model_ops_t.near of the path-loss model (rfs_pathloss_draw.c): the coarse candidate
 * with the most weight per metre, when it beats the leader. */
bool rfs_pathloss_near_op(const void *self, const rfs_model_near_t *q, rfs_q16_t *x,
                          rfs_q16_t *y);

/* The cache row of wall origin (cx, cy), RFS_PATHLOSS_NO_ROW when none. */
uint16_t rfs_pathloss_walls_row_find(const rfs_pathloss_t *p, uint16_t cx, uint16_t cy);

/* A cache row for origin (cx, cy), which has none, kept from the next fit's tidying only
 * when a bin of it has that origin: a row never used, else (after one tidy since the last
 * fit, *tidied set: rows no bin of the last fit holds emptied, rfs_pathloss_walls.c) one
 * no bin of the last fit holds; RFS_PATHLOSS_NO_ROW when every row holds one. */
uint16_t rfs_pathloss_walls_row_warm(rfs_pathloss_t *p, uint16_t cx, uint16_t cy, bool *tidied);

/* The cache column of lattice point (li, lj) as rfs_pathloss_walls_col() finds it, or -1
 * when it has none; never a new one. */
int32_t rfs_pathloss_walls_col_find(const rfs_pathloss_t *p, uint16_t li, uint16_t lj,
                                    bool coarse);

/* Count the walls of origin row `row` (wall origin wx, wy) to column `col`, lattice point
 * (li, lj) counted with footprint fp, into the cache unless counted; the lines computed
 * (0 when it was). */
uint32_t rfs_pathloss_walls_warm(rfs_pathloss_t *p, uint16_t row, rfs_q16_t wx, rfs_q16_t wy,
                                 int32_t col, uint16_t li, uint16_t lj, rfs_q16_t fp);

/* rfs_model_ops_t.warm of the path-loss model (rfs_pathloss_warm.c). */
bool rfs_pathloss_warm_op(void *self, const rfs_model_fit_in_t *in, uint32_t budget);

/// rfs_model_ops_t.mean (rfs_pathloss_draw.c).
bool rfs_pathloss_mean_op(const void *self, rfs_q16_t temp, rfs_q16_t *x, rfs_q16_t *y);

#endif /* RFS_PATHLOSS_INTERNAL_H */
