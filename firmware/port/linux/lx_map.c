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

/* Largest image accepted: 2^26 pixels (8192 x 8192), one byte each once classified, so a
 * map input costs at most 64 MB here plus the core's bit grids (lx_map_to_core: three of
 * at most 8 MB): under 100 MB whatever the file (docs/RELIABILITY.md). */
#define LX_MAP_MAX_PIXELS (1u << 26)
/* Largest YAML accepted: a map_server YAML is a few lines. */
#define LX_MAP_MAX_YAML (1u << 20)

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

/* Read at most `max` bytes of `path` (a stream such as /dev/zero is cut off there). */
static int read_file(const char *path, size_t max, uint8_t **buf, size_t *len, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return fail(err, errlen, path, "cannot open: %s", strerror(errno));
    }
    uint8_t *b = NULL;
    size_t n = 0;
    (void)lx_yaml_read(f, max, &b, &n);
    int bad = ferror(f);
    fclose(f);
    if (b == NULL) {
        return fail(err, errlen, path, "out of memory");
    }
    if (bad || n > max) {
        free(b);
        return bad ? fail(err, errlen, path, "read error")
                   : fail(err, errlen, path, "larger than %zu bytes (a map_server YAML is a few lines)", max);
    }
    *buf = b;
    *len = n;
    return 0;
}

/* --- PGM (P5 binary, P2 ASCII) --------------------------------------------------------- */

/* The image is read as a stream, one byte of look-ahead: never more than the header
 * declares, so a huge or endless file (/dev/zero, a sparse file) costs no memory. */
typedef struct pgm_in {
    FILE *f;
    int c;        /* the next byte, or EOF */
    uint64_t pos; /* bytes consumed before c */
} pgm_in_t;

static void pgm_next(pgm_in_t *in)
{
    if (in->c != EOF) {
        in->pos++;
    }
    in->c = getc(in->f);
}

