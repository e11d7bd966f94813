/* rfseek-map - inspect a ROS map_server map as the core will see it (docs/MAPS.md).
 *
 *   rfseek-map MAP.yaml [--res 0.1] [--clearance 0.25] [--grid 0.25] [--pgm OUT.pgm]
 *                       [--png OUT.png] [--crop OUT.yaml] [--mcu] [--bench N]
 *
 * Prints the image size, its free / occupied / unknown cells, the core grid at --res,
 * the share of legal cells, the bytes of the core's bit grids and of the planner; --pgm
 * writes the core grid as an image, --png a picture for placing things (hs_mapdraw.h),
 * --crop the known area as a map_server pair, --mcu whether the map fits the STM32
 * image. Every output goes to NAME.tmp first, then is renamed.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "hs_mapdraw.h"
#include "lx_err.h"
#include "lx_map.h"
#include "rfs_app.h"
#include "rfs_plan.h"

static const char k_usage[] =
    "usage: rfseek-map MAP.yaml [--res M] [--clearance M] [--grid M] [--pgm OUT.pgm]\n"
    "                  [--png OUT.png] [--crop OUT.yaml] [--mcu] [--bench N]\n"
    "Load a ROS map_server map (YAML + PGM or PNG image; mode trinary, scale or raw) and\n"
    "report it as the rfseek core sees it.\n"
    "  --res M        core cell size in metres (default 0.1)\n"
    "  --clearance M  free space required around a legal point, metres (default 0.25)\n"
    "  --grid M       lattice spacing for search and planning, metres (default 0.25)\n"
    "  --pgm OUT.pgm  write the core grid as a PGM: legal 255, free but too close to a\n"
    "                 wall or the unknown 200, unknown 128, wall 0 (row 0 = top)\n"
    "  --png OUT.png  draw the map for placing things in world coordinates: each map cell\n"
    "                 S x S pixels, S = ceil(20 x resolution) (a metre is 20 pixels or\n"
    "                 more); white where a start is legal, pale yellow free but within\n"
    "                 the clearance, gray unknown, black occupied; a blue line at every\n"
    "                 whole metre, x = 0 and y = 0 in red, labels in metres. Size\n"
    "                 (88 + S w + 16) x (24 + S h + 44) pixels for a w x h-cell map\n"
    "  --crop OUT.yaml  write the known area (the box of the cells not unknown) as a\n"
    "                 map_server pair OUT.yaml + OUT.pgm (trinary P5): the origin moves\n"
    "                 by the cells cut, so every point keeps its world coordinates and\n"
    "                 its cell; scripts/map2c.py can bake it into the firmware\n"
    "  --mcu          say whether the map fits the STM32 image at --res (bytes per bit\n"
    "                 grid and lattice points against firmware/rfs_app.h, the image's\n"
    "                 0.25 m lattice and clearance), why not, and what would fit\n"
    "  --bench N      plan between N random pairs of legal lattice points (seeded) and\n"
    "                 print the planner's median time, expansions and queue use, and the\n"
    "                 median time to derive the legal grid\n"
    "  -h, --help     this text\n"
    "Exit 0 on success, 1 on a bad map or I/O error, 2 on bad options, 3 when --mcu finds\n"
    "that the map does not fit (the other outputs are written all the same).\n";

static const char PROG[] = "rfseek-map"; /* the prefix of its error lines (lx_err_print) */

/* Option ranges, metres: the core's limits (rfs_map_init: clearance at most 64 m) and
 * lx_map_to_core's (resolution at most 1000 m); both far inside Q16.16's 32767 m, so the
 * conversion below cannot wrap. */
#define MAP_OPT_MAX_M 1000.0
#define MAP_CLEARANCE_MAX_M 64.0

