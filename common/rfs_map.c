/* rfs_map.c - bit grids, legality and exact grid traversal (paper section 2: "movements
 * are restricted to legal movements").
 *
 * Rules (docs/MAPS.md):
 *  - Cell legality: cell c is legal when it and every cell whose square comes closer
 *    than `clearance` to c's square are on the map and free, so every point of a legal
 *    cell keeps the clearance. Off-map counts as not free, so cells within the clearance
 *    of the map edge are illegal.
 *  - A point is legal when the cell it lies in is legal.
 *  - A segment passes through every cell whose CLOSED square it touches (supercover):
 *    a segment through a cell corner passes through all the cells sharing that corner,
 *    and one running along a cell edge passes through the cells on both sides. This is
 *    the conservative reading: a move never squeezes between two diagonal obstacles.
 *    The traversal is exact (integer cross-multiplication, no rounding).
 *  - Walls crossed (rfs_map_walls.c): runs of consecutive wall cells in traversal order
 *    along the segment.
 */
#include "rfs_map.h"

#include <string.h>

#include "rfs_assert.h"
#include "rfs_map_internal.h"

/* The map extent is limited to 2^30 Q16 units (16384 m) per axis so that coordinates
 * relative to the origin fit in 31 bits and the traversal's products fit in int64. */
#define MAP_EXTENT_MAX ((int64_t)1 << 30)
/* Clearance at most 64 m and 255 cells: keeps the mask loop short and its squares
 * below 2^46. */
#define CLEARANCE_MAX RFS_Q16_INT(64)
#define CLEARANCE_CELLS_MAX 255

rfs_map_cfg_t rfs_map_cfg_default(void)
{
    rfs_map_cfg_t c;
    c.clearance = RFS_Q16_FRAC(1, 4);
    c.grid = RFS_Q16_FRAC(1, 4);
    return c;
}

void rfs_map_bit_set(uint8_t *bits, uint16_t stride, uint16_t cx, uint16_t cy, bool v)
{
    uint32_t i = (uint32_t)cy * stride + (cx >> 3);
    uint8_t m = (uint8_t)(1u << (cx & 7u));
    bits[i] = v ? (uint8_t)(bits[i] | m) : (uint8_t)(bits[i] & ~m);
}

/* Does the cell at offset (dx, dy) cells (dx, dy >= 0) come within the clearance of a
 * cell's square? The cell itself always counts. The two squares are dx-1 and dy-1 cells apart per axis (0 when the
 * offset is 0 or 1). Scaling and overflow: terms are distances in Q16 (res Q16 times a
 * small integer, int64); a term >= clearance excludes at once, so the squares are taken
 * only below (64 m)^2 = 2^44 in Q32. */
static bool mask_in(rfs_q16_t res, rfs_q16_t clearance, int32_t dx, int32_t dy)
{
    if (dx == 0 && dy == 0) {
        return true; /* the cell itself */
    }
    int64_t lim = clearance;
    int64_t ex = dx > 1 ? (int64_t)(dx - 1) * res : 0;
    int64_t ey = dy > 1 ? (int64_t)(dy - 1) * res : 0;
    if (ex >= lim || ey >= lim) {
        return false;
    }
    return ex * ex + ey * ey < lim * lim;
}

/* Eight bits of a row starting at bit `pos` (may be negative); bits off the row
 * (pos < 0 or >= w) read as 0. */
static uint8_t row_get8(const uint8_t *row, uint16_t w, int32_t pos)
{
    int32_t lo = pos < 0 ? -pos : 0;                       /* first bit on the row */
    int32_t hi = (int32_t)w - pos < 8 ? (int32_t)w - pos : 8; /* one past the last */
    if (hi <= lo) {
        return 0;
    }
    uint32_t v = 0;
    int32_t q = pos >> 3; /* arithmetic shift: floor */
    int32_t sh = pos & 7;
    if (q >= 0) {
        v = (uint32_t)row[q] >> sh;
    }
    if (sh != 0 && q + 1 >= 0 && q + 1 < (int32_t)((w + 7u) / 8u)) {
        v |= (uint32_t)row[q + 1] << (8 - sh);
    }
    uint32_t mask = ((1u << hi) - 1u) & ~((1u << lo) - 1u);
    return (uint8_t)(v & mask);
}

/* Half-width in cells of the clearance mask's row dy (dy >= 0), or -1 when the row is
 * entirely outside the clearance. */
