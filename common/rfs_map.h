/* rfs_map.h - the occupancy map as the core sees it: bit grids and legality (paper section 2).
 *
 * The host (or a firmware image) loads a ROS map_server map and hands the core two bit
 * grids at the core's own resolution (default 0.1 m): `free` (1 = every fine cell under
 * it is free; unknown is not free) and `wall` (1 = some fine cell under it is occupied).
 * rfs_map_init() derives `legal` (1 = every cell within the clearance is free) into a
 * third caller buffer. Bit (cx, cy) is bit (cx & 7) of byte (cy * stride + cx / 8);
 * cell (0, 0) is the lower-left cell, whose lower-left corner is at the origin.
 *
 * "movements are restricted to legal movements, i.e., ones which are not part of a wall
 * or outside of the known map": a point is legal when its cell is legal, i.e. that cell
 * and every cell whose square comes closer than `clearance` to the cell's centre are on
 * the map and free; a straight move is legal when every cell its segment touches (closed
 * squares: corners and edges count, so no squeezing between diagonal obstacles) is legal.
 * The segment traversal is exact (integer arithmetic, docs/MAPS.md).
 *
 * The lattice: greedy grid search, epsilon candidates and path planning all use one
 * lattice of points `grid` apart (default 0.25 m): point (i, j) is at origin + grid/2 +
 * (i, j) * grid, and lw x lh points lie inside the map's extent. When grid is a whole
 * multiple of res (0.25 m over 0.125 m cells), every lattice step of one direction
 * visits the same cells relative to its start's cell: rfs_map_init records them once
 * from the traversal, and rfs_map_lattice_step_legal tests those bits directly.
 */
#ifndef RFS_MAP_H
#define RFS_MAP_H

#include <stdbool.h>
#include <stdint.h>

#include "rfs_fix.h"

/// Map configuration.
typedef struct rfs_map_cfg {
    rfs_q16_t clearance; ///< metres, Q16.16: free space required around a legal point (0.25)
    rfs_q16_t grid;      ///< metres, Q16.16: lattice spacing for search and planning (0.25)
} rfs_map_cfg_t;

/// Most columns and rows of a lattice step's cell box (one byte per row).
#define RFS_MAP_STEP_BOX 8u

/// The cells the exact traversal visits for one lattice step, as a bit box relative to
/// the cell of the step's start point. Recorded at init from the traversal itself on one
/// reference step; valid for every step of its direction when every lattice point lies
/// at the same place within its cell (grid a whole multiple of res).
typedef struct rfs_map_step {
    int8_t cx;                       ///< cells: the box's left column minus the start's
    int8_t cy;                       ///< cells: the box's bottom row minus the start's
    uint8_t cols;                    ///< columns in the box, 1..RFS_MAP_STEP_BOX
    uint8_t rows;                    ///< rows in the box, 1..RFS_MAP_STEP_BOX
    uint8_t mask[RFS_MAP_STEP_BOX];  ///< bit c of mask[k]: cell (cx + c, cy + k) is visited
} rfs_map_step_t;

/// The map; the bit arrays are caller-owned and must outlive it.
typedef struct rfs_map {
    rfs_map_cfg_t cfg;     ///< configuration copied at init
    uint16_t w;            ///< width, cells
    uint16_t h;            ///< height, cells
    uint16_t stride;       ///< bytes per row, (w + 7) / 8
    rfs_q16_t res;         ///< metres per cell, Q16.16
    rfs_q16_t origin_x;    ///< map frame x of the lower-left corner of cell (0, 0), metres Q16.16
    rfs_q16_t origin_y;    ///< map frame y of that corner, metres Q16.16
    const uint8_t *free;   ///< 1 = free, h * stride bytes
    const uint8_t *wall;   ///< 1 = occupied, h * stride bytes; may be NULL
    uint8_t *legal;        ///< 1 = legal (derived), h * stride bytes
    uint16_t lw;           ///< lattice points along x
    uint16_t lh;           ///< lattice points along y
    /// Lattice step patterns for the directions (1, 0), (1, 1), (0, 1), (-1, 1); the
    /// other four are the same segments walked backwards.
    rfs_map_step_t step[4];
    uint8_t step_n;        ///< cells per lattice step (grid / res); 0 = no patterns
    uint8_t step_c0;       ///< cells: the cell of lattice point 0 along an axis, (grid/2) / res
    uint16_t *memo;        ///< lattice memo (rfs_map_memo_attach()); NULL (init): none
    const uint8_t *wall_dist; ///< cells to the nearest wall cell (rfs_map_wall_dist_attach());
                              ///< NULL (init): none
    uint16_t *edges;       ///< lattice edge table (rfs_map_edges_attach()); NULL (init): none
    const uint8_t *wall_fwd; ///< free squares ahead of each cell (rfs_map_wall_fwd_attach());
                             ///< NULL (init): none
    const uint8_t *wall_cols; ///< the wall grid column by column (rfs_map_wall_cols_attach());
                              ///< NULL (init): none
} rfs_map_t;