/* A number of metres in [0, max]; one error line and -1 otherwise. */
static int parse_pos(const char *opt, const char *s, double max, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = s != NULL ? strtod(s, &end) : 0.0;
    if (s == NULL || end == s || *end != '\0' || errno != 0 || !isfinite(v) || v < 0) {
        lx_err_print(PROG, "%s: a non-negative number of metres expected, got '%s'", opt,
                 s != NULL ? s : "(nothing)");
        return -1;
    }
    if (v > max) {
        lx_err_print(PROG, "%s: %s m out of range (0 .. %g m)", opt, s, max);
        return -1;
    }
    *out = v;
    return 0;
}

/* Write path through NAME.tmp and a rename: body fills the open file, 0 or -1 with a
 * reason in err. 0, or -1 after one error line (nothing left behind). */
static int write_atomic(const char *path, int (*body)(FILE *f, const void *ctx, char *err, size_t errlen),
                        const void *ctx)
{
    char tmp[4096];
    if ((size_t)snprintf(tmp, sizeof(tmp), "%s.tmp", path) >= sizeof(tmp)) {
        lx_err_print(PROG, "%s: file name too long", path);
        return -1;
    }
    FILE *f = fopen(tmp, "wb");
    if (f == NULL) {
        lx_err_print(PROG, "%s: cannot create: %s", tmp, strerror(errno));
        return -1;
    }
    char err[512] = "write error";
    int rc = body(f, ctx, err, sizeof(err));
    if (rc != 0 || fflush(f) != 0 || ferror(f)) {
        fclose(f);
        lx_err_print(PROG, "%s: %s", tmp, err);
        remove(tmp);
        return -1;
    }
    if (fclose(f) != 0) {
        lx_err_print(PROG, "%s: write error", tmp);
        remove(tmp);
        return -1;
    }
    if (rename(tmp, path) != 0) {
        lx_err_print(PROG, "%s: cannot rename to %s: %s", tmp, path, strerror(errno));
        remove(tmp);
        return -1;
    }
    return 0;
}

static int pgm_body(FILE *f, const void *ctx, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    const lx_core_map_t *c = ctx;
    const rfs_map_t *m = &c->map;
    fprintf(f, "P5\n# rfseek-map core grid: legal 255, free 200, unknown 128, wall 0\n%u %u\n255\n",
            m->w, m->h);
    for (int32_t y = (int32_t)m->h - 1; y >= 0; y--) {
        for (uint16_t x = 0; x < m->w; x++) {
            uint8_t v = 128;
            if (rfs_map_bit(m->legal, m->stride, x, (uint16_t)y)) {
                v = 255;
            } else if (rfs_map_bit(m->free, m->stride, x, (uint16_t)y)) {
                v = 200;
            } else if (rfs_map_bit(c->wall_bits, m->stride, x, (uint16_t)y)) {
                v = 0;
            }
            fputc(v, f);
        }
    }
    return 0;
}

/* The map and its converted core map, for the picture. */
typedef struct png_job {
    const lx_map_t *m;
    const lx_core_map_t *c;
} png_job_t;

static int png_body(FILE *f, const void *ctx, char *err, size_t errlen)
{
    const png_job_t *j = ctx;
    return hs_mapdraw_png(j->m, &j->c->map, f, err, errlen);
}

/* --- --mcu: the STM32 image's verdict ------------------------------------------------------ */

/* A map against the firmware's limits at one core resolution. */
typedef struct mcu_fit {
    bool converted;        /* lx_map_to_core accepted it (why holds its reason when not) */
    char why[512];
    uint16_t w, h, lw, lh; /* core grid and lattice */
    uint32_t bytes;        /* per bit grid */
    uint32_t lattice;      /* points */
    bool init_ok;          /* rfs_app_init accepted it */
} mcu_fit_t;

static bool mcu_fits(const mcu_fit_t *f)
{
    return f->converted && f->bytes <= RFS_APP_MAX_MAP_BYTES && f->lattice <= RFS_APP_MAX_LATTICE && f->init_ok;
}

/* Convert m at res with the image's map configuration and ask the firmware's own
 * rfs_app_init (rfs_app_cfg_mcu()) when the sizes are within its arrays. 0, or -1 out of
 * memory. */
