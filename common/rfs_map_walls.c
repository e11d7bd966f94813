/* rfs_map_walls.c - walls crossed by a segment: runs of wall cells along the exact
 * supercover traversal of rfs_map.c, with the two accelerations a caller may attach, the
 * wall-block grid and the wall-distance grid (docs/MAPS.md, "The core's grids").
 */
#include "rfs_map.h"

#include <string.h>

#include "rfs_fix.h"
#include "rfs_map_internal.h"

static int64_t clamp64(int64_t v, int64_t lo, int64_t hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/* Whether the block column holding column i (on the map) has a wall block among the rows
 * ra..rb (real rows, ra <= rb; the parts off the map have none). */
static bool blocks_hold_wall(const rfs_map_t *m, const rfs_map_wall_blocks_t *b, int32_t i,
                             int32_t ra, int32_t rb)
{
    ra = ra < 0 ? 0 : ra;
    rb = rb >= (int32_t)m->h ? (int32_t)m->h - 1 : rb;
    const uint16_t bi = (uint16_t)((uint32_t)i >> b->shift);
    for (int32_t bj = ra >> b->shift; bj <= (rb >> b->shift) && ra <= rb; ++bj) {
        if (rfs_map_bit(b->bits, b->stride, bi, (uint16_t)bj)) {
            return true;
        }
    }
    return false;
}

/* The state of a wall walk: runs of wall cells so far, and whether the last cell visited
 * was a wall. */
typedef struct walk {
    uint32_t runs;
    bool in_wall;
} walk_t;

/* Visit rows jlo..jhi (walk order) of column i (on the map). step: bytes from one row to
 * the next in walk order, flip: walk rows run down the map, slow: the column needs the
 * careful walk (edge: rows -1 and h, which are not walls, may be among its rows; or with
 * blocks b it is long enough that a wall-free block's cells are passed over at once). */
static inline void walk_column(const rfs_map_t *m, const rfs_map_wall_blocks_t *b, walk_t *wk,
                               int32_t i, int32_t jlo, int32_t jhi, bool flip, int32_t step,
                               bool slow)
{
    const uint8_t mask = (uint8_t)(1u << (i & 7));
    if (slow) {
        const int32_t bs = b != 0 ? (int32_t)1 << b->shift : 0;
        const uint8_t *wd = m->wall_dist;
        for (int32_t j = jlo; j <= jhi; j++) {
            const int32_t jr = flip ? -1 - j : j;
            if (jr < 0 || jr >= (int32_t)m->h) {
                wk->in_wall = false;
                continue;
            }
            if (wd != 0) {
                /* The next d - 1 cells of the column either way are free too. */
                const int32_t d = wd[(uint32_t)jr * m->w + (uint32_t)i];
                wk->runs += (d == 0 && !wk->in_wall) ? 1u : 0u;
                wk->in_wall = d == 0;
                j += d > 1 ? d - 1 : 0;
                continue;
            }
            if (b != 0 && !rfs_map_bit(b->bits, b->stride, (uint16_t)((uint32_t)i >> b->shift),
                                       (uint16_t)((uint32_t)jr >> b->shift))) {
                wk->in_wall = false;
                j = flip ? -1 - (jr & -bs) : (jr | (bs - 1)); /* the rest of the block */
                continue;
            }
            const bool wall = (m->wall[(uint32_t)jr * m->stride + ((uint32_t)i >> 3)] & mask) != 0u;
            wk->runs += (wall && !wk->in_wall) ? 1u : 0u;
            wk->in_wall = wall;
        }
        return;
    }
    const int32_t jr0 = flip ? -1 - jlo : jlo;
    const uint8_t *p = m->wall + (uint32_t)jr0 * m->stride + ((uint32_t)i >> 3);
    uint32_t runs = wk->runs;
    uint32_t in = wk->in_wall ? 1u : 0u;
    for (int32_t j = jlo; j <= jhi; j++, p += step) {
        const uint32_t wall = (*p & mask) != 0u ? 1u : 0u;
        runs += wall & (in ^ 1u);
        in = wall;
    }
    wk->runs = runs;
    wk->in_wall = in != 0u;
}

/* The wall distance of cell (i, j), i on the map: 0 off the map's rows (no promise). */
static inline int32_t dist_at(const rfs_map_t *m, int32_t i, int32_t j)
{
    return (uint32_t)j < m->h ? m->wall_dist[(uint32_t)j * m->w + (uint32_t)i] : 0;
}

/* Step row j and its bound (j + 1) r dx while the bound is below n, four rows a step. */
static inline void rows_to(int32_t *j, int64_t *bound, int64_t n, int64_t rdx)
{
    while (*bound + 3 * rdx < n) {
        *j += 4;
        *bound += 4 * rdx;
    }
    while (*bound < n) {
        (*j)++;
        *bound += rdx;
    }
}

/* dx / dy in Q16 (0 <= dx, dy < 2^31), at most 256, rounded down after dropping low bits
 * so that one 32-bit division does (the skips only need a lower bound). */
static inline uint64_t slope_q16(int64_t dx, int64_t dy)
{
    if (dy * 256 <= dx) {
        return (uint64_t)256 << 16;
    }
    uint32_t sh = 0u; /* (dx >> sh) << 16 in 32 bits, dy >> sh below 2^15 */
    while ((dx >> sh) >= 65536 || (dy >> sh) >= 32768) {
        sh++;
    }
    return (((uint32_t)(dx >> sh) << 16) / (uint32_t)((dy >> sh) + 1));
}

/* The free square ahead of cell (i, jr), i on the map, jr the real row of the column's
 * first cell in walk order: its side in *d and the columns of it the walk may pass over.
 * With a forward grid (fwd, for the walk's direction), the square of side d with the
 * cell as its corner: the columns a segment of slope 1 / slope (Q16) crosses in it from
 * the bottom of its first row, min(d, (d - 1) slope), any slope. With a wall-distance
 * grid instead, on a shallow segment (shallow), the square round the cell, d its
 * distance: d - 1 columns ahead (steep segments pass over free cells inside a column,
 * walk_column). 0: none. */
static inline int32_t square_ahead(const rfs_map_t *m, const uint8_t *fwd, uint64_t slope,
                                   bool shallow, int32_t i, int32_t jr, int32_t *d)
{
    if (fwd != 0 && (uint32_t)jr < m->h) {
        *d = fwd[(uint32_t)jr * m->w + (uint32_t)i];
        const uint64_t c = ((uint64_t)(*d > 0 ? *d - 1 : 0) * slope) >> 16;
        return c < (uint64_t)*d ? (int32_t)c : *d;
    }
    if (fwd == 0 && shallow) {
        *d = dist_at(m, i, jr);
        return *d - 1;
    }
    return 0;
}

/* traverse() with the VISIT_WALLS visitor, specialised: the same cells in the same order
 * (the same endpoint swap, mirror and column recurrences), counting runs of wall cells.
 * Cells off the map are not walls: columns -1 and w (first and last, when an endpoint
 * lies on the map's edge) and rows -1 and h (a segment touching the bottom or top edge).
 * With blocks b, cells in wall-free blocks are passed over (they end a run, as a free cell
 * does): inside a column by whole blocks, and from the first column of a block column to
 * its last at once when the rows the segment spans there hold no wall block. With a
 * wall-distance grid (rfs_map_wall_dist_attach) instead of blocks, free cells are passed
 * over by the free squares their distances promise.
 * Scaling and overflow: as traverse() (y * dx below 2^61; r * dy, the step of y(x) * dx
 * per column, below 2^46); the count saturates at UINT16_MAX. */
static uint16_t walls_walk(const rfs_map_t *m, const rfs_map_wall_blocks_t *b, int64_t X0,
                           int64_t Y0, int64_t X1, int64_t Y1)
{
    const int32_t r = m->res;
    if (X1 < X0 || (X1 == X0 && Y1 < Y0)) {
        int64_t t = X0; X0 = X1; X1 = t;
        t = Y0; Y0 = Y1; Y1 = t;
    }
    const bool flip = Y1 < Y0;
    const bool edge = (flip ? Y1 : Y0) <= 0 || (flip ? Y0 : Y1) >= (int64_t)m->h * r;
    if (flip) {
        Y0 = -Y0;
        Y1 = -Y1;
    }
    const int64_t dx = X1 - X0;
    const int64_t dy = Y1 - Y0;
    const int32_t ia = rfs_map_low_cell(X0, r);
    const int32_t ib = rfs_map_fdiv(X1, r);
    const int32_t bs = b != 0 ? (int32_t)1 << b->shift : 1; /* block side, cells */
    walk_t wk = {0u, false};
    int32_t jlo = rfs_map_low_cell(Y0, r), jhi = dx == 0 ? rfs_map_fdiv(Y1, r) : jlo;
    const int64_t rdx = (int64_t)r * dx, rdy = (int64_t)r * dy;
    int64_t blo = ((int64_t)jlo + 1) * rdx; /* (jlo + 1) * r * dx */
    int64_t bhi = blo;                      /* (jhi + 1) * r * dx */
    int64_t nl = Y0 * dx;                   /* y(xl) * dx, xl the column's left end */
    int64_t nr = Y0 * dx + ((int64_t)(ia + 1) * r - X0) * dy; /* y(xr) * dx before clamping */
    const int32_t step = flip ? -(int32_t)m->stride : (int32_t)m->stride;
    const uint8_t *wd = m->wall_dist;
    const bool shallow = wd != 0 && dy <= dx;
    const uint8_t *fwd = m->wall_fwd != 0 ? m->wall_fwd + (flip ? (size_t)m->w * m->h : 0u) : 0;
    const uint64_t fwd_slope = fwd == 0 ? 0u : slope_q16(dx, dy);
    const int32_t long_col = b != 0 ? bs : (wd != 0 ? 3 : INT32_MAX); /* rows from which skips pay */
    for (int32_t i = ia; i <= ib; i++, nr += rdy) {
        if (dx != 0) {
            const int64_t n_r = i == ib ? Y1 * dx : nr; /* y(min(xr, X1)) * dx */
            while (blo < nl) {
                jlo++;
                blo += rdx;
            }
            if (jhi < jlo) {
                jhi = jlo;
                bhi = blo;
            }
            while (bhi <= n_r) {
                jhi++;
                bhi += rdx;
            }
            nl = n_r; /* the next column starts where this one ends */
            /* The columns i .. ie in the free square of side d ahead (square_ahead) when
             * their rows stay below jlo + d: y(xr) * dx at ie, ne, below (jlo + d) r dx. */
            int32_t d = 0;
            const int32_t cols = (fwd != 0 || shallow) && i < ib && (uint32_t)i < m->w
                                     ? square_ahead(m, fwd, fwd_slope, shallow, i,
                                                    flip ? -1 - jlo : jlo, &d) : 0;
            if (cols > 1) {
                const int32_t ie = i + cols - 1 > ib ? ib : i + cols - 1;
                const int64_t ne = ie == ib ? Y1 * dx : nr + (int64_t)(ie - i) * rdy;
                if (jhi - jlo < d && ne < blo + (int64_t)(d - 1) * rdx) {
                    rows_to(&jhi, &bhi, ne + 1, rdx);
                    rows_to(&jlo, &blo, ne, rdx);
                    wk.in_wall = false;
                    nl = ne;
                    nr += (int64_t)(ie - i) * rdy;
                    i = ie;
                    continue;
                }
            }
            /* A block column at once, from its first column, when the rows the segment
             * spans in it hold no wall block: those of its last column ie from the same
             * recurrence (jlo catches up in the next column's loop). */
            if (b != 0 && (i & (bs - 1)) == 0 && i < ib && (uint32_t)i < m->w) {
                const int32_t ie = i + bs - 1 > ib ? ib : i + bs - 1;
                const int64_t ne = ie == ib ? Y1 * dx : nr + (int64_t)(ie - i) * rdy;
                int32_t je = jhi;
                int64_t be = bhi;
                while (be <= ne) {
                    je++;
                    be += rdx;
                }
                if (!blocks_hold_wall(m, b, i, flip ? -1 - je : jlo, flip ? -1 - jlo : je)) {
                    wk.in_wall = false;
                    jhi = je;
                    bhi = be;
                    nl = ne;
                    nr += (int64_t)(ie - i) * rdy;
                    i = ie;
                    continue;
                }
            }
        }
        if ((uint32_t)i >= m->w) {
            wk.in_wall = false; /* column -1 or w */
            continue;
        }
        walk_column(m, b, &wk, i, jlo, jhi, flip, step, edge || jhi - jlo >= long_col);
    }
    return (uint16_t)(wk.runs > UINT16_MAX ? UINT16_MAX : wk.runs);
}

uint32_t rfs_map_wall_fwd_bytes(const rfs_map_t *m)
{
    return 2u * (uint32_t)m->w * m->h;
}

/* Side of the free square with cell (i, j) as its corner towards -x and -dj (dj = +-1):
 * 0 on a wall, else one more than the least of its three neighbours' ahead (0 off the map). */
static uint8_t fwd_square(const rfs_map_t *m, const uint8_t *g, int32_t i, int32_t j, int32_t dj)
{
    if (rfs_map_bit(m->wall, m->stride, (uint16_t)i, (uint16_t)j)) {
        return 0u;
    }
    const int32_t w = m->w, h = m->h, jn = j + dj;
    const bool in_i = i + 1 < w, in_j = jn >= 0 && jn < h;
    uint32_t a = in_i ? g[(uint32_t)j * (uint32_t)w + (uint32_t)i + 1u] : 0u;
    uint32_t b = in_j ? g[(uint32_t)jn * (uint32_t)w + (uint32_t)i] : 0u;
    uint32_t c = in_i && in_j ? g[(uint32_t)jn * (uint32_t)w + (uint32_t)i + 1u] : 0u;
    uint32_t v = (a < b ? a : b);
    v = (v < c ? v : c) + 1u;
    return (uint8_t)(v > 255u ? 255u : v);
}

int rfs_map_wall_fwd_attach(rfs_map_t *m, uint8_t *buf, uint32_t bytes)
{
    if (m->wall == 0 || buf == 0 || bytes < rfs_map_wall_fwd_bytes(m)) {
        return -1;
    }
    /* Squares towards +y first (rows from the top down), then towards -y (bottom up). */
    const int32_t w = m->w, h = m->h;
    uint8_t *dn = buf + (uint32_t)w * (uint32_t)h;
    for (int32_t j = h - 1; j >= 0; --j) {
        for (int32_t i = w - 1; i >= 0; --i) {
            buf[(uint32_t)j * (uint32_t)w + (uint32_t)i] = fwd_square(m, buf, i, j, 1);
        }
    }
    for (int32_t j = 0; j < h; ++j) {
        for (int32_t i = w - 1; i >= 0; --i) {
            dn[(uint32_t)j * (uint32_t)w + (uint32_t)i] = fwd_square(m, dn, i, j, -1);
        }
    }
    m->wall_fwd = buf;
    return 0;
}

uint16_t rfs_map_walls_crossed(const rfs_map_t *m, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                               rfs_q16_t y1)
{
    return rfs_map_walls_crossed_blocks(m, 0, x0, y0, x1, y1);
}

uint16_t rfs_map_walls_crossed_blocks(const rfs_map_t *m, const rfs_map_wall_blocks_t *b,
                                      rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1, rfs_q16_t y1)
{
    if (m->wall == 0) {
        return 0;
    }
    /* Endpoints off the map are clamped onto its edge (the off-map part has no walls;
     * the clamp moves them along the axes, an approximation documented in MAPS.md). */
    int64_t we = (int64_t)m->w * m->res;
    int64_t he = (int64_t)m->h * m->res;
    return walls_walk(m, m->wall_dist != 0 ? 0 : b, clamp64((int64_t)x0 - m->origin_x, 0, we),
                      clamp64((int64_t)y0 - m->origin_y, 0, he),
                      clamp64((int64_t)x1 - m->origin_x, 0, we),
                      clamp64((int64_t)y1 - m->origin_y, 0, he));
}

int rfs_map_wall_blocks(const rfs_map_t *m, uint8_t *buf, uint32_t bytes,
                        rfs_map_wall_blocks_t *b)
{
    if (m->wall == 0 || buf == 0) {
        return -1;
    }
    uint8_t shift = 3u;
    for (;; ++shift) {
        if (shift > 15u) {
            return -1;
        }
        uint32_t bw = ((uint32_t)m->w + (1u << shift) - 1u) >> shift;
        uint32_t bh = ((uint32_t)m->h + (1u << shift) - 1u) >> shift;
        if (bh * ((bw + 7u) / 8u) <= bytes) {
            b->bw = (uint16_t)bw;
            b->bh = (uint16_t)bh;
            b->stride = (uint16_t)((bw + 7u) / 8u);
            break;
        }
    }
    b->shift = shift;
    memset(buf, 0, (uint32_t)b->bh * b->stride);
    /* A block is 2^(shift - 3) whole bytes of each of its 2^shift rows. */
    for (uint32_t cy = 0u; cy < m->h; ++cy) {
        const uint8_t *row = m->wall + cy * m->stride;
        for (uint32_t k = 0u; k < m->stride; ++k) {
            if (row[k] != 0u) {
                rfs_map_bit_set(buf, b->stride, (uint16_t)(k >> (shift - 3u)),
                                (uint16_t)(cy >> shift), true);
            }
        }
    }
    b->bits = buf;
    return 0;
}

uint32_t rfs_map_wall_dist_bytes(const rfs_map_t *m)
{
    return (uint32_t)m->w * m->h;
}

/* d's neighbour (i + di, j + dj) plus one, 255 off the map (cells there are not walls). */
static uint32_t dist_via(const rfs_map_t *m, const uint8_t *d, int32_t i, int32_t j)
{
    if (i < 0 || j < 0 || i >= (int32_t)m->w || j >= (int32_t)m->h) {
        return 255u;
    }
    uint32_t v = d[(uint32_t)j * m->w + (uint32_t)i] + 1u;
    return v > 255u ? 255u : v;
}

int rfs_map_wall_dist_attach(rfs_map_t *m, uint8_t *buf, uint32_t bytes)
{
    if (m->wall == 0 || buf == 0 || bytes < rfs_map_wall_dist_bytes(m)) {
        return -1;
    }
    /* The chessboard distance transform: a forward and a backward pass over the eight
     * neighbours (exact for the L-infinity metric on a rectangle). */
    const int32_t w = m->w, h = m->h;
    for (int32_t j = 0; j < h; ++j) {
        for (int32_t i = 0; i < w; ++i) {
            uint32_t v = 255u;
            if (rfs_map_bit(m->wall, m->stride, (uint16_t)i, (uint16_t)j)) {
                v = 0u;
            } else {
                static const int8_t nb[4][2] = {{-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
                for (uint32_t k = 0u; k < 4u; ++k) {
                    uint32_t t = dist_via(m, buf, i + nb[k][0], j + nb[k][1]);
                    v = t < v ? t : v;
                }
            }
            buf[(uint32_t)j * (uint32_t)w + (uint32_t)i] = (uint8_t)v;
        }
    }
    for (int32_t j = h - 1; j >= 0; --j) {
        for (int32_t i = w - 1; i >= 0; --i) {
            static const int8_t nb[4][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}};
            uint8_t *c = &buf[(uint32_t)j * (uint32_t)w + (uint32_t)i];
            for (uint32_t k = 0u; k < 4u; ++k) {
                uint32_t t = dist_via(m, buf, i + nb[k][0], j + nb[k][1]);
                *c = t < *c ? (uint8_t)t : *c;
            }
        }
    }
    m->wall_dist = buf;
    return 0;
}
