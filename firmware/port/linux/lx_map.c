/* lx_map.c - ROS map_server YAML + PGM loader and conversion to the core's bit grids.
 * The convention is documented in lx_map.h and docs/MAPS.md. The YAML is read through
 * lx_yaml.h.
 */
#include "lx_map.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "lx_err.h"
#include "lx_yaml.h"

/* Largest image accepted: 2^28 pixels (16384 x 16384). */
#define LX_MAP_MAX_PIXELS (1u << 28)

static int fail(char *err, size_t errlen, const char *file, const char *fmt, ...)
{
    if (err != NULL && errlen > 0) {
        char msg[512];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof(msg), fmt, ap);
        va_end(ap);
        snprintf(err, errlen, "%s: %s", file, msg);
        lx_err_one_line(err); /* a file name from the YAML can hold line breaks */
    }
    return -1;
}

static int read_file(const char *path, uint8_t **buf, size_t *len, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return fail(err, errlen, path, "cannot open: %s", strerror(errno));
    }
    size_t cap = 1 << 16;
    size_t n = 0;
    uint8_t *b = malloc(cap);
    while (b != NULL) {
        size_t got = fread(b + n, 1, cap - n, f);
        n += got;
        if (n < cap) {
            break;
        }
        uint8_t *nb = realloc(b, cap * 2);
        if (nb == NULL) {
            free(b);
            b = NULL;
            break;
        }
        b = nb;
        cap *= 2;
    }
    int bad = ferror(f);
    fclose(f);
    if (b == NULL) {
        return fail(err, errlen, path, "out of memory");
    }
    if (bad) {
        free(b);
        return fail(err, errlen, path, "read error");
    }
    *buf = b;
    *len = n;
    return 0;
}

/* --- PGM (P5 binary, P2 ASCII) --------------------------------------------------------- */

/* Skip whitespace and '#' comments in a PGM header. */
static void pgm_skip(const uint8_t *b, size_t n, size_t *pos)
{
    while (*pos < n) {
        uint8_t c = b[*pos];
        if (c == '#') {
            while (*pos < n && b[*pos] != '\n' && b[*pos] != '\r') {
                (*pos)++;
            }
        } else if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f') {
            (*pos)++;
        } else {
            break;
        }
    }
}

/* A decimal unsigned integer; -1 when absent or above max. */
static long pgm_uint(const uint8_t *b, size_t n, size_t *pos, long max)
{
    pgm_skip(b, n, pos);
    if (*pos >= n || b[*pos] < '0' || b[*pos] > '9') {
        return -1;
    }
    long v = 0;
    while (*pos < n && b[*pos] >= '0' && b[*pos] <= '9') {
        v = v * 10 + (b[*pos] - '0');
        if (v > max) {
            return -1;
        }
        (*pos)++;
    }
    return v;
}