static int32_t mask_half_width(const rfs_map_t *m, int32_t dy)
{
    int32_t k = -1;
    while (k + 1 <= CLEARANCE_CELLS_MAX + 1 && mask_in(m->res, m->cfg.clearance, k + 1, dy)) {
        k++;
    }
    return k;
}

/* legal = erosion of free by the clearance mask: for every mask row dy with half-width
 * k, AND into each legal row cy the free row cy + dy eroded horizontally by k (rows off
 * the map are all 0). Loops run mask row by mask row so no table is needed: the stack
 * stays small on the microcontroller (2.5 KB in all). */
static void derive_legal(rfs_map_t *m)
{
    int32_t R = 0;
    while (R < CLEARANCE_CELLS_MAX + 1 && mask_half_width(m, R + 1) >= 0) {
        R++;
    }
    memset(m->legal, 0xFF, (uint32_t)m->h * m->stride);
    for (int32_t dy = -R; dy <= R; dy++) {
        int32_t k = mask_half_width(m, dy < 0 ? -dy : dy);
        for (uint16_t cy = 0; cy < m->h; cy++) {
            uint8_t *out = m->legal + (uint32_t)cy * m->stride;
            int32_t ry = (int32_t)cy + dy;
            if (ry < 0 || ry >= (int32_t)m->h) {
                memset(out, 0, m->stride);
                continue;
            }
            const uint8_t *row = m->free + (uint32_t)ry * m->stride;
            for (uint16_t b = 0; b < m->stride; b++) {
                uint8_t acc = out[b];
                for (int32_t d = -k; d <= k && acc; d++) {
                    acc &= row_get8(row, m->w, (int32_t)b * 8 + d);
                }
                out[b] = acc;
            }
        }
    }
    /* Padding bits past w stay 0. */
    if (m->w & 7u) {
        for (uint16_t cy = 0; cy < m->h; cy++) {
            m->legal[(uint32_t)cy * m->stride + m->stride - 1u] &= (uint8_t)((1u << (m->w & 7u)) - 1u);
        }
    }
}

static void derive_steps(rfs_map_t *m);

int rfs_map_init(rfs_map_t *m, const rfs_map_cfg_t *cfg, uint16_t w, uint16_t h,
                 rfs_q16_t res, rfs_q16_t origin_x, rfs_q16_t origin_y,
                 const uint8_t *free_bits, const uint8_t *wall_bits, uint8_t *legal_bits)
{
    if (m == 0 || cfg == 0 || free_bits == 0 || legal_bits == 0 || w == 0 || h == 0 ||
        res <= 0 || cfg->clearance < 0 || cfg->clearance > CLEARANCE_MAX || cfg->grid <= 0) {
        return -1;
    }
    int64_t wext = (int64_t)w * res;
    int64_t hext = (int64_t)h * res;
    if (wext > MAP_EXTENT_MAX || hext > MAP_EXTENT_MAX) {
        return -1;
    }
    /* The far corner must be representable in Q16.16. */
    if ((int64_t)origin_x + wext > INT32_MAX || (int64_t)origin_y + hext > INT32_MAX) {
        return -1;
    }
    if ((uint32_t)cfg->clearance / (uint32_t)res > CLEARANCE_CELLS_MAX) {
        return -1;
    }
    /* Lattice points grid/2 + i*grid inside the extent. */
    int64_t half = cfg->grid / 2;
    if (wext <= half || hext <= half) {
        return -1;
    }
    uint32_t lw = (uint32_t)(wext - half - 1) / (uint32_t)cfg->grid + 1u;
    uint32_t lh = (uint32_t)(hext - half - 1) / (uint32_t)cfg->grid + 1u;
    if (lw > UINT16_MAX || lh > UINT16_MAX) {
        return -1;
    }
    memset(m, 0, sizeof(*m));
    m->cfg = *cfg;
    m->w = w;
    m->h = h;
    m->stride = (uint16_t)((w + 7u) / 8u);
    m->res = res;
    m->origin_x = origin_x;
    m->origin_y = origin_y;
    m->free = free_bits;
    m->wall = wall_bits;
    m->legal = legal_bits;
    m->lw = (uint16_t)lw;
    m->lh = (uint16_t)lh;
    derive_legal(m);
    derive_steps(m);
    return 0;
}

