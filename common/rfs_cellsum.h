/* rfs_cellsum.h - cell sums: a spatial index of the sample store for the local ridge
 * (docs/MODELS.md, "Cell sums").
 *
 * The local ridge needs nine sums over the samples within its radius of the query
 * (rfs_ridge.h). Kept per square cell of 2^shift centimetres (n, x, y, z, xx, xy, yy, xz,
 * yz, positions relative to the index's box), cells that lie wholly inside the disc add
 * their sums, cells wholly outside are skipped, and only the samples of cells the circle
 * cuts are tested one by one (each cell keeps a list of its store slots). The sums are
 * integers, so the result is exactly the one-by-one pass: the same fit, bit for bit.
 *
 * Updated on every store write (rfs_store_set_index). Memory: rfs_cellsum_cells() cells
 * of sizeof(rfs_cellsum_cell_t) and two uint16_t links per store slot; a 40 x 20 m box at
 * 32 cm cells is about 440 KB, so the Linux port and the simulator use it and the
 * microcontroller image does not (its fits then scan every sample, the same result).
 */
#ifndef RFS_CELLSUM_H
#define RFS_CELLSUM_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_store.h"

/// End of a cell's slot list.
#define RFS_CELLSUM_NONE 0xFFFFu

/// Sums of one cell's samples, positions in cm relative to the box's lower-left corner.
typedef struct rfs_cellsum_cell {
    int64_t sxx;  ///< sum of x*x, cm^2 (< 2^48)
    int64_t sxy;  ///< sum of x*y, cm^2
    int64_t syy;  ///< sum of y*y, cm^2
    int64_t sxz;  ///< sum of x*z, cm x Q9.6 (< 2^47)
    int64_t syz;  ///< sum of y*z, cm x Q9.6
    uint32_t sx;  ///< sum of x, cm (< 2^32: 65,535 samples below 65,536 cm)
    uint32_t sy;  ///< sum of y, cm
    int32_t sz;   ///< sum of z, Q9.6 (|z| <= 2^15, 65,535 samples: < 2^31)
    uint16_t n;   ///< samples in the cell
    uint16_t head; ///< first store slot of its list, RFS_CELLSUM_NONE: empty
} rfs_cellsum_cell_t;

/// The nine sums over a disc, positions relative to its centre (the ridge's u, v, z).
typedef struct rfs_cellsum_disc {
    int64_t n;   ///< samples
    int64_t su;  ///< sum of u, cm
    int64_t sv;  ///< sum of v, cm
    int64_t sz;  ///< sum of z, Q9.6
    int64_t suu; ///< sum of u*u, cm^2
    int64_t suv; ///< sum of u*v, cm^2
    int64_t svv; ///< sum of v*v, cm^2
    int64_t suz; ///< sum of u*z, cm x Q9.6
    int64_t svz; ///< sum of v*z, cm x Q9.6
} rfs_cellsum_disc_t;

/// The index; cells and links live in caller-owned arrays.
typedef struct rfs_cellsum {
    int32_t x0_cm;             ///< box lower-left corner x, cm (map frame)
    int32_t y0_cm;             ///< its y, cm
    uint16_t w;                ///< cells across
    uint16_t h;                ///< cells up
    uint8_t shift;             ///< cell side 2^shift cm
    rfs_cellsum_cell_t *cells; ///< w * h cells, row-major from the lower-left
    uint16_t *next;            ///< per store slot: next slot of its list
    uint16_t *prev;            ///< per store slot: previous slot, RFS_CELLSUM_NONE: the head
    uint16_t cap;              ///< store slots the links cover
    uint16_t outside;          ///< list of the slots off the box (tested one by one)
} rfs_cellsum_t;

/// Cells for a box of w_cm x h_cm at 2^shift cm cells (0: too large, over 65,535 cm
/// a side or a shift outside 3..10).
uint32_t rfs_cellsum_cells(int32_t w_cm, int32_t h_cm, uint8_t shift);

/// Start an empty index of the box (x0_cm, y0_cm, w_cm, h_cm) at 2^shift cm cells over
/// ncells cells (rfs_cellsum_cells()) and links of 2 x cap uint16_t. -1 on bad arguments.
int rfs_cellsum_init(rfs_cellsum_t *c, int32_t x0_cm, int32_t y0_cm, int32_t w_cm,
                     int32_t h_cm, uint8_t shift, rfs_cellsum_cell_t *cells, uint32_t ncells,
                     uint16_t *links, uint16_t cap);

/// Store slot `slot` now holds `s`; `old` is what it held (NULL: it was empty).
void rfs_cellsum_put(rfs_cellsum_t *c, uint16_t slot, const rfs_sample_t *old,
                     const rfs_sample_t *s);

/// The sums over the samples with u^2 + v^2 <= r_cm^2 (r_cm <= 65,535), u = x - qx_cm,
/// v = y - qy_cm;
/// `samples` is the store's array the slots index. Exactly the one-by-one sums.
/// Scaling and overflow: the sums are taken relative to the box's corner in int64 and
/// shifted to the centre once; samples in the disc lie within r_cm (<= 30,000) of it
/// and within 2^17 cm of the corner, so with 65,535 samples every term is below 2^62.
void rfs_cellsum_disc(const rfs_cellsum_t *c, const rfs_sample_t *samples, int32_t qx_cm,
                      int32_t qy_cm, int32_t r_cm, rfs_cellsum_disc_t *out);

/// The store's view of c (rfs_store_set_index(), rfs_seek_mem_t.index).
rfs_store_index_t rfs_cellsum_index(rfs_cellsum_t *c);

#endif