/* Decode a PGM into a top-row-first array of values, with maxval. */
static int pgm_decode(const char *path, const uint8_t *b, size_t n, uint32_t *w, uint32_t *h,
                      uint32_t *maxval, uint16_t **pix, char *err, size_t errlen)
{
    if (n < 2 || b[0] != 'P' || (b[1] != '5' && b[1] != '2')) {
        return fail(err, errlen, path, "not a PGM image (magic P5 or P2 expected)");
    }
    bool ascii = b[1] == '2';
    size_t pos = 2;
    long lw = pgm_uint(b, n, &pos, 1L << 20);
    long lh = pgm_uint(b, n, &pos, 1L << 20);
    long lm = pgm_uint(b, n, &pos, 65535);
    if (lw < 0 || lh < 0 || lm < 0) {
        return fail(err, errlen, path, "malformed or truncated PGM header (width height maxval)");
    }
    if (lw == 0 || lh == 0 || (uint64_t)lw * (uint64_t)lh > LX_MAP_MAX_PIXELS) {
        return fail(err, errlen, path, "image size %ld x %ld out of range (1..2^28 pixels)", lw, lh);
    }
    if (lm == 0) {
        return fail(err, errlen, path, "maxval 0 in PGM header");
    }
    size_t count = (size_t)lw * (size_t)lh;
    uint16_t *p = malloc(count * sizeof(*p));
    if (p == NULL) {
        return fail(err, errlen, path, "out of memory");
    }
    if (ascii) {
        for (size_t i = 0; i < count; i++) {
            long v = pgm_uint(b, n, &pos, lm);
            if (v < 0) {
                free(p);
                pgm_skip(b, n, &pos);
                if (pos >= n) {
                    return fail(err, errlen, path, "truncated: %zu of %zu pixels (header says %ld x %ld)",
                                i, count, lw, lh);
                }
                return fail(err, errlen, path, "bad pixel value at pixel %zu (0..%ld expected)", i, lm);
            }
            p[i] = (uint16_t)v;
        }
        pgm_skip(b, n, &pos);
        if (pos != n) {
            free(p);
            return fail(err, errlen, path, "data after the %ld x %ld pixels the header declares", lw, lh);
        }
    } else {
        /* Exactly one whitespace byte after maxval, then the raster. */
        if (pos >= n || !(b[pos] == ' ' || b[pos] == '\t' || b[pos] == '\n' || b[pos] == '\r')) {
            free(p);
            return fail(err, errlen, path, "malformed or truncated PGM header (no raster)");
        }
        pos++;
        size_t bpp = lm > 255 ? 2 : 1;
        size_t need = count * bpp;
        if (n - pos < need) {
            free(p);
            return fail(err, errlen, path, "truncated: %zu raster bytes, header says %ld x %ld needs %zu",
                        n - pos, lw, lh, need);
        }
        if (n - pos > need) {
            free(p);
            return fail(err, errlen, path, "%zu bytes after the %ld x %ld raster the header declares",
                        n - pos - need, lw, lh);
        }
        for (size_t i = 0; i < count; i++) {
            uint32_t v = bpp == 2 ? ((uint32_t)b[pos + 2 * i] << 8 | b[pos + 2 * i + 1]) : b[pos + i];
            if (v > (uint32_t)lm) {
                free(p);
                return fail(err, errlen, path, "pixel %zu value %u above maxval %ld", i, v, lm);
            }
            p[i] = (uint16_t)v;
        }
    }
    *w = (uint32_t)lw;
    *h = (uint32_t)lh;
    *maxval = (uint32_t)lm;
    *pix = p;
    return 0;
}

/* --- YAML --------------------------------------------------------------------------------- */

typedef struct yaml_fields {
    char image[4096];
    bool has_image, has_res, has_origin, has_occ, has_free, has_negate;
    double res, ox, oy, yaw, occ, free_th;
    int negate;
} yaml_fields_t;

static bool parse_double(const char *s, double *out)
{
    if (s == NULL || *s == '\0') {
        return false;
    }
    char *end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    if (errno != 0 || end == s || *end != '\0' || !isfinite(v)) {
        return false;
    }
    *out = v;
    return true;
}

