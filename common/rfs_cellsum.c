/* rfs_cellsum.c - cell sums: a spatial index of the sample store for the local ridge
 * (docs/MODELS.md, "Cell sums"). */
#include "rfs_cellsum.h"

#include <string.h>

#include "rfs_assert.h"

/// Largest box side, cm: positions relative to the box stay below 2^16.
#define CELLSUM_SIDE_MAX_CM 65535

uint32_t rfs_cellsum_cells(int32_t w_cm, int32_t h_cm, uint8_t shift)
{
    if (w_cm <= 0 || h_cm <= 0 || w_cm > CELLSUM_SIDE_MAX_CM || h_cm > CELLSUM_SIDE_MAX_CM ||
        shift < 3u || shift > 10u) {
        return 0u;
    }
    const uint32_t side = (uint32_t)1 << shift;
    const uint32_t w = ((uint32_t)w_cm + side - 1u) >> shift;
    const uint32_t h = ((uint32_t)h_cm + side - 1u) >> shift;
    return w * h;
}

int rfs_cellsum_init(rfs_cellsum_t *c, int32_t x0_cm, int32_t y0_cm, int32_t w_cm,
                     int32_t h_cm, uint8_t shift, rfs_cellsum_cell_t *cells, uint32_t ncells,
                     uint16_t *links, uint16_t cap)
{
    const uint32_t need = rfs_cellsum_cells(w_cm, h_cm, shift);
    if (c == 0 || cells == 0 || links == 0 || need == 0u || ncells < need || cap == 0u ||
        cap == RFS_CELLSUM_NONE) {
        return -1;
    }
    const uint32_t side = (uint32_t)1 << shift;
    c->x0_cm = x0_cm;
    c->y0_cm = y0_cm;
    c->w = (uint16_t)(((uint32_t)w_cm + side - 1u) >> shift);
    c->h = (uint16_t)(((uint32_t)h_cm + side - 1u) >> shift);
    c->shift = shift;
    c->cells = cells;
    c->next = links;
    c->prev = links + cap;
    c->cap = cap;
    c->outside = RFS_CELLSUM_NONE;
    memset(cells, 0, sizeof(*cells) * need);
    for (uint32_t i = 0; i < need; ++i) {
        cells[i].head = RFS_CELLSUM_NONE;
    }
    return 0;
}

/* The cell holding (x, y) cm, or NULL off the box; *rx, *ry: the position relative to
 * the box's corner. */
static rfs_cellsum_cell_t *cell_of(const rfs_cellsum_t *c, const rfs_sample_t *s, int32_t *rx,
                                   int32_t *ry)
{
    *rx = (int32_t)s->x_cm - c->x0_cm;
    *ry = (int32_t)s->y_cm - c->y0_cm;
    if (*rx < 0 || *ry < 0) {
        return 0;
    }
    const uint32_t i = (uint32_t)*rx >> c->shift, j = (uint32_t)*ry >> c->shift;
    if (i >= c->w || j >= c->h) {
        return 0;
    }
    return &c->cells[j * c->w + i];
}

/* Remove slot from the list whose head is *head. */
static void unlink_slot(rfs_cellsum_t *c, uint16_t *head, uint16_t slot)
{
    const uint16_t p = c->prev[slot], n = c->next[slot];
    if (p == RFS_CELLSUM_NONE) {
        *head = n;
    } else {
        c->next[p] = n;
    }
    if (n != RFS_CELLSUM_NONE) {
        c->prev[n] = p;
    }
}

static void link_slot(rfs_cellsum_t *c, uint16_t *head, uint16_t slot)
{
    c->next[slot] = *head;
    c->prev[slot] = RFS_CELLSUM_NONE;
    if (*head != RFS_CELLSUM_NONE) {
        c->prev[*head] = slot;
    }
    *head = slot;
}

/* Add (sign 1) or remove (sign -1) a sample's terms. Scaling and overflow: x, y below
 * 2^16, |z| <= 2^15; the bounds of rfs_cellsum_cell_t hold for 65,535 samples. */
static void cell_add(rfs_cellsum_cell_t *e, int32_t x, int32_t y, int32_t z, int32_t sign)
{
    e->n = (uint16_t)(e->n + sign);
    e->sx = (uint32_t)((int64_t)e->sx + sign * x);
    e->sy = (uint32_t)((int64_t)e->sy + sign * y);
    e->sz += sign * z;
    e->sxx += sign * ((int64_t)x * x);
    e->sxy += sign * ((int64_t)x * y);
    e->syy += sign * ((int64_t)y * y);
    e->sxz += sign * ((int64_t)x * z);
    e->syz += sign * ((int64_t)y * z);
}

