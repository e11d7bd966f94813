/* lx_map.c - ROS map_server YAML + PGM / PNG loader, conversion to the core's bit grids,
 * crop and save. The convention is documented in lx_map.h and docs/MAPS.md. The YAML is
 * read through lx_yaml.h, a PNG through lx_png.h.
 */
#include "lx_map.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "lx_err.h"
#include "lx_pgm.h"
#include "lx_png.h"
#include "lx_yaml.h"

/* Largest image accepted: 2^26 pixels (8192 x 8192), one byte each once classified, so a
 * map input costs at most 64 MB here plus a PNG's rows while it is read (lx_png.h: 24 MB,
 * or an interlaced image's 32 MB with at most 2^25 pixels) or the core's bit grids
 * afterwards (lx_map_to_core: three of at most 8 MB): under 100 MB whatever the file
 * (docs/RELIABILITY.md). */
#define LX_MAP_MAX_PIXELS (1u << 26)
/* Largest YAML accepted: a map_server YAML is a few lines. */
#define LX_MAP_MAX_YAML (1u << 20)

/* Read at most `max` bytes of `path` (a stream such as /dev/zero is cut off there). */
static int read_file(const char *path, size_t max, uint8_t **buf, size_t *len, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return lx_err_set(err, errlen, path, "cannot open: %s", strerror(errno));
    }
    uint8_t *b = NULL;
    size_t n = 0;
    (void)lx_yaml_read(f, max, &b, &n);
    int bad = ferror(f);
    fclose(f);
    if (b == NULL) {
        return lx_err_set(err, errlen, path, "out of memory");
    }
    if (bad || n > max) {
        free(b);
        return bad ? lx_err_set(err, errlen, path, "read error")
                   : lx_err_set(err, errlen, path, "larger than %zu bytes (a map_server YAML is a few lines)", max);
    }
    *buf = b;
    *len = n;
    return 0;
}

/* --- pixels to occupancy ------------------------------------------------------------------ */

int8_t lx_map_value(const lx_map_reading_t *r, const uint16_t *ch, int n, uint32_t maxval)
{
    const bool alpha = n == 2 || n == 4;
    const double m = (double)maxval;
    /* nav2 averages the red, green and blue samples (a gray image's three are equal), and
     * the alpha sample too in trinary mode; sums of integers, so exact. */
    double sum = n <= 2 ? 3.0 * ch[0] : (double)ch[0] + ch[1] + ch[2];
    double count = 3.0;
    if (alpha && r->mode == LX_MAP_TRINARY) {
        sum += ch[n - 1];
        count = 4.0;
    }
    const double mean = sum / count;
    if (r->mode == LX_MAP_RAW) {
        const double v = round(mean / m * 255.0);
        return v >= 0.0 && v <= 100.0 ? (int8_t)v : -1;
    }
    if (r->mode == LX_MAP_SCALE && alpha && ch[n - 1] != maxval) {
        return -1;
    }
    /* (M - mean) / M as the ROS wiki writes it: nav2's 1 - mean / M differs only in the
     * last bit, which decides nothing unless p equals a threshold exactly. */
    const double p = r->negate ? mean / m : (m - mean) / m;
    if (p > r->occ_th) {
        return 100;
    }
    if (p < r->free_th) {
        return 0;
    }
    if (r->mode == LX_MAP_TRINARY) {
        return -1;
    }
    return (int8_t)rint((p - r->free_th) / (r->occ_th - r->free_th) * 100.0);
}

uint8_t lx_map_cell_of(int8_t value)
{
    return value < 0 ? LX_CELL_UNKNOWN : (value >= 100 ? LX_CELL_OCC : LX_CELL_FREE);
}

/* Where an image's pixels go: cell states (lx_map_load) or values (lx_map_load_values). */
typedef struct img_sink {
    const char *path;
    lx_map_reading_t r;
    bool want_values;
    uint32_t w, h, maxval;
    int channels;
    uint8_t *cell;
    int8_t *value;
    uint32_t n_partial;
    char format[48];
} img_sink_t;