static int parse_yaml(const char *path, const uint8_t *buf, size_t len, yaml_fields_t *f,
                      char *err, size_t errlen)
{
    lx_yaml_doc_t doc;
    lx_yaml_error_t ye;
    lx_yaml_rc_t yrc = lx_yaml_load_string(buf, len, &doc, &ye);
    if (yrc != LX_YAML_OK) {
        int rc = yrc == LX_YAML_SYNTAX
                   ? fail(err, errlen, path, "malformed YAML at line %lu: %s", ye.line,
                          ye.problem ? ye.problem : "parse error")
               : yrc == LX_YAML_TOO_BIG
                   ? fail(err, errlen, path, "more than %u YAML nodes", LX_YAML_MAX_NODES)
                   : fail(err, errlen, path, "cannot initialise the YAML parser");
        lx_yaml_free(&doc);
        return rc;
    }
    int rc = 0;
    const lx_yaml_node_t *root = doc.root;
    if (root == NULL || root->kind != LX_YAML_MAPPING) {
        rc = fail(err, errlen, path, "not a map_server YAML (a mapping of keys expected)");
        goto out;
    }
    for (size_t i = 0; i < root->n; i++) {
        const char *key = lx_yaml_scalar(root->child[2 * i]);
        const lx_yaml_node_t *vn = root->child[2 * i + 1];
        const char *val = lx_yaml_scalar(vn);
        if (key == NULL) {
            rc = fail(err, errlen, path, "non-scalar key");
            goto out;
        }
        if (strcmp(key, "image") == 0) {
            if (val == NULL || *val == '\0' || strlen(val) >= sizeof(f->image)) {
                rc = fail(err, errlen, path, "image: a file name expected");
                goto out;
            }
            snprintf(f->image, sizeof(f->image), "%s", val);
            f->has_image = true;
        } else if (strcmp(key, "resolution") == 0) {
            if (!parse_double(val, &f->res)) {
                rc = fail(err, errlen, path, "resolution: a number expected");
                goto out;
            }
            f->has_res = true;
        } else if (strcmp(key, "origin") == 0) {
            double v[3];
            int k = 0;
            if (vn == NULL || vn->kind != LX_YAML_SEQUENCE) {
                rc = fail(err, errlen, path, "origin: a list [x, y, yaw] expected");
                goto out;
            }
            for (size_t it = 0; it < vn->n; it++) {
                if (k == 3 || !parse_double(lx_yaml_scalar(vn->child[it]), &v[k])) {
                    rc = fail(err, errlen, path, "origin: a list of three numbers [x, y, yaw] expected");
                    goto out;
                }
                k++;
            }
            if (k != 3) {
                rc = fail(err, errlen, path, "origin: a list of three numbers [x, y, yaw] expected");
                goto out;
            }
            f->ox = v[0];
            f->oy = v[1];
            f->yaw = v[2];
            f->has_origin = true;
        } else if (strcmp(key, "occupied_thresh") == 0) {
            if (!parse_double(val, &f->occ)) {
                rc = fail(err, errlen, path, "occupied_thresh: a number expected");
                goto out;
            }
            f->has_occ = true;
        } else if (strcmp(key, "free_thresh") == 0) {
            if (!parse_double(val, &f->free_th)) {
                rc = fail(err, errlen, path, "free_thresh: a number expected");
                goto out;
            }
            f->has_free = true;
        } else if (strcmp(key, "negate") == 0) {
            if (val != NULL && (strcmp(val, "0") == 0 || strcasecmp(val, "false") == 0)) {
                f->negate = 0;
            } else if (val != NULL && (strcmp(val, "1") == 0 || strcasecmp(val, "true") == 0)) {
                f->negate = 1;
            } else {
                rc = fail(err, errlen, path, "negate: 0 or 1 expected, got '%s'", val ? val : "(not a scalar)");
                goto out;
            }
            f->has_negate = true;
        } else if (strcmp(key, "mode") == 0) {
            if (val == NULL || strcmp(val, "trinary") != 0) {
                rc = fail(err, errlen, path, "mode: '%s' not supported (only trinary)",
                          val ? val : "(not a scalar)");
                goto out;
            }
        }
        /* Other keys are ignored, as map_server does. */
    }
    const char *missing = !f->has_image ? "image" : !f->has_res ? "resolution"
                        : !f->has_origin ? "origin" : !f->has_negate ? "negate"
                        : !f->has_occ ? "occupied_thresh" : !f->has_free ? "free_thresh" : NULL;
    if (missing != NULL) {
        rc = fail(err, errlen, path, "missing key '%s'", missing);
    } else if (!(f->res > 0)) {
        rc = fail(err, errlen, path, "resolution: must be > 0 (got %g)", f->res);
    } else if (f->yaw != 0.0) {
        rc = fail(err, errlen, path, "origin: yaw %g unsupported (rotated maps; only 0)", f->yaw);
    } else if (f->occ < 0 || f->occ > 1 || f->free_th < 0 || f->free_th > 1) {
        rc = fail(err, errlen, path, "thresholds must lie in [0, 1] (occupied_thresh %g, free_thresh %g)",
                  f->occ, f->free_th);
    } else if (!(f->free_th < f->occ)) {
        rc = fail(err, errlen, path, "thresholds out of order: free_thresh %g must be below occupied_thresh %g",
                  f->free_th, f->occ);
    }
out:
    lx_yaml_free(&doc);
    return rc;
}