void rfs_cellsum_put(rfs_cellsum_t *c, uint16_t slot, const rfs_sample_t *old,
                     const rfs_sample_t *s)
{
    RFS_ASSERT(c != 0 && s != 0 && slot < c->cap);
    int32_t x, y;
    if (old != 0) {
        rfs_cellsum_cell_t *e = cell_of(c, old, &x, &y);
        if (e != 0) {
            cell_add(e, x, y, old->v_q6, -1);
            unlink_slot(c, &e->head, slot);
        } else {
            unlink_slot(c, &c->outside, slot);
        }
    }
    rfs_cellsum_cell_t *e = cell_of(c, s, &x, &y);
    if (e != 0) {
        cell_add(e, x, y, s->v_q6, 1);
        link_slot(c, &e->head, slot);
    } else {
        link_slot(c, &c->outside, slot);
    }
}

/* Sums in box coordinates (x, y relative to the corner), int64 throughout. */
typedef struct box_sums {
    int64_t n, sx, sy, sz, sxx, sxy, syy, sxz, syz;
} box_sums_t;

/* The samples of one list that lie in the disc, one by one. */
static void add_list(const rfs_cellsum_t *c, const rfs_sample_t *samples, uint16_t head,
                     int32_t qx_cm, int32_t qy_cm, int64_t r2, box_sums_t *b)
{
    for (uint16_t k = head; k != RFS_CELLSUM_NONE; k = c->next[k]) {
        const rfs_sample_t *s = &samples[k];
        const int64_t u = (int64_t)s->x_cm - qx_cm, v = (int64_t)s->y_cm - qy_cm;
        if (u * u + v * v > r2) {
            continue;
        }
        const int64_t x = (int64_t)s->x_cm - c->x0_cm, y = (int64_t)s->y_cm - c->y0_cm;
        const int64_t z = s->v_q6;
        b->n++;
        b->sx += x;
        b->sy += y;
        b->sz += z;
        b->sxx += x * x;
        b->sxy += x * y;
        b->syy += y * y;
        b->sxz += x * z;
        b->syz += y * z;
    }
}

static void add_cell(const rfs_cellsum_cell_t *e, box_sums_t *b)
{
    b->n += e->n;
    b->sx += e->sx;
    b->sy += e->sy;
    b->sz += e->sz;
    b->sxx += e->sxx;
    b->sxy += e->sxy;
    b->syy += e->syy;
    b->sxz += e->sxz;
    b->syz += e->syz;
}

/* floor(v / 2^s) and ceil(v / 2^s) for any sign (no right shift of a negative). */
static int64_t floor_shift(int64_t v, uint8_t s)
{
    return v >= 0 ? v >> s : -((-v + ((int64_t)1 << s) - 1) >> s);
}
static int64_t ceil_shift(int64_t v, uint8_t s)
{
    return -floor_shift(-v, s);
}

/* Nearest and farthest offsets from q of the integer range [lo, lo + side - 1]. */
static void range_offsets(int64_t lo, int64_t side, int64_t q, int64_t *near, int64_t *far)
{
    const int64_t a = lo - q, b = lo + side - 1 - q;
    *near = a > 0 ? a : (b < 0 ? -b : 0);
    const int64_t fa = a < 0 ? -a : a, fb = b < 0 ? -b : b;
    *far = fa > fb ? fa : fb;
}

/* Clamp a column range to [0, w - 1]; false when empty. */
static bool clamp_span(int64_t lo, int64_t hi, uint32_t w, uint32_t *i0, uint32_t *i1)
{
    lo = lo < 0 ? 0 : lo;
    hi = hi > (int64_t)w - 1 ? (int64_t)w - 1 : hi;
    if (lo > hi) {
        return false;
    }
    *i0 = (uint32_t)lo;
    *i1 = (uint32_t)hi;
    return true;
}

/* The cells of a row [i0, i1] the circle cuts: their samples one by one. */
static void add_cut(const rfs_cellsum_t *c, const rfs_sample_t *samples,
                    const rfs_cellsum_cell_t *row, uint32_t i0, uint32_t i1, int32_t qx_cm,
                    int32_t qy_cm, int64_t r2, box_sums_t *b)
{
    for (uint32_t i = i0; i <= i1; ++i) {
        if (row[i].n != 0u) {
            add_list(c, samples, row[i].head, qx_cm, qy_cm, r2, b);
        }
    }
}