bool rfs_map_cell(const rfs_map_t *m, rfs_q16_t x, rfs_q16_t y, uint16_t *cx, uint16_t *cy)
{
    int64_t rx = (int64_t)x - m->origin_x;
    int64_t ry = (int64_t)y - m->origin_y;
    if (rx < 0 || ry < 0 || rx >= (int64_t)m->w * m->res || ry >= (int64_t)m->h * m->res) {
        return false;
    }
    /* Both below 2^30: 32-bit division (hardware on Cortex-M4, no libgcc helper). */
    *cx = (uint16_t)((uint32_t)rx / (uint32_t)m->res);
    *cy = (uint16_t)((uint32_t)ry / (uint32_t)m->res);
    return true;
}

bool rfs_map_point_legal(const rfs_map_t *m, rfs_q16_t x, rfs_q16_t y)
{
    uint16_t cx;
    uint16_t cy;
    if (!rfs_map_cell(m, x, y, &cx, &cy)) {
        return false;
    }
    return rfs_map_bit(m->legal, m->stride, cx, cy);
}

/* --- exact supercover traversal ---------------------------------------------------- */

typedef enum visit_mode {
    VISIT_LEGAL,  /* check legality */
    VISIT_RECORD  /* record the cells (step patterns) */
} visit_mode_t;

typedef struct visitor {
    const rfs_map_t *m;
    uint16_t *rec;    /* VISIT_RECORD: 16 x 16 bit box of cells (0..15, 0..15) */
    uint8_t mode;     /* visit_mode_t */
    bool legal;       /* legality so far (VISIT_RECORD: every cell inside the box) */
} visitor_t;

/* Visit cell (i, j); false stops the traversal. */
static bool visit(visitor_t *v, int32_t i, int32_t j)
{
    const rfs_map_t *m = v->m;
    if (v->mode == VISIT_LEGAL) {
        bool on = i >= 0 && j >= 0 && i < (int32_t)m->w && j < (int32_t)m->h;
        if (!on || !rfs_map_bit(m->legal, m->stride, (uint16_t)i, (uint16_t)j)) {
            v->legal = false;
            return false;
        }
        return true;
    }
    if (i < 0 || i > 15 || j < 0 || j > 15) { /* VISIT_RECORD */
        v->legal = false;
        return false;
    }
    v->rec[j] = (uint16_t)(v->rec[j] | (1u << i));
    return true;
}

/* Traverse the closed supercover of the segment between two points given relative to
 * the origin (each coordinate in [-2^30, 2^30]), in order along the segment.
 * Scaling and overflow: coordinates are Q16 metres below 2^30 in magnitude, so
 * y*dx and x*dy products are below 2^61 and (j + 1) * res * dx stays below 2^62. */
static void traverse(visitor_t *v, int64_t X0, int64_t Y0, int64_t X1, int64_t Y1)
{
    const int32_t r = v->m->res;
    if (X1 < X0 || (X1 == X0 && Y1 < Y0)) {
        int64_t t = X0; X0 = X1; X1 = t;
        t = Y0; Y0 = Y1; Y1 = t;
    }
    bool flip = Y1 < Y0;
    if (flip) {
        /* Mirror y: cell j' of -y is cell -1 - j' of y. */
        Y0 = -Y0;
        Y1 = -Y1;
    }
    const int64_t dx = X1 - X0;
    const int64_t dy = Y1 - Y0;
    const int32_t ia = rfs_map_low_cell(X0, r);
    const int32_t ib = rfs_map_fdiv(X1, r);
    if (dx == 0) {
        int32_t ja = rfs_map_low_cell(Y0, r);
        int32_t jb = rfs_map_fdiv(Y1, r);
        for (int32_t i = ia; i <= ib; i++) {
            for (int32_t j = ja; j <= jb; j++) {
                if (!visit(v, i, flip ? -1 - j : j)) {
                    return;
                }
            }
        }
        return;
    }
    const int64_t rdx = (int64_t)r * dx;
    const int64_t y0dx = Y0 * dx;
    int32_t jlo = rfs_map_low_cell(Y0, r);
    int64_t blo = ((int64_t)jlo + 1) * r * dx; /* (jlo + 1) * r * dx */
    int32_t jhi = jlo;
    int64_t bhi = blo;                         /* (jhi + 1) * r * dx */
    for (int32_t i = ia; i <= ib; i++) {
        int64_t xl = (int64_t)i * r;
        int64_t xr = xl + r;
        if (xl < X0) {
            xl = X0;
        }
        if (xr > X1) {
            xr = X1;
        }
        int64_t nl = y0dx + (xl - X0) * dy; /* y(xl) * dx */
        int64_t nr = y0dx + (xr - X0) * dy; /* y(xr) * dx */
        while (blo < nl) {
            jlo++;
            blo += rdx;
        }
        if (jhi < jlo) {
            jhi = jlo;
            bhi = blo;
        }
        while (bhi <= nr) {
            jhi++;
            bhi += rdx;
        }
        for (int32_t j = jlo; j <= jhi; j++) {
            if (!visit(v, i, flip ? -1 - j : j)) {
                return;
            }
        }
    }
}