int lx_map_load(const char *yaml_path, lx_map_t *m, char *err, size_t errlen)
{
    memset(m, 0, sizeof(*m));
    uint8_t *ybuf = NULL;
    size_t ylen = 0;
    if (read_file(yaml_path, &ybuf, &ylen, err, errlen) != 0) {
        return -1;
    }
    yaml_fields_t f;
    memset(&f, 0, sizeof(f));
    int rc = parse_yaml(yaml_path, ybuf, ylen, &f, err, errlen);
    free(ybuf);
    if (rc != 0) {
        return -1;
    }
    /* The image path is relative to the YAML file's directory unless absolute. */
    char ipath[8192];
    const char *slash = strrchr(yaml_path, '/');
    if (f.image[0] == '/' || slash == NULL) {
        snprintf(ipath, sizeof(ipath), "%s", f.image);
    } else {
        snprintf(ipath, sizeof(ipath), "%.*s/%s", (int)(slash - yaml_path), yaml_path, f.image);
    }
    uint8_t *ibuf = NULL;
    size_t ilen = 0;
    if (read_file(ipath, &ibuf, &ilen, err, errlen) != 0) {
        return -1;
    }
    uint32_t w = 0;
    uint32_t h = 0;
    uint32_t maxval = 1;
    uint16_t *pix = NULL;
    rc = pgm_decode(ipath, ibuf, ilen, &w, &h, &maxval, &pix, err, errlen);
    free(ibuf);
    if (rc != 0) {
        return -1;
    }
    uint8_t *cell = malloc((size_t)w * h); // NOLINT(clang-analyzer-optin.portability.UnixAPI): pgm_decode gives w, h >= 1
    if (cell == NULL) {
        free(pix);
        return fail(err, errlen, ipath, "out of memory");
    }
    for (uint32_t y = 0; y < h; y++) {
        /* PGM row 0 is the top; ours is the bottom. */
        const uint16_t *src = pix + (size_t)(h - 1 - y) * w;
        uint8_t *dst = cell + (size_t)y * w;
        for (uint32_t x = 0; x < w; x++) {
            double v = src[x];
            double p = f.negate ? v / maxval : (maxval - v) / maxval;
            dst[x] = p > f.occ ? LX_CELL_OCC : (p < f.free_th ? LX_CELL_FREE : LX_CELL_UNKNOWN);
        }
    }
    free(pix);
    m->w = w;
    m->h = h;
    m->res = f.res;
    m->origin_x = f.ox;
    m->origin_y = f.oy;
    m->occ_th = f.occ;
    m->free_th = f.free_th;
    m->negate = f.negate;
    m->cell = cell;
    return 0;
}

void lx_map_free(lx_map_t *m)
{
    if (m != NULL) {
        free(m->cell);
        m->cell = NULL;
    }
}

void lx_map_count(const lx_map_t *m, uint32_t *n_free, uint32_t *n_occ, uint32_t *n_unknown)
{
    uint32_t c[3] = {0, 0, 0};
    for (size_t i = 0; i < (size_t)m->w * m->h; i++) {
        c[m->cell[i] < 3 ? m->cell[i] : LX_CELL_UNKNOWN]++;
    }
    if (n_free != NULL) {
        *n_free = c[LX_CELL_FREE];
    }
    if (n_occ != NULL) {
        *n_occ = c[LX_CELL_OCC];
    }
    if (n_unknown != NULL) {
        *n_unknown = c[LX_CELL_UNKNOWN];
    }
}

/* --- conversion to the core ------------------------------------------------------------- */

/* Overlaps thinner than this share of a fine cell are ignored: the core's resolution is
 * rounded to Q16.16 (0.1 m becomes 0.100006 m), so its cell edges drift slowly against
 * the image's (3.5 mm after 580 cells); without the tolerance every coarse cell would
 * pick up a sliver of its neighbours and the conversion would erode free space and
 * thicken walls by a whole cell. */
#define LX_MAP_SLIVER 0.1