/// Defaults: 0.25 m clearance, 0.25 m lattice.
rfs_map_cfg_t rfs_map_cfg_default(void);

/// Bytes of one bit grid of w x h cells.
static inline uint32_t rfs_map_bytes(uint16_t w, uint16_t h)
{
    return (uint32_t)h * (uint32_t)((w + 7u) / 8u);
}

/// Validate and derive the legal grid. Returns 0, or -1 on zero size, res <= 0,
/// clearance < 0 or above 64 m or 255 cells, grid <= 0, an extent (w * res or h * res)
/// above 16384 m or a far corner outside Q16.16, a lattice above 65535 points per axis or
/// empty, or a null free/legal array. free and wall may be const data (flash).
int rfs_map_init(rfs_map_t *m, const rfs_map_cfg_t *cfg, uint16_t w, uint16_t h,
                 rfs_q16_t res, rfs_q16_t origin_x, rfs_q16_t origin_y,
                 const uint8_t *free_bits, const uint8_t *wall_bits, uint8_t *legal_bits);

/// Cell of a point; false when off the map.
bool rfs_map_cell(const rfs_map_t *m, rfs_q16_t x, rfs_q16_t y, uint16_t *cx, uint16_t *cy);

/// Bit test on one of the map's grids (no bounds check beyond an assert).
static inline bool rfs_map_bit(const uint8_t *bits, uint16_t stride, uint16_t cx, uint16_t cy)
{
    return (bits[(uint32_t)cy * stride + (cx >> 3)] >> (cx & 7u)) & 1u;
}

/// Set or clear a bit in a grid (used by loaders and tests).
void rfs_map_bit_set(uint8_t *bits, uint16_t stride, uint16_t cx, uint16_t cy, bool v);

/// Point legality: on the map and clear of every non-free cell within the clearance.
bool rfs_map_point_legal(const rfs_map_t *m, rfs_q16_t x, rfs_q16_t y);

/// Straight-move legality: every cell the segment passes through is legal.
bool rfs_map_segment_legal(const rfs_map_t *m, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                           rfs_q16_t y1);

/// Legality of the lattice step from point (i, j) to (i + di, j + dj), di and dj in
/// {-1, 0, 1}: exactly rfs_map_segment_legal between the two points (false when either
/// is off the lattice). With step patterns (grid a multiple of res, at most 6 cells) and
/// the step's cell box on the map it tests the recorded cells' legal bits directly, a
/// few byte loads; otherwise it runs the traversal.
bool rfs_map_lattice_step_legal(const rfs_map_t *m, uint16_t i, uint16_t j, int32_t di,
                                int32_t dj);

/// Walls crossed by the straight line: the number of runs of consecutive wall cells the
/// segment touches, in order along it (0 when the map has no wall grid). Endpoints off
/// the map are clamped onto its edge first.
uint16_t rfs_map_walls_crossed(const rfs_map_t *m, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                               rfs_q16_t y1);

/// Which blocks of 2^shift x 2^shift cells of a map hold a wall cell, one bit each (bit
/// (bi, bj) as rfs_map_bit): lets rfs_map_walls_crossed_blocks() pass over wall-free
/// blocks in long columns without reading their cells.
typedef struct rfs_map_wall_blocks {
    uint8_t shift;       ///< log2 of the block side, cells (>= 3: a block is whole bytes)
    uint16_t bw;         ///< blocks along x
    uint16_t bh;         ///< blocks along y
    uint16_t stride;     ///< bytes per block row, (bw + 7) / 8
    const uint8_t *bits; ///< 1 = the block holds a wall cell, bh * stride bytes
} rfs_map_wall_blocks_t;

/// Fill *b from the map's wall grid into buf (bytes long), with the smallest block side
/// of 8, 16, 32 ... cells whose bit grid fits. Returns 0, or -1 when the map has no wall
/// grid or buf is too small even for blocks of 2^15 cells.
int rfs_map_wall_blocks(const rfs_map_t *m, uint8_t *buf, uint32_t bytes,
                        rfs_map_wall_blocks_t *b);

/// rfs_map_walls_crossed() of the same map, equal for every segment, passing over
/// wall-free blocks in long columns (b from rfs_map_wall_blocks() of that map).
uint16_t rfs_map_walls_crossed_blocks(const rfs_map_t *m, const rfs_map_wall_blocks_t *b,
                                      rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1);