static int mcu_check(const lx_map_t *m, double res, mcu_fit_t *f)
{
    memset(f, 0, sizeof(*f));
    rfs_app_cfg_t cfg = rfs_app_cfg_mcu();
    lx_core_map_t c;
    if (lx_map_to_core(m, res, &cfg.map, &c, f->why, sizeof(f->why)) != 0) {
        return 0;
    }
    f->converted = true;
    f->w = c.map.w;
    f->h = c.map.h;
    f->lw = c.map.lw;
    f->lh = c.map.lh;
    f->bytes = rfs_map_bytes(c.map.w, c.map.h);
    f->lattice = (uint32_t)c.map.lw * c.map.lh;
    int rc = 0;
    if (f->bytes <= RFS_APP_MAX_MAP_BYTES && f->lattice <= RFS_APP_MAX_LATTICE) {
        rfs_app_t *app = malloc(sizeof(*app));
        cfg.samples = calloc(RFS_APP_MAX_SAMPLES, sizeof(rfs_sample_t));
        if (app == NULL || cfg.samples == NULL) {
            rc = -1;
        } else {
            const rfs_app_map_t am = {c.map.w, c.map.h, c.map.res, c.map.origin_x, c.map.origin_y,
                                      c.free_bits, c.wall_bits};
            f->init_ok = rfs_app_init(app, &cfg, &am) == 0;
        }
        free(cfg.samples);
        free(app);
    }
    lx_core_map_free(&c);
    return rc;
}

/* The finest whole multiple of the map's resolution above res, up to 1 m (rfseekd's
 * --res range), at which m fits; 0 when none does or the lattice is what overflows. */
static double mcu_coarser(const lx_map_t *m, double res, const mcu_fit_t *at_res)
{
    if (!at_res->converted || at_res->lattice > RFS_APP_MAX_LATTICE) {
        return 0;
    }
    for (int k = 1; k * m->res <= 1.0 + 1e-9; k++) {
        double r = k * m->res;
        /* Skip without converting while even the grid's bare size is too large. */
        double cw = ceil(m->w * m->res / r - 1e-9);
        double ch = ceil(m->h * m->res / r - 1e-9);
        if (r <= res + 1e-9 || ceil(cw / 8.0) * ch > RFS_APP_MAX_MAP_BYTES) {
            continue;
        }
        mcu_fit_t f;
        if (mcu_check(m, r, &f) != 0) {
            return 0;
        }
        if (mcu_fits(&f)) {
            return r;
        }
    }
    return 0;
}

static void mcu_print(const char *what, const mcu_fit_t *f)
{
    if (!f->converted) {
        printf("mcu          - %s: %s\n", what, f->why);
        return;
    }
    printf("mcu          - %s: bit grids %u x %u cells, %u bytes each of the image's %u "
           "(RFS_APP_MAX_MAP_BYTES)%s\n", what, f->w, f->h, f->bytes, RFS_APP_MAX_MAP_BYTES,
           f->bytes > RFS_APP_MAX_MAP_BYTES ? ": too large" : "");
    printf("mcu          - %s: lattice %u x %u = %u points of the image's %u (RFS_APP_MAX_LATTICE)%s\n", what,
           f->lw, f->lh, f->lattice, RFS_APP_MAX_LATTICE, f->lattice > RFS_APP_MAX_LATTICE ? ": too many" : "");
    if (f->bytes <= RFS_APP_MAX_MAP_BYTES && f->lattice <= RFS_APP_MAX_LATTICE && !f->init_ok) {
        printf("mcu          - %s: rfs_app_init refuses it\n", what);
    }
}