int lx_map_to_core(const lx_map_t *m, double core_res, const rfs_map_cfg_t *cfg,
                   lx_core_map_t *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof(*out));
    if (!(core_res > 0) || !isfinite(core_res) || core_res > 1000.0) {
        return fail(err, errlen, "map", "core resolution %g out of range (0, 1000] m", core_res);
    }
    rfs_map_cfg_t c = cfg != NULL ? *cfg : rfs_map_cfg_default();
    /* The core's cells use the Q16 resolution and origin; align the resampling to them. */
    int64_t res_q = llround(core_res * 65536.0);
    double oxd = m->origin_x * 65536.0;
    double oyd = m->origin_y * 65536.0;
    if (res_q <= 0 || fabs(oxd) > 2147483647.0 || fabs(oyd) > 2147483647.0) {
        return fail(err, errlen, "map", "resolution or origin not representable in Q16.16");
    }
    int64_t ox_q = llround(oxd);
    int64_t oy_q = llround(oyd);
    double cr = (double)res_q / 65536.0;
    double ox = (double)ox_q / 65536.0;
    double oy = (double)oy_q / 65536.0;
    double wm = m->w * m->res;
    double hm = m->h * m->res;
    /* Cover the whole image from the (quantised) origin. */
    double cwd = ceil((m->origin_x + wm - ox - LX_MAP_SLIVER * m->res) / cr);
    double chd = ceil((m->origin_y + hm - oy - LX_MAP_SLIVER * m->res) / cr);
    if (cwd < 1 || chd < 1 || cwd > 65535 || chd > 65535) {
        return fail(err, errlen, "map", "core grid %.0f x %.0f cells at %g m does not fit 1..65535",
                    cwd, chd, core_res);
    }
    /* 2^26 cells (8 MB per bit grid, e.g. 800 x 800 m at 0.1 m): a larger floor is a
     * wrong resolution in the YAML, not a building, and would take minutes to derive. */
    if (cwd * chd > 67108864.0) {
        return fail(err, errlen, "map", "core grid %.0f x %.0f cells at %g m is over the 2^26-cell limit",
                    cwd, chd, core_res);
    }
    uint16_t cw = (uint16_t)cwd;
    uint16_t ch = (uint16_t)chd;
    uint32_t bytes = rfs_map_bytes(cw, ch);
    out->free_bits = calloc(bytes, 1);
    out->wall_bits = calloc(bytes, 1);
    out->legal_bits = calloc(bytes, 1);
    if (out->free_bits == NULL || out->wall_bits == NULL || out->legal_bits == NULL) {
        lx_core_map_free(out);
        return fail(err, errlen, "map", "out of memory");
    }
    uint16_t stride = (uint16_t)((cw + 7u) / 8u);
    for (uint16_t cy = 0; cy < ch; cy++) {
        /* Fine rows overlapping [oy + cy*cr, oy + (cy+1)*cr] by more than a sliver. */
        double y0 = (oy + cy * cr - m->origin_y) / m->res;
        double y1 = (oy + (cy + 1) * cr - m->origin_y) / m->res;
        long fy0 = (long)floor(y0 + LX_MAP_SLIVER);
        long fy1 = (long)ceil(y1 - LX_MAP_SLIVER) - 1;
        if (fy1 < fy0) {
            fy1 = fy0; /* a core cell inside one fine cell (core finer than the image) */
        }
        for (uint16_t cx = 0; cx < cw; cx++) {
            double x0 = (ox + cx * cr - m->origin_x) / m->res;
            double x1 = (ox + (cx + 1) * cr - m->origin_x) / m->res;
            long fx0 = (long)floor(x0 + LX_MAP_SLIVER);
            long fx1 = (long)ceil(x1 - LX_MAP_SLIVER) - 1;
            if (fx1 < fx0) {
                fx1 = fx0;
            }
            bool all_free = true;
            bool any_occ = false;
            for (long fy = fy0; fy <= fy1; fy++) {
                for (long fx = fx0; fx <= fx1; fx++) {
                    if (fx < 0 || fy < 0 || fx >= (long)m->w || fy >= (long)m->h) {
                        all_free = false;
                        continue;
                    }
                    uint8_t s = m->cell[(size_t)fy * m->w + (size_t)fx];
                    all_free = all_free && s == LX_CELL_FREE;
                    any_occ = any_occ || s == LX_CELL_OCC;
                }
            }
            rfs_map_bit_set(out->free_bits, stride, cx, cy, all_free);
            rfs_map_bit_set(out->wall_bits, stride, cx, cy, any_occ);
        }
    }
    if (rfs_map_init(&out->map, &c, cw, ch, (rfs_q16_t)res_q, (rfs_q16_t)ox_q, (rfs_q16_t)oy_q,
                     out->free_bits, out->wall_bits, out->legal_bits) != 0) {
        lx_core_map_free(out);
        return fail(err, errlen, "map", "the core rejects the map (%u x %u cells at %g m, clearance %g m, "
                    "grid %g m: extent above 16384 m, clearance above 64 m or 255 cells, or lattice above 65535)",
                    cw, ch, core_res, c.clearance / 65536.0, c.grid / 65536.0);
    }
    return 0;
}

void lx_core_map_free(lx_core_map_t *c)
{
    if (c != NULL) {
        free(c->free_bits);
        free(c->wall_bits);
        free(c->legal_bits);
        c->free_bits = NULL;
        c->wall_bits = NULL;
        c->legal_bits = NULL;
    }
}