/// Position of lattice point (i, j), metres Q16.16.
void rfs_map_lattice_point(const rfs_map_t *m, uint16_t i, uint16_t j, rfs_q16_t *x,
                           rfs_q16_t *y);

/// Nearest lattice point to (x, y), clamped to the lattice.
void rfs_map_lattice_nearest(const rfs_map_t *m, rfs_q16_t x, rfs_q16_t y, uint16_t *i,
                             uint16_t *j);

/// Lattice point legality (its position is a legal point).
bool rfs_map_lattice_legal(const rfs_map_t *m, uint16_t i, uint16_t j);

/// Entries of a lattice memo for m (rfs_map_memo_attach()): one per lattice point.
uint32_t rfs_map_memo_entries(const rfs_map_t *m);

/// Attach a lattice memo (`entries` >= rfs_map_memo_entries(m), cleared here; it stays the
/// caller's): without step patterns, rfs_map_lattice_legal() and
/// rfs_map_lattice_step_legal() then compute each answer once per map (the planner tests
/// every edge of every search). rfs_map_init() detaches it. -1 when buf is NULL or too
/// small.
int rfs_map_memo_attach(rfs_map_t *m, uint16_t *buf, uint32_t entries);

/// Bit 8 of an edge table entry: bits 0..7 hold the point's rfs_map_lattice_edges().
#define RFS_MAP_EDGES_KNOWN 0x100u

/// Legal edges of lattice point (i, j): bit k set when the neighbour towards direction k
/// ((1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)) is on the
/// lattice and legal (rfs_map_lattice_legal) and the step to it is legal
/// (rfs_map_lattice_step_legal). Remembered in the edge table when one is attached.
uint8_t rfs_map_lattice_edges(const rfs_map_t *m, uint16_t i, uint16_t j);

/// Attach an edge table (rfs_map_memo_entries(m) entries or more, cleared here; it stays
/// the caller's): rfs_map_lattice_edges() then computes each point's answer once per map,
/// and the planner reads a point's edges in one load instead of sixteen tests (a host
/// index, 2 bytes a lattice point). rfs_map_init() detaches it. -1 when buf is NULL or
/// too small.
int rfs_map_edges_attach(rfs_map_t *m, uint16_t *buf, uint32_t entries);

/// Bytes of a wall-distance grid for m (rfs_map_wall_dist_attach()): one per cell.
uint32_t rfs_map_wall_dist_bytes(const rfs_map_t *m);

/// Fill buf with each cell's Chebyshev distance in cells to the nearest wall cell (0 on a
/// wall, saturated at 255; cells off the map are not walls) and attach it (it stays the
/// caller's, outliving m): rfs_map_walls_crossed() then passes over the free squares a
/// distance promises instead of reading their cells (the same counts; a host index, about
/// 1 byte a cell, docs/PATHLOSS.md, "Work, the wall-count cache and slicing").
/// rfs_map_init() detaches it. -1 when the map has no wall grid or buf is NULL or too small.
int rfs_map_wall_dist_attach(rfs_map_t *m, uint8_t *buf, uint32_t bytes);

/// Bytes of a forward free-square grid for m (rfs_map_wall_fwd_attach()): two per cell,
/// saturated at UINT32_MAX (a map of 2^31 cells or more cannot take the grid).
uint32_t rfs_map_wall_fwd_bytes(const rfs_map_t *m);

/// Fill buf with the side in cells of the largest wall-free square on the map with each
/// cell as its corner towards -x, once towards -y and once towards +y (saturated at 255),
/// and attach it (it stays the caller's, outliving m): rfs_map_walls_crossed() then passes
/// over the free square ahead of the walk, whatever lies behind (the same counts; a host
/// index, docs/PATHLOSS.md, "Work, the wall-count cache and slicing"). rfs_map_init()
/// detaches it. -1 when the map has no wall grid or buf is NULL or too small.
int rfs_map_wall_fwd_attach(rfs_map_t *m, uint8_t *buf, uint32_t bytes);

/// Bytes of a column grid for m (rfs_map_wall_cols_attach()): twice w x ((h + 7) / 8 + 4).
uint32_t rfs_map_wall_cols_bytes(const rfs_map_t *m);

/// Fill buf with the wall grid column by column, once bottom up and once top down, and
/// attach it (it stays the caller's, outliving m): rfs_map_walls_crossed() with a forward
/// or wall-distance grid then reads a steep walk's column a word at a time, as a shallow
/// walk reads its rows (the same counts; a host index). rfs_map_init() detaches it. -1
/// when the map has no wall grid or buf is NULL or too small.
int rfs_map_wall_cols_attach(rfs_map_t *m, uint8_t *buf, uint32_t bytes);

#endif /* RFS_MAP_H */