/* The --mcu report: 0 when the map fits the image, 3 when not, 1 out of memory. */
static int report_mcu(const lx_map_t *m, double res)
{
    mcu_fit_t f;
    if (mcu_check(m, res, &f) != 0) {
        lx_err_print(PROG, "--mcu: out of memory");
        return 1;
    }
    const bool fits = mcu_fits(&f);
    printf("mcu          %s the STM32 image at %g m cells (docs/MAPS.md, \"The largest map on the "
           "microcontroller\")\n", fits ? "fits" : "does NOT fit", res);
    mcu_print("map", &f);
    if (fits && 2u * ((uint32_t)f.lw + f.lh) > RFS_APP_PLAN_QUEUE) {
        printf("mcu          - note: the planner queue holds %u entries, under 2 x (lw + lh) = %u: a long plan "
               "may fail\n", RFS_APP_PLAN_QUEUE, 2u * ((uint32_t)f.lw + f.lh));
    }
    uint32_t x0;
    uint32_t y0;
    uint32_t x1;
    uint32_t y1;
    lx_map_t crop;
    memset(&crop, 0, sizeof(crop));
    char err[512];
    const lx_map_t *target = m;
    mcu_fit_t cf = f;
    if (!fits && lx_map_known_box(m, &x0, &y0, &x1, &y1) && (x1 - x0 + 1 < m->w || y1 - y0 + 1 < m->h) &&
        lx_map_crop(m, x0, y0, x1 - x0 + 1, y1 - y0 + 1, &crop, err, sizeof(err)) == 0) {
        if (mcu_check(&crop, res, &cf) != 0) {
            lx_map_free(&crop);
            lx_err_print(PROG, "--mcu: out of memory");
            return 1;
        }
        printf("mcu          the known area, %u x %u cells from column %u, row %u (x %g .. %g m, y %g .. %g m), "
               "%s\n", crop.w, crop.h, x0, y0, crop.origin_x, crop.origin_x + crop.w * crop.res, crop.origin_y,
               crop.origin_y + crop.h * crop.res,
               mcu_fits(&cf) ? "fits: --crop OUT.yaml writes it" : "does not fit either");
        if (!mcu_fits(&cf)) {
            mcu_print("known area", &cf);
        }
        target = &crop;
    }
    if (!fits && !mcu_fits(&cf)) {
        double r = mcu_coarser(target, res, &cf);
        if (r > 0) {
            printf("mcu          %s fits at --res %g (%d image cells a side)\n",
                   target == m ? "the map" : "the known area", r, (int)lround(r / m->res));
        } else {
            printf("mcu          no coarser resolution up to 1 m makes it fit%s\n",
                   cf.converted && cf.lattice > RFS_APP_MAX_LATTICE ? " (the lattice is too large)" : "");
        }
    }
    lx_map_free(&crop);
    /* What scripts/map2c.py, which bakes a map into the image, reads. */
    double k = res / m->res;
    if (fabs(k - lround(k)) > 1e-6 || lround(k) < 1) {
        printf("mcu          note: scripts/map2c.py bakes a map only at a whole multiple of its %g m cells\n",
               m->res);
    }
    if (m->mode != LX_MAP_TRINARY || strcmp(m->format, "PGM P5, maxval 255") != 0) {
        printf("mcu          note: scripts/map2c.py reads trinary P5 PGMs of maxval 255: --crop OUT.yaml "
               "writes one\n");
    }
    return fits ? 0 : 3;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int cmp_double(const void *a, const void *b)
{
    double d = *(const double *)a - *(const double *)b;
    return d < 0 ? -1 : d > 0;
}

/* Planner and legal-grid figures for docs/PERFORMANCE.md. */
static void run_bench(const lx_core_map_t *c, long n)
{
    const rfs_map_t *m = &c->map;
    uint32_t lat = (uint32_t)m->lw * m->lh;
    uint32_t cap_big = 4u * lat + 64u;
    uint32_t cap_doc = 2u * ((uint32_t)m->lw + m->lh);
    uint8_t *work = malloc(lat); // NOLINT(clang-analyzer-optin.portability.UnixAPI): an initialised map has lw, lh >= 1
    uint32_t *queue = malloc(cap_big * sizeof(*queue));
    uint8_t *legal = malloc(rfs_map_bytes(m->w, m->h)); // NOLINT(clang-analyzer-optin.portability.UnixAPI): w, h >= 1
    double *t = malloc((size_t)n * sizeof(*t)); // NOLINT(clang-analyzer-optin.portability.UnixAPI): --bench N is 1..1000000
    double *e = malloc((size_t)n * sizeof(*e));
    if (work == NULL || queue == NULL || legal == NULL || t == NULL || e == NULL) {
        fprintf(stderr, "rfseek-map: out of memory for --bench\n");
        exit(1);
    }
    rfs_plan_t big;
    rfs_plan_t doc;
    rfs_plan_init(&big, m, work, lat, queue, cap_big);
    rfs_plan_init(&doc, m, work, lat, queue, cap_doc);
    rfs_rng_t rng;
    rfs_rng_seed(&rng, 1);
    uint32_t reach = 0;
    uint32_t peak = 0;
    uint32_t doc_fail = 0;
    double ratio_sum = 0;
    long k = 0;
    while (k < n) {
        uint16_t i0 = (uint16_t)rfs_rng_below(&rng, m->lw), j0 = (uint16_t)rfs_rng_below(&rng, m->lh);
        uint16_t i1 = (uint16_t)rfs_rng_below(&rng, m->lw), j1 = (uint16_t)rfs_rng_below(&rng, m->lh);
        if (!rfs_map_lattice_legal(m, i0, j0) || !rfs_map_lattice_legal(m, i1, j1)) {
            continue;
        }
        rfs_q16_t x0, y0, x1, y1;
        rfs_map_lattice_point(m, i0, j0, &x0, &y0);
        rfs_map_lattice_point(m, i1, j1, &x1, &y1);
        rfs_path_t path;
        double t0 = now_s();
        bool ok = rfs_plan_path(&big, x0, y0, x1, y1, &path);
        t[k] = now_s() - t0;
        e[k] = big.expanded;
        if (big.queue_peak > peak) {
            peak = big.queue_peak;
        }
        if (ok) {
            reach++;
            double straight = hypot(x1 - x0, y1 - y0) / 65536.0;
            ratio_sum += straight > 0 ? (path.length / 65536.0) / straight : 1.0;
            rfs_path_t p2;
            doc_fail += !rfs_plan_path(&doc, x0, y0, x1, y1, &p2);
        }
        k++;
    }
    qsort(t, (size_t)n, sizeof(*t), cmp_double);
    qsort(e, (size_t)n, sizeof(*e), cmp_double);
    double tl[7];
    for (int r = 0; r < 7; r++) {
        double t0 = now_s();
        rfs_map_t mm;
        rfs_map_init(&mm, &m->cfg, m->w, m->h, m->res, m->origin_x, m->origin_y, m->free, m->wall, legal);
        tl[r] = now_s() - t0;
    }
    qsort(tl, 7, sizeof(*tl), cmp_double);
    printf("bench        %ld plans between random legal lattice points: %u reachable\n", n, reach);
    printf("bench plan   median %.3f ms, max %.3f ms, median %.0f / max %.0f points expanded\n",
           t[n / 2] * 1e3, t[n - 1] * 1e3, e[n / 2], e[n - 1]);
    printf("bench queue  peak %u entries per quarter (%u for the whole queue); with the\n"
           "             documented 2 * (lw + lh) = %u entries: %u of %u reachable plans failed\n",
           peak, 4 * peak, cap_doc, doc_fail, reach);
    printf("bench path   mean planned length / straight line %.3f\n", reach ? ratio_sum / reach : 0.0);
    printf("bench legal  median %.2f ms to derive the legal grid (rfs_map_init)\n", tl[3] * 1e3);
    /* What planning buys over straight moves only: goals a greedy step (<= 1 m) or an
     * epsilon step (mostly within a few metres) away, from random legal points. */
    const double radii[3] = {1.0, 3.0, 10.0};
    for (int ri = 0; ri < 3; ri++) {
        int32_t rl = (int32_t)lround(radii[ri] / (m->cfg.grid / 65536.0));
        uint32_t los = 0;
        uint32_t planned = 0;
        uint32_t none = 0;
        long got = 0;
        while (got < n) {
            uint16_t i0 = (uint16_t)rfs_rng_below(&rng, m->lw), j0 = (uint16_t)rfs_rng_below(&rng, m->lh);
            int32_t i1 = i0 + (int32_t)rfs_rng_below(&rng, 2u * (uint32_t)rl + 1u) - rl;
            int32_t j1 = j0 + (int32_t)rfs_rng_below(&rng, 2u * (uint32_t)rl + 1u) - rl;
            if ((i1 - i0) * (i1 - i0) + (j1 - j0) * (j1 - j0) > rl * rl || (i1 == i0 && j1 == j0) ||
                i1 < 0 || j1 < 0 || i1 >= m->lw || j1 >= m->lh || !rfs_map_lattice_legal(m, i0, j0) ||
                !rfs_map_lattice_legal(m, (uint16_t)i1, (uint16_t)j1)) {
                continue;
            }
            rfs_q16_t x0, y0, x1, y1;
            rfs_map_lattice_point(m, i0, j0, &x0, &y0);
            rfs_map_lattice_point(m, (uint16_t)i1, (uint16_t)j1, &x1, &y1);
            rfs_path_t path;
            if (rfs_map_segment_legal(m, x0, y0, x1, y1)) {
                los++;
            } else if (rfs_plan_path(&big, x0, y0, x1, y1, &path)) {
                planned++;
            } else {
                none++;
            }
            got++;
        }
        printf("bench goals  within %4.1f m: %5.1f %% in line of sight, %5.1f %% need a planned path, "
               "%5.1f %% unreachable\n", radii[ri], 100.0 * los / n, 100.0 * planned / n, 100.0 * none / n);
    }
    free(work);
    free(queue);
    free(legal);
    free(t);
    free(e);
}

/* The options. */
typedef struct opts {
    const char *yaml;
    const char *pgm;
    const char *png;
    const char *crop;
    char crop_image[4096]; /* the image --crop writes beside its YAML */
    bool mcu;
    double res, clearance, grid;
    long bench;
} opts_t;

/* 0, or the exit status after one error line. */
static int parse_opts(int argc, char **argv, opts_t *o)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(k_usage, stdout);
            return -1;
        } else if (strcmp(a, "--pgm") == 0 || strcmp(a, "--png") == 0 || strcmp(a, "--crop") == 0) {
            const char *v = i + 1 < argc ? argv[++i] : NULL;
            if (v == NULL || *v == '\0') {
                lx_err_print(PROG, "%s: an output file name expected", a);
                return 2;
            }
            if (lx_err_path_opt(PROG, a, v) != 0) {
                return 2;
            }
            *(strcmp(a, "--pgm") == 0 ? &o->pgm : strcmp(a, "--png") == 0 ? &o->png : &o->crop) = v;
        } else if (strcmp(a, "--res") == 0 || strcmp(a, "--clearance") == 0 || strcmp(a, "--grid") == 0) {
            const char *v = i + 1 < argc ? argv[++i] : NULL;
            if (strcmp(a, "--clearance") == 0
                    ? parse_pos(a, v, MAP_CLEARANCE_MAX_M, &o->clearance) != 0
                    : parse_pos(a, v, MAP_OPT_MAX_M, strcmp(a, "--res") == 0 ? &o->res : &o->grid) != 0) {
                return 2;
            }
        } else if (strcmp(a, "--mcu") == 0) {
            o->mcu = true;
        } else if (strcmp(a, "--bench") == 0) {
            const char *v = i + 1 < argc ? argv[++i] : NULL;
            char *end = NULL;
            o->bench = v != NULL ? strtol(v, &end, 10) : -1;
            if (v == NULL || *end != '\0' || o->bench < 1 || o->bench > 1000000) {
                lx_err_print(PROG, "--bench: a count 1..1000000 expected, got '%s'", v != NULL ? v : "(nothing)");
                return 2;
            }
        } else if (a[0] == '-' && a[1] != '\0') {
            lx_err_print(PROG, "%s: unknown option (see --help)", a);
            return 2;
        } else if (o->yaml == NULL) {
            o->yaml = a;
        } else {
            lx_err_print(PROG, "%s: only one map expected (see --help)", a);
            return 2;
        }
    }
    if (o->yaml == NULL) {
        lx_err_print(PROG, "no map given (see --help)");
        return 2;
    }
    if (!(o->res > 0) || !(o->grid > 0)) {
        lx_err_print(PROG, "%s: must be > 0 metres", o->res > 0 ? "--grid" : "--res");
        return 2;
    }
    if (o->crop != NULL && !lx_map_save_image_path(o->crop, o->crop_image, sizeof(o->crop_image))) {
        lx_err_print(PROG, "--crop: %s: file name too long", o->crop);
        return 2;
    }
    return 0;
}