static int sink_alloc(img_sink_t *s, uint32_t w, uint32_t h, uint32_t maxval, int channels, char *err,
                      size_t errlen)
{
    s->w = w;
    s->h = h;
    s->maxval = maxval;
    s->channels = channels;
    void *p = malloc((size_t)w * h);
    if (p == NULL) {
        return lx_err_set(err, errlen, s->path, "out of memory");
    }
    if (s->want_values) {
        s->value = p;
    } else {
        s->cell = p;
    }
    return 0;
}

/* Pixel x of image row r (row 0 = the top) with its channels ch. */
static void sink_put(img_sink_t *s, uint32_t x, uint32_t r, const uint16_t *ch)
{
    const size_t i = (size_t)(s->h - 1 - r) * s->w + x; /* image row 0 is the top; ours the bottom */
    const int8_t v = lx_map_value(&s->r, ch, s->channels, s->maxval);
    s->n_partial += v > 0 && v < 100;
    if (s->value != NULL) {
        s->value[i] = v;
    } else {
        s->cell[i] = lx_map_cell_of(v);
    }
}

static void sink_row(void *ctx, uint32_t r, const uint16_t *samples)
{
    img_sink_t *s = ctx;
    for (uint32_t x = 0; x < s->w; x++) {
        sink_put(s, x, r, samples + (size_t)x * (size_t)s->channels);
    }
}

static int pgm_on_info(void *ctx, uint32_t w, uint32_t h, uint32_t maxval, bool ascii, char *err, size_t errlen)
{
    img_sink_t *s = ctx;
    snprintf(s->format, sizeof(s->format), "PGM %s, maxval %u", ascii ? "P2" : "P5", maxval);
    return sink_alloc(s, w, h, maxval, 1, err, errlen);
}

/* --- the image: PGM or PNG ------------------------------------------------------------------- */

static const char *png_color_name(int color_type)
{
    switch (color_type) {
    case 0: return "gray";
    case 2: return "RGB";
    case 3: return "palette";
    case 4: return "gray + alpha";
    default: return "RGBA";
    }
}

static int png_on_info(void *ctx, const lx_png_info_t *pi, char *err, size_t errlen)
{
    img_sink_t *s = ctx;
    snprintf(s->format, sizeof(s->format), "PNG %s, %u bit%s%s", png_color_name(pi->color_type), pi->bit_depth,
             pi->bit_depth > 1 ? "s" : "", pi->interlaced ? ", interlaced" : "");
    return sink_alloc(s, pi->w, pi->h, pi->depth == 16 ? 65535u : 255u, pi->channels, err, errlen);
}

/* A PNG (its signature at the start) or else a PGM: map_server tells them apart by content. */
static int image_load(img_sink_t *s, char *err, size_t errlen)
{
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    uint8_t head[8];
    size_t n = 0;
    FILE *f = fopen(s->path, "rb");
    if (f != NULL) {
        n = fread(head, 1, sizeof(head), f);
        fclose(f);
    }
    if (n == sizeof(head) && memcmp(head, sig, sizeof(sig)) == 0) {
        return lx_png_read(s->path, LX_MAP_MAX_PIXELS, png_on_info, sink_row, s, err, errlen);
    }
    return lx_pgm_read(s->path, LX_MAP_MAX_PIXELS, pgm_on_info, sink_row, s, err, errlen);
}

/* --- YAML --------------------------------------------------------------------------------- */

