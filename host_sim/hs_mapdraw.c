/* hs_mapdraw.c - the placement picture of rfseek-map --png (hs_mapdraw.h). Rendered one row
 * at a time straight into the PNG writer, so memory is one row whatever the map. */
#include "hs_mapdraw.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "lx_err.h"
#include "lx_png.h"

/* A 5 x 7 font, drawn 2 x 2 pixels a dot: each glyph is 7 rows, bit 4 the left column. */
#define FONT_DOT 2
#define FONT_ADVANCE 12 /* 5 dots and a 1-dot gap */
#define FONT_HEIGHT 14

static const char k_chars[] = "0123456789-xym() ";
static const uint8_t k_glyphs[][7] = {
    {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},
    {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},
    {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},
    {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
    {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C},
    {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}, {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11},
    {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E}, {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11},
    {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}, {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08},
    {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00},
};

#define INK 0x282828u   /* frame, ticks and text */
#define PAPER 0xffffffu /* the margins */

typedef struct draw {
    const lx_map_t *m;
    const rfs_map_t *core;
    hs_mapdraw_layout_t lay;
    double ppm;            /* pixels per metre, S / res */
    long kx0, kx1, ky0, ky1; /* the whole metres inside the map along x and y */
    uint8_t *col_kind;     /* per picture column: 1 a whole metre of x, 2 x = 0, else 0 */
    uint8_t *row;
} draw_t;

static void put(const draw_t *d, long x, uint32_t rgb)
{
    if (x >= 0 && x < (long)d->lay.width) {
        d->row[3 * x] = (uint8_t)(rgb >> 16);
        d->row[3 * x + 1] = (uint8_t)(rgb >> 8);
        d->row[3 * x + 2] = (uint8_t)rgb;
    }
}

/* Pixel row y of text s whose top-left corner is (x0, top). */
static void text_row(const draw_t *d, long x0, long top, uint32_t y, const char *s)
{
    long dy = (long)y - top;
    if (dy < 0 || dy >= FONT_HEIGHT) {
        return;
    }
    for (size_t i = 0; s[i] != '\0'; i++) {
        const char *at = strchr(k_chars, s[i]);
        uint8_t bits = at != NULL ? k_glyphs[at - k_chars][dy / FONT_DOT] : 0;
        for (int c = 0; c < 5 * FONT_DOT; c++) {
            if (bits & (0x10 >> (c / FONT_DOT))) {
                put(d, x0 + (long)i * FONT_ADVANCE + c, INK);
            }
        }
    }
}

static long text_width(const char *s)
{
    return (long)strlen(s) * FONT_ADVANCE - FONT_DOT;
}

/* Column of the whole metre x = k and row of y = k (hs_mapdraw.h). */
static long col_of(const draw_t *d, long k)
{
    return (long)HS_MAPDRAW_LEFT + lround(((double)k - d->m->origin_x) * d->ppm);
}

static long row_of(const draw_t *d, long k)
{
    return (long)HS_MAPDRAW_TOP + lround((d->m->origin_y + d->m->h * d->m->res - (double)k) * d->ppm);
}

static long div_floor(long a, long b)
{
    return a / b - (a % b != 0 && (a < 0) != (b < 0));
}

int hs_mapdraw_layout(const lx_map_t *m, hs_mapdraw_layout_t *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof(*out));
    uint32_t side = m->w > m->h ? m->w : m->h;
    if (side > HS_MAPDRAW_MAX_SIDE) {
        return lx_err_set(err, errlen, NULL, "the map is %u x %u cells: more than %u a side to draw", m->w, m->h,
                          HS_MAPDRAW_MAX_SIDE);
    }
    uint32_t s = (uint32_t)ceil(20.0 * m->res - 1e-9);
    s = s < 1 ? 1 : s;
    if ((uint64_t)s * side > HS_MAPDRAW_MAX_SIDE) {
        s = HS_MAPDRAW_MAX_SIDE / side;
    }
    out->scale = s;
    out->width = HS_MAPDRAW_LEFT + s * m->w + HS_MAPDRAW_RIGHT;
    out->height = HS_MAPDRAW_TOP + s * m->h + HS_MAPDRAW_BOTTOM;
    /* Labels far enough apart for the widest along x, "-123" style, and a gap. */
    const double ppm = s / m->res;
    char a[24];
    char b[24];
    snprintf(a, sizeof(a), "%ld", (long)floor(m->origin_x));
    snprintf(b, sizeof(b), "%ld", (long)ceil(m->origin_x + m->w * m->res));
    long need = (text_width(a) > text_width(b) ? text_width(a) : text_width(b)) + FONT_ADVANCE;
    static const uint32_t steps[3] = {1, 2, 5};
    for (uint32_t decade = 1; out->label_m == 0; decade *= 10) {
        for (int i = 0; i < 3 && out->label_m == 0; i++) {
            if (steps[i] * decade * ppm >= (double)need || decade >= 100000) {
                out->label_m = steps[i] * decade;
            }
        }
    }
    return 0;
}