/* Cell (i, j) is on the map and legal (unsigned compares: a negative index is off). */
static bool legal_cell(const rfs_map_t *m, int32_t i, int32_t j)
{
    return (uint32_t)i < m->w && (uint32_t)j < m->h &&
           ((m->legal[(uint32_t)j * m->stride + ((uint32_t)i >> 3)] >> ((uint32_t)i & 7u)) & 1u);
}

/* traverse() for VISIT_LEGAL alone, the visit inlined: the same cells in the same order
 * (the planner's string pulling runs it on every test, docs/MAPS.md, "Planning"); true
 * when every one is legal. Scaling and overflow: traverse()'s. */
static bool traverse_legal(const rfs_map_t *m, int64_t X0, int64_t Y0, int64_t X1, int64_t Y1)
{
    const int32_t r = m->res;
    if (X1 < X0 || (X1 == X0 && Y1 < Y0)) {
        int64_t t = X0; X0 = X1; X1 = t;
        t = Y0; Y0 = Y1; Y1 = t;
    }
    const bool flip = Y1 < Y0;
    if (flip) {
        Y0 = -Y0;
        Y1 = -Y1;
    }
    const int64_t dx = X1 - X0;
    const int64_t dy = Y1 - Y0;
    const int32_t ia = rfs_map_low_cell(X0, r);
    const int32_t ib = rfs_map_fdiv(X1, r);
    if (dx == 0) {
        const int32_t ja = rfs_map_low_cell(Y0, r);
        const int32_t jb = rfs_map_fdiv(Y1, r);
        for (int32_t i = ia; i <= ib; i++) {
            for (int32_t j = ja; j <= jb; j++) {
                if (!legal_cell(m, i, flip ? -1 - j : j)) {
                    return false;
                }
            }
        }
        return true;
    }
    const int64_t rdx = (int64_t)r * dx;
    const int64_t y0dx = Y0 * dx;
    int32_t jlo = rfs_map_low_cell(Y0, r);
    int64_t blo = ((int64_t)jlo + 1) * r * dx;
    int32_t jhi = jlo;
    int64_t bhi = blo;
    int64_t xl = (int64_t)ia * r;
    for (int32_t i = ia; i <= ib; i++, xl += r) {
        const int64_t cl = xl < X0 ? X0 : xl;
        const int64_t cr = xl + r > X1 ? X1 : xl + r;
        const int64_t nl = y0dx + (cl - X0) * dy;
        const int64_t nr = y0dx + (cr - X0) * dy;
        while (blo < nl) {
            jlo++;
            blo += rdx;
        }
        if (jhi < jlo) {
            jhi = jlo;
            bhi = blo;
        }
        while (bhi <= nr) {
            jhi++;
            bhi += rdx;
        }
        for (int32_t j = jlo; j <= jhi; j++) {
            if (!legal_cell(m, i, flip ? -1 - j : j)) {
                return false;
            }
        }
    }
    return true;
}

bool rfs_map_segment_legal(const rfs_map_t *m, rfs_q16_t x0, rfs_q16_t y0, rfs_q16_t x1,
                           rfs_q16_t y1)
{
    uint16_t cx;
    uint16_t cy;
    if (!rfs_map_cell(m, x0, y0, &cx, &cy) || !rfs_map_cell(m, x1, y1, &cx, &cy)) {
        return false;
    }
    return traverse_legal(m, (int64_t)x0 - m->origin_x, (int64_t)y0 - m->origin_y,
                          (int64_t)x1 - m->origin_x, (int64_t)y1 - m->origin_y);
}

/* --- lattice step patterns ------------------------------------------------------------ */