static bool pgm_space(int c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Skip whitespace and '#' comments in a PGM header. */
static void pgm_skip(pgm_in_t *in)
{
    while (in->c != EOF) {
        if (in->c == '#') {
            while (in->c != EOF && in->c != '\n' && in->c != '\r') {
                pgm_next(in);
            }
        } else if (pgm_space(in->c)) {
            pgm_next(in);
        } else {
            break;
        }
    }
}

/* A decimal unsigned integer; -1 when absent or above max. */
static long pgm_uint(pgm_in_t *in, long max)
{
    pgm_skip(in);
    if (in->c < '0' || in->c > '9') {
        return -1;
    }
    long v = 0;
    while (in->c >= '0' && in->c <= '9') {
        v = v * 10 + (in->c - '0');
        if (v > max) {
            return -1;
        }
        pgm_next(in);
    }
    return v;
}

/* Classification of one pixel value v (maxval M), lx_map.h's convention. */
typedef struct pgm_class {
    double maxval, occ, free_th;
    int negate;
} pgm_class_t;

static uint8_t pgm_cell(const pgm_class_t *k, uint32_t v)
{
    double d = v;
    double p = k->negate ? d / k->maxval : (k->maxval - d) / k->maxval;
    return p > k->occ ? LX_CELL_OCC : (p < k->free_th ? LX_CELL_FREE : LX_CELL_UNKNOWN);
}

/* The raster of a P5 image, row by row, into cells (row 0 = bottom). */
static int pgm_raster_p5(const char *path, pgm_in_t *in, const pgm_class_t *k, uint32_t w, uint32_t h,
                         uint32_t lm, uint8_t *cell, char *err, size_t errlen)
{
    size_t bpp = lm > 255 ? 2 : 1;
    uint8_t *row = malloc((size_t)w * bpp);
    if (row == NULL) {
        return fail(err, errlen, path, "out of memory");
    }
    for (uint32_t r = 0; r < h; r++) {
        size_t got = fread(row, bpp, w, in->f);
        if (got < w) {
            free(row);
            return fail(err, errlen, path, "truncated: %zu raster bytes, header says %u x %u needs %zu",
                        ((size_t)r * w + got) * bpp, w, h, (size_t)w * h * bpp);
        }
        uint8_t *dst = cell + (size_t)(h - 1 - r) * w; /* PGM row 0 is the top; ours the bottom */
        for (uint32_t x = 0; x < w; x++) {
            uint32_t v = bpp == 2 ? ((uint32_t)row[2 * x] << 8 | row[2 * x + 1]) : row[x];
            if (v > lm) {
                free(row);
                return fail(err, errlen, path, "pixel %zu value %u above maxval %u", (size_t)r * w + x, v, lm);
            }
            dst[x] = pgm_cell(k, v);
        }
    }
    free(row);
    in->pos += 1 + (uint64_t)w * h * bpp; /* the whitespace byte held in c, then the raster */
    in->c = getc(in->f);
    return 0;
}

/* The raster of a P2 image, value by value, into cells (row 0 = bottom). */
static int pgm_raster_p2(const char *path, pgm_in_t *in, const pgm_class_t *k, uint32_t w, uint32_t h,
                         uint32_t lm, uint8_t *cell, char *err, size_t errlen)
{
    size_t count = (size_t)w * h;
    for (size_t i = 0; i < count; i++) {
        long v = pgm_uint(in, (long)lm);
        if (v < 0) {
            pgm_skip(in);
            if (in->c == EOF) {
                return fail(err, errlen, path, "truncated: %zu of %zu pixels (header says %u x %u)", i, count, w, h);
            }
            return fail(err, errlen, path, "bad pixel value at pixel %zu (0..%u expected)", i, lm);
        }
        cell[(size_t)(h - 1 - i / w) * w + i % w] = pgm_cell(k, (uint32_t)v);
    }
    pgm_skip(in);
    return 0;
}

/* Read a PGM of at most LX_MAP_MAX_PIXELS into w * h classified cells, reading only what
 * its header declares and then one byte to refuse data after it. */
static int pgm_load(const char *path, const pgm_class_t *k0, uint32_t *w, uint32_t *h, uint8_t **cells,
                    char *err, size_t errlen)
{
    pgm_in_t in = {fopen(path, "rb"), EOF, 0};
    if (in.f == NULL) {
        return fail(err, errlen, path, "cannot open: %s", strerror(errno));
    }
    int c0 = getc(in.f);
    int c1 = getc(in.f);
    if (c0 != 'P' || (c1 != '5' && c1 != '2')) {
        int rc = ferror(in.f) ? fail(err, errlen, path, "read error")
                              : fail(err, errlen, path, "not a PGM image (magic P5 or P2 expected)");
        fclose(in.f);
        return rc;
    }
    bool ascii = c1 == '2';
    in.pos = 2;
    in.c = getc(in.f);
    long lw = pgm_uint(&in, 1L << 20);
    long lh = pgm_uint(&in, 1L << 20);
    long lm = pgm_uint(&in, 65535);
    int rc = 0;
    uint8_t *cell = NULL;
    if (lw < 0 || lh < 0 || lm < 0) {
        rc = fail(err, errlen, path, "malformed or truncated PGM header (width height maxval)");
    } else if (lw == 0 || lh == 0 || (uint64_t)lw * (uint64_t)lh > LX_MAP_MAX_PIXELS) {
        rc = fail(err, errlen, path, "image size %ld x %ld out of range (1..2^26 pixels)", lw, lh);
    } else if (lm == 0) {
        rc = fail(err, errlen, path, "maxval 0 in PGM header");
    } else if (!ascii && !(in.c == ' ' || in.c == '\t' || in.c == '\n' || in.c == '\r')) {
        /* P5: exactly one whitespace byte after maxval (already read as in.c), then the raster. */
        rc = fail(err, errlen, path, "malformed or truncated PGM header (no raster)");
    } else if ((cell = malloc((size_t)lw * (size_t)lh)) == NULL) {
        rc = fail(err, errlen, path, "out of memory");
    } else {
        pgm_class_t k = *k0;
        k.maxval = (double)lm;
        rc = ascii ? pgm_raster_p2(path, &in, &k, (uint32_t)lw, (uint32_t)lh, (uint32_t)lm, cell, err, errlen)
                   : pgm_raster_p5(path, &in, &k, (uint32_t)lw, (uint32_t)lh, (uint32_t)lm, cell, err, errlen);
        if (rc == 0 && in.c != EOF) {
            rc = fail(err, errlen, path, "data after the %ld x %ld %s the header declares (at byte %llu)", lw, lh,
                      ascii ? "pixels" : "raster", (unsigned long long)in.pos);
        }
    }
    if (rc == 0 && ferror(in.f)) {
        rc = fail(err, errlen, path, "read error");
    }
    fclose(in.f);
    if (rc != 0) {
        free(cell);
        return -1;
    }
    *w = (uint32_t)lw;
    *h = (uint32_t)lh;
    *cells = cell;
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

/* The map's plain number keys: where each goes and its presence flag. */
typedef struct number_key {
    double *value;
    bool *have;
} number_key_t;

static bool number_key(yaml_fields_t *f, const char *key, number_key_t *k)
{
    if (strcmp(key, "resolution") == 0) {
        *k = (number_key_t){&f->res, &f->has_res};
    } else if (strcmp(key, "occupied_thresh") == 0) {
        *k = (number_key_t){&f->occ, &f->has_occ};
    } else if (strcmp(key, "free_thresh") == 0) {
        *k = (number_key_t){&f->free_th, &f->has_free};
    } else {
        return false;
    }
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
        number_key_t num;
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
        } else if (number_key(f, key, &num)) {
            if (!parse_double(val, num.value)) {
                rc = fail(err, errlen, path, "%s: a number expected", key);
                goto out;
            }
            *num.have = true;
        } else if (strcmp(key, "origin") == 0) {
            double v[3];
            if (vn == NULL || vn->kind != LX_YAML_SEQUENCE) {
                rc = fail(err, errlen, path, "origin: a list [x, y, yaw] expected");
                goto out;
            }
            bool ok = vn->n == 3;
            for (size_t it = 0; ok && it < 3; it++) {
                ok = parse_double(lx_yaml_scalar(vn->child[it]), &v[it]);
            }
            if (!ok) {
                rc = fail(err, errlen, path, "origin: a list of three numbers [x, y, yaw] expected");
                goto out;
            }
            f->ox = v[0];
            f->oy = v[1];
            f->yaw = v[2];
            f->has_origin = true;
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
    } else if (!(f->res >= LX_MAP_RES_MIN && f->res <= LX_MAP_RES_MAX)) {
        rc = fail(err, errlen, path, "resolution: %g m out of range (%g .. %g m per pixel)", f->res,
                  LX_MAP_RES_MIN, LX_MAP_RES_MAX);
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
    if (read_file(yaml_path, LX_MAP_MAX_YAML, &ybuf, &ylen, err, errlen) != 0) {
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
    pgm_class_t k = {1.0, f.occ, f.free_th, f.negate};
    uint32_t w = 0;
    uint32_t h = 0;
    uint8_t *cell = NULL;
    if (pgm_load(ipath, &k, &w, &h, &cell, err, errlen) != 0) {
        return -1;
    }
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

/* A fine-cell index (floor or ceil already taken) clamped to [-1, n]: every index outside
 * the image means the same ("beyond it"), and the clamp keeps the conversion to long
 * defined whatever the origin and resolutions. */
static long fine_index(double v, uint32_t n)
{
    return v < -1.0 ? -1 : (v > (double)n ? (long)n : (long)v);
}

int lx_map_to_core(const lx_map_t *m, double core_res, const rfs_map_cfg_t *cfg,
                   lx_core_map_t *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof(*out));
    if (!(core_res > 0) || !isfinite(core_res) || core_res > 1000.0) {
        return fail(err, errlen, "map", "core resolution %g out of range (0, 1000] m", core_res);
    }
    if (!(m->res >= LX_MAP_RES_MIN && m->res <= LX_MAP_RES_MAX)) {
        return fail(err, errlen, "map", "resolution %g m out of range (%g .. %g m per pixel)", m->res,
                    LX_MAP_RES_MIN, LX_MAP_RES_MAX);
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
        long fy0 = fine_index(floor(y0 + LX_MAP_SLIVER), m->h);
        long fy1 = fine_index(ceil(y1 - LX_MAP_SLIVER) - 1, m->h);
        if (fy1 < fy0) {
            fy1 = fy0; /* a core cell inside one fine cell (core finer than the image) */
        }
        for (uint16_t cx = 0; cx < cw; cx++) {
            double x0 = (ox + cx * cr - m->origin_x) / m->res;
            double x1 = (ox + (cx + 1) * cr - m->origin_x) / m->res;
            long fx0 = fine_index(floor(x0 + LX_MAP_SLIVER), m->w);
            long fx1 = fine_index(ceil(x1 - LX_MAP_SLIVER) - 1, m->w);
            if (fx1 < fx0) {
                fx1 = fx0;
            }
            /* Fine cells beyond the image count as unknown: visit only those inside, so
             * the work is bounded by the image, however coarse the core cell. */
            bool all_free = fx0 >= 0 && fy0 >= 0 && fx1 < (long)m->w && fy1 < (long)m->h;
            bool any_occ = false;
            for (long fy = fy0 < 0 ? 0 : fy0; fy <= fy1 && fy < (long)m->h; fy++) {
                for (long fx = fx0 < 0 ? 0 : fx0; fx <= fx1 && fx < (long)m->w; fx++) {
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