typedef struct yaml_fields {
    char image[4096];
    bool has_image, has_res, has_origin, has_occ, has_free, has_negate;
    double res, ox, oy, yaw, occ, free_th;
    int negate, mode;
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
                   ? lx_err_set(err, errlen, path, "malformed YAML at line %lu: %s", ye.line,
                                ye.problem ? ye.problem : "parse error")
               : yrc == LX_YAML_TOO_BIG
                   ? lx_err_set(err, errlen, path, "more than %u YAML nodes", LX_YAML_MAX_NODES)
                   : lx_err_set(err, errlen, path, "cannot initialise the YAML parser");
        lx_yaml_free(&doc);
        return rc;
    }
    int rc = 0;
    const lx_yaml_node_t *root = doc.root;
    if (root == NULL || root->kind != LX_YAML_MAPPING) {
        rc = lx_err_set(err, errlen, path, "not a map_server YAML (a mapping of keys expected)");
        goto out;
    }
    for (size_t i = 0; i < root->n; i++) {
        const char *key = lx_yaml_scalar(root->child[2 * i]);
        const lx_yaml_node_t *vn = root->child[2 * i + 1];
        const char *val = lx_yaml_scalar(vn);
        number_key_t num;
        if (key == NULL) {
            rc = lx_err_set(err, errlen, path, "non-scalar key");
            goto out;
        }
        if (strcmp(key, "image") == 0) {
            if (val == NULL || *val == '\0' || strlen(val) >= sizeof(f->image)) {
                rc = lx_err_set(err, errlen, path, "image: a file name expected");
                goto out;
            }
            snprintf(f->image, sizeof(f->image), "%s", val);
            f->has_image = true;
        } else if (number_key(f, key, &num)) {
            if (!parse_double(val, num.value)) {
                rc = lx_err_set(err, errlen, path, "%s: a number expected", key);
                goto out;
            }
            *num.have = true;
        } else if (strcmp(key, "origin") == 0) {
            double v[3];
            if (vn == NULL || vn->kind != LX_YAML_SEQUENCE) {
                rc = lx_err_set(err, errlen, path, "origin: a list [x, y, yaw] expected");
                goto out;
            }
            bool ok = vn->n == 3;
            for (size_t it = 0; ok && it < 3; it++) {
                ok = parse_double(lx_yaml_scalar(vn->child[it]), &v[it]);
            }
            if (!ok) {
                rc = lx_err_set(err, errlen, path, "origin: a list of three numbers [x, y, yaw] expected");
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
                rc = lx_err_set(err, errlen, path, "negate: 0 or 1 expected, got '%s'", val ? val : "(not a scalar)");
                goto out;
            }
            f->has_negate = true;
        } else if (strcmp(key, "mode") == 0) {
            /* Spelled exactly as map_server and nav2 compare them. */
            static const char *const modes[3] = {"trinary", "scale", "raw"};
            f->mode = -1;
            for (int k = 0; k < 3 && val != NULL; k++) {
                f->mode = strcmp(val, modes[k]) == 0 ? k : f->mode;
            }
            if (f->mode < 0) {
                rc = lx_err_set(err, errlen, path, "mode: '%s' unknown (trinary, scale or raw)",
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
        rc = lx_err_set(err, errlen, path, "missing key '%s'", missing);
    } else if (!(f->res > 0)) {
        rc = lx_err_set(err, errlen, path, "resolution: must be > 0 (got %g)", f->res);
    } else if (!(f->res >= LX_MAP_RES_MIN && f->res <= LX_MAP_RES_MAX)) {
        rc = lx_err_set(err, errlen, path, "resolution: %g m out of range (%g .. %g m per pixel)", f->res,
                        LX_MAP_RES_MIN, LX_MAP_RES_MAX);
    } else if (f->yaw != 0.0) {
        rc = lx_err_set(err, errlen, path, "origin: yaw %g unsupported (rotated maps; only 0)", f->yaw);
    } else if (f->occ < 0 || f->occ > 1 || f->free_th < 0 || f->free_th > 1) {
        rc = lx_err_set(err, errlen, path, "thresholds must lie in [0, 1] (occupied_thresh %g, free_thresh %g)",
                        f->occ, f->free_th);
    } else if (!(f->free_th < f->occ)) {
        rc = lx_err_set(err, errlen, path, "thresholds out of order: free_thresh %g must be below occupied_thresh %g",
                        f->free_th, f->occ);
    }
out:
    lx_yaml_free(&doc);
    return rc;
}

static int map_load(const char *yaml_path, bool want_values, lx_map_t *m, char *err, size_t errlen)
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
    img_sink_t s;
    memset(&s, 0, sizeof(s));
    s.path = ipath;
    s.r = (lx_map_reading_t){f.occ, f.free_th, f.negate, f.mode};
    s.want_values = want_values;
    char *ip = strdup(ipath);
    if (ip == NULL || image_load(&s, err, errlen) != 0) {
        if (ip == NULL) {
            lx_err_set(err, errlen, yaml_path, "out of memory");
        }
        free(ip);
        free(s.cell);
        free(s.value);
        return -1;
    }
    m->w = s.w;
    m->h = s.h;
    m->res = f.res;
    m->origin_x = f.ox;
    m->origin_y = f.oy;
    m->occ_th = f.occ;
    m->free_th = f.free_th;
    m->negate = f.negate;
    m->mode = f.mode;
    memcpy(m->format, s.format, sizeof(m->format));
    m->n_partial = s.n_partial;
    m->cell = s.cell;
    m->value = s.value;
    m->image_path = ip;
    return 0;
}

int lx_map_load(const char *yaml_path, lx_map_t *m, char *err, size_t errlen)
{
    return map_load(yaml_path, false, m, err, errlen);
}

int lx_map_load_values(const char *yaml_path, lx_map_t *m, char *err, size_t errlen)
{
    return map_load(yaml_path, true, m, err, errlen);
}

void lx_map_free(lx_map_t *m)
{
    if (m != NULL) {
        free(m->cell);
        free(m->value);
        free(m->image_path);
        m->cell = NULL;
        m->value = NULL;
        m->image_path = NULL;
    }
}

void lx_map_count(const lx_map_t *m, uint32_t *n_free, uint32_t *n_occ, uint32_t *n_unknown)
{
    uint32_t c[3] = {0, 0, 0};
    for (size_t i = 0; i < (size_t)m->w * m->h; i++) {
        uint8_t k = m->cell != NULL ? m->cell[i] : lx_map_cell_of(m->value[i]);
        c[k < 3 ? k : LX_CELL_UNKNOWN]++;
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
        return lx_err_set(err, errlen, "map", "core resolution %g out of range (0, 1000] m", core_res);
    }
    if (!(m->res >= LX_MAP_RES_MIN && m->res <= LX_MAP_RES_MAX)) {
        return lx_err_set(err, errlen, "map", "resolution %g m out of range (%g .. %g m per pixel)", m->res,
                          LX_MAP_RES_MIN, LX_MAP_RES_MAX);
    }
    rfs_map_cfg_t c = cfg != NULL ? *cfg : rfs_map_cfg_default();
    /* The core's cells use the Q16 resolution and origin; align the resampling to them. */
    int64_t res_q = llround(core_res * 65536.0);
    double oxd = m->origin_x * 65536.0;
    double oyd = m->origin_y * 65536.0;
    if (res_q <= 0 || fabs(oxd) > 2147483647.0 || fabs(oyd) > 2147483647.0) {
        return lx_err_set(err, errlen, "map", "resolution or origin not representable in Q16.16");
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
        return lx_err_set(err, errlen, "map", "core grid %.0f x %.0f cells at %g m does not fit 1..65535",
                          cwd, chd, core_res);
    }
    /* 2^26 cells (8 MB per bit grid, e.g. 800 x 800 m at 0.1 m): a larger floor is a
     * wrong resolution in the YAML, not a building, and would take minutes to derive. */
    if (cwd * chd > 67108864.0) {
        return lx_err_set(err, errlen, "map", "core grid %.0f x %.0f cells at %g m is over the 2^26-cell limit",
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
        return lx_err_set(err, errlen, "map", "out of memory");
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
        return lx_err_set(err, errlen, "map", "the core rejects the map (%u x %u cells at %g m, clearance %g m, "
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

/* --- crop and save ------------------------------------------------------------------------ */

/* The state of cell i, whichever array the map holds. */
static uint8_t cell_at(const lx_map_t *m, size_t i)
{
    return m->cell != NULL ? m->cell[i] : lx_map_cell_of(m->value[i]);
}

bool lx_map_cell_at(const lx_map_t *m, double x, double y, uint32_t *cx, uint32_t *cy)
{
    const double fx = (x - m->origin_x) / m->res, fy = (y - m->origin_y) / m->res;
    if (!(fx >= 0.0 && fy >= 0.0 && fx < m->w && fy < m->h)) {
        return false;
    }
    *cx = (uint32_t)fx;
    *cy = (uint32_t)fy;
    return true;
}

bool lx_map_known_box(const lx_map_t *m, uint32_t *x0, uint32_t *y0, uint32_t *x1, uint32_t *y1)
{
    uint32_t bx0 = UINT32_MAX;
    uint32_t by0 = UINT32_MAX;
    uint32_t bx1 = 0;
    uint32_t by1 = 0;
    for (uint32_t y = 0; y < m->h; y++) {
        for (uint32_t x = 0; x < m->w; x++) {
            if (cell_at(m, (size_t)y * m->w + x) != LX_CELL_UNKNOWN) {
                bx0 = x < bx0 ? x : bx0;
                bx1 = x > bx1 ? x : bx1;
                by0 = y < by0 ? y : by0;
                by1 = y;
            }
        }
    }
    if (bx0 == UINT32_MAX) {
        return false;
    }
    *x0 = bx0;
    *y0 = by0;
    *x1 = bx1;
    *y1 = by1;
    return true;
}

int lx_map_crop(const lx_map_t *m, uint32_t x0, uint32_t y0, uint32_t w, uint32_t h, lx_map_t *out,
                char *err, size_t errlen)
{
    memset(out, 0, sizeof(*out));
    if (w == 0 || h == 0 || x0 > m->w || y0 > m->h || w > m->w - x0 || h > m->h - y0) {
        return lx_err_set(err, errlen, "map", "crop %u x %u at (%u, %u) outside the %u x %u image", w, h, x0, y0, m->w,
                          m->h);
    }
    uint8_t *dst = malloc((size_t)w * h);
    if (dst == NULL) {
        return lx_err_set(err, errlen, "map", "out of memory");
    }
    const bool values = m->cell == NULL; /* the map holds occupancy values, not cells */
    const uint8_t *src = values ? (const uint8_t *)m->value : m->cell;
    for (uint32_t y = 0; y < h; y++) {
        memcpy(dst + (size_t)y * w, src + (size_t)(y0 + y) * m->w + x0, w);
    }
    *out = *m;
    out->w = w;
    out->h = h;
    out->origin_x = m->origin_x + x0 * m->res;
    out->origin_y = m->origin_y + y0 * m->res;
    out->n_partial = 0;
    out->cell = values ? NULL : dst;
    out->value = values ? (int8_t *)dst : NULL;
    out->image_path = NULL;
    for (size_t i = 0; values && i < (size_t)w * h; i++) {
        out->n_partial += (int8_t)dst[i] > 0 && (int8_t)dst[i] < 100;
    }
    return 0;
}

bool lx_map_save_image_path(const char *yaml_path, char *out, size_t n)
{
    size_t len = strlen(yaml_path);
    const char *dot = strrchr(yaml_path, '.');
    const char *slash = strrchr(yaml_path, '/');
    if (dot != NULL && (slash == NULL || dot > slash) &&
        (strcmp(dot, ".yaml") == 0 || strcmp(dot, ".yml") == 0)) {
        len = (size_t)(dot - yaml_path);
    }
    return (size_t)snprintf(out, n, "%.*s.pgm", (int)len, yaml_path) < n;
}

/* The shortest decimal that reads back as v exactly. */
static void shortest(char *buf, size_t n, double v)
{
    for (int prec = 1; prec <= 17; prec++) {
        snprintf(buf, n, "%.*g", prec, v);
        if (strtod(buf, NULL) == v) {
            return;
        }
    }
}

static int save_pgm(const lx_map_t *m, const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "wb");
    if (f == NULL) {
        return lx_err_set(err, errlen, path, "cannot create: %s", strerror(errno));
    }
    /* Trinary levels as map_saver writes them; the YAML's thresholds keep 205 unknown. */
    static const uint8_t level[3] = {[LX_CELL_FREE] = 254, [LX_CELL_OCC] = 0, [LX_CELL_UNKNOWN] = 205};
    fprintf(f, "P5\n# rfseek-map --crop: free 254, occupied 0, unknown 205\n%u %u\n255\n", m->w, m->h);
    for (uint32_t r = 0; r < m->h; r++) {
        const size_t base = (size_t)(m->h - 1 - r) * m->w; /* PGM row 0 is the top */
        for (uint32_t x = 0; x < m->w; x++) {
            uint8_t k = cell_at(m, base + x);
            putc(level[k < 3 ? k : LX_CELL_UNKNOWN], f);
        }
    }
    if (fflush(f) != 0 || ferror(f)) {
        fclose(f);
        return lx_err_set(err, errlen, path, "write error: %s", strerror(errno));
    }
    return fclose(f) != 0 ? lx_err_set(err, errlen, path, "write error: %s", strerror(errno)) : 0;
}

static int save_yaml(const lx_map_t *m, const char *path, const char *image, char *err, size_t errlen)
{
    char res[32];
    char ox[32];
    char oy[32];
    shortest(res, sizeof(res), m->res);
    /* To 1 nm: the crop's x0 * res adds rounding noise far below any cell. */
    shortest(ox, sizeof(ox), round(m->origin_x * 1e9) / 1e9 + 0.0);
    shortest(oy, sizeof(oy), round(m->origin_y * 1e9) / 1e9 + 0.0);
    FILE *f = fopen(path, "w");
    if (f == NULL) {
        return lx_err_set(err, errlen, path, "cannot create: %s", strerror(errno));
    }
    fputs("# written by rfseek-map --crop (docs/MAPS.md)\nimage: '", f);
    for (const char *c = image; *c != '\0'; c++) {
        fputs(*c == '\'' ? "''" : (char[2]){*c, '\0'}, f); /* a single-quoted YAML scalar */
    }
    fprintf(f, "'\nresolution: %s\norigin: [%s, %s, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
               "free_thresh: 0.1\nmode: trinary\n", res, ox, oy);
    if (fflush(f) != 0 || ferror(f)) {
        fclose(f);
        return lx_err_set(err, errlen, path, "write error: %s", strerror(errno));
    }
    return fclose(f) != 0 ? lx_err_set(err, errlen, path, "write error: %s", strerror(errno)) : 0;
}

int lx_map_save(const lx_map_t *m, const char *yaml_path, char *err, size_t errlen)
{
    char ipath[4096];
    char itmp[4100];
    char ytmp[4100];
    if (!lx_map_save_image_path(yaml_path, ipath, sizeof(ipath)) ||
        (size_t)snprintf(ytmp, sizeof(ytmp), "%s.tmp", yaml_path) >= sizeof(ytmp)) {
        return lx_err_set(err, errlen, yaml_path, "file name too long");
    }
    snprintf(itmp, sizeof(itmp), "%s.tmp", ipath);
    const char *slash = strrchr(ipath, '/');
    const char *iname = slash != NULL ? slash + 1 : ipath;
    for (const char *c = iname; *c != '\0'; c++) {
        if ((unsigned char)*c < 0x20 || *c == 0x7f) {
            return lx_err_set(err, errlen, yaml_path, "the image name would hold a control character");
        }
    }
    int rc = save_pgm(m, itmp, err, errlen);
    rc = rc == 0 ? save_yaml(m, ytmp, iname, err, errlen) : rc;
    if (rc == 0 && rename(itmp, ipath) != 0) {
        rc = lx_err_set(err, errlen, itmp, "cannot rename to %s: %s", ipath, strerror(errno));
    } else if (rc == 0 && rename(ytmp, yaml_path) != 0) {
        rc = lx_err_set(err, errlen, ytmp, "cannot rename to %s: %s", yaml_path, strerror(errno));
        remove(ipath);
    }
    remove(itmp);
    remove(ytmp);
    return rc;
}