/* One row of cells: with |x - q| <= xo for some point of a cell it is not wholly
 * outside (near^2 + ny^2 <= r^2), with |x - q| <= xi for all its points wholly inside
 * (far^2 + fy^2 <= r^2; xi < 0: none), both exact on the integer positions. */
static void add_row(const rfs_cellsum_t *c, const rfs_sample_t *samples, uint32_t j, int64_t qx,
                    int64_t xo, int64_t xi, int32_t qx_cm, int32_t qy_cm, int64_t r2,
                    box_sums_t *b)
{
    const uint8_t sh = c->shift;
    const rfs_cellsum_cell_t *row = &c->cells[j * c->w];
    uint32_t o0, o1, n0, n1;
    if (!clamp_span(floor_shift(qx - xo, sh), floor_shift(qx + xo, sh), c->w, &o0, &o1)) {
        return;
    }
    if (xi < 0 || !clamp_span(ceil_shift(qx - xi, sh),
                              floor_shift(qx + xi - ((int64_t)1 << sh) + 1, sh), c->w, &n0,
                              &n1)) {
        add_cut(c, samples, row, o0, o1, qx_cm, qy_cm, r2, b);
        return;
    }
    if (n0 > o0) {
        add_cut(c, samples, row, o0, n0 - 1u, qx_cm, qy_cm, r2, b);
    }
    for (uint32_t i = n0; i <= n1; ++i) {
        add_cell(&row[i], b);
    }
    if (n1 < o1) {
        add_cut(c, samples, row, n1 + 1u, o1, qx_cm, qy_cm, r2, b);
    }
}

void rfs_cellsum_disc(const rfs_cellsum_t *c, const rfs_sample_t *samples, int32_t qx_cm,
                      int32_t qy_cm, int32_t r_cm, rfs_cellsum_disc_t *out)
{
    RFS_ASSERT(c != 0 && samples != 0 && out != 0 && r_cm >= 0 && r_cm <= 65535);
    box_sums_t b = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    const int64_t r2 = (int64_t)r_cm * r_cm;
    const int64_t qx = (int64_t)qx_cm - c->x0_cm, qy = (int64_t)qy_cm - c->y0_cm;
    const int64_t side = (int64_t)1 << c->shift;
    uint32_t j0, j1;
    if (clamp_span(floor_shift(qy - r_cm, c->shift), floor_shift(qy + r_cm, c->shift), c->h,
                   &j0, &j1)) {
        for (uint32_t j = j0; j <= j1; ++j) {
            int64_t ny, fy;
            range_offsets((int64_t)j << c->shift, side, qy, &ny, &fy);
            if (ny * ny > r2) {
                continue;
            }
            /* r^2 < 2^32: the square roots are 32-bit. */
            const int64_t xo = rfs_isqrt32((uint32_t)(r2 - ny * ny));
            const int64_t xi = fy * fy <= r2 ? (int64_t)rfs_isqrt32((uint32_t)(r2 - fy * fy)) : -1;
            add_row(c, samples, j, qx, xo, xi, qx_cm, qy_cm, r2, &b);
        }
    }
    add_list(c, samples, c->outside, qx_cm, qy_cm, r2, &b);
    /* Shift to the centre: u = x - qx, so Su = Sx - n qx, Suu = Sxx - 2 qx Sx + n qx^2,
     * Suv = Sxy - qy Sx - qx Sy + n qx qy, Suz = Sxz - qx Sz. */
    out->n = b.n;
    out->su = b.sx - b.n * qx;
    out->sv = b.sy - b.n * qy;
    out->sz = b.sz;
    out->suu = b.sxx - 2 * qx * b.sx + b.n * qx * qx;
    out->svv = b.syy - 2 * qy * b.sy + b.n * qy * qy;
    out->suv = b.sxy - qy * b.sx - qx * b.sy + b.n * qx * qy;
    out->suz = b.sxz - qx * b.sz;
    out->svz = b.syz - qy * b.sz;
}

static void index_put(void *self, uint16_t slot, const rfs_sample_t *old, const rfs_sample_t *s)
{
    rfs_cellsum_put((rfs_cellsum_t *)self, slot, old, s);
}

static void index_disc(const void *self, const rfs_sample_t *samples, int32_t qx_cm,
                       int32_t qy_cm, int32_t r_cm, rfs_cellsum_disc_t *out)
{
    rfs_cellsum_disc((const rfs_cellsum_t *)self, samples, qx_cm, qy_cm, r_cm, out);
}

rfs_store_index_t rfs_cellsum_index(rfs_cellsum_t *c)
{
    RFS_ASSERT(c != 0);
    rfs_store_index_t ix = {index_put, index_disc, c, c->cap};
    return ix;
}