/* Directions of the four recorded patterns; the other four walk the same segments back. */
static const int8_t STEP_DX[4] = {1, 1, 0, -1};
static const int8_t STEP_DY[4] = {0, 1, 1, 1};

/* Record each direction's pattern from the traversal itself. The traversal is invariant
 * under shifts by whole cells (floors and cross-multiplications shift together), so when
 * grid = n * res every lattice point (g/2 + i*g) lies at the same offset (g/2) mod res
 * within its cell, its cell is i*n + (g/2)/res, and the cells of one step from any point
 * at that offset, relative to its cell, are those of every step in that direction:
 * corners and edges included, by construction. The reference step starts at that offset
 * in cell (8, 8) of a 16 x 16 box (coordinates only: recording reads no grid, so the
 * map's size does not matter). Other ratios (0.25 m over 0.1 m cells: the offset drifts
 * from point to point) keep step_n 0 and rfs_map_lattice_step_legal runs the traversal.
 * Scaling and overflow: n <= 6 and grid <= 2^24 (256 m), so the reference coordinates
 * (below 8 res + 2 grid) are far inside the traversal's 2^30 limit. */
static void derive_steps(rfs_map_t *m)
{
    m->step_n = 0;
    if (m->cfg.grid > ((int32_t)1 << 24)) {
        return;
    }
    /* 32-bit divisions: both positive and below 2^31 (no libgcc helper on the M4). */
    const uint32_t r = (uint32_t)m->res;
    const uint32_t g = (uint32_t)m->cfg.grid;
    if (g % r != 0u || g / r > 6u) {
        return;
    }
    const int64_t x0 = 8 * (int64_t)r + (int64_t)((g / 2u) % r);
    for (uint32_t k = 0; k < 4u; k++) {
        uint16_t box[16];
        memset(box, 0, sizeof(box));
        visitor_t v = {m, box, VISIT_RECORD, true};
        traverse(&v, x0, x0, x0 + STEP_DX[k] * (int64_t)g, x0 + STEP_DY[k] * (int64_t)g);
        if (!v.legal) {
            return;
        }
        int32_t c_lo = 16, c_hi = -1, k_lo = 16, k_hi = -1;
        for (int32_t row = 0; row < 16; row++) {
            for (int32_t c = 0; c < 16; c++) {
                if ((box[row] >> c) & 1u) {
                    c_lo = c < c_lo ? c : c_lo;
                    c_hi = c > c_hi ? c : c_hi;
                    k_lo = row < k_lo ? row : k_lo;
                    k_hi = row > k_hi ? row : k_hi;
                }
            }
        }
        if (c_hi < 0 || c_hi - c_lo + 1 > (int32_t)RFS_MAP_STEP_BOX ||
            k_hi - k_lo + 1 > (int32_t)RFS_MAP_STEP_BOX) {
            return;
        }
        rfs_map_step_t *st = &m->step[k];
        memset(st, 0, sizeof(*st));
        st->cx = (int8_t)(c_lo - 8);
        st->cy = (int8_t)(k_lo - 8);
        st->cols = (uint8_t)(c_hi - c_lo + 1);
        st->rows = (uint8_t)(k_hi - k_lo + 1);
        for (int32_t row = k_lo; row <= k_hi; row++) {
            st->mask[row - k_lo] = (uint8_t)(box[row] >> c_lo);
        }
    }
    m->step_c0 = (uint8_t)((g / 2u) / r);
    m->step_n = (uint8_t)(g / r);
}

/* --- lattice memo ---------------------------------------------------------------------- */

/* Memo bits of a lattice point: its four steps towards (1, 0), (1, 1), (0, 1), (-1, 1)
 * (the other four are its neighbours' steps walked back), then whether each is known;
 * its own legality, then whether that is known. */
#define MEMO_STEP_KNOWN(k) (0x10u << (k))
#define MEMO_LEGAL 0x100u
#define MEMO_LEGAL_KNOWN 0x200u

uint32_t rfs_map_memo_entries(const rfs_map_t *m)
{
    return (uint32_t)m->lw * m->lh;
}

/* Clear a caller's per-lattice-point buffer and attach it at *slot (memo, edge table). */
static int attach_lattice_buf(rfs_map_t *m, uint16_t *buf, uint32_t entries, uint16_t **slot)
{
    if (buf == 0 || entries < rfs_map_memo_entries(m)) {
        return -1;
    }
    memset(buf, 0, (size_t)rfs_map_memo_entries(m) * sizeof(buf[0]));
    *slot = buf;
    return 0;
}