/* Every output is neither an input (the YAML, and once known the image) nor another
 * output, and can be created. 0, or -1 after one error line. */
static int check_outputs(const opts_t *o, const char *image)
{
    const char *outs[4] = {o->pgm, o->png, o->crop, o->crop != NULL ? o->crop_image : NULL};
    for (int i = 0; i < 4; i++) {
        if (outs[i] == NULL) {
            continue;
        }
        if (lx_err_same_file(PROG, image != NULL ? image : o->yaml, outs[i]) != 0 ||
            (image == NULL && lx_err_check_dest(PROG, outs[i]) != 0)) {
            return -1;
        }
        for (int j = 0; j < i && image == NULL; j++) {
            if (outs[j] != NULL && lx_err_same_dest(PROG, outs[j], outs[i]) != 0) {
                return -1;
            }
        }
    }
    return 0;
}

/* --crop: the known area written as a map_server pair. 0, or 1 after one error line. */
static int write_crop(const lx_map_t *m, const opts_t *o)
{
    uint32_t x0;
    uint32_t y0;
    uint32_t x1;
    uint32_t y1;
    if (!lx_map_known_box(m, &x0, &y0, &x1, &y1)) {
        lx_err_print(PROG, "%s: --crop: every cell is unknown, nothing to keep", o->yaml);
        return 1;
    }
    lx_map_t crop;
    char err[1024];
    if (lx_map_crop(m, x0, y0, x1 - x0 + 1, y1 - y0 + 1, &crop, err, sizeof(err)) != 0 ||
        lx_map_save(&crop, o->crop, err, sizeof(err)) != 0) {
        lx_err_print(PROG, "%s", err);
        lx_map_free(&crop);
        return 1;
    }
    printf("crop         %u x %u cells from column %u, row %u: origin (%g, %g), %s + %s\n", crop.w, crop.h, x0, y0,
           crop.origin_x, crop.origin_y, o->crop, o->crop_image);
    lx_map_free(&crop);
    return 0;
}

