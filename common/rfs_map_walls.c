/* rfs_map_walls.c - walls crossed by a segment: runs of wall cells along the exact
 * supercover traversal of rfs_map.c, with the accelerations a caller may attach, the
 * wall-block grid and the host's wall-distance, forward and column grids (docs/MAPS.md,
 * "The core's grids").
 */
#include "rfs_map.h"

#include <string.h>

#include "rfs_fix.h"

static int64_t clamp64(int64_t v, int64_t lo, int64_t hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/* floor(n / d) for d > 0 and a quotient below 2^32: two 32-bit divisions when d < 2^16
 * and n < 2^48, else bit by bit (the core links no 64-bit division helper).
 * Scaling and overflow: the high digit qh = floor(n / 2^16 / d) < 2^16 as the quotient
 * is below 2^32; the low dividend (remainder < d < 2^16, shifted 16) stays in 32 bits. */
static uint32_t div_q32(uint64_t n, uint32_t d)
{
    if (d < 65536u && n < ((uint64_t)1 << 48)) {
        const uint32_t hi = (uint32_t)(n >> 16);
        const uint32_t qh = hi / d;
        const uint32_t lo = ((hi - qh * d) << 16) | (uint32_t)(n & 0xFFFFu);
        return (qh << 16) + lo / d;
    }
    uint32_t q = 0u;
    for (int32_t k = 31; k >= 0; --k) {
        if (((uint64_t)d << k) <= n) {
            n -= (uint64_t)d << k;
            q |= 1u << k;
        }
    }
    return q;
}

/* The bands a segment's cells fall into across one axis (the along axis p: its columns,
 * or its rows), in the mirrored frame (both extents >= 0): band k holds the cells lo..hi
 * of the other axis q, hi the cell where the segment leaves the band at p = (k + 1) r,
 * q_c there. Exactly: q_c / r = hi + (r u + v) / (r dp), 0 <= u < dp, 0 <= v < r. From
 * one crossing to the next q_c grows by r dq / dp, a = floor(dq / dp) cells and s / dp
 * of one (s = dq mod dp), so u steps in 32 bits (v, a multiple of r apart, never moves):
 * a carry when u + s >= dp. A crossing lies on a cell corner when u == 0 and v == 0
 * (then the next band starts a cell before hi). */
typedef struct bands {
    int32_t hi;   /* cells: the band's last cell along q, at the crossing */
    uint32_t u;   /* the crossing's remainder, 0 .. dp - 1 */
    uint32_t dp;  /* the segment's extent along p, Q16 (> 0) */
    uint32_t s;   /* dq mod dp */
    int32_t a;    /* floor(dq / dp) */
    bool on_edge; /* v == 0: a crossing with u == 0 lies on a cell corner */
} bands_t;

/* A coordinate of the mirrored frame, v = c r + f: its cell c = floor(v / r) and offset
 * f in [0, r); its lowest touching cell (rfs_map_low_cell) is c - 1 when f == 0. */
typedef struct pos {
    int32_t c; /* cells */
    uint32_t f; /* Q16, 0 .. r - 1 */
} pos_t;

/* The position of v = V or -V (neg), V < 2^31: one 32-bit division. */
static inline pos_t pos_of(uint32_t v, bool neg, uint32_t r)
{
    const uint32_t q = v / r, f = v - q * r;
    pos_t p = {(int32_t)q, f};
    if (neg) {
        p.c = -(int32_t)q - (f != 0u ? 1 : 0);
        p.f = f != 0u ? r - f : 0u;
    }
    return p;
}

/* The lowest cell touching v. */
static inline int32_t pos_low(pos_t p)
{
    return p.c - (p.f == 0u ? 1 : 0);
}

/* The first crossing, at p = (k0 + 1) r, k0 = pos_low(p0): t0 = (k0 + 1) r - p0 in
 * [0, r) (r - f, or 0 on a cell edge); q_c dp = q0 dp + t0 dq, so with q0 = g r + f:
 * n = f dp + t0 dq < r (dp + dq), q_c / r = g + n / (r dp).
 * Scaling and overflow: dp, dq <= 2^30 (the map's extent), so n < 2^61 and
 * floor(n / r) < dp + dq <= 2^31 (div_q32). */
static void bands_init(bands_t *bd, uint32_t r, pos_t p0, pos_t q0, uint32_t dp, uint32_t dq)
{
    const uint32_t t0 = p0.f != 0u ? r - p0.f : 0u;
    const uint64_t n = (uint64_t)q0.f * dp + (uint64_t)t0 * dq;
    const uint32_t nr = div_q32(n, r); /* floor(n / r) */
    bd->dp = dp;
    bd->hi = q0.c + (int32_t)(nr / dp);
    bd->u = nr % dp;
    bd->on_edge = n == (uint64_t)nr * r;
    bd->a = (int32_t)(dq / dp);
    bd->s = dq % dp;
}

/* Whether the crossing now lies on a cell corner. */
static inline bool bands_corner(const bands_t *bd)
{
    return bd->on_edge && bd->u == 0u;
}

/* (a b) mod m for a, b < m < 2^31. Scaling and overflow: the product is below 2^62 and its
 * quotient by m below 2^31 (div_q32). */
static uint32_t mul_mod(uint32_t a, uint32_t b, uint32_t m)
{
    const uint64_t p = (uint64_t)a * b;
    return (uint32_t)(p - (uint64_t)div_q32(p, m) * m);
}

/* Whether one of the first nb crossings lies on a cell corner (v == 0): u + k s = 0
 * (mod dp) for some 0 <= k < nb. With g = gcd(s, dp) dividing dp - u, the least such k is
 * ((dp - u) / g) (s / g)^-1 mod (dp / g) (extended Euclid, 32-bit divisions). Scaling and
 * overflow: the Bezout coefficients stay within dp / g < 2^31 in magnitude. */
static bool meet_corner(const bands_t *bd, int32_t nb)
{
    if (nb <= 0) {
        return false;
    }
    if (bd->u == 0u) {
        return true;
    }
    int64_t r0 = bd->s, r1 = bd->dp, x0 = 1, x1 = 0; /* r0 = x0 s (mod dp) */
    while (r1 != 0) {
        const int64_t q = (int64_t)((uint32_t)r0 / (uint32_t)r1);
        const int64_t r2 = r0 - q * r1, x2 = x0 - q * x1;
        r0 = r1;
        r1 = r2;
        x0 = x1;
        x1 = x2;
    }
    const uint32_t g = (uint32_t)r0, need = bd->dp - bd->u;
    const uint32_t mg = g != 0u ? bd->dp / g : 0u; /* |x0| <= mg: one step into 0 .. mg - 1 */
    if (mg == 0u || need % g != 0u) {
        return false; /* s == 0: u never moves from its nonzero start */
    }
    const int64_t inv = x0 < 0 ? x0 + (int64_t)mg : (x0 >= (int64_t)mg ? x0 - (int64_t)mg : x0);
    const uint32_t k = mul_mod((need / g) % mg, (uint32_t)inv, mg);
    return k < (uint32_t)nb;
}

/* meet_corner() when a crossing may lie on a corner at all (v == 0). */
static inline bool bands_meet_corner(const bands_t *bd, int32_t nb)
{
    return bd->on_edge && meet_corner(bd, nb);
}

/* To the next crossing. */
static inline void bands_step(bands_t *bd)
{
    bd->u += bd->s; /* both below dp <= 2^30 */
    const uint32_t c = bd->u >= bd->dp ? 1u : 0u;
    bd->u -= c != 0u ? bd->dp : 0u;
    bd->hi += bd->a + (int32_t)c;
}

/* The state of a wall walk in one word: bit 0, whether the last cell visited was a wall;
 * the bits above, the runs of wall cells so far (a segment has below 2^18 cells). */
#define WALK_RUN 2u

/* One cell of the walk, wall 1 or 0. */
static inline uint32_t walk_one(uint32_t ws, uint32_t wall)
{
    return ((ws + ((wall & ~ws) << 1)) & ~1u) | wall;
}

/* Cell (i, jr), real row jr; off the map it is not a wall. */
static inline uint32_t walk_cell(const rfs_map_t *m, uint32_t ws, int32_t i, int32_t jr)
{
    return walk_one(ws, (uint32_t)i < m->w && (uint32_t)jr < m->h &&
                                rfs_map_bit(m->wall, m->stride, (uint16_t)i, (uint16_t)jr) ? 1u : 0u);
}

/* Bits lo .. lo + n - 1 (n >= 1) of a row of the wall grid, in order, up to 24 at a time:
 * a run starts at each wall bit whose predecessor is free. avail: the grid's bytes from
 * the row's first on (four load at once while there, the last ones one by one). */
static inline uint32_t walk_bits(const uint8_t *row, uint32_t avail, uint32_t ws, uint32_t lo,
                                 uint32_t n)
{
    while (n != 0u) {
        const uint32_t b = lo >> 3;
        const uint8_t *p = row + b;
        uint32_t w = 0u;
        if (avail >= 4u && b <= avail - 4u) {
            w = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
        } else {
            for (uint32_t k = 0u; b + k < avail && k < 4u; k++) {
                w |= (uint32_t)p[k] << (8u * k);
            }
        }
        w >>= lo & 7u; /* 25 bits or more left: the ones wanted */
        const uint32_t t = n <= 25u ? n : 24u; /* bits taken, 1 .. 25 */
        w &= 0x1FFFFFFu >> (25u - t);
        for (uint32_t st = w & ~((w << 1) | (ws & 1u)); st != 0u; st &= st - 1u) {
            ws += WALK_RUN;
        }
        ws = (ws & ~1u) | (((w << 1) >> t) & 1u); /* bit t - 1 */
        n -= t;
        lo += t;
    }
    return ws;
}

/* Columns lo..hi (lo <= hi) of real row jr, any of them off the map (not walls). */
static uint32_t walk_row(const rfs_map_t *m, uint32_t ws, int32_t jr, int32_t lo, int32_t hi)
{
    if ((uint32_t)jr >= m->h || hi < 0 || lo >= (int32_t)m->w) {
        return ws & ~1u;
    }
    const bool after = hi >= (int32_t)m->w; /* column w last */
    if (lo < 0) {
        ws &= ~1u; /* column -1 first */
        lo = 0;
    }
    hi = after ? (int32_t)m->w - 1 : hi;
    ws = walk_bits(m->wall + (uint32_t)jr * m->stride, ((uint32_t)m->h - (uint32_t)jr) * m->stride,
                   ws, (uint32_t)lo, (uint32_t)(hi - lo + 1));
    return after ? ws & ~1u : ws;
}

/* Mirrored rows jlo..jhi of column i, any of them off the map (not walls), passing over
 * wall-free blocks (b) or the free cells a wall-distance grid promises. */
static uint32_t walk_col(const rfs_map_t *m, const rfs_map_wall_blocks_t *b, uint32_t ws,
                         int32_t i, int32_t jlo, int32_t jhi, bool flip)
{
    if ((uint32_t)i >= m->w) {
        return ws & ~1u; /* column -1 or w */
    }
    const int32_t bs = b != 0 ? (int32_t)1 << b->shift : 0;
    const uint8_t *wd = m->wall_dist;
    for (int32_t j = jlo; j <= jhi; j++) {
        const int32_t jr = flip ? -1 - j : j;
        if ((uint32_t)jr >= m->h) {
            ws &= ~1u;
            continue;
        }
        if (wd != 0) {
            /* The next d - 1 cells of the column either way are free too. */
            const int32_t d = wd[(uint32_t)jr * m->w + (uint32_t)i];
            ws = walk_one(ws, d == 0 ? 1u : 0u);
            j += d > 1 ? d - 1 : 0;
            continue;
        }
        if (b != 0) {
            /* The rest of the cell's block (on the map): passed over, or read. */
            const int32_t ky = flip ? -1 - (jr & -bs) : (jr | (bs - 1));
            const int32_t top = flip ? -1 : (int32_t)m->h - 1;
            const int32_t e = ky < jhi ? (ky < top ? ky : top) : (jhi < top ? jhi : top);
            if (!rfs_map_bit(b->bits, b->stride, (uint16_t)((uint32_t)i >> b->shift),
                             (uint16_t)((uint32_t)jr >> b->shift))) {
                ws &= ~1u;
            } else {
                const int32_t rstep = flip ? -(int32_t)m->stride : (int32_t)m->stride;
                const uint8_t *p = m->wall + (uint32_t)jr * m->stride + ((uint32_t)i >> 3);
                for (int32_t n = e - j, o = 0; n >= 0; n--, o += rstep) {
                    ws = walk_one(ws, (p[o] >> ((uint32_t)i & 7u)) & 1u);
                }
            }
            j = e;
            continue;
        }
        ws = walk_one(ws, rfs_map_bit(m->wall, m->stride, (uint16_t)i, (uint16_t)jr) ? 1u : 0u);
    }
    return ws;
}

/* The free square ahead of cell (i, j) on the map (mirrored row j) that a host grid
 * promises, towards +x and the walk's rows: its last column *x1 and mirrored row *y1,
 * false when the cell is a wall. The forward grid (fwd, for the walk's direction): the
 * square of side d with the cell as its corner; else the wall-distance grid: the square
 * round the cell, d - 1 cells either way. */
static inline bool free_ahead(const rfs_map_t *m, const uint8_t *fwd, int32_t i, int32_t j,
                              bool flip, int32_t *x1, int32_t *y1)
{
    const uint8_t *g = fwd != 0 ? fwd : m->wall_dist;
    const int32_t d = g[(uint32_t)(flip ? -1 - j : j) * m->w + (uint32_t)i];
    *x1 = i + (d > 1 ? d - 1 : 0);
    *y1 = j + (d > 1 ? d - 1 : 0);
    return d != 0;
}

/* The bands' next crossing (bands_step() on copies kept in registers). */
#define BANDS_NEXT(hi, u, bd)  \
    do {                       \
        (u) += (bd).s;         \
        if ((u) >= (bd).dp) {  \
            (u) -= (bd).dp;    \
            (hi)++;            \
        }                      \
        (hi) += (bd).a;        \
    } while (0)

/* BANDS_NEXT() without a branch: the host's walks (*_look), whose carries a branch
 * predictor cannot guess (the Cortex-M4's walks keep the branch, which costs it less). */
#define BANDS_NEXT_FLAT(hi, u, bd)                            \
    do {                                                      \
        (u) += (bd).s;                                        \
        const uint32_t carry_ = (u) >= (bd).dp ? 1u : 0u;     \
        (u) -= (bd).dp & (0u - carry_);                       \
        (hi) += (bd).a + (int32_t)carry_;                     \
    } while (0)

/* Bits from..from + n (n > 24) of a row: as walk_bits, every four-byte load from the
 * row's cells inside the grid. */
__attribute__((noinline)) static uint32_t row_bits_long(const uint8_t *row, uint32_t ws,
                                                        uint32_t from, uint32_t n)
{
    return walk_bits(row, UINT32_MAX, ws, from, n + 1u);
}

/* Bits from..end of a row (from <= end), every four-byte load from the row's cells inside
 * the grid: the band's bits shifted down to bit 0, a run starting at each wall bit whose
 * predecessor is free. */
static inline uint32_t row_bits(const uint8_t *row, uint32_t ws, int32_t from, int32_t end)
{
    const uint32_t n = (uint32_t)(end - from); /* bits - 1 */
    if (n > 24u) {
        return row_bits_long(row, ws, (uint32_t)from, n);
    }
    const uint8_t *p = row + ((uint32_t)from >> 3);
    uint32_t w = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    w = (w << (31u - ((uint32_t)from & 7u) - n)) >> (31u - n);
    for (uint32_t st = w & ~((w << 1) | (ws & 1u)); st != 0u; st &= st - 1u) {
        ws += WALK_RUN;
    }
    return (ws & ~1u) | (w >> n);
}

/* A shallow walk on the map whose crossings miss every cell corner, every four-byte load
 * from a row's cells inside the grid: from row pointer row (rstep bytes a band) and
 * column from, nb crossings (bands_t bd), then the last band to column ie; each band's
 * bits read at once (the Cortex-M4's walk: few live values; blocks would not pay, a band
 * of a few cells enters another block every band or two). */
__attribute__((noinline)) static uint32_t walk_rows(const uint8_t *row, int32_t rstep,
                                                    uint32_t ws, int32_t from, bands_t bd,
                                                    int32_t nb, int32_t ie)
{
    int32_t hi = bd.hi;
    uint32_t u = bd.u;
    for (const uint8_t *last = row + nb * rstep; row != last; row += rstep) {
        ws = row_bits(row, ws, from, hi);
        from = hi;
        BANDS_NEXT(hi, u, bd);
    }
    return row_bits(row, ws, from, ie);
}

/* walk_rows() with a host grid (fwd, or the wall-distance grid), k the first band: a
 * band's cells inside the free square last found (free_ahead, looked up again when a band
 * starts outside it) are passed over, the bands wholly inside it in a tight loop. */
__attribute__((noinline)) static uint32_t walk_rows_look(const rfs_map_t *m, const uint8_t *fwd,
                                                         const uint8_t *row, uint32_t ws,
                                                         int32_t k, int32_t from, bands_t bd,
                                                         int32_t nb, int32_t ie, bool flip)
{
    const int32_t rstep = flip ? -(int32_t)m->stride : (int32_t)m->stride;
    int32_t hi = bd.hi, fx1 = INT32_MIN, fy1 = INT32_MIN;
    bool free = false;
    uint32_t u = bd.u;
    for (;;) {
        int32_t end = nb == 0 ? ie : hi;
        if (k > fy1 || from > fx1) {
            free = free_ahead(m, fwd, from, k, flip, &fx1, &fy1);
        }
        if (free && end <= fx1) {
            ws &= ~1u;
            if (nb == 0) {
                return ws;
            }
            /* Step over the bands ending inside the square (the last band, or the first
             * past its rows, back through the loop's checks above). */
            const int32_t lim = fy1 - k < nb - 1 ? fy1 - k : nb - 1;
            int32_t t = 0;
            do {
                from = hi;
                BANDS_NEXT_FLAT(hi, u, bd);
                t++;
            } while (t <= lim && hi <= fx1);
            nb -= t;
            k += t;
            row += t * rstep;
            continue;
        }
        if (free) {
            ws &= ~1u;
            from = fx1 + 1;
        }
        ws = row_bits(row, ws, from, end);
        if (nb-- == 0) {
            return ws;
        }
        from = hi;
        BANDS_NEXT_FLAT(hi, u, bd);
        k++;
        row += rstep;
    }
}

/* A steep walk on the map whose crossings miss every cell corner: from column i, mirrored
 * row jlo, nb crossings (bands_t bd), then the last column to row je; columns of long_col
 * rows or more through walk_col (blocks b), the others a byte a cell (the Cortex-M4's
 * walk). */
__attribute__((noinline)) static uint32_t walk_cols(const rfs_map_t *m,
                                                    const rfs_map_wall_blocks_t *b, uint32_t ws,
                                                    int32_t i, int32_t jlo, bands_t bd,
                                                    int32_t nb, int32_t je, bool flip,
                                                    int32_t long_col)
{
    const uint8_t *wall = m->wall;
    const int32_t stride = (int32_t)m->stride, rstep = flip ? -stride : stride;
    int32_t hi = bd.hi;
    uint32_t u = bd.u;
    for (;; i++) {
        const int32_t end = nb == 0 ? je : hi;
        if (end - jlo >= long_col) {
            ws = walk_col(m, b, ws, i, jlo, end, flip);
        } else {
            const uint8_t *p = wall + (flip ? -1 - jlo : jlo) * stride + ((uint32_t)i >> 3);
            const uint32_t sh = (uint32_t)i & 7u;
            for (int32_t n = end - jlo, o = 0; n >= 0; n--, o += rstep) {
                ws = walk_one(ws, (p[o] >> sh) & 1u);
            }
        }
        if (nb-- == 0) {
            return ws;
        }
        jlo = hi;
        BANDS_NEXT(hi, u, bd);
    }
}

/* Bytes a column of the column grid (rfs_map_wall_cols_attach()): row_bits() loads four
 * bytes from any bit's byte. */
static uint32_t cols_stride(const rfs_map_t *m)
{
    return ((uint32_t)m->h + 7u) / 8u + 4u;
}

/* walk_cols() with a host grid (fwd, or the wall-distance grid): a column's cells inside
 * the free square last found (free_ahead) are passed over, the columns wholly inside it
 * in a tight loop; the others' cells read from the column grid when attached (its
 * top-down half for a mirrored walk: mirrored row j is its row h + j), else long columns
 * through walk_col (the wall-distance grid, blocks b). */
__attribute__((noinline)) static uint32_t walk_cols_look(const rfs_map_t *m,
                                                         const rfs_map_wall_blocks_t *b,
                                                         const uint8_t *fwd, uint32_t ws,
                                                         int32_t i, int32_t jlo, bands_t bd,
                                                         int32_t nb, int32_t je, bool flip,
                                                         int32_t long_col)
{
    const int32_t stride = (int32_t)m->stride, rstep = flip ? -stride : stride;
    const uint32_t cstride = cols_stride(m);
    const int32_t coff = flip ? (int32_t)m->h : 0;
    const uint8_t *cols = m->wall_cols != 0 ? m->wall_cols + (flip ? (uint32_t)m->w * cstride : 0u) : 0;
    int32_t hi = bd.hi, fx1 = INT32_MIN, fy1 = INT32_MIN;
    bool free = false;
    uint32_t u = bd.u;
    for (;;) {
        int32_t end = nb == 0 ? je : hi, j = jlo;
        if (i > fx1 || j > fy1) {
            free = free_ahead(m, fwd, i, j, flip, &fx1, &fy1);
        }
        if (free && end <= fy1) {
            ws &= ~1u;
            if (nb == 0) {
                return ws;
            }
            /* Step over the columns ending inside the square (as walk_rows_look()). */
            const int32_t lim = fx1 - i < nb - 1 ? fx1 - i : nb - 1;
            int32_t t = 0;
            do {
                jlo = hi;
                BANDS_NEXT_FLAT(hi, u, bd);
                t++;
            } while (t <= lim && hi <= fy1);
            nb -= t;
            i += t;
            continue;
        }
        if (free) {
            ws &= ~1u;
            j = fy1 + 1;
        }
        if (cols != 0) {
            if (j <= end) {
                ws = row_bits(cols + (uint32_t)i * cstride, ws, coff + j, coff + end);
            }
        } else if (end - j >= long_col) {
            ws = walk_col(m, b, ws, i, j, end, flip);
        } else {
            const uint8_t *p = m->wall + (flip ? -1 - j : j) * stride + ((uint32_t)i >> 3);
            const uint32_t sh = (uint32_t)i & 7u;
            for (int32_t n = end - j, o = 0; n >= 0; n--, o += rstep) {
                ws = walk_one(ws, (p[o] >> sh) & 1u);
            }
        }
        if (nb-- == 0) {
            return ws;
        }
        jlo = hi;
        BANDS_NEXT_FLAT(hi, u, bd);
        i++;
    }
}

/* The cells of traverse() (rfs_map.c) with the VISIT_WALLS visitor, in the same order
 * (the same endpoint swap and mirror; columns left to right, each column's rows in the
 * segment's y direction), counting runs of wall cells. Cells off the map are not walls:
 * columns -1 and w (first and last, when an endpoint lies on the map's edge) and rows -1
 * and h (a segment touching the bottom or top edge). The bands (bands_t) step in exact
 * 32-bit remainders where traverse() compares 64-bit bounds. A shallow segment
 * (0 < |dy| < |dx|) is walked row by row over the row-major wall bits: a row's cells are
 * a range of columns, consecutive in traverse()'s order too, except where the segment
 * crosses a row at a cell corner: traverse() takes the four cells round it column by
 * column, and so does this walk. Steeper ones go column by column. careful: cells off
 * the map may be on the walk (an endpoint on the map's edge); then, or when a crossing
 * may meet a corner, the general loops below run, else the fast ones above.
 * Scaling and overflow: bands_init's; the count saturates at UINT16_MAX. */
static uint16_t walls_walk(const rfs_map_t *m, const rfs_map_wall_blocks_t *b, uint32_t X0,
                           uint32_t Y0, uint32_t X1, uint32_t Y1)
{
    const uint32_t r = (uint32_t)m->res;
    if (X1 < X0 || (X1 == X0 && Y1 < Y0)) {
        uint32_t t = X0; X0 = X1; X1 = t;
        t = Y0; Y0 = Y1; Y1 = t;
    }
    const bool flip = Y1 < Y0;
    const bool careful = (flip ? Y1 : Y0) == 0u || (flip ? Y0 : Y1) == m->h * r || X0 == 0u ||
                         X1 == m->w * r;
    const uint32_t dx = X1 - X0, dy = flip ? Y0 - Y1 : Y1 - Y0;
    const pos_t x0 = pos_of(X0, false, r), x1 = pos_of(X1, false, r);
    const pos_t y0 = pos_of(Y0, flip, r), y1 = pos_of(Y1, flip, r); /* mirrored */
    const int32_t rstep = flip ? -(int32_t)m->stride : (int32_t)m->stride;
    const uint8_t *fwd = m->wall_fwd != 0 ? m->wall_fwd + (flip ? (size_t)m->w * m->h : 0u) : 0;
    uint32_t ws = 0u;
    bands_t bd = {0, 0u, 1u, 0u, 0, false};
    if (dy != 0u && dy < dx) {
        const int32_t kb = y1.c, ie = x1.c;
        int32_t k = pos_low(y0), from = pos_low(x0);
        bands_init(&bd, r, y0, x0, dy, dx);
        const int32_t jtop = flip ? -1 - k : kb; /* the highest real row */
        if (!careful && !bands_meet_corner(&bd, kb - k) &&
            (uint32_t)(jtop + 1) * m->stride + 3u <= (uint32_t)m->h * m->stride) {
            const uint8_t *row = m->wall + (uint32_t)(flip ? -1 - k : k) * m->stride;
            ws = fwd != 0 || m->wall_dist != 0
                     ? walk_rows_look(m, fwd, row, ws, k, from, bd, kb - k, ie, flip)
                     : walk_rows(row, rstep, ws, from, bd, kb - k, ie);
            return (uint16_t)((ws >> 1) > UINT16_MAX ? UINT16_MAX : (ws >> 1));
        }
        for (;; k++) {
            const bool last = k == kb;
            const bool corner = !last && bands_corner(&bd);
            const int32_t hi = last ? ie : bd.hi;
            const int32_t end = corner ? hi - 2 : hi;
            if (from <= end) {
                ws = walk_row(m, ws, flip ? -1 - k : k, from, end);
            }
            if (last) {
                break;
            }
            from = hi;
            if (corner) {
                /* Through the corner between columns hi - 1 and hi: both rows of one
                 * column, then of the next (a shallow segment meets the next row again
                 * only past column hi). */
                const int32_t jr = flip ? -1 - k : k, jn = flip ? jr - 1 : jr + 1;
                ws = walk_cell(m, ws, hi - 1, jr);
                ws = walk_cell(m, ws, hi - 1, jn);
                ws = walk_cell(m, ws, hi, jr);
                ws = walk_cell(m, ws, hi, jn);
                from = hi + 1;
            }
            bands_step(&bd);
        }
    } else {
        const int32_t long_col = b != 0 ? (int32_t)1 << b->shift : (m->wall_dist != 0 ? 3 : INT32_MAX);
        const int32_t ib = x1.c, je = y1.c;
        int32_t i = pos_low(x0), jlo = pos_low(y0);
        if (dx != 0u) {
            bands_init(&bd, r, x0, y0, dx, dy);
            if (!careful && !bands_meet_corner(&bd, ib - i)) {
                ws = fwd != 0 || m->wall_dist != 0
                         ? walk_cols_look(m, b, fwd, ws, i, jlo, bd, ib - i, je, flip, long_col)
                         : walk_cols(m, b, ws, i, jlo, bd, ib - i, je, flip, long_col);
                return (uint16_t)((ws >> 1) > UINT16_MAX ? UINT16_MAX : (ws >> 1));
            }
        }
        for (;; i++) {
            const bool last = i >= ib;
            const int32_t hi = dx == 0u || last ? je : bd.hi;
            if (careful || hi - jlo >= long_col) {
                ws = walk_col(m, b, ws, i, jlo, hi, flip);
            } else {
                const uint8_t *p = m->wall + (int32_t)(flip ? -1 - jlo : jlo) * (int32_t)m->stride +
                                   ((uint32_t)i >> 3);
                const uint32_t sh = (uint32_t)i & 7u;
                for (int32_t n = hi - jlo, o = 0; n >= 0; n--, o += rstep) {
                    ws = walk_one(ws, (p[o] >> sh) & 1u);
                }
            }
            if (last) {
                break;
            }
            if (dx != 0u) {
                jlo = bd.hi - (bands_corner(&bd) ? 1 : 0);
                bands_step(&bd);
            }
        }
    }
    ws >>= 1;
    return (uint16_t)(ws > UINT16_MAX ? UINT16_MAX : ws);
}

/* Two bytes a cell, in 64 bits: w * h < 2^32, twice that need not be. */
static uint64_t fwd_bytes64(const rfs_map_t *m)
{
    return 2u * (uint64_t)m->w * m->h;
}

uint32_t rfs_map_wall_fwd_bytes(const rfs_map_t *m)
{
    const uint64_t n = fwd_bytes64(m);
    return n > UINT32_MAX ? UINT32_MAX : (uint32_t)n;
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
    if (m->wall == 0 || buf == 0 || bytes < fwd_bytes64(m)) {
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

uint32_t rfs_map_wall_cols_bytes(const rfs_map_t *m)
{
    return 2u * (uint32_t)m->w * cols_stride(m); /* w, h < 2^16: below 2^31 */
}

int rfs_map_wall_cols_attach(rfs_map_t *m, uint8_t *buf, uint32_t bytes)
{
    if (m->wall == 0 || buf == 0 || bytes < rfs_map_wall_cols_bytes(m)) {
        return -1;
    }
    const uint32_t cs = cols_stride(m), h = m->h;
    uint8_t *dn = buf + (uint32_t)m->w * cs;
    memset(buf, 0, rfs_map_wall_cols_bytes(m));
    for (uint32_t j = 0u; j < h; ++j) {
        for (uint32_t i = 0u; i < m->w; ++i) {
            if (rfs_map_bit(m->wall, m->stride, (uint16_t)i, (uint16_t)j)) {
                buf[i * cs + (j >> 3)] |= (uint8_t)(1u << (j & 7u));
                dn[i * cs + ((h - 1u - j) >> 3)] |= (uint8_t)(1u << ((h - 1u - j) & 7u));
            }
        }
    }
    m->wall_cols = buf;
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
    return walls_walk(m, m->wall_dist != 0 ? 0 : b,
                      (uint32_t)clamp64((int64_t)x0 - m->origin_x, 0, we),
                      (uint32_t)clamp64((int64_t)y0 - m->origin_y, 0, he),
                      (uint32_t)clamp64((int64_t)x1 - m->origin_x, 0, we),
                      (uint32_t)clamp64((int64_t)y1 - m->origin_y, 0, he));
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