int rfs_map_memo_attach(rfs_map_t *m, uint16_t *buf, uint32_t entries)
{
    return attach_lattice_buf(m, buf, entries, &m->memo);
}

/* The step from lattice point (si, sj) towards (di, dj) of the upper half ((1, 0), (1, 1),
 * (0, 1), (-1, 1): k 0..3), both ends on the lattice, by the traversal; remembered in the
 * memo when one is attached. Out of line: the step patterns' path stays lean. */
__attribute__((noinline)) static bool step_by_traversal(const rfs_map_t *m, uint32_t si,
                                                        uint32_t sj, int32_t di, int32_t dj)
{
    const uint32_t k = dj == 0 ? 0u : (uint32_t)(2 - di);
    uint16_t *e = m->memo != 0 ? &m->memo[sj * m->lw + si] : 0;
    if (e != 0 && (*e & MEMO_STEP_KNOWN(k)) != 0u) {
        return ((*e >> k) & 1u) != 0u;
    }
    rfs_q16_t x0;
    rfs_q16_t y0;
    rfs_q16_t x1;
    rfs_q16_t y1;
    rfs_map_lattice_point(m, (uint16_t)si, (uint16_t)sj, &x0, &y0);
    rfs_map_lattice_point(m, (uint16_t)(si + (uint32_t)di), (uint16_t)(sj + (uint32_t)dj), &x1,
                          &y1);
    const bool ok = rfs_map_segment_legal(m, x0, y0, x1, y1);
    if (e != 0) {
        *e = (uint16_t)(*e | MEMO_STEP_KNOWN(k) | (ok ? 1u << k : 0u));
    }
    return ok;
}

/* --- lattice edge table ------------------------------------------------------------ */

static const int8_t EDGE_DX[8] = {1, 1, 0, -1, -1, -1, 0, 1};
static const int8_t EDGE_DY[8] = {0, 1, 1, 1, 0, -1, -1, -1};

int rfs_map_edges_attach(rfs_map_t *m, uint16_t *buf, uint32_t entries)
{
    return attach_lattice_buf(m, buf, entries, &m->edges);
}

uint8_t rfs_map_lattice_edges(const rfs_map_t *m, uint16_t i, uint16_t j)
{
    if (i >= m->lw || j >= m->lh) {
        return 0;
    }
    uint16_t *e = m->edges != 0 ? &m->edges[(uint32_t)j * m->lw + i] : 0;
    if (e != 0 && (*e & RFS_MAP_EDGES_KNOWN) != 0u) {
        return (uint8_t)*e;
    }
    uint32_t bits = 0;
    for (uint32_t k = 0; k < 8u; k++) {
        const int32_t ti = (int32_t)i + EDGE_DX[k];
        const int32_t tj = (int32_t)j + EDGE_DY[k];
        if (ti >= 0 && tj >= 0 && rfs_map_lattice_legal(m, (uint16_t)ti, (uint16_t)tj) &&
            rfs_map_lattice_step_legal(m, i, j, EDGE_DX[k], EDGE_DY[k])) {
            bits |= 1u << k;
        }
    }
    if (e != 0) {
        *e = (uint16_t)(bits | RFS_MAP_EDGES_KNOWN);
    }
    return (uint8_t)bits;
}

/* Lattice point (i, j)'s legality by its position; remembered in the memo when one is
 * attached. Out of line, as step_by_traversal. */
__attribute__((noinline)) static bool legal_by_position(const rfs_map_t *m, uint16_t i,
                                                        uint16_t j)
{
    uint16_t *e = m->memo != 0 ? &m->memo[(uint32_t)j * m->lw + i] : 0;
    if (e != 0 && (*e & MEMO_LEGAL_KNOWN) != 0u) {
        return (*e & MEMO_LEGAL) != 0u;
    }
    rfs_q16_t x;
    rfs_q16_t y;
    rfs_map_lattice_point(m, i, j, &x, &y);
    const bool ok = rfs_map_point_legal(m, x, y);
    if (e != 0) {
        *e = (uint16_t)(*e | MEMO_LEGAL_KNOWN | (ok ? MEMO_LEGAL : 0u));
    }
    return ok;
}