static uint32_t cell_colour(const draw_t *d, uint32_t px, uint32_t py)
{
    const lx_map_t *m = d->m;
    const uint32_t s = d->lay.scale;
    const uint32_t cx = (px - HS_MAPDRAW_LEFT) / s;
    const uint32_t cy = m->h - 1 - (py - HS_MAPDRAW_TOP) / s;
    const uint8_t c = m->cell[(size_t)cy * m->w + cx];
    if (c == LX_CELL_OCC) {
        return HS_MAPDRAW_WALL;
    }
    if (c != LX_CELL_FREE) {
        return HS_MAPDRAW_UNKNOWN;
    }
    if (d->core == NULL) {
        return HS_MAPDRAW_LEGAL;
    }
    /* The pixel's centre in the map frame, Q16.16 (inside the map: far from overflow). */
    const double x = m->origin_x + (px - HS_MAPDRAW_LEFT + 0.5) / d->ppm;
    const double y = m->origin_y + m->h * m->res - (py - HS_MAPDRAW_TOP + 0.5) / d->ppm;
    return rfs_map_point_legal(d->core, (rfs_q16_t)lround(x * 65536.0), (rfs_q16_t)lround(y * 65536.0))
               ? HS_MAPDRAW_LEGAL
               : HS_MAPDRAW_FREE;
}

static void fill_row(void *ctx, uint32_t y, uint8_t *row)
{
    draw_t *d = ctx;
    d->row = row;
    const lx_map_t *m = d->m;
    const long left = HS_MAPDRAW_LEFT;
    const long top = HS_MAPDRAW_TOP;
    const long right = left + (long)(d->lay.scale * m->w); /* first column past the map */
    const long bottom = top + (long)(d->lay.scale * m->h); /* first row past the map */
    const long yy = (long)y;
    memset(row, 0xff, (size_t)d->lay.width * 3);
    if (yy >= top && yy < bottom) {
        bool grid_row = false;
        bool axis_row = false;
        for (long k = d->ky0; k <= d->ky1; k++) {
            if (row_of(d, k) == yy) {
                grid_row = true;
                axis_row = k == 0;
            }
        }
        for (long x = left; x < right; x++) {
            uint32_t c = cell_colour(d, (uint32_t)x, y);
            const uint8_t kind = d->col_kind[x];
            if (axis_row || kind == 2) {
                c = HS_MAPDRAW_AXIS;
            } else if ((grid_row || kind == 1) && c != HS_MAPDRAW_WALL) {
                c = HS_MAPDRAW_GRID;
            }
            put(d, x, c);
        }
        put(d, left - 1, INK);
        put(d, right, INK);
        for (long k = d->ky0; k <= d->ky1; k++) { /* ticks on the left */
            if (row_of(d, k) == yy) {
                for (long x = left - 6; x < left - 1; x++) {
                    put(d, x, INK);
                }
            }
        }
    } else if (yy == top - 1 || yy == bottom) {
        for (long x = left - 1; x <= right; x++) {
            put(d, x, INK);
        }
    } else if (yy > bottom && yy <= bottom + 5) { /* ticks below */
        for (long k = d->kx0; k <= d->kx1; k++) {
            put(d, col_of(d, k), INK);
        }
    }
    char s[24];
    const long n = (long)d->lay.label_m;
    for (long k = div_floor(d->kx0 + n - 1, n) * n; k <= d->kx1; k += n) { /* x labels */
        snprintf(s, sizeof(s), "%ld", k);
        text_row(d, col_of(d, k) - text_width(s) / 2, bottom + 8, y, s);
    }
    for (long k = div_floor(d->ky0 + n - 1, n) * n; k <= d->ky1; k += n) { /* y labels */
        snprintf(s, sizeof(s), "%ld", k);
        text_row(d, left - 8 - text_width(s), row_of(d, k) - FONT_HEIGHT / 2, y, s);
    }
    text_row(d, 4, 4, y, "y (m)");
    text_row(d, right - text_width("x (m)"), bottom + 8 + FONT_HEIGHT + 4, y, "x (m)");
}

int hs_mapdraw_png(const lx_map_t *m, const rfs_map_t *core, FILE *f, char *err, size_t errlen)
{
    draw_t d;
    memset(&d, 0, sizeof(d));
    d.m = m;
    d.core = core;
    if (m->cell == NULL || hs_mapdraw_layout(m, &d.lay, err, errlen) != 0) {
        return m->cell == NULL ? lx_err_set(err, errlen, NULL, "no cells to draw") : -1;
    }
    d.ppm = d.lay.scale / m->res;
    /* The whole metres whose line falls inside the map area. */
    const long left = HS_MAPDRAW_LEFT;
    const long right = left + (long)(d.lay.scale * m->w);
    const long top = HS_MAPDRAW_TOP;
    const long bottom = top + (long)(d.lay.scale * m->h);
    d.kx0 = (long)floor(m->origin_x) - 1;
    d.kx1 = (long)ceil(m->origin_x + m->w * m->res) + 1;
    while (col_of(&d, d.kx0) < left) {
        d.kx0++;
    }
    while (col_of(&d, d.kx1) >= right) {
        d.kx1--;
    }
    d.ky0 = (long)floor(m->origin_y) - 1;
    d.ky1 = (long)ceil(m->origin_y + m->h * m->res) + 1;
    while (row_of(&d, d.ky0) >= bottom) {
        d.ky0++;
    }
    while (row_of(&d, d.ky1) < top) {
        d.ky1--;
    }
    d.col_kind = calloc(d.lay.width, 1);
    if (d.col_kind == NULL) {
        return lx_err_set(err, errlen, NULL, "out of memory");
    }
    for (long k = d.kx0; k <= d.kx1; k++) {
        d.col_kind[col_of(&d, k)] = k == 0 ? 2 : 1;
    }
    int rc = lx_png_write(f, d.lay.width, d.lay.height, 3, fill_row, &d, err, errlen);
    free(d.col_kind);
    return rc;
}