static int map_main(int argc, char **argv)
{
    opts_t o = {.res = 0.1, .clearance = 0.25, .grid = 0.25};
    int orc = parse_opts(argc, argv, &o);
    if (orc != 0) {
        return orc < 0 ? 0 : orc;
    }
    const char *yaml = o.yaml;
    const double res = o.res;
    char err[1024];
    lx_map_t m;
    if (check_outputs(&o, NULL) != 0) {
        return 1;
    }
    if (lx_map_load(yaml, &m, err, sizeof(err)) != 0) {
        lx_err_print(PROG, "%s", err);
        return 1;
    }
    if (check_outputs(&o, m.image_path) != 0) {
        lx_map_free(&m);
        return 1;
    }
    rfs_map_cfg_t cfg = rfs_map_cfg_default();
    cfg.clearance = (rfs_q16_t)lround(o.clearance * 65536.0);
    cfg.grid = (rfs_q16_t)lround(o.grid * 65536.0);
    lx_core_map_t c;
    if (lx_map_to_core(&m, res, &cfg, &c, err, sizeof(err)) != 0) {
        lx_err_print(PROG, "%s: %s", yaml, err);
        lx_map_free(&m);
        return 1;
    }
    uint32_t nf;
    uint32_t no;
    uint32_t nu;
    lx_map_count(&m, &nf, &no, &nu);
    const rfs_map_t *cm = &c.map;
    uint32_t cfree = 0;
    uint32_t cwall = 0;
    uint32_t clegal = 0;
    for (uint16_t y = 0; y < cm->h; y++) {
        for (uint16_t x = 0; x < cm->w; x++) {
            cfree += rfs_map_bit(cm->free, cm->stride, x, y);
            cwall += rfs_map_bit(c.wall_bits, cm->stride, x, y);
            clegal += rfs_map_bit(cm->legal, cm->stride, x, y);
        }
    }
    uint32_t llegal = 0;
    for (uint16_t j = 0; j < cm->lh; j++) {
        for (uint16_t i = 0; i < cm->lw; i++) {
            llegal += rfs_map_lattice_legal(cm, i, j);
        }
    }
    uint32_t grid_bytes = rfs_map_bytes(cm->w, cm->h);
    uint32_t cells = (uint32_t)cm->w * cm->h;
    uint32_t lattice = (uint32_t)cm->lw * cm->lh;
    printf("map          %s\n", yaml);
    printf("image        %u x %u cells at %g m = %.2f x %.2f m, origin (%g, %g)\n", m.w, m.h, m.res,
           m.w * m.res, m.h * m.res, m.origin_x, m.origin_y);
    printf("image cells  free %u, occupied %u, unknown %u\n", nf, no, nu);
    printf("reading      %s, mode %s, negate %d", m.format,
           m.mode == LX_MAP_SCALE ? "scale" : m.mode == LX_MAP_RAW ? "raw" : "trinary", m.negate);
    if (m.mode != LX_MAP_TRINARY) {
        printf(": %u cells of value 1..99, read as free", m.n_partial);
    }
    printf("\n");
    printf("core grid    %u x %u cells at %g m (Q16 %.7f m)\n", cm->w, cm->h, res, cm->res / 65536.0);
    printf("core cells   free %u, wall %u, legal %u (clearance %g m)\n", cfree, cwall, clegal,
           o.clearance);
    printf("legal share  %.1f %% of the core cells, %.1f %% of the free ones\n",
           100.0 * clegal / cells, cfree ? 100.0 * clegal / cfree : 0.0);
    printf("core bytes   %u per bit grid: free + legal %u, with wall %u\n", grid_bytes,
           2 * grid_bytes, 3 * grid_bytes);
    printf("lattice      %u x %u points at %g m, %u legal (%.1f %%)\n", cm->lw, cm->lh, o.grid, lattice
           ? llegal : 0, lattice ? 100.0 * llegal / lattice : 0.0);
    printf("planner      %u bytes work (1 per lattice point) + queue\n", lattice);
    if (o.bench > 0) {
        run_bench(&c, o.bench);
    }
    int rc = o.mcu ? report_mcu(&m, res) : 0;
    const png_job_t pj = {&m, &c};
    if ((o.pgm != NULL && write_atomic(o.pgm, pgm_body, &c) != 0) ||
        (o.png != NULL && write_atomic(o.png, png_body, &pj) != 0) || (o.crop != NULL && write_crop(&m, &o) != 0)) {
        rc = 1;
    }
    lx_core_map_free(&c);
    lx_map_free(&m);
    return rc;
}

int main(int argc, char **argv)
{
    return lx_err_close_stdout(PROG, map_main(argc, argv));
}