bool rfs_map_lattice_step_legal(const rfs_map_t *m, uint16_t i, uint16_t j, int32_t di,
                                int32_t dj)
{
    RFS_ASSERT(di >= -1 && di <= 1 && dj >= -1 && dj <= 1);
    int32_t ti = (int32_t)i + di;
    int32_t tj = (int32_t)j + dj;
    if (i >= m->lw || j >= m->lh || ti < 0 || tj < 0 || ti >= (int32_t)m->lw ||
        tj >= (int32_t)m->lh) {
        return false;
    }
    /* Walk a step of the lower half of the directions backwards: same segment. */
    int32_t si = (int32_t)i;
    int32_t sj = (int32_t)j;
    if (dj < 0 || (dj == 0 && di < 0)) {
        si = ti;
        sj = tj;
        di = -di;
        dj = -dj;
    }
    if (m->step_n != 0 && dj >= 0 && dj <= 1 && di >= -1 && di <= 1 && (di | dj) != 0) {
        const rfs_map_step_t *st = &m->step[dj == 0 ? 0 : 2 - di];
        /* Scaling and overflow: lattice index < 2^16 times n <= 6 fits in int32. */
        int32_t cx = si * m->step_n + m->step_c0 + st->cx;
        int32_t cy = sj * m->step_n + m->step_c0 + st->cy;
        if (cx >= 0 && cy >= 0 && cx + st->cols <= (int32_t)m->w &&
            cy + st->rows <= (int32_t)m->h) {
            const uint8_t *row = m->legal + (uint32_t)cy * m->stride + ((uint32_t)cx >> 3);
            const uint32_t sh = (uint32_t)cx & 7u;
            const bool two = sh + st->cols > 8u; /* then cx + cols <= w keeps row[1] on the row */
            for (uint32_t k = 0; k < st->rows; k++, row += m->stride) {
                uint32_t bits = (uint32_t)row[0] >> sh;
                if (two) {
                    bits |= (uint32_t)row[1] << (8u - sh);
                }
                if ((bits & st->mask[k]) != st->mask[k]) {
                    return false;
                }
            }
            return true;
        }
    }
    return step_by_traversal(m, (uint32_t)si, (uint32_t)sj, di, dj);
}

/* --- lattice -------------------------------------------------------------------------- */

void rfs_map_lattice_point(const rfs_map_t *m, uint16_t i, uint16_t j, rfs_q16_t *x,
                           rfs_q16_t *y)
{
    /* Scaling and overflow: grid/2 + i*grid is inside the extent (< 2^30) for lattice
     * indices; the sum with the origin is within the Q16 range checked at init. */
    int64_t g = m->cfg.grid;
    *x = rfs_sat32((int64_t)m->origin_x + g / 2 + (int64_t)i * g);
    *y = rfs_sat32((int64_t)m->origin_y + g / 2 + (int64_t)j * g);
}

/* Nearest index to a relative coordinate a along an axis with n points. */
static uint16_t nearest_index(int64_t a, rfs_q16_t grid, uint16_t n)
{
    /* round((a - grid/2) / grid) = floor(a / grid): point i owns [i*grid, (i+1)*grid). */
    int64_t t = a;
    if (t < 0) {
        return 0;
    }
    if (t >= (int64_t)n * grid) {
        return (uint16_t)(n - 1u);
    }
    uint32_t k = (uint32_t)t / (uint32_t)grid;
    return (uint16_t)(k >= n ? n - 1u : k);
}

void rfs_map_lattice_nearest(const rfs_map_t *m, rfs_q16_t x, rfs_q16_t y, uint16_t *i,
                             uint16_t *j)
{
    *i = nearest_index((int64_t)x - m->origin_x, m->cfg.grid, m->lw);
    *j = nearest_index((int64_t)y - m->origin_y, m->cfg.grid, m->lh);
}

bool rfs_map_lattice_legal(const rfs_map_t *m, uint16_t i, uint16_t j)
{
    if (i >= m->lw || j >= m->lh) {
        return false;
    }
    if (m->step_n != 0) {
        /* grid = n * res: point i is at g/2 + i*n*res from the origin, inside the extent,
         * so its cell is i*n + (g/2)/res exactly (what rfs_map_cell computes). Scaling
         * and overflow: i < 2^16, n <= 6, and the cell is below w (< 2^16). */
        return rfs_map_bit(m->legal, m->stride, (uint16_t)(i * m->step_n + m->step_c0),
                           (uint16_t)(j * m->step_n + m->step_c0));
    }
    return legal_by_position(m, i, j);
}
